"""A Monte Carlo job from start to end: :func:`run_montecarlo`, the Python entry point.

    table = run_montecarlo("spinner.toml", samples=1000, seed=7)   # a pandas DataFrame

The job is planned (``attitude.montecarlo.plan``), run on Dask
(``attitude.montecarlo.simulation``, which describes the steps) and, with ``out``,
reported (``attitude.montecarlo.report``).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from attitude.files.scenario_reader import ScenarioFile, load_scenario
from attitude.montecarlo.plan import plan_montecarlo
from attitude.montecarlo.report import check_folder, write_montecarlo_report
from attitude.montecarlo.simulation import simulate

if TYPE_CHECKING:
    import pandas

__all__ = ["run_montecarlo"]


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
    :func:`attitude.files.scenario_reader.load_scenario`); ``samples`` and ``seed`` replace
    the table's.  ``scheduler``: the address of a Dask scheduler (every worker with
    this version of attitude); by default a local cluster of ``workers`` processes
    (every core).  ``batch_size``: samples per task (chosen from the measured costs by
    default).  ``out``: also write the report folder there (``attitude montecarlo
    --out``; the folder rules of ``attitude run``).

    The table has one row per sample, in order: ``sample``, ``status`` ("ok" or
    "failed"), ``error``, ``warnings``, the drawn parameters (named after the scenario
    key they disperse) and the metrics (``docs/montecarlo.md``).  Raises
    :class:`attitude.base.errors.InputError` for a bad scenario, dispersion or folder.
    """
    loaded = _load(scenario)
    mc = plan_montecarlo(loaded, samples=samples, seed=seed)
    if out is not None:
        check_folder(mc, out)
    result = simulate(mc, scheduler, workers, batch_size, progress)
    if out is not None:
        write_montecarlo_report(result, out)
    return result.table
