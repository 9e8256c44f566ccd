"""Monte Carlo dispersions on Dask: a scenario's samples, on every core or on a cluster.

    table = run_montecarlo("spinner.toml", samples=1000, seed=7)   # a pandas DataFrame

A job, step by step:

1. **Plan** (:func:`plan_montecarlo`, also run by ``attitude check``): the nominal
   scenario is checked as ``attitude run`` checks it (``attitude.run_plan``), the
   ``[dispersions]`` table read (``attitude.dispersions``), and the table's size
   checked against the memory available.
2. **The nominal run**, on the client: its metrics (reported beside the statistics) and
   its cost, which with Dask's measured cost per task sets the batch size
   (:func:`choose_batch_size`).
3. **Batches** on ``dask.distributed``: an embedded ``LocalCluster`` (processes, one
   thread each, every core by default) or the cluster at ``scheduler``.  A task
   evaluates a batch of consecutive samples (:func:`evaluate_batch`): for each, the
   sample's document is drawn (``attitude.dispersions.draw_sample``), read as a file
   is read (``scenario_from_document``), checked and propagated (``plan_run``), and
   reduced to its metrics, the numbers ``summary.json`` of ``attitude run`` reports
   (:func:`sample_metrics`), and to the extremes of each body vector's Sun angle in
   each of :data:`TIME_BINS` time bins, quantized to :data:`ANGLE_STEP_DEG` (a few kB
   a sample instead of the whole series).  A sample that fails is a row with its
   parameters and its error; the job goes on.
4. **Results** stream back as tasks finish; the client adds the Sun-angle extremes
   into per-bin histograms (:class:`Envelope`: fixed memory whatever the sample count,
   the same counts in any order) and sorts the rows by sample.

Every sample draws from streams of its own (``attitude.dispersions``), so the table is
the same whatever the number of workers and the batch size.  On a cluster, every
worker needs the same version of ``attitude`` installed (checked before the job).

Ctrl-C stops the job: the local cluster is closed (its worker processes ignore the
terminal's SIGINT, which the client handles) and nothing is written.
"""

from __future__ import annotations

import contextlib
import math
import os
import pickle
import signal
import sys
import tempfile
import threading
import time
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from attitude.dispersions import Dispersions, draw_sample, read_dispersions
from attitude.errors import InputError
from attitude.output_budget import ResourceError, available_memory_bytes
from attitude.output_folder import held_signals
from attitude.output_formats import OutputChoice
from attitude.pointing import PointingSpec, pointing_analysis, pointing_samples
from attitude.run_plan import RunPlan, plan_run
from attitude.scenario import Scenario
from attitude.scenario_file import ScenarioFile, load_scenario, scenario_from_document
from attitude.scenario_writer import with_absolute_files
from attitude.summaries import motion_summary, pointing_summary
from attitude.trajectory import Trajectory
from attitude.version import __version__

if TYPE_CHECKING:
    import pandas

__all__ = [
    "ANGLE_STEP_DEG",
    "METRICS_ONLY",
    "TIME_BINS",
    "Envelope",
    "Job",
    "MonteCarloPlan",
    "MonteCarloResult",
    "choose_batch_size",
    "evaluate_batch",
    "metric_names",
    "plan_montecarlo",
    "pointing_outcome",
    "run_montecarlo",
    "sample_metrics",
    "simulate",
    "sun_angles_deg",
]

# The Sun-angle series of each sample is reduced to its extremes in this many time
# bins, quantized to this step (uint16: 0 to 3600 steps of 0.05 deg).
TIME_BINS = 200
ANGLE_STEP_DEG = 0.05
_ANGLE_STEPS = round(180.0 / ANGLE_STEP_DEG)
# A task should last this many times the scheduler's cost per task (so that the
# overhead is at most 1 %), and every worker should get at least this many tasks
# (balance at the end of the job, and a progress bar that moves).
_OVERHEAD_FACTOR = 100
_TASKS_PER_WORKER = 4
# The bytes the client holds per cell of the table (the DataFrame, the rows while
# they arrive, the CSV and Parquet buffers), with a margin.
_BYTES_PER_CELL = 64
_CONNECT_TIMEOUT_S = 10
# A sample writes no files: its plan checks the scenario, the motion and the pointing
# as `attitude run` does, and no output's own limits (no AEM records are chosen, no
# Parquet span is checked; the CSV's estimated size goes unused).
METRICS_ONLY = OutputChoice(formats=("csv",))
_OVERHEAD_PROBES = 40

