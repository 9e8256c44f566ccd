"""Long jobs on Dask, shared by the Monte Carlo and the envelope: where a job runs (a
local cluster or a scheduler, its workers checked), its batches and their gathering.

Modules:

- ``batches``: A job's batches: how many items a task takes (from the measured costs),
  the batches' ranges, and the tasks sent to the cluster and gathered as they finish.
- ``cluster``: Where a long job runs (a Monte Carlo job, an envelope): a
  ``distributed.Client`` to a local cluster or to a scheduler, its workers checked
  (the same versions) and its cost per task measured.
"""
