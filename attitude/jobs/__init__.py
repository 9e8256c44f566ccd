"""Long jobs on Dask, shared by the Monte Carlo and the envelope: where a job runs (a
local cluster, a scheduler, or this process), its workers checked, its batches and
their gathering, what its failures are, and its checkpoint.

Modules:

- ``batches``: A job's batches: how many items a task takes (from the measured costs),
  the batches' ranges, and the tasks sent to the cluster and gathered as they finish.
- ``checkpoint``: A long job's finished batches, kept as they arrive, so that an
  interrupted job continues with ``--resume`` from what was finished.
- ``cluster``: Where a long job runs (a Monte Carlo job, an envelope): a
  ``distributed.Client`` to a local cluster or to a scheduler, or this very process;
  its workers checked (the same code) and its cost per task measured.
- ``failures``: What a job's failures are: the item's own, the machine's, or ours.
- ``fingerprint``: What a process runs: a digest of the package's code and the
  versions of the libraries its numbers depend on.
"""