# ------------------------------------------------------------------------- metrics


def _segment_metric_names(k: int) -> list[str]:
    return [
        f"segment{k}_{name}"
        for name in (
            "motion",
            "body_period_s",
            "flip_count",
            "flip_period_s",
            "nutation_min_deg",
            "nutation_max_deg",
            "nutation_period_s",
            "spin_period_s",
            "precession_period_s",
            "kinetic_energy_J",
            "angular_momentum_norm_N_m_s",
        )
    ]


# Each body vector's extrema, as summary.json names them (attitude.summaries): the
# quantity, and whether it is an angle (reported in degrees).
_VECTOR_EXTREMA = (
    ("sun_angle", True, False),
    ("moon_angle", True, False),
    ("nadir_angle", True, True),
    ("earth_limb_angle", True, True),
    ("cos_incidence", False, False),
)  # (quantity, in degrees, needs an orbit)
_CONSTRAINTS = (
    ("sun_exclusion", "sun_exclusion_half_angle_rad"),
    ("moon_exclusion", "moon_exclusion_half_angle_rad"),
    ("earth_limb_exclusion", "earth_limb_exclusion_angle_rad"),
)


def _vector_metric_names(vector, on_orbit: bool) -> list[str]:
    v = vector.name
    names = []
    for quantity, degrees, needs_orbit in _VECTOR_EXTREMA:
        if needs_orbit and not on_orbit:
            continue
        unit = "_deg" if degrees else ""
        names += [
            f"{v}_{quantity}_min{unit}",
            f"{v}_{quantity}_min_at_s",
            f"{v}_{quantity}_max{unit}",
            f"{v}_{quantity}_max_at_s",
        ]
    names += [f"{v}_mean_cos_incidence", f"{v}_sun_visible_s"]
    for constraint, angle in _CONSTRAINTS:
        if getattr(vector, angle) is not None:
            names += [f"{v}_{constraint}_{total}" for total in ("count", "total_s", "longest_s")]
    return names


def metric_names(scenario: Scenario, pointing: PointingSpec) -> list[str]:
    """The outcome columns of a scenario's samples (the same for every sample: the
    dispersions change numbers, not the number of segments or body vectors)."""
    names = ["flip_count", "max_rate_deg_s"]
    for k in range(len(scenario.events) + 1):
        names += _segment_metric_names(k)
    for vector in pointing.body_vectors:
        names += _vector_metric_names(vector, pointing.on_orbit)
    if pointing.on_orbit:
        names += [
            "eclipse_count",
            "eclipse_total_s",
            "umbra_total_s",
            "sunlit_fraction",
            "moon_behind_earth_total_s",
        ]
    return names


def _number(value: Any) -> float:
    return math.nan if value is None else float(value)


def pointing_outcome(plan: RunPlan) -> dict[str, float]:
    """The pointing metrics of one checked scenario, as ``summary.json`` reports them:
    each body vector's extrema (with their times, TT seconds) and constraint totals, and
    the eclipses, all found on the exact motion over the span by
    :func:`attitude.pointing.pointing_analysis` on the plan's search grid, as
    ``attitude run`` finds them (none from the output grid)."""
    analysis = pointing_analysis(plan.trajectory, plan.pointing, grid=plan.search)
    summary = pointing_summary(analysis, float)  # times as TT seconds, not ISO text
    metrics: dict[str, float] = {}
    for name, entry in summary["body_vectors"].items():
        for quantity, degrees, _ in _VECTOR_EXTREMA:
            unit = "_deg" if degrees else ""
            if f"{quantity}_min{unit}" not in entry:  # an orbit's quantity, without one
                continue
            for end in ("min", "max"):
                metrics[f"{name}_{quantity}_{end}{unit}"] = entry[f"{quantity}_{end}{unit}"]
                metrics[f"{name}_{quantity}_{end}_at_s"] = entry[f"{quantity}_{end}_at"]
        metrics[f"{name}_mean_cos_incidence"] = entry["mean_cos_incidence"]
        metrics[f"{name}_sun_visible_s"] = entry["sun_visible"]["total_s"]
        for constraint, _ in _CONSTRAINTS:
            if constraint in entry:
                for total in ("count", "total_s", "longest_s"):
                    metrics[f"{name}_{constraint}_{total}"] = entry[constraint][total]
    if "eclipses" in summary:
        eclipses = summary["eclipses"]
        metrics["eclipse_count"] = eclipses["shadow"]["count"]
        metrics["eclipse_total_s"] = eclipses["shadow"]["total_s"]
        metrics["umbra_total_s"] = eclipses["umbra"]["total_s"]
        metrics["sunlit_fraction"] = eclipses["sunlit_fraction_of_span"]
        metrics["moon_behind_earth_total_s"] = summary["moon_behind_earth"]["total_s"]
    return metrics


