"""A Monte Carlo job's plan and its tasks: the job checked before anything runs
(:func:`plan_montecarlo`, also run by ``attitude check``), what every task needs
(:class:`Job`), and a batch of samples evaluated on a worker (:func:`evaluate_batch`):
for each, the sample's document is drawn (``attitude.montecarlo.dispersions.draw_sample``), read as
a file is read (``scenario_from_document``), checked and propagated (``plan_run``), and
reduced to its metrics (``attitude.montecarlo.metrics``).  A sample whose own input is
refused is a row with its parameters and its error; the job goes on.
"""

from __future__ import annotations

import contextlib
import time
import warnings
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from attitude.base.errors import InputError
from attitude.base.version import __version__
from attitude.files.scenario_reader import (
    ScenarioFile,
    ScenarioFileWarning,
    scenario_from_document,
)
from attitude.files.scenario_writer import with_absolute_files
from attitude.jobs.failures import TaskError
from attitude.montecarlo.dispersions import Dispersions, draw_sample, read_dispersions
from attitude.montecarlo.metrics import (
    METRICS_ONLY,
    TIME_BINS,
    angle_extremes,
    metric_names,
    sample_metrics,
)
from attitude.outputs.budget import ResourceError, available_memory_bytes
from attitude.report.plan import RunPlan, plan_run
from attitude.trajectory.guided import GUIDED

__all__ = [
    "BatchResult",
    "Job",
    "MonteCarloPlan",
    "emit_samples",
    "error_text",
    "evaluate_batch",
    "failure_row",
    "plan_montecarlo",
    "sample_cost_s",
]

