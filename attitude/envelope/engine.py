"""The envelope's failures on Dask, through the jobs' engine: the same local cluster
or scheduler as the Monte Carlo's (:mod:`attitude.jobs.cluster`), batch sizes from the
measured costs (:func:`attitude.jobs.batches.choose_batch_size`), results gathered as
tasks finish (:func:`attitude.jobs.batches.gather`), a progress callback.

Each failure is computed from the job alone (its hand-off state, the shared
surroundings, one step for the splitting chosen before the job), so the table is the
same whatever the number of workers and the batch size; the rows are sorted by τ.
With one worker and no scheduler the batches run in this process, no cluster.  A
batch is kept in the job's checkpoint as it comes in (:mod:`attitude.jobs.checkpoint`),
and a job resumed from it gives the same table, to the last bit.  A failure time
whose motion is refused is a row saying so; anything else (a bug, a lost scheduler,
workers that keep dying) ends the job (:mod:`attitude.jobs.failures`).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from attitude.envelope.failure import BatchResult, evaluate_batch
from attitude.envelope.plan import EnvelopePlan, make_job
from attitude.jobs.batches import check_batch_size, choose_batch_size, gather, split_ranges
from attitude.jobs.checkpoint import Checkpoint, batch_table, canonical_rows, missing_ranges
from attitude.jobs.cluster import WORKER_MODULES, check_where, workers_for

if TYPE_CHECKING:
    import pandas

__all__ = ["EnvelopeResult", "simulate"]

# Failures timed on the client to size the batches.
_TIMED = 2

# What a worker imports before its first failure, beside the cluster's own list.
_FAILURE_MODULES = ("attitude.envelope.failure",)


@dataclass
class EnvelopeResult:
    """The table (one row a failure, in τ order) and how the job ran."""

    plan: EnvelopePlan
    table: pandas.DataFrame
    execution: dict[str, Any]


def simulate(
    plan: EnvelopePlan,
    scheduler: str | None = None,
    workers: int | None = None,
    batch_size: int | None = None,
    progress: Callable[[int, int, int], None] | None = None,
    stage: Callable[[str], None] | None = None,
    probed: bool = False,
    checkpoint: Checkpoint | None = None,
) -> EnvelopeResult:
    """Compute every failure of ``plan`` on Dask (module notes); ``progress(done,
    total, failed)`` as batches finish, ``stage(text)`` what is happening;
    ``checkpoint``: where finished batches are kept, and those already there are
    taken as they are (``--resume``)."""
    import pandas

    stage = stage or (lambda text: None)
    check_batch_size(batch_size, plan.count)
    count = check_where(scheduler, workers, probe=not probed)
    started = time.perf_counter()
    stage("the nominal timeline and the hand-off states")
    job, epochs, modes = make_job(plan)
    gathered = _Gathered(job.count, _checkpoint_columns(plan), checkpoint)
    missing = gathered.resume(stage)
    size = tasks = threads = 0
    described, failure_s = "the checkpoint (nothing left to compute)", math.nan
    if missing:
        # The first failures left, timed here to size the batches: a batch of the job
        # like any other (each row is the same bits in any process and any batch).
        first = missing[0][0]
        stop = min(first + _TIMED, missing[0][1])
        stage(f"timing {stop - first} failure{'s' if stop - first > 1 else ''} in this process")
        timed = evaluate_batch(job, first, stop)
        gathered.add_new(first, stop, timed)
        failure_s = timed.compute_s / (stop - first)
        stage(f"{failure_s * 1e3:.3g} ms a failure")
        missing = missing_ranges(job.count, gathered.finished)
    if missing:
        if scheduler is None and count > 1:
            stage(f"starting a local Dask cluster of {count} worker processes")
        preload = WORKER_MODULES + _FAILURE_MODULES
        with workers_for(scheduler, workers, preload, probed=True) as where:
            threads, described = where.threads, where.described
            left = sum(b - a for a, b in missing)
            size = batch_size or choose_batch_size(left, threads, failure_s, where.overhead_s)
            batches = split_ranges(missing, size)
            tasks = len(batches)
            stage(
                f"{left} failures on {threads} worker{'s' if threads > 1 else ''} "
                f"({where.where}): {tasks} tasks of {size}"
            )
            gather(
                where,
                evaluate_batch,
                job,
                batches,
                job.count,
                gathered.add_new,
                progress,
                "failures",
                done=job.count - left,
                failed=gathered.failed,
            )
    elif progress:
        progress(job.count, job.count, gathered.failed)
    rows = sorted(gathered.rows, key=lambda row: row["failure"])
    for row in rows:
        row["epoch_utc"] = epochs[row["failure"]]
        row["mode"] = modes[row["failure"]]
    table = pandas.DataFrame(rows, columns=plan.columns)
    execution = {
        "scheduler": described,
        "workers": threads,
        "batch_size": size,
        "tasks": tasks,
        "resumed_failures": gathered.resumed,
        "failure_s": failure_s,
        "compute_s": gathered.compute_s,
        "wall_s": time.perf_counter() - started,
        "step_s": job.step,
    }
    return EnvelopeResult(plan, table, execution)


def _checkpoint_columns(plan: EnvelopePlan) -> list[str]:
    """A batch's columns as a task computes them (the epoch and the mode come after)."""
    return [c for c in plan.columns if c not in ("epoch_utc", "mode")]


@dataclass
class _Gathered:
    """The finished tasks' rows, kept in the checkpoint (if any) as they come in."""

    count: int
    columns: list[str]
    checkpoint: Checkpoint | None
    rows: list[dict[str, Any]] = field(default_factory=list)
    finished: list[int] = field(default_factory=list)  # the failures added
    failed: int = 0
    resumed: int = 0
    compute_s: float = 0.0

    def add_new(self, first: int, stop: int, result: BatchResult) -> int:
        """A batch just computed: kept, then added as it reads back."""
        import pandas

        table = batch_table(pandas.DataFrame(result.rows, columns=self.columns))
        if self.checkpoint is not None:
            self.checkpoint.add(table, {"compute_s": result.compute_s})
        self.finished += range(first, stop)
        return self._add(table, result.compute_s)

    def resume(self, stage: Callable[[str], None]) -> list[tuple[int, int]]:
        """Add the checkpoint's batches; the ranges of failures still to compute."""
        if self.checkpoint is None:
            return [(0, self.count)]
        for table, meta in self.checkpoint.parts():
            self._add(table, meta["compute_s"])
            self.finished += table.column("failure").to_pylist()
        self.resumed = len(self.finished)
        if self.resumed:
            kept = self.checkpoint.shown
            stage(f"resumed: {self.resumed} of {self.count} failures from {kept}")
        return missing_ranges(self.count, self.finished)

    def _add(self, table, compute_s: float) -> int:
        rows = canonical_rows(table)
        self.rows += rows
        self.compute_s += compute_s
        failed = sum(row["status"] != "ok" for row in rows)
        self.failed += failed
        return failed
