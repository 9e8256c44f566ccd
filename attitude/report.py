"""A scenario run, from a scenario to its report folder, streamed in chunks.

``produce(scenario, out_dir, pointing)`` checks the scenario (``attitude.run_plan``),
claims the output folder (``attitude.output_folder``: it never touches a file it did
not write, and refuses a folder of the user's), propagates and writes into
``out_dir``; a failed or interrupted run leaves no half-written output and the
previous report untouched.  The formats are the user's choice
(``attitude.output_formats``):

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
  for a stated interpolation accuracy (``attitude.aem_sampling``);
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
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from attitude.aem import AemWriter
from attitude.aem_sampling import INTERPOLATION_METHOD
from attitude.epoch_texts import EpochTexts
from attitude.exports import (
    QUATERNION_CONVENTION,
    CsvWriter,
    motion_summary,
    pointing_columns,
    pointing_summary,
    sample,
    trajectory_columns,
    write_intervals_csv,
    write_json,
)
from attitude.output_budget import check_fits
from attitude.output_folder import claim
from attitude.output_formats import OUTPUT_NAMES, OutputChoice
from attitude.plots import (
    Envelope,
    plot_angular_velocity,
    plot_eclipse,
    plot_polhode,
    plot_sun_angles,
)
from attitude.pointing import (
    PointingAnalysis,
    PointingSamples,
    PointingSpec,
    pointing_analysis,
    pointing_samples,
)
from attitude.report_figures import (
    angular_velocity_envelope,
    eclipse_zoom,
    polhode_paths,
    rate_zoom,
    sun_angle_zoom,
)
from attitude.report_page import render_page
from attitude.run_plan import RunPlan, plan_run
from attitude.scenario import Scenario
from attitude.timeseries_parquet import ParquetWriter
from attitude.version import __version__

__all__ = ["CHUNK_SAMPLES", "OUTPUT_NAMES", "Progress", "output_grid", "produce"]

# Output epochs evaluated and written at a time: large enough that the per-chunk
# overheads vanish, small enough that a chunk with pointing holds tens of MB.
CHUNK_SAMPLES = 16384
# A progress line at most this often during the stream (seconds).
_PROGRESS_EVERY_S = 2.0


class Progress:
    """Stage messages with the elapsed time, to a callable (stderr for the command line)."""

    def __init__(self, write: Callable[[str], None] | None = None) -> None:
        self._write = write
        self._start = time.perf_counter()

    def __call__(self, message: str) -> None:
        if self._write is not None:
            self._write(f"[{time.perf_counter() - self._start:7.1f} s] {message}")


def _scenario_summary(scenario: Scenario, source: str) -> dict[str, Any]:
    craft = scenario.spacecraft
    return {
        "name": scenario.name,
        "file": source,
        "epoch": scenario.format_epoch(0.0),
        "time_scale": scenario.time_scale.upper(),
        "stop": scenario.format_epoch(scenario.stop_s),
        "duration_s": scenario.stop_s,
        "output": {
            "start": scenario.format_epoch(scenario.start_s),
            "step_s": scenario.step_s,
            "samples": scenario.output_count(),
        },
        "spacecraft": {
            "name": craft.name,
            "inertia_tensor_body_kg_m2": craft.inertia_tensor,
            "principal_moments_kg_m2": craft.principal_moments,
        },
        "events": [_event_summary(scenario, t, event) for t, event in scenario.events],
    }


def _event_summary(scenario: Scenario, offset_s: float, event) -> dict[str, Any]:
    """An event as the user gave it: its epoch, and what it changes."""
    entry: dict[str, Any] = {
        "type": event.kind,
        "label": event.label or None,
        "epoch": scenario.format_epoch(offset_s),
        "offset_s": offset_s,
    }
    if event.kind == "angular_impulse":
        entry["impulse_N_m_s"] = event.impulse
        entry["frame"] = event.frame  # body axes, or inertial (ICRF) axes
    elif event.kind == "inertia_change":
        entry["inertia_tensor_body_kg_m2"] = event.inertia.tensor
        entry["principal_moments_kg_m2"] = event.inertia.moments
    else:
        if event.attitude is not None:
            entry["q_body_to_icrf_wxyz"] = event.attitude.as_quat(scalar_first=True)
        if event.angular_velocity is not None:
            entry["angular_velocity_body_rad_s"] = event.angular_velocity
        if event.angular_momentum is not None:
            entry["angular_momentum_body_N_m_s"] = event.angular_momentum
    return entry


def _aem_text(value: str, upper: bool = True, width: int = 60) -> str:
    """A text value the AEM accepts: printable ASCII (any other character, such as the
    en dash of "T-handle – flip", becomes a blank), single blanks, at most ``width``
    characters, in upper case for a keyword value."""
    text = "".join(c if c.isascii() and c.isprintable() else " " for c in value)
    text = " ".join(text.split())[:width].rstrip()
    return (text.upper() if upper else text) or "UNKNOWN"


def _object_id(tle: tuple[str, str] | None) -> str:
    """The international designator from a TLE (line 1, columns 10–17), e.g. 1998-067A."""
    if tle is None:
        return "UNKNOWN"
    designator = tle[0][9:17].strip()
    if len(designator) < 5 or not designator[:5].isdigit():
        return "UNKNOWN"
    year = int(designator[:2])
    return f"{1900 + year if year >= 57 else 2000 + year}-{designator[2:]}"


def output_grid(scenario: Scenario, first: int, stop: int) -> np.ndarray:
    """Output epochs ``first`` … ``stop`` − 1 of the grid, TT seconds since the epoch:
    the same values as ``scenario.output_seconds()[first:stop]``, without building the
    whole grid (start + step × k, and stop itself last when the step does not reach it)."""
    regular = int(np.floor((scenario.stop_s - scenario.start_s) / scenario.step_s * (1 + 1e-12)))
    regular += 1
    stop = min(stop, scenario.output_count())
    k = np.arange(first, min(stop, regular), dtype=np.float64)
    τ = scenario.start_s + scenario.step_s * k
    if stop > regular:
        τ = np.append(τ, scenario.stop_s)
    return τ


# --- the pointing ------------------------------------------------------------------


class _Pointing:
    """The pointing of a run: its samples on any epochs (a chunk of the output grid, a
    zoom panel's window), from :func:`~attitude.pointing.pointing_samples`, which keeps
    nothing between calls; and its intervals and extrema over the whole span, found
    once on the exact motion by :func:`~attitude.pointing.pointing_analysis` (on the
    search grid the plan checked), independently of the output grid and its chunks.
    """

    def __init__(self, plan: RunPlan) -> None:
        self.trajectory, self.spec, self.grid = plan.trajectory, plan.pointing, plan.search

    def samples(self, seconds: np.ndarray) -> PointingSamples:
        return pointing_samples(self.trajectory, self.spec, seconds)

    def analysis(self) -> PointingAnalysis:
        return pointing_analysis(self.trajectory, self.spec, grid=self.grid)


# --- the run -----------------------------------------------------------------------


def produce(
    scenario: Scenario,
    out_dir: Path,
    pointing: PointingSpec | None = None,
    source: str = "",
    progress: Progress | None = None,
    plan: RunPlan | None = None,
    outputs: OutputChoice | None = None,
    chunk_samples: int = CHUNK_SAMPLES,
) -> dict[str, Any]:
    """Propagate ``scenario`` and write its report into ``out_dir``; returns the summary.

    ``pointing``: the pointing outputs asked for; ``source``: the scenario file's
    name, for the headers; ``plan``: the scenario already checked by
    :func:`attitude.run_plan.plan_run` (checked here otherwise, for ``outputs``: the
    formats and the AEM's tolerance, the defaults when None); ``chunk_samples``:
    output epochs evaluated and written at a time.  Raises :class:`InputError` (the
    scenario, or an output folder that holds files this tool did not write) before
    anything is computed or written, and ``OSError`` if the files cannot be written.
    """
    progress = progress or Progress()
    pointing = pointing or PointingSpec()
    if plan is None:
        plan = plan_run(scenario, pointing, outputs)
    check_fits(plan.budget, out_dir)
    folder = claim(out_dir, OUTPUT_NAMES)
    written: dict[str, Any] = {}

    def build(tmp: Path) -> list[str]:
        written["summary"], files = _build(plan, tmp, source, progress, chunk_samples)
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
    from attitude.timescales import iso_texts, offline_time

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
        "(a UTC leap second is written 23:59:60); tt_ns: int64 TT nanoseconds since epoch_tt; "
        "t_s: the same in float seconds",
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
            self.parquet = self.stack.enter_context(
                ParquetWriter(
                    tmp / "timeseries.parquet",
                    label,
                    _parquet_metadata(scenario, source),
                    f"ISO 8601 epoch in {scenario.time_scale.upper()}",
                )
            )
            self.files.append("timeseries.parquet")
        span = (scenario.start_s, scenario.stop_s)
        vectors = [v.name for v in plan.pointing.body_vectors]
        plots = "plots" in plan.outputs
        self.sun = Envelope(*span, vectors) if plots and vectors else None
        self.sunlit = Envelope(*span, ["sunlit"]) if plots and plan.pointing.on_orbit else None
        self.peak_rate = (-1.0, 0.0)  # (rad/s, at TT s)

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
        rate = np.linalg.norm(samples.angular_velocity, axis=1)
        peak = int(np.argmax(rate))
        if rate[peak] > self.peak_rate[0]:  # the first of equal maxima, as on one grid
            self.peak_rate = (float(rate[peak]), float(τ[peak]))


def _build(
    plan: RunPlan, tmp: Path, source: str, progress: Progress, chunk_samples: int = CHUNK_SAMPLES
) -> tuple[dict[str, Any], list[str]]:
    """Stream ``plan``'s outputs into ``tmp``: (summary, file names)."""
    scenario, spec, outputs = plan.scenario, plan.pointing, plan.outputs
    trajectory, motion = plan.trajectory, plan.motion
    count = scenario.output_count()
    texts = EpochTexts(scenario.epoch)
    source_of_pointing = None if spec.is_empty else _Pointing(plan)
    chunk = max(1, int(chunk_samples))
    series = [name for name in ("timeseries.csv", "timeseries.parquet") if name[11:] in outputs]
    progress(
        f"sampling {count} epochs over {scenario.stop_s:g} s, {min(chunk, count)} at a time"
        + (f": writing {', '.join(series)}" if series else "")
        + (
            f"; pointing: {len(spec.body_vectors)} body vectors, "
            f"{'Earth centre' if spec.orbit is None else spec.orbit.describe()}"
            if source_of_pointing
            else ""
        )
    )
    stream = _Stream(plan, tmp, source, texts)
    with stream.stack:
        shown = time.perf_counter()
        for first in range(0, count, chunk):
            τ = output_grid(scenario, first, first + chunk)
            samples = sample(trajectory, τ)
            pointing = None if source_of_pointing is None else source_of_pointing.samples(τ)
            stream.add(τ, samples, pointing)
            # After the first chunk (a stream has started), then every few seconds.
            late = first == 0 or time.perf_counter() - shown > _PROGRESS_EVERY_S
            if late and first + chunk < count:
                shown = time.perf_counter()
                progress(f"  {100.0 * (first + chunk) / count:.0f}% ({first + chunk} epochs)")
    files = list(stream.files)
    summary: dict[str, Any] = {
        "attitude_version": __version__,
        "scenario": _scenario_summary(scenario, source),
        "motion": motion_summary(trajectory, motion),
        "extrema": {
            "max_rate_deg_s": math.degrees(stream.peak_rate[0]),
            "max_rate_at": scenario.format_epoch(stream.peak_rate[1]),
        },
    }
    analysis = None
    if source_of_pointing is not None:
        progress(
            f"pointing: intervals and extrema on the exact motion ({plan.search.count} "
            f"search points, every {plan.search.step_s:.3g} s); writing intervals.csv"
        )
        analysis = source_of_pointing.analysis()
        summary["pointing"] = pointing_summary(analysis, scenario.format_epoch)
        write_intervals_csv(
            tmp / "intervals.csv",
            analysis,
            texts.strings,
            [
                *_preamble(scenario, source)[:3],
                f"interval ends refined to {spec.interval_precision_s:g} s",
            ],
        )
        files.append("intervals.csv")
    summary["outputs"] = _outputs_summary(plan)
    if "aem" in outputs:
        aem = plan.aem
        progress(
            f"writing attitude.aem (CCSDS AEM 2.0): {aem.records} records, "
            f"{INTERPOLATION_METHOD} to {aem.tolerance_rad:g} rad"
        )
        _write_aem(tmp / "attitude.aem", plan, texts, chunk_samples)
        files.append("attitude.aem")
    images: dict[str, str] = {}
    if "plots" in outputs:
        progress("plotting")
        images = _plots(plan, tmp, stream, source_of_pointing, analysis)
    progress("writing summary.json" + (" and report.html" if "report" in outputs else ""))
    write_json(tmp / "summary.json", summary)
    files.append("summary.json")
    if "report" in outputs:
        (tmp / "report.html").write_text(render_page(summary, images, files), encoding="utf-8")
        files.append("report.html")
    files += list(images.values())
    return summary, files


def _outputs_summary(plan: RunPlan) -> dict[str, Any]:
    """The formats written, and the AEM's sampling and stated accuracy."""
    entry: dict[str, Any] = {"formats": list(plan.outputs.formats)}
    if "aem" in plan.outputs:
        entry["aem"] = {
            "tolerance_rad": plan.aem.tolerance_rad,
            "interpolation": f"{INTERPOLATION_METHOD}, degree as declared per segment: "
            "each of Q1..QC interpolated over the degree + 1 records centred on the "
            "interval, then normalized",
            "records": plan.aem.records,
            "segments": [
                {
                    "segment": item.segment,
                    "records": item.count,
                    "step_s": item.step_s,
                    "interpolation_degree": item.degree,
                    "largest_error_found_rad": item.tested_error_rad,
                }
                for item in plan.aem.segments
            ],
        }
    return entry


def _write_aem(path: Path, plan: RunPlan, texts: EpochTexts, chunk_samples: int) -> None:
    """The AEM, streamed: one segment per stretch of motion, records in chunks."""
    scenario, trajectory = plan.scenario, plan.trajectory
    with open(path, "wb") as stream:
        writer = AemWriter(
            stream,
            object_name=_aem_text(scenario.spacecraft.name),
            object_id=_object_id(plan.pointing.tle),
            time_scale=scenario.time_scale,
            comments=(
                _aem_text(scenario.name, upper=False),
                f"computed by attitude {__version__}",
                f"sampled so that {INTERPOLATION_METHOD} interpolation as declared (each of "
                "Q1..QC over the degree + 1 records",
                f"centred on the interval, normalized) stays within {plan.aem.tolerance_rad:g} "
                "rad of the exact attitude",
            ),
        )
        for item in plan.aem.segments:
            segment = trajectory.segments[item.segment]
            ends = texts(np.array([item.start_s, item.end_s]))
            writer.begin_segment(
                ends[0].decode("ascii"),
                ends[1].decode("ascii"),
                interpolation=None if item.degree is None else (INTERPOLATION_METHOD, item.degree),
                comments=(
                    f"motion segment {item.segment}",
                    *((f"started by {segment.event.kind}",) if segment.event else ()),
                    f"a record every {item.step_s:.6g} s",
                ),
            )
            for first in range(0, item.count, chunk_samples):
                τ = item.seconds(first, first + chunk_samples)
                # One record is evaluated as a pair (see attitude.exports.sample).
                pair = np.repeat(τ, 2) if τ.size == 1 else τ
                writer.write_records(
                    texts(τ),
                    segment.solver.attitude_quaternion(pair)[: τ.size],
                    segment.solver.angular_velocity(pair)[: τ.size],
                )
            writer.end_segment()
        writer.close()


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
