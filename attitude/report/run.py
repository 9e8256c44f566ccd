"""A scenario run, from a scenario to its report folder, streamed in chunks.

``write_report(scenario, out_dir, pointing)`` checks the scenario (``attitude.report.plan``),
claims the output folder (``attitude.outputs.folder``: it never touches a file it did
not write, and refuses a folder of the user's), propagates and writes into
``out_dir``; a failed or interrupted run leaves no half-written output and the
previous report untouched.  The formats are the user's choice
(``attitude.outputs.formats``):

- ``timeseries.csv`` / ``timeseries.parquet``: attitude, rates, momentum, energy and,
  with a ``[pointing]`` section, the Sun and Moon angles, incidences, nadir and limb
  angles, constraint flags, boresight RA/Dec and the attitude in LVLH, on the output
  grid;
- ``intervals.csv`` (with pointing): eclipses, Sun, Moon and Earth-limb exclusions,
  Sun visibility, found on the exact motion;
- ``summary.json`` (always): the scenario, its segments (flips, nutation, spin,
  precession), extrema with their times (the pointing's on the exact motion),
  exclusion totals, flip times, the outputs;
- ``attitude.aem``: the attitude as a CCSDS AEM 2.0 file, a segment per event, sampled
  for a stated interpolation accuracy (``attitude.outputs.aem_sampling``);
- ``*.png`` and ``report.html``: the plots and a page that gathers everything.

Memory does not grow with the span: the output grid is evaluated :data:`CHUNK_SAMPLES`
epochs at a time, and each chunk is appended to every time series file, to the
plots' per-pixel envelopes and to the summary's extrema before the next is computed.
The pointing's intervals and extrema do not come from that grid: they are searched
once over the span on the exact motion (``attitude.pointing``), in bounded memory.
The AEM is streamed the same way over its own records.  Chunk boundaries leave no
trace in the files (``tests/test_streamed_outputs_equal_unstreamed.py``).
"""

from __future__ import annotations

import contextlib
import math
import time
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from attitude.base.progress import Progress
from attitude.base.version import __version__
from attitude.environment.epoch_texts import EpochTexts
from attitude.environment.orbit import TleOrbit
from attitude.outputs.aem_sampling import INTERPOLATION_METHOD, AemPlan, write_planned_aem
from attitude.outputs.aem_writer import aem_text
from attitude.outputs.budget import check_fits
from attitude.outputs.csv import (
    QUATERNION_CONVENTION,
    CsvWriter,
    pointing_columns,
    sample,
    trajectory_columns,
    write_intervals_csv,
)
from attitude.outputs.folder import claim
from attitude.outputs.formats import OUTPUT_NAMES, OutputChoice
from attitude.outputs.lock import folder_lock
from attitude.outputs.parquet import ParquetWriter
from attitude.pointing.sampling import PointingSamples, pointing_samples
from attitude.pointing.search import PointingAnalysis, pointing_analysis
from attitude.pointing.spec import PointingSpec
from attitude.report.beside import Beside
from attitude.report.figures import (
    angular_velocity_envelope,
    eclipse_zoom,
    polhode_paths,
    rate_zoom,
    sun_angle_zoom,
)
from attitude.report.guidance import guidance_summary
from attitude.report.page import render_page
from attitude.report.plan import RunPlan, horizon_beside, plan_run
from attitude.report.plots import (
    Envelope,
    plot_angular_velocity,
    plot_eclipse,
    plot_polhode,
    plot_sun_angles,
)
from attitude.report.summaries import (
    motion_summary,
    outputs_summary,
    pointing_summary,
    scenario_summary,
    to_json,
    write_json,
)
from attitude.report.torques import torques_summary
from attitude.scenario.scenario import Scenario
from attitude.trajectory.horizon import ValidityHorizon
from attitude.trajectory.motion import largest_rate_of

__all__ = ["CHUNK_SAMPLES", "OUTPUT_NAMES", "Progress", "write_report"]

# Output epochs evaluated and written at a time: large enough that the per-chunk
# overheads vanish, small enough that a chunk with pointing holds tens of MB.
CHUNK_SAMPLES = 16384
# A progress line at most this often during the stream (seconds).
_PROGRESS_EVERY_S = 2.0


# --- the pointing ------------------------------------------------------------------