def sun_angles_deg(plan: RunPlan, seconds: NDArray[np.float64]) -> NDArray[np.float64]:
    """Each body vector's Sun angle at ``seconds`` (deg, one row per vector): the series
    the envelopes reduce (:func:`attitude.pointing.pointing_samples`, as the time
    series of ``attitude run`` samples it)."""
    samples = pointing_samples(plan.trajectory, plan.pointing, seconds)
    angles = [np.degrees(item.sun_angle_rad) for item in samples.vectors]
    return np.array(angles).reshape(len(samples.vectors), seconds.size)


def grid_rates(trajectories: list[Trajectory], seconds: NDArray[np.float64]) -> NDArray:
    """|ω| (rad/s) of each trajectory on the output grid, shape (samples, epochs).

    Each trajectory is evaluated over all its epochs at once (the solver is vectorized
    over times).  Advancing the batch's samples together instead, with the free-flow map
    vectorized over states (``attitude.free_flow.advance``), does not pay here: this
    step is under 0.1 % of a sample's cost, which is the exact pointing search
    (docs/benchmarks.md, "Monte Carlo").
    """
    rates = np.empty((len(trajectories), seconds.size))
    for row, trajectory in zip(rates, trajectories, strict=True):
        row[:] = np.linalg.norm(trajectory.angular_velocity(seconds), axis=1)
    return rates


def sample_metrics(
    plan: RunPlan, rate: NDArray[np.float64] | None = None
) -> tuple[dict[str, Any], NDArray[np.float64]]:
    """The metrics of one checked scenario: the numbers its ``summary.json`` holds
    (flips, each segment's motion, the largest rate, the pointing extrema, violation
    and eclipse totals), and its Sun-angle series (one row per body vector, deg).

    ``rate``: |ω| on the output grid, if already evaluated (:func:`grid_rates`).
    """
    scenario = plan.scenario
    seconds = scenario.output_seconds()
    if rate is None:
        rate = grid_rates([plan.trajectory], seconds)[0]
    motion = motion_summary(plan.trajectory, plan.motion)
    # As the report takes it: the largest |ω| among the output epochs, in deg/s.
    metrics: dict[str, Any] = {
        "flip_count": motion["flips"]["count"],
        "max_rate_deg_s": math.degrees(float(rate[int(np.argmax(rate))])),
    }
    for k, segment in enumerate(motion["segments"]):
        names = _segment_metric_names(k)
        values = [
            segment["motion"],
            segment["body_period_s"],
            segment["flip_count"],
            segment["flip_period_s"],
            segment["nutation_angle_min_deg"],
            segment["nutation_angle_max_deg"],
            segment["nutation_period_s"],
            segment["spin_period_s"],
            segment["precession_period_s"],
            segment["kinetic_energy_J"],
            segment["angular_momentum_norm_N_m_s"],
        ]
        metrics[names[0]] = values[0]
        metrics.update({n: _number(v) for n, v in zip(names[1:], values[1:], strict=True)})
        metrics[names[2]] = segment["flip_count"]  # a count: an integer column
    angles = np.empty((0, seconds.size))
    if not plan.pointing.is_empty:
        metrics.update(pointing_outcome(plan))
        if plan.pointing.body_vectors:
            angles = sun_angles_deg(plan, seconds)
    return metrics, angles


def _time_bin_edges(count: int) -> NDArray[np.intp]:
    """Edges (output indices) of min(TIME_BINS, count) bins of nearly equal size."""
    bins = min(TIME_BINS, count)
    return (np.arange(bins + 1) * count) // bins


