"""Monte Carlo dispersions on Dask: a scenario's samples, on every core or on a cluster.

    table = run_montecarlo("spinner.toml", samples=1000, seed=7)   # a pandas DataFrame

A job, step by step:

1. **Plan** (:func:`plan_montecarlo`, also run by ``attitude check``): the nominal
   scenario is checked as ``attitude run`` checks it (``attitude.report.plan``), the
   ``[dispersions]`` table read (``attitude.montecarlo.dispersions``), and the table's size
   checked against the memory available.
2. **The nominal run**, on the client: its metrics (reported beside the statistics) and
   its cost, which with Dask's measured cost per task sets the batch size
   (:func:`attitude.jobs.batches.choose_batch_size`).
3. **Batches** on ``dask.distributed``: an embedded ``LocalCluster`` (processes, one
   thread each, every core by default) or the cluster at ``scheduler``.  A task
   evaluates a batch of consecutive samples (:func:`evaluate_batch`): for each, the
   sample's document is drawn (``attitude.montecarlo.dispersions.draw_sample``), read as a file
   is read (``scenario_from_document``), checked and propagated (``plan_run``), and
   reduced to its metrics, the numbers ``summary.json`` of ``attitude run`` reports
   (:func:`sample_metrics`), and to the extremes of each body vector's Sun angle in
   each of :data:`TIME_BINS` time bins, quantized to :data:`ANGLE_STEP_DEG` (a few kB
   a sample instead of the whole series).  A sample that fails is a row with its
   parameters and its error; the job goes on.
4. **Results** stream back as tasks finish; the client adds the Sun-angle extremes
   into per-bin histograms (:class:`Envelope`: fixed memory whatever the sample count,
   the same counts in any order) and sorts the rows by sample.

Every sample draws from streams of its own (``attitude.montecarlo.dispersions``), so the table is
the same whatever the number of workers and the batch size.  On a cluster, every
worker needs the same version of ``attitude`` installed (checked before the job).

Ctrl-C stops the job: the local cluster is closed (its worker processes ignore the
terminal's SIGINT, which the client handles) and nothing is written.
"""

from __future__ import annotations

import pickle
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from attitude.jobs.batches import batch_ranges, check_batch_size, choose_batch_size, gather
from attitude.jobs.cluster import (
    WORKER_MODULES,
    check_where,
    check_workers,
    connect,
    task_overhead_s,
)
from attitude.montecarlo.dispersions import draw_sample
from attitude.montecarlo.metrics import (
    ANGLE_STEP_DEG,
    ANGLE_STEPS,
    METRICS_ONLY,
    sample_metrics,
    time_bin_edges,
)
from attitude.montecarlo.plan import (
    BatchResult,
    Job,
    MonteCarloPlan,
    error_text,
    evaluate_batch,
    failure_row,
)
from attitude.report.plan import plan_run

if TYPE_CHECKING:
    import pandas

__all__ = ["Envelope", "MonteCarloResult", "simulate"]

# What a worker imports before its first sample, beside the cluster's own list.
_SAMPLE_MODULES = ("attitude.montecarlo.plan",)


class Envelope:
    """Per-time-bin histograms of each body vector's Sun-angle extremes over the samples.

    ``counts[v, e, t, a]``: the number of samples whose minimum (e = 0) or maximum
    (e = 1) Sun angle on vector v in time bin t was a·ANGLE_STEP_DEG, rounded.  Integer
    sums: the same in any order of the batches.
    """

    def __init__(self, vectors: list[str], seconds: NDArray[np.float64]) -> None:
        self.vectors = vectors
        edges = time_bin_edges(seconds.size)
        self.bin_start_s = seconds[edges[:-1]]
        self.bin_end_s = seconds[edges[1:] - 1]
        self.counts = np.zeros((len(vectors), 2, edges.size - 1, ANGLE_STEPS + 1), np.int64)

    def add(self, extremes: NDArray[np.uint16]) -> None:
        """Add a batch's (samples, vectors, 2, bins) extremes."""
        if extremes.size == 0:
            return
        v, e, t, a = self.counts.shape
        cell = np.arange(v * e * t).reshape(1, v, e, t) * a  # each (v, e, t) histogram
        flat = (cell + extremes.astype(np.int64)).ravel()
        # In place, in proportion to the batch (not to the histograms' size): the client
        # keeps up with hundreds of tasks a second.
        np.add.at(self.counts.reshape(-1), flat, 1)

    def percentiles_deg(self, percentiles: tuple[float, ...]) -> NDArray[np.float64]:
        """(percentiles, vectors, 2, bins) in degrees, to within ANGLE_STEP_DEG / 2."""
        from attitude.montecarlo.statistics import histogram_percentiles

        return histogram_percentiles(self.counts, percentiles) * ANGLE_STEP_DEG


@dataclass
class MonteCarloResult:
    """A finished job: the per-sample table, the envelopes, the nominal's metrics and
    how the job ran (workers, batch size, costs), for the report."""

    plan: MonteCarloPlan
    table: pandas.DataFrame
    envelope: Envelope
    nominal: dict[str, Any]
    execution: dict[str, Any] = field(default_factory=dict)

    @property
    def failed(self) -> pandas.DataFrame:
        return self.table[self.table["status"] != "ok"]


