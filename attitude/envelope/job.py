"""The envelope from Python: :func:`loss_of_control_envelope`, and :func:`envelope_job`,
which ``attitude envelope`` runs too.

table = loss_of_control_envelope("eo.toml")                  # the file's [envelope]
table = loss_of_control_envelope(scenario, pointing, EnvelopeSettings(window=3600.0, every=60.0))

With ``out``, the job holds the folder's lock from before the first failure to the
last file, and keeps its finished batches in the folder's checkpoint
(``attitude.jobs.checkpoint``: ``resume`` continues an interrupted job).
"""

from __future__ import annotations

import hashlib
import pickle
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from attitude.base.errors import InputError
from attitude.envelope.engine import EnvelopeResult, simulate
from attitude.envelope.plan import EnvelopePlan, plan_envelope
from attitude.envelope.report import check_folder, write_report
from attitude.envelope.settings import EnvelopeSettings
from attitude.files.scenario_reader import ScenarioFile, load_scenario
from attitude.files.scenario_writer import files_named, with_absolute_files
from attitude.jobs.checkpoint import file_digests, job_folder
from attitude.pointing.spec import PointingSpec
from attitude.scenario.scenario import Scenario

if TYPE_CHECKING:
    import pandas

__all__ = ["envelope_job", "envelope_result", "identity", "loss_of_control_envelope"]


def identity(plan: EnvelopePlan, loaded: ScenarioFile | None) -> dict[str, Any]:
    """What makes an envelope the one a checkpoint belongs to: the scenario document
    (with its files' contents) when it came from a file, else the pickled scenario and
    pointing; the settings and the failure times."""
    if loaded is not None:
        document = with_absolute_files(loaded.document, loaded.path.parent)
        source: dict[str, Any] = {
            "document": document,
            "files": file_digests(files_named(document)),
        }
    else:
        try:
            blob = pickle.dumps((plan.scenario, plan.pointing), protocol=5)
        except Exception:  # a scenario that does not pickle (a lambda torque): no resume
            blob = repr(id(plan)).encode()
        source = {"pickled": hashlib.sha256(blob).hexdigest()}
    return {
        "kind": "envelope",
        **source,
        "settings": repr(plan.settings),
        "failure_times": hashlib.sha256(plan.seconds.tobytes()).hexdigest(),
    }


def envelope_job(
    plan: EnvelopePlan,
    out: str | Path | None,
    loaded: ScenarioFile | None = None,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    batch_size: int | None = None,
    progress: Callable[[int, int, int], None] | None = None,
    stage: Callable[[str], None] | None = None,
    note: Callable[[str], None] | None = None,
    resume: bool = False,
    probed: bool = False,
    refuse_all_failed: bool = False,
) -> EnvelopeResult:
    """Compute ``plan`` and, with ``out``, write its outputs there (module notes);
    ``loaded``: the scenario file it came from; ``note`` receives what the user should
    know whatever ``--quiet`` says; ``refuse_all_failed``: an envelope whose every
    failure time failed raises :class:`InputError` instead of writing it."""
    if out is None:
        if resume:
            raise InputError(
                "continues a job written into an output folder: give out", key="resume"
            )
        return simulate(plan, scheduler, workers, batch_size, progress, stage, probed)
    check_folder(plan, out)
    describe = f"{plan.file or 'a scenario built in Python'}, {plan.count} failure times"
    with job_folder(
        out,
        "envelope",
        identity(plan, loaded),
        plan.count,
        "failures",
        "failure",
        describe,
        resume,
        note or (lambda text: warnings.warn(text, stacklevel=4)),
    ) as checkpoint:
        result = simulate(plan, scheduler, workers, batch_size, progress, stage, probed, checkpoint)
        failed = result.table[result.table["status"] != "ok"]
        every = refuse_all_failed and len(failed) == plan.count
        if not every:
            write_report(result, out, stage)
    if every:  # a job that ran to its end: its checkpoint is gone, nothing is written
        raise InputError(f"every failure failed; the first: {failed.iloc[0]['error']}")
    return result


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
    resume: bool = False,
) -> EnvelopeResult:
    """:func:`loss_of_control_envelope`, with how it ran; ``out``: also write the
    outputs (table, plots, summary.json, page) into that folder."""
    if isinstance(scenario, str | Path):
        scenario = load_scenario(scenario)
    loaded = scenario if isinstance(scenario, ScenarioFile) else None
    plan = plan_envelope(scenario, pointing, settings)
    return envelope_job(
        plan,
        out,
        loaded,
        workers=workers,
        scheduler=scheduler,
        batch_size=batch_size,
        progress=progress,
        resume=resume,
    )


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
    resume: bool = False,
) -> pandas.DataFrame:
    """The loss-of-control envelope of ``scenario`` as a table, one row per failure time.

    ``scenario``: a scenario file (its ``[pointing]`` and ``[envelope]`` are used unless
    ``pointing`` or ``settings`` are given), or a :class:`Scenario` under attitude laws
    with ``pointing`` (the body vectors, the orbit) and ``settings``
    (:class:`EnvelopeSettings`).  Runs on a local Dask cluster of ``workers`` processes
    (all cores by default; ``workers=1``: in this process, no cluster, so that a script
    needs no ``if __name__ == "__main__":`` guard) or at ``scheduler``; the table is
    the same either way.  ``out``: also write the outputs there, keeping the finished
    batches in its checkpoint; ``resume``: continue the interrupted job whose
    checkpoint ``out`` holds.  Columns: ``failure``, ``tau_s`` (TT s after the epoch),
    ``epoch_utc``, ``mode`` (the nominal law at τ), the metrics (docs/envelope.md),
    ``status``, ``error``.
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
        resume=resume,
    ).table