def angle_extremes(angles_deg: NDArray[np.float64]) -> NDArray[np.uint16]:
    """Each series' minimum and maximum in each time bin, in steps of ANGLE_STEP_DEG:
    shape (vectors, 2, bins)."""
    edges = _time_bin_edges(angles_deg.shape[1])[:-1]
    low = np.minimum.reduceat(angles_deg, edges, axis=1)
    high = np.maximum.reduceat(angles_deg, edges, axis=1)
    steps = np.rint(np.stack([low, high], axis=1) / ANGLE_STEP_DEG)
    return np.clip(steps, 0, _ANGLE_STEPS).astype(np.uint16)


# ---------------------------------------------------------------------- the plan


@dataclass
class MonteCarloPlan:
    """A Monte Carlo job checked before anything runs: the nominal scenario and its
    plan, the dispersions, and the table's columns."""

    loaded: ScenarioFile
    plan: RunPlan
    dispersions: Dispersions
    parameters: list[str]
    metrics: list[str]

    @property
    def samples(self) -> int:
        return self.dispersions.samples

    @property
    def columns(self) -> list[str]:
        return ["sample", "status", "error", "warnings", *self.parameters, *self.metrics]

    @property
    def vectors(self) -> list[str]:
        return [v.name for v in self.loaded.pointing.body_vectors]

    def describe(self) -> list[str]:
        """What ``attitude check`` prints about the job."""
        d = self.dispersions
        lines = [
            f"  dispersions {self.samples:,} samples, seed {d.seed}; a row holds "
            f"{len(self.parameters)} drawn parameters and {len(self.metrics)} metrics"
        ]
        return lines + [f"    {line}" for line in d.describe()]


def plan_montecarlo(
    loaded: ScenarioFile,
    plan: RunPlan | None = None,
    samples: int | None = None,
    seed: int | None = None,
) -> MonteCarloPlan:
    """Check a Monte Carlo job as ``attitude check`` does: the nominal scenario
    (``plan``, from :func:`attitude.run_plan.plan_run` if not given), the
    ``[dispersions]`` table (``samples`` and ``seed`` replace its own), and the size of
    the per-sample table against the memory available."""
    plan = plan or plan_run(loaded.scenario, loaded.pointing, METRICS_ONLY, horizon=False)
    dispersions = read_dispersions(loaded, samples, seed)
    mc = MonteCarloPlan(
        loaded,
        plan,
        dispersions,
        dispersions.parameter_names(),
        metric_names(loaded.scenario, loaded.pointing),
    )
    need = mc.samples * len(mc.columns) * _BYTES_PER_CELL
    available = available_memory_bytes()
    if need > 0.8 * available:
        raise ResourceError(
            f"dispersions.samples: {mc.samples:,} samples of {len(mc.columns)} columns "
            f"need about {need / 1e9:.3g} GB of memory for the table, and "
            f"{available / 1e9:.3g} GB is available: run fewer samples"
        )
    return mc


# ------------------------------------------------------------------ the workers


@dataclass(frozen=True)
class Job:
    """What every task needs (scattered once to each worker): the nominal document, the
    file it came from (named in errors), the dispersions and the table's columns."""

    path: Path
    document: dict[str, Any]
    dispersions: Dispersions
    parameters: list[str]
    metrics: list[str]
    vectors: int

    @classmethod
    def of(cls, mc: MonteCarloPlan) -> Job:
        return cls(
            mc.loaded.path.absolute(),
            # The files it names, absolute: a worker's working folder may be another.
            with_absolute_files(mc.loaded.document, mc.loaded.path.parent),
            mc.dispersions,
            mc.parameters,
            mc.metrics,
            len(mc.vectors),
        )


@dataclass
class BatchResult:
    """The rows of a batch of samples, and the Sun-angle extremes of those that ran:
    ``extremes[i]`` (vectors, 2, bins) belongs to sample ``ran[i]``."""

    rows: list[dict[str, Any]]
    ran: list[int]
    extremes: NDArray[np.uint16]
    compute_s: float


def _failure(index: int, parameters: dict[str, float], error: str) -> dict[str, Any]:
    return {"sample": index, "status": "failed", "error": error, "warnings": "", **parameters}


