"""The command line: ``attitude run``, ``check`` and ``montecarlo``.

Modules:

- ``main``: The command line: ``attitude run``, ``check`` and ``montecarlo`` (also
  ``python -m attitude``).
- ``montecarlo``: ``attitude montecarlo``: the command (its options are parsed in
  ``attitude.cli.main``).
"""