class _Pointing:
    """The pointing of a run: its samples on any epochs (a chunk of the output grid, a
    zoom panel's window), from :func:`~attitude.pointing.sampling.pointing_samples`, which keeps
    nothing between calls; and its intervals and extrema over the whole span, found
    once on the exact motion by :func:`~attitude.pointing.search.pointing_analysis` (on the
    search grid the plan checked), independently of the output grid and its chunks.
    """

    def __init__(self, plan: RunPlan) -> None:
        self.trajectory, self.spec, self.grid = plan.trajectory, plan.pointing, plan.search

    def samples(self, seconds: np.ndarray) -> PointingSamples:
        return pointing_samples(self.trajectory, self.spec, seconds)

    def analysis(self) -> PointingAnalysis:
        return pointing_analysis(self.trajectory, self.spec, grid=self.grid)


# --- the run -----------------------------------------------------------------------


def write_report(
    scenario: Scenario,
    out_dir: Path,
    pointing: PointingSpec | None = None,
    source: str = "",
    progress: Progress | None = None,
    plan: RunPlan | None = None,
    outputs: OutputChoice | None = None,
    chunk_samples: int = CHUNK_SAMPLES,
    horizon: Beside[ValidityHorizon] | None = None,
    lock: bool = True,
) -> dict[str, Any]:
    """Propagate ``scenario`` and write its report into ``out_dir``; returns the summary.

    ``pointing``: the pointing outputs asked for; ``source``: the scenario file's
    name, for the headers; ``plan``: the scenario already checked by
    :func:`attitude.report.plan.plan_run` (checked here otherwise, for ``outputs``: the
    formats and the AEM's tolerance, the defaults when None); ``chunk_samples``:
    output epochs evaluated and written at a time; ``horizon``: the plan's deferred
    validity horizon already started beside (:func:`attitude.report.plan.horizon_beside`;
    started here otherwise, and closed either way by its owner).  Raises :class:`InputError` (the
    scenario, or an output folder that holds files this tool did not write, or that
    cannot be written, or that another run holds) before anything is computed or
    written, and :class:`~attitude.outputs.folder.OutputWriteError` if the files cannot
    be written (a full disk).  ``lock``: hold the folder's lock for the run
    (:mod:`attitude.outputs.lock`; False: the caller holds it).
    """
    progress = progress or Progress()
    pointing = pointing or PointingSpec()
    if plan is None:
        plan = plan_run(scenario, pointing, outputs, horizon=False)
    check_fits(plan.budget, out_dir)
    claim(out_dir, OUTPUT_NAMES, dry_run=True)  # a folder not ours: refused before the lock
    with folder_lock(out_dir, "run") if lock else contextlib.nullcontext():
        folder = claim(out_dir, OUTPUT_NAMES)
        written: dict[str, Any] = {}

        def build(tmp: Path) -> list[str]:
            written["summary"], files = _build(plan, tmp, source, progress, chunk_samples, horizon)
            return files

        folder.write(build, source, __version__)
    last = "report.html" if "report" in plan.outputs else "summary.json"
    progress(f"done: {folder.path / last}")
    return written["summary"]


def _preamble(scenario: Scenario, source: str) -> list[str]:
    scale = scenario.time_scale
    return [
        f"attitude {__version__}: {scenario.name} ({source})",
        f"spacecraft: {scenario.spacecraft.name}",
        f"epoch: {scenario.format_epoch(0.0)}; t_s = TT seconds since the epoch",
        f"time_{scale}: ISO 8601 epochs in {scale.upper()}",
        "frames: body = spacecraft body axes; icrf = ICRF axes (GCRS, geocentric)",
        QUATERNION_CONVENTION,
        "units: SI (s, rad/s, N m s, J), angles in deg where the name says _deg",
    ]