def evaluate_batch(job: Job, first: int, stop: int) -> BatchResult:
    """Samples ``first`` to ``stop - 1`` of ``job``: draw, read, check, propagate, reduce.

    Runs on a worker.  A sample whose draw, scenario or motion is refused (an
    :class:`InputError`, or any other exception: it is reported, not raised) becomes
    a failed row with its parameters and the error's one line.
    """
    start = time.perf_counter()
    rows: list[dict[str, Any]] = []
    built: list[tuple[int, dict[str, Any], RunPlan, str]] = []
    for index in range(first, stop):
        sample = draw_sample(job.dispersions, job.document, index)
        if sample.error is not None:
            rows.append(_failure(index, sample.parameters, sample.error))
            continue
        try:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                loaded = scenario_from_document(job.path, sample.document)
                plan = plan_run(loaded.scenario, loaded.pointing, METRICS_ONLY, horizon=False)
        except Exception as exc:  # a sample's failure is data: reported, not raised
            rows.append(_failure(index, sample.parameters, _error_text(exc)))
            continue
        notes = " / ".join([str(w.message) for w in caught] + plan.notes)
        built.append((index, sample.parameters, plan, notes))

    ran, extremes = [], []
    rates: list[Any] = [None] * len(built)  # None: each sample evaluates its own
    if built:
        seconds = built[0][2].scenario.output_seconds()
        with contextlib.suppress(Exception):  # a failure is then the sample's, below
            rates = list(grid_rates([plan.trajectory for _, _, plan, _ in built], seconds))
    for (index, parameters, plan, notes), rate in zip(built, rates, strict=True):
        try:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                metrics, angles = sample_metrics(plan, rate)
        except Exception as exc:  # the same
            rows.append(_failure(index, parameters, _error_text(exc)))
            continue
        notes = " / ".join(filter(None, [notes, *(str(w.message) for w in caught)]))
        rows.append(
            {
                "sample": index,
                "status": "ok",
                "error": "",
                "warnings": notes,
                **parameters,
                **metrics,
            }
        )
        ran.append(index)
        extremes.append(angle_extremes(angles))
    bins = min(TIME_BINS, built[0][2].scenario.output_count()) if built else 0
    stacked = np.stack(extremes) if extremes else np.empty((0, job.vectors, 2, bins), np.uint16)
    return BatchResult(rows, ran, stacked, time.perf_counter() - start)


def _error_text(exc: BaseException) -> str:
    if isinstance(exc, InputError):
        return " / ".join(line.strip() for line in str(exc).splitlines() if line.strip())
    return f"internal error: {type(exc).__name__}: {exc}"


def _noop(index: int) -> int:
    return index


def _worker_versions() -> tuple[str, str, str]:
    """(attitude, numpy, scipy) on a worker; importing the sample's modules warms it up."""
    import scipy

    import attitude.pointing  # noqa: F401 (loaded here, not in the first task)

    return __version__, np.__version__, scipy.__version__


# ------------------------------------------------------------------- the client


class Envelope:
    """Per-time-bin histograms of each body vector's Sun-angle extremes over the samples.

    ``counts[v, e, t, a]``: the number of samples whose minimum (e = 0) or maximum
    (e = 1) Sun angle on vector v in time bin t was a·ANGLE_STEP_DEG, rounded.  Integer
    sums: the same in any order of the batches.
    """

    def __init__(self, vectors: list[str], seconds: NDArray[np.float64]) -> None:
        self.vectors = vectors
        edges = _time_bin_edges(seconds.size)
        self.bin_start_s = seconds[edges[:-1]]
        self.bin_end_s = seconds[edges[1:] - 1]
        self.counts = np.zeros((len(vectors), 2, edges.size - 1, _ANGLE_STEPS + 1), np.int64)

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
        from attitude.montecarlo_statistics import histogram_percentiles

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


def choose_batch_size(samples: int, workers: int, sample_s: float, task_overhead_s: float) -> int:
    """Samples per task: enough that a task lasts _OVERHEAD_FACTOR times the scheduler's
    cost per task, few enough that every worker gets _TASKS_PER_WORKER tasks."""
    long_enough = math.ceil(_OVERHEAD_FACTOR * task_overhead_s / max(sample_s, 1e-9))
    balanced = math.ceil(samples / (_TASKS_PER_WORKER * max(workers, 1)))
    return max(1, min(long_enough, balanced))