def _nominal(mc: MonteCarloPlan) -> tuple[dict[str, Any], float]:
    """The nominal scenario's metrics, and the cost of one sample (s), measured on a
    second run (the first one loads the ephemeris)."""
    loaded = mc.loaded
    start = time.perf_counter()
    metrics, _ = sample_metrics(mc.plan)
    cost = time.perf_counter() - start
    if cost < 2.0:
        start = time.perf_counter()
        plan = plan_run(loaded.scenario, loaded.pointing, METRICS_ONLY, horizon=False)
        sample_metrics(plan)
        cost = time.perf_counter() - start
    return metrics, cost


def simulate(
    mc: MonteCarloPlan,
    scheduler: str | None = None,
    workers: int | None = None,
    batch_size: int | None = None,
    progress: Callable[[int, int, int], None] | None = None,
    stage: Callable[[str], None] | None = None,
    probed: bool = False,
) -> MonteCarloResult:
    """Run the samples of ``mc`` on Dask (see the module docstring).

    ``progress(done, total, failed)`` is called as batches finish; ``stage(text)``
    says what is happening (the command line prints both to stderr); ``probed``: the
    caller has checked ``scheduler`` and ``workers`` already
    (:func:`attitude.jobs.cluster.check_where`).
    """
    import pandas

    stage = stage or (lambda text: None)
    check_batch_size(batch_size, mc.samples)
    if scheduler is not None and not probed:
        stage(f"trying the Dask scheduler at {scheduler}")
    count = check_where(scheduler, workers, probe=not probed)
    started = time.perf_counter()
    nominal, sample_s = _nominal(mc)
    stage(f"nominal run: {sample_s:.3g} s a sample")
    job = Job.of(mc)
    if scheduler is None:
        stage(f"starting a local Dask cluster of {count} worker processes")
    # scipy.stats draws the truncated laws: imported once for every worker, when used.
    truncated = any(d.kind == "truncated_normal" for d in mc.dispersions.distributions())
    preload = WORKER_MODULES + _SAMPLE_MODULES + (("scipy.stats",) if truncated else ())
    with connect(scheduler, workers, probed=True, preload=preload) as client:
        threads = check_workers(client)
        overhead = task_overhead_s(client)
        size = batch_size or choose_batch_size(mc.samples, threads, sample_s, overhead)
        batches = batch_ranges(mc.samples, size)
        stage(
            f"{mc.samples} samples on {threads} workers: {len(batches)} tasks of {size} "
            f"(Dask: {1e3 * overhead:.2g} ms a task)"
        )
        gathered = _run_batches(client, mc, job, batches, progress)
    wall = time.perf_counter() - started
    table = pandas.DataFrame(gathered.rows, columns=mc.columns)
    table = table.sort_values("sample", ignore_index=True)
    result_bytes = gathered.result_bytes
    execution = {
        "scheduler": scheduler or f"local cluster ({threads} processes, one thread each)",
        "workers": threads,
        "batch_size": size,
        "tasks": len(batches),
        "nominal_sample_s": sample_s,
        "task_overhead_s": overhead,
        "compute_s": gathered.compute_s,
        "wall_s": wall,
        "job_bytes": len(pickle.dumps(job, protocol=5)),
        "result_bytes_per_task": float(np.mean(result_bytes)) if result_bytes else None,
    }
    return MonteCarloResult(mc, table, gathered.envelope, nominal, execution)


@dataclass
class _Gathered:
    """The finished tasks' rows and envelope, summed as they come in, in any order."""

    envelope: Envelope
    rows: list[dict[str, Any]] = field(default_factory=list)
    failed: int = 0
    compute_s: float = 0.0
    result_bytes: list[int] = field(default_factory=list)  # of the first 20 results

    def add(self, result: BatchResult) -> None:
        self.rows += result.rows
        self.envelope.add(result.extremes)
        self.compute_s += result.compute_s
        self.failed += sum(row["status"] != "ok" for row in result.rows)
        if len(self.result_bytes) < 20:
            self.result_bytes.append(len(pickle.dumps(result, protocol=5)))

    def add_dead_task(self, mc: MonteCarloPlan, first: int, stop: int, exc: Any) -> None:
        """A task that died (a worker killed, say): its samples failed, each with the
        parameters it drew (drawn again here: the draws are the sample's own)."""
        error = f"the task of samples {first}-{stop - 1} failed: {error_text(exc)}"
        for index in range(first, stop):
            sample = draw_sample(mc.dispersions, mc.loaded.document, index)
            self.rows.append(failure_row(index, sample.parameters, error))
        self.failed += stop - first


def _run_batches(
    client,
    mc: MonteCarloPlan,
    job: Job,
    batches: list[tuple[int, int]],
    progress: Callable[[int, int, int], None] | None,
) -> _Gathered:
    """Gather the tasks as they finish (:func:`attitude.jobs.batches.gather`)."""
    gathered = _Gathered(Envelope(mc.vectors, mc.plan.scenario.output_seconds()))

    def add(first: int, stop: int, result: Any) -> int:
        before = gathered.failed
        if isinstance(result, BatchResult):
            gathered.add(result)
        else:
            gathered.add_dead_task(mc, first, stop, result)
        return gathered.failed - before

    gather(client, evaluate_batch, job, batches, mc.samples, add, progress)
    return gathered
