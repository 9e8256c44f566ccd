"""The command line: ``attitude run``, ``check``, ``montecarlo`` and ``fit``.

Modules:

- ``envelope``: ``attitude envelope``: the command (its options are parsed in
  ``attitude.cli.main``).
- ``fit``: ``attitude fit``: the spin state and inertia ratios fitted to a telemetry
  file.
- ``main``: The command line: ``attitude run``, ``check``, ``montecarlo`` and ``envelope``
  (also ``python -m attitude``).
- ``montecarlo``: ``attitude montecarlo``: the command (its options are parsed in
  ``attitude.cli.main``).
"""
