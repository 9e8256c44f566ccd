"""Scenario files: the TOML format read into a scenario (and an initial attitude read from
an AEM), and scenario documents written back.

Modules:

- ``aem_reader``: An attitude read from a CCSDS Attitude Ephemeris Message (AEM 2.0,
  KVN) at an epoch.
- ``law_reader``: Attitude laws, slews, wheels and ground sites in scenario files.
- ``scenario_reader``: Scenario files: the TOML format (``docs/scenarios.md``) read into
  a Scenario.
- ``scenario_writer``: Scenario files written back: a scenario document (the TOML that
  :mod:`attitude.files.scenario_reader` reads) as text that reads back to the same
  document.
"""