def _parquet_metadata(scenario: Scenario, source: str) -> dict[str, Any]:
    from attitude.environment.timescales import iso_texts, offline_time

    with offline_time():
        epoch_tt = iso_texts(scenario.times(0.0).tt)
    return {
        "version": __version__,
        "scenario": scenario.name,
        "source": source,
        "spacecraft": scenario.spacecraft.name,
        "epoch": scenario.format_epoch(0.0),
        "epoch_tt": f"{epoch_tt} TT",
        "time_scale": scenario.time_scale.upper(),
        "time_columns": f"time_{scenario.time_scale}: ISO 8601 in {scenario.time_scale.upper()} "
        "(a UTC leap second is written 23:59:60: parse it with astropy, not with pandas or "
        "polars, which read it as the next second); timestamp_tt: the epoch in TT as a "
        "timestamp (TT's calendar, no leap seconds: the column to order, plot and "
        "difference by from pandas, polars or DuckDB); tt_ns: int64 TT nanoseconds since "
        "epoch_tt, exact; t_s: the same in float seconds",
        "frames": "body = spacecraft body axes; icrf = ICRF axes (GCRS, geocentric)",
        "quaternion_convention": QUATERNION_CONVENTION,
        "units": "SI (s, rad/s, N m s, J), angles in deg where the name says _deg; "
        "each field's metadata gives its unit",
    }


class _Stream:
    """The chunk loop's state: the open time-series writers, the plots' envelopes and
    the summary's running extremum."""

    def __init__(self, plan: RunPlan, tmp: Path, source: str, texts: EpochTexts) -> None:
        scenario = plan.scenario
        self.texts = texts
        self.files: list[str] = []
        self.stack = contextlib.ExitStack()
        label = f"time_{scenario.time_scale}"
        self.csv = self.parquet = None
        if "csv" in plan.outputs:
            self.csv = self.stack.enter_context(
                CsvWriter(tmp / "timeseries.csv", label, _preamble(scenario, source))
            )
            self.files.append("timeseries.csv")
        if "parquet" in plan.outputs:
            metadata = _parquet_metadata(scenario, source)
            self.parquet = self.stack.enter_context(
                ParquetWriter(
                    tmp / "timeseries.parquet",
                    label,
                    metadata,
                    f"ISO 8601 epoch in {scenario.time_scale.upper()}",
                    epoch_tt=metadata["epoch_tt"],
                    span_s=(scenario.start_s, scenario.stop_s),
                )
            )
            self.files.append("timeseries.parquet")
        span = (scenario.start_s, scenario.stop_s)
        vectors = [v.name for v in plan.pointing.body_vectors]
        plots = "plots" in plan.outputs
        self.sun = Envelope(*span, vectors) if plots and vectors else None
        self.sunlit = Envelope(*span, ["sunlit"]) if plots and plan.pointing.on_orbit else None

    def add(self, τ: np.ndarray, samples, pointing: PointingSamples | None) -> None:
        columns = trajectory_columns(samples)
        if pointing is not None:
            columns += pointing_columns(pointing)
            if self.sun is not None:
                self.sun.add(
                    τ, {v.vector.name: np.degrees(v.sun_angle_rad) for v in pointing.vectors}
                )
            if self.sunlit is not None:
                self.sunlit.add(τ, {"sunlit": pointing.sunlit_fraction})
        if self.csv is not None or self.parquet is not None:
            epochs = self.texts(τ)
            if self.csv is not None:
                self.csv.write(epochs, columns)
            if self.parquet is not None:
                self.parquet.write(epochs, τ, columns)


def _build(
    plan: RunPlan,
    tmp: Path,
    source: str,
    progress: Progress,
    chunk_samples: int = CHUNK_SAMPLES,
    horizon: Beside[ValidityHorizon] | None = None,
) -> tuple[dict[str, Any], list[str]]:
    """Stream ``plan``'s outputs into ``tmp``: (summary, file names).

    In order: the output grid streamed into the time series and the figures'
    envelopes; the pointing's exact search (intervals.csv, the summary's pointing); the
    AEM over its own records; the figures; summary.json and the page.  A validity
    horizon the plan left to the run is computed meanwhile in a process beside this one
    (:class:`attitude.report.beside.Beside`: the machine's other core), for the summary."""
    started = None if horizon is not None else horizon_beside(plan)
    if started is None:
        return _build_with(plan, horizon, tmp, source, progress, chunk_samples)
    with started:
        return _build_with(plan, started, tmp, source, progress, chunk_samples)