# The bytes the client holds per cell of the table (the DataFrame, the rows while
# they arrive, the CSV and Parquet buffers), with a margin.
_BYTES_PER_CELL = 64


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
    (``plan``, from :func:`attitude.report.plan.plan_run` if not given), the
    ``[dispersions]`` table (``samples`` and ``seed`` replace its own), and the size of
    the per-sample table against the memory available."""
    plan = plan or plan_run(loaded.scenario, loaded.pointing, METRICS_ONLY, horizon=False)
    dispersions = read_dispersions(loaded, samples, seed)
    _warn_of_inertia_under_laws(loaded, plan, dispersions)
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
            f"{mc.samples:,} samples of {len(mc.columns)} columns "
            f"need about {need / 1e9:.3g} GB of memory for the table, and "
            f"{available / 1e9:.3g} GB is available: run fewer samples",
            key="dispersions.samples" if samples is None else "--samples",
            value=mc.samples,
        )
    return mc


def _warn_of_inertia_under_laws(
    loaded: ScenarioFile, plan: RunPlan, dispersions: Dispersions
) -> None:
    """One line when the inertia is dispersed but every segment is guided (no control
    loss): the laws hold the attitude and the rate, so the draws change no motion, only
    each segment's bounds of the body's momentum and energy, I·ω and ½ ω·Iω."""
    dispersed = [
        name
        for name, found in (
            ("principal_moments", dispersions.moments),
            ("principal_axes", dispersions.axes),
        )
        if found is not None
    ]
    if not dispersed:
        return
    if not all(getattr(s.solver, "formula", "") in GUIDED for s in plan.trajectory.segments):
        return
    warnings.warn(
        ScenarioFileWarning(
            f"{loaded.path.name}: dispersions.spacecraft.{dispersed[0]}: the spacecraft is "
            "guided by attitude laws over the whole span (no control loss): the laws hold "
            "its attitude and rate, so its dispersed inertia changes no motion and no "
            "pointing, only each segment's momentum and energy"
        ),
        stacklevel=2,
    )


def sample_cost_s(mc: MonteCarloPlan) -> float:
    """The CPU seconds of one sample, for ``attitude check``'s time estimate: the
    nominal planned and reduced as a worker does a sample, timed on a second run (the
    first loads what a worker loads once: the ephemeris, compiled kernels) unless the
    first took a second or more."""
    loaded = mc.loaded

    def once() -> float:
        start = time.process_time()
        plan = plan_run(loaded.scenario, loaded.pointing, METRICS_ONLY, horizon=False)
        sample_metrics(plan)
        return time.process_time() - start

    first = once()
    return first if first >= 1.0 else once()


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


def failure_row(index: int, parameters: dict[str, float], error: str) -> dict[str, Any]:
    return {"sample": index, "status": "failed", "error": error, "warnings": "", **parameters}


def evaluate_batch(job: Job, first: int, stop: int) -> BatchResult:
    """Samples ``first`` to ``stop - 1`` of ``job``: draw, read, check, propagate, reduce.

    Runs on a worker.  A sample whose draw, scenario or motion is refused (an
    :class:`InputError`: the sample's own input) becomes a failed row with its
    parameters and the error's one line.  Any other exception is a bug, never a row:
    it ends the task as a :class:`~attitude.jobs.failures.TaskError` naming the
    sample (a memory error is the machine's: raised as it is).  The sample's plan is
    not checked against the worker's free memory (``plan_run(free_memory=False)``):
    the same seed gives the same table on any machine; the job checked the nominal's
    memory before it started (:func:`plan_montecarlo`), and a worker that runs out
    of it fails the job (:mod:`attitude.jobs.failures`).
    """
    start = time.perf_counter()
    rows: list[dict[str, Any]] = []
    built: list[tuple[int, dict[str, Any], RunPlan, str]] = []
    for index in range(first, stop):
        sample = draw_sample(job.dispersions, job.document, index)
        if sample.error is not None:
            rows.append(failure_row(index, sample.parameters, sample.error))
            continue
        try:
            with warnings.catch_warnings(record=True) as caught, _bugs_named(index):
                warnings.simplefilter("always")
                loaded = scenario_from_document(job.path, sample.document)
                plan = plan_run(
                    loaded.scenario, loaded.pointing, METRICS_ONLY, horizon=False, free_memory=False
                )
        except InputError as exc:  # the sample's own input refused: data, reported
            rows.append(failure_row(index, sample.parameters, error_text(exc)))
            continue
        notes = " / ".join([str(w.message) for w in caught] + plan.notes)
        built.append((index, sample.parameters, plan, notes))

    ran, extremes = [], []
    for index, parameters, plan, notes in built:
        try:
            with warnings.catch_warnings(record=True) as caught, _bugs_named(index):
                warnings.simplefilter("always")
                metrics, angles = sample_metrics(plan)
        except InputError as exc:  # the same
            rows.append(failure_row(index, parameters, error_text(exc)))
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


@contextlib.contextmanager
def _bugs_named(index: int) -> Iterator[None]:
    """An exception of the block that is neither a refusal (:class:`InputError`) nor
    the machine's (a memory error) raised as a :class:`TaskError` naming sample
    ``index``."""
    try:
        yield
    except (InputError, MemoryError):
        raise
    except Exception as exc:
        raise TaskError.of(exc, f"sample {index}") from exc


def error_text(exc: InputError) -> str:
    """A refusal's one line, for a failed sample's row."""
    return " / ".join(line.strip() for line in str(exc).splitlines() if line.strip())


def emit_samples(mc: MonteCarloPlan, indices: list[int], out_dir: str | Path) -> list[str]:
    """Write samples ``indices`` as ordinary scenario files (``sample_K.toml``) into
    ``out_dir`` (an output folder of attitude's: new, empty or written by it before)."""
    from attitude.files.scenario_writer import scenario_text
    from attitude.outputs.folder import claim

    for index in indices:
        if not 0 <= index < mc.samples:
            raise InputError(
                f"expected 0 to {mc.samples - 1}, got {index}", key="--sample", value=index
            )
    names = {index: f"sample_{index}.toml" for index in indices}
    folder = claim(out_dir, names.values(), option="--emit-scenario")
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
