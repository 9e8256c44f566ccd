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
   a sample instead of the whole series).  A sample whose own input is refused is a
   row with its parameters and its error; the job goes on.  Anything else (a bug, a
   lost scheduler, workers that keep dying) ends the job: :mod:`attitude.jobs.failures`.
   With one worker and no scheduler, the batches run in this process, no cluster.
4. **Results** stream back as tasks finish, each kept in the job's checkpoint when it
   has one (:mod:`attitude.jobs.checkpoint`: a job resumed from it gives the same
   table, to the last bit); the client adds the Sun-angle extremes into per-bin
   histograms (:class:`Envelope`: fixed memory whatever the sample count, the same
   counts in any order) and sorts the rows by sample.

Every sample draws from streams of its own (``attitude.montecarlo.dispersions``), so the table is
the same whatever the number of workers and the batch size.  On a cluster, every
worker needs this very code and the same numpy, scipy and numba (checked before the
job: :func:`attitude.jobs.cluster.check_workers`).

Ctrl-C stops the job: the local cluster is closed (its worker processes ignore the
terminal's SIGINT, which the client handles) and nothing is written but the
checkpoint's finished batches.
"""

from __future__ import annotations

import pickle
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from attitude.jobs.batches import check_batch_size, choose_batch_size, gather, split_ranges
from attitude.jobs.checkpoint import Checkpoint, batch_table, canonical_rows, missing_ranges
from attitude.jobs.cluster import WORKER_MODULES, check_where, workers_for
from attitude.montecarlo.metrics import (
    ANGLE_STEP_DEG,
    ANGLE_STEPS,
    METRICS_ONLY,
    sample_metrics,
    time_bin_edges,
)
from attitude.montecarlo.plan import BatchResult, Job, MonteCarloPlan, evaluate_batch
from attitude.report.plan import plan_run

if TYPE_CHECKING:
    import pandas
    import pyarrow

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
    checkpoint: Checkpoint | None = None,
) -> MonteCarloResult:
    """Run the samples of ``mc`` on Dask (see the module docstring).

    ``progress(done, total, failed)`` is called as batches finish; ``stage(text)``
    says what is happening (the command line prints both to stderr); ``probed``: the
    caller has checked ``scheduler`` and ``workers`` already
    (:func:`attitude.jobs.cluster.check_where`); ``checkpoint``: where finished batches
    are kept, and those already there are taken as they are (``--resume``).
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
    gathered = _Gathered(mc, Envelope(mc.vectors, mc.plan.scenario.output_seconds()), checkpoint)
    missing = gathered.resume(stage)
    size = tasks = 0
    described, threads, overhead = "the checkpoint (nothing left to compute)", 0, 0.0
    if missing:
        if scheduler is None and count > 1:
            stage(f"starting a local Dask cluster of {count} worker processes")
        # scipy.stats draws the truncated laws: imported once for every worker, when used.
        truncated = any(d.kind == "truncated_normal" for d in mc.dispersions.distributions())
        preload = WORKER_MODULES + _SAMPLE_MODULES + (("scipy.stats",) if truncated else ())
        with workers_for(scheduler, workers, preload, probed=True) as where:
            threads, overhead, described = where.threads, where.overhead_s, where.described
            left = sum(b - a for a, b in missing)
            size = batch_size or choose_batch_size(left, threads, sample_s, overhead)
            batches = split_ranges(missing, size)
            tasks = len(batches)
            stage(
                f"{left} samples on {threads} worker{'s' if threads > 1 else ''} "
                f"({where.where}): {tasks} tasks of {size}"
                + (f" (Dask: {1e3 * overhead:.2g} ms a task)" if where.client else "")
            )
            gather(
                where,
                evaluate_batch,
                job,
                batches,
                mc.samples,
                gathered.add_new,
                progress,
                "samples",
                done=mc.samples - left,
                failed=gathered.failed,
            )
    elif progress:
        progress(mc.samples, mc.samples, gathered.failed)
    table = pandas.DataFrame(gathered.rows, columns=mc.columns)
    table = table.sort_values("sample", ignore_index=True)
    result_bytes = gathered.result_bytes
    execution = {
        "scheduler": described,
        "workers": threads,
        "batch_size": size,
        "tasks": tasks,
        "resumed_samples": gathered.resumed,
        "nominal_sample_s": sample_s,
        "task_overhead_s": overhead,
        "compute_s": gathered.compute_s,
        "wall_s": time.perf_counter() - started,
        "job_bytes": len(pickle.dumps(job, protocol=5)),
        "result_bytes_per_task": float(np.mean(result_bytes)) if result_bytes else None,
    }
    return MonteCarloResult(mc, table, gathered.envelope, nominal, execution)


# The checkpoint's column of each sample's Sun-angle extremes (bytes; null if it failed).
_EXTREMES = "_sun_angle_extremes_uint16"


@dataclass
class _Gathered:
    """The finished tasks' rows and envelope, summed as they come in, in any order, and
    kept in the checkpoint (if any) as they come in."""

    mc: MonteCarloPlan
    envelope: Envelope
    checkpoint: Checkpoint | None
    rows: list[dict[str, Any]] = field(default_factory=list)
    failed: int = 0
    resumed: int = 0
    compute_s: float = 0.0
    result_bytes: list[int] = field(default_factory=list)  # of the first 20 results

    def add_new(self, first: int, stop: int, result: BatchResult) -> int:
        """A batch just computed: kept, then added as it reads back."""
        if len(self.result_bytes) < 20:
            self.result_bytes.append(len(pickle.dumps(result, protocol=5)))
        table = self._table(result)
        if self.checkpoint is not None:
            bins = result.extremes.shape[-1] if result.extremes.ndim == 4 else 0
            self.checkpoint.add(table, {"compute_s": result.compute_s, "bins": bins})
        return self._add(table, result.extremes, result.compute_s)

    def resume(self, stage: Callable[[str], None]) -> list[tuple[int, int]]:
        """Add the checkpoint's batches; the ranges of samples still to compute."""
        if self.checkpoint is None:
            return [(0, self.mc.samples)]
        done: list[int] = []
        for table, meta in self.checkpoint.parts():
            self._add(table, self._extremes(table, int(meta.get("bins", 0))), meta["compute_s"])
            done += table.column("sample").to_pylist()
        self.resumed = len(done)
        if self.resumed:
            kept = self.checkpoint.shown
            stage(f"resumed: {self.resumed} of {self.mc.samples} samples from {kept}")
        return missing_ranges(self.mc.samples, done)

    def _table(self, result: BatchResult) -> pyarrow.Table:
        """A batch as the checkpoint keeps it: its rows, and each sample's extremes."""
        import pandas

        frame = pandas.DataFrame(result.rows, columns=self.mc.columns)
        blobs: dict[int, bytes] = {
            index: np.ascontiguousarray(extremes).tobytes()
            for index, extremes in zip(result.ran, result.extremes, strict=True)
        }
        frame[_EXTREMES] = [blobs.get(int(index)) for index in frame["sample"]]
        return batch_table(frame)

    def _extremes(self, table: pyarrow.Table, bins: int) -> NDArray[np.uint16]:
        blobs = [blob for blob in table.column(_EXTREMES).to_pylist() if blob is not None]
        shape = (len(blobs), len(self.mc.vectors), 2, bins)
        if not blobs:
            return np.empty(shape, np.uint16)
        return np.frombuffer(b"".join(blobs), np.uint16).reshape(shape)

    def _add(self, table: pyarrow.Table, extremes: NDArray[np.uint16], compute_s: float) -> int:
        rows = canonical_rows(table.drop_columns([_EXTREMES]))
        self.rows += rows
        self.envelope.add(extremes)
        self.compute_s += compute_s
        failed = sum(row["status"] != "ok" for row in rows)
        self.failed += failed
        return failed