def _build_with(
    plan: RunPlan,
    horizon: Beside[ValidityHorizon] | None,
    tmp: Path,
    source: str,
    progress: Progress,
    chunk_samples: int,
) -> tuple[dict[str, Any], list[str]]:
    outputs = plan.outputs
    texts = EpochTexts(plan.scenario.epoch)
    pointing = None if plan.pointing.is_empty else _Pointing(plan)
    stream = _stream_output_grid(plan, tmp, source, texts, pointing, progress, chunk_samples)
    files = list(stream.files)
    summary = _summary_of_the_stream(plan, source, stream)
    analysis = None
    if pointing is not None:
        analysis = _search_pointing(plan, tmp, source, texts, pointing, progress)
        summary["pointing"] = pointing_summary(analysis, plan.scenario.format_epoch)
        files.append("intervals.csv")
    if "aem" in outputs:
        # The AEM's stated error is measured on its records as they are written.
        plan = replace(
            plan, aem=_write_aem(tmp / "attitude.aem", plan, texts, chunk_samples, progress)
        )
        files.append("attitude.aem")
    summary["outputs"] = outputs_summary(plan)
    images: dict[str, str] = {}
    if "plots" in outputs:
        progress("plotting")
        images = _plots(plan, tmp, stream, pointing, analysis)
    if horizon is not None:
        # The same key, at the same place in the summary, with the horizon filled in.
        summary["torques"] = torques_summary(replace(plan, horizon=horizon.result()))
    progress("writing summary.json" + (" and report.html" if "report" in outputs else ""))
    write_json(tmp / "summary.json", summary)
    files.append("summary.json")
    if "report" in outputs:
        # The page from what summary.json holds (no inf where the file has null).
        page = render_page(to_json(summary), images, files)
        (tmp / "report.html").write_text(page, encoding="utf-8")
        files.append("report.html")
    files += list(images.values())
    return summary, files


def _stream_output_grid(
    plan: RunPlan,
    tmp: Path,
    source: str,
    texts: EpochTexts,
    pointing: _Pointing | None,
    progress: Progress,
    chunk_samples: int,
) -> _Stream:
    """The output grid, a chunk at a time, into the time series files and the figures'
    envelopes; returns the finished stream (its files, envelopes and peak rate)."""
    scenario, spec, outputs = plan.scenario, plan.pointing, plan.outputs
    count = scenario.output_count()
    chunk = max(1, int(chunk_samples))
    series = [name for name in ("timeseries.csv", "timeseries.parquet") if name[11:] in outputs]
    progress(
        f"sampling {count} epochs over {scenario.stop_s:g} s, {min(chunk, count)} at a time"
        + (f": writing {', '.join(series)}" if series else "")
        + (
            f"; pointing: {len(spec.body_vectors)} body "
            f"{'vector' if len(spec.body_vectors) == 1 else 'vectors'}, "
            f"{'Earth centre' if spec.orbit is None else spec.orbit.describe()}"
            if pointing
            else ""
        )
    )
    stream = _Stream(plan, tmp, source, texts)
    with stream.stack:
        shown = time.perf_counter()
        for first in range(0, count, chunk):
            τ = scenario.output_seconds(first, first + chunk)
            samples = sample(plan.trajectory, τ)
            stream.add(τ, samples, None if pointing is None else pointing.samples(τ))
            # After the first chunk (a stream has started), then every few seconds.
            late = first == 0 or time.perf_counter() - shown > _PROGRESS_EVERY_S
            if late and first + chunk < count:
                shown = time.perf_counter()
                progress(f"  {100.0 * (first + chunk) / count:.0f}% ({first + chunk} epochs)")
    return stream


def _summary_of_the_stream(plan: RunPlan, source: str, stream: _Stream) -> dict[str, Any]:
    """The summary's scenario, motion, torques and the largest rate, found on the
    motion (``attitude.trajectory.rates``), not on the output grid."""
    scenario = plan.scenario
    largest = largest_rate_of(plan.motion)
    return {
        "attitude_version": __version__,
        "scenario": scenario_summary(scenario, source),
        "motion": motion_summary(plan.trajectory, plan.motion),
        "torques": torques_summary(plan),
        **({"guidance": guidance} if (guidance := guidance_summary(plan)) else {}),
        "extrema": {
            "max_rate_deg_s": None if largest is None else math.degrees(largest[0]),
            "max_rate_at": None if largest is None else scenario.format_epoch(largest[1]),
        },
    }


