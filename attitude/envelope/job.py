"""The envelope from Python: :func:`loss_of_control_envelope`.

table = loss_of_control_envelope("eo.toml")                  # the file's [envelope]
table = loss_of_control_envelope(scenario, pointing, EnvelopeSettings(window=3600.0, every=60.0))
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from attitude.envelope.engine import EnvelopeResult, simulate
from attitude.envelope.plan import plan_envelope
from attitude.envelope.report import write_report
from attitude.envelope.settings import EnvelopeSettings
from attitude.files.scenario_reader import ScenarioFile, load_scenario
from attitude.pointing.spec import PointingSpec
from attitude.scenario.scenario import Scenario

if TYPE_CHECKING:
    import pandas

__all__ = ["envelope_result", "loss_of_control_envelope"]


def envelope_result(
    scenario: str | Path | ScenarioFile | Scenario,
    pointing: PointingSpec | None = None,
    settings: EnvelopeSettings | None = None,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    batch_size: int | None = None,
    progress: Callable[[int, int, int], None] | None = None,
    out: str | Path | None = None,
) -> EnvelopeResult:
    """:func:`loss_of_control_envelope`, with how it ran; ``out``: also write the
    outputs (table, plots, summary.json, page) into that folder."""
    if isinstance(scenario, str | Path):
        scenario = load_scenario(scenario)
    plan = plan_envelope(scenario, pointing, settings)
    if out is not None:
        from attitude.envelope.report import check_folder

        check_folder(plan, out)
    result = simulate(plan, scheduler, workers, batch_size, progress)
    if out is not None:
        write_report(result, out)
    return result


def loss_of_control_envelope(
    scenario: str | Path | ScenarioFile | Scenario,
    pointing: PointingSpec | None = None,
    settings: EnvelopeSettings | None = None,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    batch_size: int | None = None,
    progress: Callable[[int, int, int], None] | None = None,
    out: str | Path | None = None,
) -> pandas.DataFrame:
    """The loss-of-control envelope of ``scenario`` as a table, one row per failure time.

    ``scenario``: a scenario file (its ``[pointing]`` and ``[envelope]`` are used unless
    ``pointing`` or ``settings`` are given), or a :class:`Scenario` under attitude laws
    with ``pointing`` (the body vectors, the orbit) and ``settings``
    (:class:`EnvelopeSettings`).  Runs on a local Dask cluster of ``workers`` processes
    (all cores by default) or at ``scheduler``; the table is the same either way.
    Columns: ``failure``, ``tau_s`` (TT s after the epoch), ``epoch_utc``, ``mode`` (the
    nominal law at τ), the metrics (docs/envelope.md), ``status``, ``error``.
    """
    return envelope_result(
        scenario,
        pointing,
        settings,
        workers=workers,
        scheduler=scheduler,
        batch_size=batch_size,
        progress=progress,
        out=out,
    ).table