@contextlib.contextmanager
def _workers_ignore_interrupts() -> Iterator[None]:
    """SIGINT ignored while worker processes start: they inherit it (an ignored signal
    stays ignored across exec), so the terminal's Ctrl-C, sent to every process of the
    foreground group, reaches only the client, which closes the cluster.  A Ctrl-C in
    this window (the cluster's start, about two seconds) is lost."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _ignore_interrupts_plugin():
    """A worker plugin that ignores SIGINT in worker processes the nanny restarts."""
    from distributed.diagnostics.plugin import WorkerPlugin

    class IgnoreInterrupts(WorkerPlugin):
        name = "attitude-ignore-sigint"

        def setup(self, worker) -> None:
            if threading.current_thread() is threading.main_thread():
                signal.signal(signal.SIGINT, signal.SIG_IGN)

    return IgnoreInterrupts()


def _check_where(scheduler: str | None, workers: int | None) -> int:
    """The local cluster's worker count (0 with a scheduler), after checking the options;
    a malformed address is refused before a Client exists (a half-made one hangs at exit)."""
    if scheduler is not None:
        if workers is not None:
            raise InputError("--workers: sets the size of the local cluster; not with --scheduler")
        from distributed.comm.addressing import get_address_host_port

        try:
            get_address_host_port(scheduler)
        except (ValueError, TypeError) as exc:
            raise InputError(f"--scheduler {scheduler!r}: not a scheduler address: {exc}") from None
        return 0
    count = workers if workers is not None else len(os.sched_getaffinity(0))
    if not 1 <= count <= 4 * (os.cpu_count() or 1):
        raise InputError(f"--workers: expected 1 to {4 * (os.cpu_count() or 1)}, got {count}")
    return count


@contextlib.contextmanager
def connect(scheduler: str | None = None, workers: int | None = None) -> Iterator[Any]:
    """A ``distributed.Client``: to the scheduler at ``scheduler``, or to a local cluster
    of ``workers`` processes (default: every core), one thread each, on 127.0.0.1,
    closed on exit (with its processes and ports) whatever ends the block."""
    import logging

    from distributed import Client, LocalCluster

    count = _check_where(scheduler, workers)
    if scheduler is not None:
        try:
            client = Client(scheduler, timeout=_CONNECT_TIMEOUT_S, set_as_default=False)
        except (OSError, TimeoutError, ValueError, TypeError) as exc:
            text = " ".join(str(exc).split())
            raise InputError(f"--scheduler {scheduler}: cannot connect: {text}") from None
        try:
            yield client
        finally:
            with held_signals():
                client.close()
        return
    with tempfile.TemporaryDirectory(prefix="attitude-dask-") as scratch:
        with _workers_ignore_interrupts():
            cluster = LocalCluster(
                n_workers=count,
                threads_per_worker=1,
                processes=True,
                host="127.0.0.1",
                dashboard_address=":0",  # no fixed port (8787 may be taken)
                silence_logs=logging.CRITICAL,
                local_directory=scratch,  # workers' spill files: removed with it
            )
        try:
            client = Client(cluster, set_as_default=False)
            try:
                client.register_plugin(_ignore_interrupts_plugin())
                yield client
            finally:
                with held_signals():
                    client.close()
        finally:
            with held_signals():
                cluster.close()


def _task_overhead_s(client) -> float:
    """The scheduler's cost per task, from no-op tasks on warm workers."""
    start = time.perf_counter()
    client.gather(client.map(_noop, range(_OVERHEAD_PROBES), pure=False))
    return (time.perf_counter() - start) / _OVERHEAD_PROBES


