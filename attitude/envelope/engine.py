"""The envelope's failures on Dask, through the jobs' engine: the same local cluster
or scheduler as the Monte Carlo's (:mod:`attitude.jobs.cluster`), batch sizes from the
measured costs (:func:`attitude.jobs.batches.choose_batch_size`), results gathered as
tasks finish (:func:`attitude.jobs.batches.gather`), a progress callback.

Each failure is computed from the job alone (its hand-off state, the shared
surroundings, one step for the splitting chosen before the job), so the table is the
same whatever the number of workers and the batch size; the rows are sorted by τ.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from attitude.envelope.failure import BatchResult, EnvelopeJob, evaluate_batch
from attitude.envelope.plan import EnvelopePlan, make_job
from attitude.jobs.batches import batch_ranges, check_batch_size, choose_batch_size, gather
from attitude.jobs.cluster import (
    WORKER_MODULES,
    check_where,
    check_workers,
    connect,
    task_overhead_s,
)

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
) -> EnvelopeResult:
    """Compute every failure of ``plan`` on Dask (module notes); ``progress(done,
    total, failed)`` as batches finish, ``stage(text)`` what is happening."""
    import pandas

    stage = stage or (lambda text: None)
    check_batch_size(batch_size, plan.count)
    count = check_where(scheduler, workers, probe=not probed)
    started = time.perf_counter()
    stage("the nominal timeline and the hand-off states")
    job, epochs, modes = make_job(plan)
    timed = evaluate_batch(job, 0, min(_TIMED, job.count))  # warms this process too
    failure_s = timed.compute_s / max(min(_TIMED, job.count), 1)
    stage(f"{failure_s * 1e3:.3g} ms a failure")
    if scheduler is None:
        stage(f"starting a local Dask cluster of {count} worker processes")
    preload = WORKER_MODULES + _FAILURE_MODULES
    with connect(scheduler, workers, probed=True, preload=preload) as client:
        threads = check_workers(client)
        overhead = task_overhead_s(client)
        size = batch_size or choose_batch_size(job.count, threads, failure_s, overhead)
        batches = batch_ranges(job.count, size)
        stage(f"{job.count} failures on {threads} workers: {len(batches)} tasks of {size}")
        rows, compute_s = _run_batches(client, job, batches, progress)
    rows.sort(key=lambda row: row["failure"])
    for row in rows:
        row["epoch_utc"] = epochs[row["failure"]]
        row["mode"] = modes[row["failure"]]
    table = pandas.DataFrame(rows, columns=plan.columns)
    execution = {
        "scheduler": scheduler or f"local cluster ({threads} processes, one thread each)",
        "workers": threads,
        "batch_size": size,
        "tasks": len(batches),
        "failure_s": failure_s,
        "compute_s": compute_s,
        "wall_s": time.perf_counter() - started,
        "step_s": job.step,
    }
    return EnvelopeResult(plan, table, execution)


def _run_batches(
    client, job: EnvelopeJob, batches: list[tuple[int, int]], progress
) -> tuple[list[dict[str, Any]], float]:
    """Gather the tasks as they finish (:func:`attitude.jobs.batches.gather`)."""
    rows: list[dict[str, Any]] = []
    compute_s = 0.0

    def add(first: int, stop: int, result: Any) -> int:
        nonlocal compute_s
        if isinstance(result, BatchResult):
            rows.extend(result.rows)
            compute_s += result.compute_s
            return sum(row["status"] != "ok" for row in result.rows)
        # A task that died (a worker killed): its failures are rows with the error.
        error = f"the task of failures {first}-{stop - 1} failed: {result!r}"
        rows.extend(
            {"failure": k, "tau_s": float(job.seconds[k]), "status": "failed", "error": error}
            for k in range(first, stop)
        )
        return stop - first

    gather(client, evaluate_batch, job, batches, job.count, add, progress)
    return rows, compute_s
