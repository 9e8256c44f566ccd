"""The files of a run: CSV, Parquet and CCSDS AEM writers, the AEM's sampling, the formats
a user chooses, the size budget, and the output folder's rules.

Modules:

- ``aem_sampling``: Where the AEM's records go: dense enough that a reader who
  interpolates them as the file declares stays within a stated tolerance of the exact
  attitude.
- ``aem_writer``: CCSDS Attitude Ephemeris Messages (AEM 2.0, KVN): the writer.
- ``budget``: How much a run writes and holds in memory, and whether that fits: decided
  before anything is sampled.
- ``csv``: The CSV files of a run: the time series of a propagated scenario (its
  columns, which the Parquet file shares, and the CSV) and intervals.csv (the JSON
  summary is :mod:`attitude.report.summaries`).
- ``folder``: Output folders: ``attitude`` removes or overwrites only files it wrote
  itself.
- ``formats``: Which outputs a run writes: the formats the user chooses, and the files
  each one is.
- ``lock``: One run at a time in an output folder: a lock the tool owns, taken before
  anything is computed (``attitude run``, ``montecarlo``, ``envelope``).
- ``parquet``: ``timeseries.parquet``: the time series in Apache Parquet, a row group
  per chunk.
"""