def _check_workers(client) -> int:
    """The workers' thread count, after checking that they run this very code."""
    here = _worker_versions()
    try:
        versions = client.run(_worker_versions)
    except Exception as exc:  # a worker without attitude, say
        text = " ".join(f"{type(exc).__name__}: {exc}".split())
        raise InputError(f"--scheduler: the workers cannot run attitude ({text})") from None
    if not versions:
        raise InputError("--scheduler: the cluster has no workers")
    for address, theirs in versions.items():
        if tuple(theirs) != here:
            raise InputError(
                f"--scheduler: worker {address} runs attitude {theirs[0]} with numpy "
                f"{theirs[1]} and scipy {theirs[2]}; this is attitude {here[0]} with numpy "
                f"{here[1]} and scipy {here[2]}: install the same versions on every worker"
            )
    return sum(w["nthreads"] for w in client.scheduler_info()["workers"].values())


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
) -> MonteCarloResult:
    """Run the samples of ``mc`` on Dask (see the module docstring).

    ``progress(done, total, failed)`` is called as batches finish; ``stage(text)``
    says what is happening (the command line prints both to stderr).
    """
    import pandas

    stage = stage or (lambda text: None)
    if batch_size is not None and not 1 <= batch_size <= mc.samples:
        raise InputError(f"--batch-size: expected 1 to {mc.samples}, got {batch_size}")
    _check_where(scheduler, workers)
    started = time.perf_counter()
    nominal, sample_s = _nominal(mc)
    stage(f"nominal run: {sample_s:.3g} s a sample")
    job = Job.of(mc)
    with connect(scheduler, workers) as client:
        threads = _check_workers(client)
        overhead = _task_overhead_s(client)
        size = batch_size or choose_batch_size(mc.samples, threads, sample_s, overhead)
        batches = [(a, min(a + size, mc.samples)) for a in range(0, mc.samples, size)]
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
        error = f"the task of samples {first}-{stop - 1} failed: {_error_text(exc)}"
        for index in range(first, stop):
            sample = draw_sample(mc.dispersions, mc.loaded.document, index)
            self.rows.append(_failure(index, sample.parameters, error))
        self.failed += stop - first


def _run_batches(
    client,
    mc: MonteCarloPlan,
    job: Job,
    batches: list[tuple[int, int]],
    progress: Callable[[int, int, int], None] | None,
) -> _Gathered:
    """Send the job once to every worker, one task per batch, and gather the tasks as
    they finish (each released as soon as it is read)."""
    from distributed import as_completed

    shared = client.scatter(job, broadcast=True, hash=False)
    futures = client.map(
        evaluate_batch,
        [shared] * len(batches),
        [a for a, _ in batches],
        [b for _, b in batches],
        pure=False,
    )
    span = {future.key: batch for future, batch in zip(futures, batches, strict=True)}
    gathered = _Gathered(Envelope(mc.vectors, mc.plan.scenario.output_seconds()))
    done = 0
    if progress:
        progress(0, mc.samples, 0)
    finished = as_completed(futures, client.loop, with_results=True, raise_errors=False)
    for future, result in finished:
        first, stop = span[future.key]
        if isinstance(result, BatchResult):
            gathered.add(result)
        else:
            gathered.add_dead_task(mc, first, stop, result)
        done += stop - first
        if progress:
            progress(done, mc.samples, gathered.failed)
        future.release()
    return gathered


def _load(scenario: str | Path | ScenarioFile) -> ScenarioFile:
    return scenario if isinstance(scenario, ScenarioFile) else load_scenario(scenario)


def run_montecarlo(
    scenario: str | Path | ScenarioFile,
    samples: int | None = None,
    seed: int | None = None,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    batch_size: int | None = None,
    out: str | Path | None = None,
    progress: Callable[[int, int, int], None] | None = None,
) -> pandas.DataFrame:
    """Run the Monte Carlo job of a scenario file; return the per-sample table.

    ``scenario``: a scenario file with a ``[dispersions]`` table (or one loaded with
    :func:`attitude.scenario_file.load_scenario`); ``samples`` and ``seed`` replace
    the table's.  ``scheduler``: the address of a Dask scheduler (every worker with
    this version of attitude); by default a local cluster of ``workers`` processes
    (every core).  ``batch_size``: samples per task (chosen from the measured costs by
    default).  ``out``: also write the report folder there (``attitude montecarlo
    --out``; the folder rules of ``attitude run``).

    The table has one row per sample, in order: ``sample``, ``status`` ("ok" or
    "failed"), ``error``, ``warnings``, the drawn parameters (named after the scenario
    key they disperse) and the metrics (``docs/montecarlo.md``).  Raises
    :class:`attitude.errors.InputError` for a bad scenario, dispersion or folder.
    """
    loaded = _load(scenario)
    mc = plan_montecarlo(loaded, samples=samples, seed=seed)
    if out is not None:
        from attitude.montecarlo_report import check_folder, write_report

        check_folder(mc, out)
    result = simulate(mc, scheduler, workers, batch_size, progress)
    if out is not None:
        write_report(result, out)
    return result.table