def _search_pointing(
    plan: RunPlan,
    tmp: Path,
    source: str,
    texts: EpochTexts,
    pointing: _Pointing,
    progress: Progress,
) -> PointingAnalysis:
    """The pointing's intervals and extrema over the span, on the exact motion; the
    intervals written to intervals.csv."""
    search = plan.search
    if search is None:
        raise ValueError("the plan has no pointing search")
    progress(
        f"pointing: intervals and extrema on the exact motion ({search.count} "
        f"search points, every {search.step_s:.3g} s); writing intervals.csv"
    )
    analysis = pointing.analysis()
    write_intervals_csv(
        tmp / "intervals.csv",
        analysis,
        texts.strings,
        [
            *_preamble(plan.scenario, source)[:3],
            f"interval ends refined to {plan.pointing.interval_precision_s:g} s",
        ],
    )
    return analysis


def _write_aem(
    path: Path, plan: RunPlan, texts: EpochTexts, chunk_samples: int, progress: Progress
) -> AemPlan:
    """attitude.aem over the records the plan chose for its tolerance; the plan with
    the error measured on them."""
    scenario, aem = plan.scenario, plan.aem
    if aem is None:
        raise ValueError("the plan writes no attitude.aem")
    progress(
        f"writing attitude.aem (CCSDS AEM 2.0): {aem.records} records, "
        f"{INTERPOLATION_METHOD} to {aem.tolerance_rad:g} rad"
    )
    orbit = plan.pointing.orbit
    designator = orbit.international_designator if isinstance(orbit, TleOrbit) else None
    with open(path, "wb") as stream:
        return write_planned_aem(
            stream,
            plan.trajectory,
            aem,
            texts,
            object_name=aem_text(scenario.spacecraft.name),
            object_id=designator or "UNKNOWN",
            comments=(aem_text(scenario.name, upper=False), f"computed by attitude {__version__}"),
            chunk_records=chunk_samples,
        )


def _plots(
    plan: RunPlan,
    tmp: Path,
    stream: _Stream,
    pointing: _Pointing | None,
    analysis: PointingAnalysis | None,
) -> dict[str, str]:
    """The figures: the motion from the exact solution, the pointing from the stream."""
    scenario, trajectory, motion = plan.scenario, plan.trajectory, plan.motion
    start, stop = scenario.start_s, scenario.stop_s
    events = [t for t, _ in scenario.events]
    images = {}
    images["Body angular velocity"] = plot_angular_velocity(
        tmp / "angular_velocity.png",
        angular_velocity_envelope(trajectory, motion, start, stop),
        events,
        rate_zoom(trajectory, motion, start, stop, events),
    )
    images["Angular momentum direction in body axes (polhode)"] = plot_polhode(
        tmp / "polhode.png", polhode_paths(trajectory, motion, start, stop)
    )
    if pointing is None or analysis is None:
        return images
    shadow = [(i.start_s, i.end_s) for i in analysis.shadow]
    umbra = [(i.start_s, i.end_s) for i in analysis.umbra]
    if stream.sun is not None:
        sun_exclusions = sorted(
            (i.start_s, i.end_s)
            for v in analysis.vectors
            for i in v.sun_exclusion
            if i.start_s > start
        )

        def sun_angles_deg(τ):
            return {v.vector.name: np.degrees(v.sun_angle_rad) for v in pointing.samples(τ).vectors}

        images["Sun angle on the body vectors"] = plot_sun_angles(
            tmp / "sun_angles.png",
            stream.sun,
            {v.name: v.sun_exclusion_half_angle_deg for v in plan.pointing.body_vectors},
            shadow,
            sun_angle_zoom(
                trajectory, motion, start, stop, sun_angles_deg, sun_exclusions, shadow, events
            ),
        )
    if stream.sunlit is not None:
        passes = []
        for a, b in shadow:
            inside = [(u0, u1) for u0, u1 in umbra if a <= u0 <= b]
            passes.append((a, b - a, sum(u1 - u0 for u0, u1 in inside)))
        long = len(shadow) > 6
        images["Eclipses"] = plot_eclipse(
            tmp / "eclipse.png",
            None if long else stream.sunlit,
            passes,
            eclipse_zoom(start, stop, lambda τ: pointing.samples(τ).sunlit_fraction, shadow, umbra),
            (start, stop),
        )
    return images
