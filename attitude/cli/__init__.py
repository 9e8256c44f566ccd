"""The command line: ``attitude run``, ``check``, ``montecarlo`` and ``fit``.

Modules:

- ``fit``: ``attitude fit``: the spin state and inertia ratios fitted to a telemetry
  file.
- ``main``: The command line: ``attitude run``, ``check`` and ``montecarlo`` (also
  ``python -m attitude``).
- ``montecarlo``: ``attitude montecarlo``: the command (its options are parsed in
  ``attitude.cli.main``).
"""