def emit_samples(mc: MonteCarloPlan, indices: list[int], out_dir: str | Path) -> list[str]:
    """Write samples ``indices`` as ordinary scenario files (``sample_K.toml``) into
    ``out_dir`` (an output folder of attitude's: new, empty or written by it before)."""
    from attitude.output_folder import claim
    from attitude.scenario_writer import scenario_text

    for index in indices:
        if not 0 <= index < mc.samples:
            raise InputError(f"--sample: expected 0 to {mc.samples - 1}, got {index}")
    names = {index: f"sample_{index}.toml" for index in indices}
    folder = claim(out_dir, names.values())
    source = mc.loaded.path.name
    d = mc.dispersions

    def build(tmp: Path) -> list[str]:
        for index, name in names.items():
            sample = draw_sample(d, mc.loaded.document, index)
            comments = [
                f"Sample {index} of the Monte Carlo job of {source} (seed {d.seed}), written "
                f"by attitude {__version__}.",
                "An ordinary scenario: `attitude run` runs it to the numbers of row "
                f"{index} of samples.csv.",
                "Drawn:",
                *(f"  {k} = {v!r}" for k, v in sample.parameters.items()),
            ]
            if sample.error:
                comments.append(f"This draw failed: {sample.error}")
            # The files it names (an OEM, an AEM) are named absolute: it is read from DIR.
            document = with_absolute_files(sample.document, mc.loaded.path.parent)
            (tmp / name).write_text(scenario_text(document, comments), encoding="utf-8")
        return list(names.values())

    folder.write(build, source, __version__)
    return [str(folder.path / name) for name in names.values()]


def command(args, loaded: ScenarioFile) -> int:
    """``attitude montecarlo`` (the command line's options in ``args``): run the job into
    ``--out``, or write samples ``--sample`` into ``--emit-scenario``."""
    from attitude.report import Progress

    mc = plan_montecarlo(loaded, None, args.samples, args.seed)
    if args.emit_scenario is not None or args.sample is not None:
        if args.emit_scenario is None or args.sample is None:
            raise InputError("--sample K and --emit-scenario DIR go together")
        if args.out is not None:
            raise InputError("--out: runs the job; --emit-scenario writes samples instead")
        for path in emit_samples(mc, args.sample, args.emit_scenario):
            print(path, flush=True)
        return 0
    if args.out is None:
        raise InputError("--out: the output folder is required (or --emit-scenario)")
    from attitude.montecarlo_report import check_folder, write_report

    check_folder(mc, args.out)
    stage = Progress(None if args.quiet else lambda line: print(line, file=sys.stderr))
    bar = None if args.quiet else ProgressBar(sys.stderr)
    result = simulate(mc, args.scheduler, args.workers, args.batch_size, bar, stage)
    failed = result.failed
    if len(failed) == mc.samples:
        first = failed.iloc[0]
        raise InputError(f"every sample failed; sample {first['sample']}: {first['error']}")
    write_report(result, args.out)
    if len(failed):
        print(
            f"attitude: note: {loaded.path.name}: {len(failed)} of {mc.samples} samples "
            f"failed (the first: sample {failed.iloc[0]['sample']}: {failed.iloc[0]['error']}); "
            "statistics.json lists them with their parameters",
            file=sys.stderr,
            flush=True,
        )
    stage(f"done: {Path(args.out) / 'report.html'}")
    return 0


class ProgressBar:
    """A one-line progress bar on a text stream (redrawn in place on a terminal, a line
    every 10 % otherwise)."""

    def __init__(self, stream=None, width: int = 30) -> None:
        self.stream = stream or sys.stderr
        self.width = width
        self.start: float | None = None  # the first call: the samples start
        self.tty = hasattr(self.stream, "isatty") and self.stream.isatty()
        self.shown = -1

    def __call__(self, done: int, total: int, failed: int) -> None:
        if self.start is None:
            self.start = time.perf_counter()
        fraction = done / total if total else 1.0
        if not self.tty:
            decile = int(10 * fraction)
            if decile == self.shown:
                return
            self.shown = decile
        elapsed = time.perf_counter() - self.start
        eta = elapsed / fraction - elapsed if fraction > 0 else math.nan
        filled = int(self.width * fraction)
        text = (
            f"[{'#' * filled}{'.' * (self.width - filled)}] {done}/{total} samples"
            + (f", {failed} failed" if failed else "")
            + f", {elapsed:.0f} s"
            + (f", {eta:.0f} s to go" if done < total and math.isfinite(eta) else "")
        )
        end = "\n" if not self.tty or done >= total else ""
        print(("\r" if self.tty else "") + text, end=end, file=self.stream, flush=True)
