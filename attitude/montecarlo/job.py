"""A Monte Carlo job from start to end: :func:`run_montecarlo`, the Python entry point,
and :func:`montecarlo_job`, which ``attitude montecarlo`` runs too.

    table = run_montecarlo("spinner.toml", samples=1000, seed=7)   # a pandas DataFrame

The job is planned (``attitude.montecarlo.plan``), run on Dask
(``attitude.montecarlo.simulation``, which describes the steps) and, with ``out``,
reported (``attitude.montecarlo.report``), holding the folder's lock from before the
first sample to the last file, and keeping its finished batches in the folder's
checkpoint (``attitude.jobs.checkpoint``: ``resume`` continues an interrupted job).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from attitude.base.errors import InputError
from attitude.files.scenario_reader import ScenarioFile, load_scenario
from attitude.files.scenario_writer import files_named
from attitude.jobs.checkpoint import file_digests, job_folder
from attitude.montecarlo.plan import Job, MonteCarloPlan, plan_montecarlo
from attitude.montecarlo.report import check_folder, write_montecarlo_report
from attitude.montecarlo.simulation import MonteCarloResult, simulate

if TYPE_CHECKING:
    import pandas

__all__ = ["identity", "montecarlo_job", "run_montecarlo"]


def _load(scenario: str | Path | ScenarioFile) -> ScenarioFile:
    return scenario if isinstance(scenario, ScenarioFile) else load_scenario(scenario)


def identity(mc: MonteCarloPlan) -> dict[str, Any]:
    """What makes a Monte Carlo job the one a checkpoint belongs to: the nominal
    document (with its files' contents), the sample count and the seed."""
    document = Job.of(mc).document
    return {
        "kind": "montecarlo",
        "document": document,
        "files": file_digests(files_named(document)),
        "samples": mc.samples,
        "seed": mc.dispersions.seed,
    }


def _warn(text: str) -> None:
    warnings.warn(text, stacklevel=4)


def montecarlo_job(
    mc: MonteCarloPlan,
    out: str | Path | None,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    batch_size: int | None = None,
    progress: Callable[[int, int, int], None] | None = None,
    stage: Callable[[str], None] | None = None,
    note: Callable[[str], None] | None = None,
    resume: bool = False,
    probed: bool = False,
    refuse_all_failed: bool = False,
) -> MonteCarloResult:
    """Run ``mc`` and, with ``out``, write its report there (module notes); ``note``
    receives what the user should know whatever ``--quiet`` says (a checkpoint
    discarded); ``refuse_all_failed``: a job whose every sample failed raises
    :class:`InputError` instead of writing a report of failures."""
    if out is None:
        if resume:
            raise InputError(
                "continues a job written into an output folder: give out", key="resume"
            )
        return simulate(mc, scheduler, workers, batch_size, progress, stage, probed)
    check_folder(mc, out)
    describe = f"{mc.loaded.path.name}, {mc.samples} samples, seed {mc.dispersions.seed}"
    with job_folder(
        out,
        "montecarlo",
        identity(mc),
        mc.samples,
        "samples",
        "sample",
        describe,
        resume,
        note or _warn,
    ) as checkpoint:
        result = simulate(mc, scheduler, workers, batch_size, progress, stage, probed, checkpoint)
        failed = result.failed
        every = refuse_all_failed and len(failed) == mc.samples
        if not every:
            write_montecarlo_report(result, out, stage)
    if every:  # a job that ran to its end: its checkpoint is gone, nothing is written
        first = failed.iloc[0]
        raise InputError(f"every sample failed; sample {first['sample']}: {first['error']}")
    return result


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
    resume: bool = False,
) -> pandas.DataFrame:
    """Run the Monte Carlo job of a scenario file; return the per-sample table.

    ``scenario``: a scenario file with a ``[dispersions]`` table (or one loaded with
    :func:`attitude.files.scenario_reader.load_scenario`); ``samples`` and ``seed`` replace
    the table's.  ``scheduler``: the address of a Dask scheduler (every worker with
    this very code of attitude); by default a local cluster of ``workers`` processes
    (every core; ``workers=1``: this process, no cluster).  ``batch_size``: samples per
    task (chosen from the measured costs by default).  ``out``: also write the report
    folder there (``attitude montecarlo --out``; the folder rules of ``attitude run``),
    keeping the finished batches in its checkpoint as they come in; ``resume``:
    continue the interrupted job whose checkpoint ``out`` holds (the same table, to
    the last bit, as an uninterrupted run).

    The table has one row per sample, in order: ``sample``, ``status`` ("ok" or
    "failed"), ``error``, ``warnings``, the drawn parameters (named after the scenario
    key they disperse) and the metrics (``docs/montecarlo.md``).  Raises
    :class:`attitude.base.errors.InputError` for a bad scenario, dispersion or folder,
    :class:`attitude.base.errors.MachineError` when the machine or the cluster fails
    the job (``docs/cli.md``).
    """
    loaded = _load(scenario)
    mc = plan_montecarlo(loaded, samples=samples, seed=seed)
    result = montecarlo_job(
        mc,
        out,
        scheduler=scheduler,
        workers=workers,
        batch_size=batch_size,
        progress=progress,
        resume=resume,
    )
    return result.table
