"""A scenario run, from a scenario to its report folder.

``produce(scenario, out_dir, pointing)`` checks the scenario (``attitude.run_plan``),
claims the output folder (``attitude.output_folder``: it never touches a file it did
not write, and refuses a folder of the user's), propagates and writes into
``out_dir``; a failed or interrupted run leaves no half-written output and the
previous report untouched:

- ``timeseries.csv``: attitude, rates, momentum, energy and, with a ``[pointing]``
  section, the Sun angles, incidences, violations, boresight RA/Dec, nadir angles;
- ``intervals.csv``: eclipses, constraint violations, Sun-visibility windows;
- ``summary.json``: the scenario, its segments (flips, nutation, spin, precession),
  extrema with their times, violation totals, flip times;
- ``attitude.aem``: the attitude as a CCSDS AEM 2.0 file, a segment per event;
- ``*.png`` and ``report.html``: the plots and a page that gathers everything.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from attitude.aem import AemSegment, write_aem
from attitude.exports import (
    QUATERNION_CONVENTION,
    motion_summary,
    pointing_columns,
    pointing_summary,
    sample,
    trajectory_columns,
    write_csv,
    write_intervals_csv,
    write_json,
)
from attitude.output_budget import check_fits
from attitude.output_folder import claim
from attitude.plots import plot_angular_velocity, plot_eclipse, plot_polhode, plot_sun_angles
from attitude.pointing import PointingSpec, pointing_analysis, pointing_samples
from attitude.report_page import render_page
from attitude.run_plan import RunPlan, plan_run
from attitude.scenario import Scenario
from attitude.timescales import SAME_INSTANT_S
from attitude.trajectory import Trajectory
from attitude.version import __version__

__all__ = ["OUTPUT_NAMES", "Progress", "produce"]

# Every file a run may write (the output folder's manifest lists those it wrote).
OUTPUT_NAMES = (
    "timeseries.csv",
    "intervals.csv",
    "summary.json",
    "attitude.aem",
    "report.html",
    "angular_velocity.png",
    "polhode.png",
    "sun_angles.png",
    "eclipse.png",
)


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


def aem_segments(trajectory: Trajectory, seconds: np.ndarray) -> list[AemSegment]:
    """One AEM segment per stretch of motion, on the output grid, closed at the events.

    A segment ends with its own (pre-event) state at the next event's epoch and the
    next one starts with the post-event state there: the attitude is continuous but
    the rate jumps, and an AEM reader must not interpolate across.
    """
    scenario = trajectory.scenario
    segments = []
    for index, segment in enumerate(trajectory.segments):
        start = max(segment.start_s, float(seconds[0]))
        end = min(segment.end_s, float(seconds[-1]))
        if end - start <= SAME_INSTANT_S:
            continue  # before the output span, or a zero-length stretch between events
        inside = seconds[(seconds > start + SAME_INSTANT_S) & (seconds < end - SAME_INSTANT_S)]
        τ = np.concatenate([[start], inside, [end]])
        segments.append(
            AemSegment(
                scenario.times(τ),
                segment.solver.attitude_quaternion(τ),
                segment.solver.angular_velocity(τ),
                comments=(f"motion segment {index}",)
                + ((f"started by {segment.event.kind}",) if segment.event else ()),
            )
        )
    return segments


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


def _zoom_window(motion, start_s: float, stop_s: float) -> tuple[float, float] | None:
    """A few turns of the first segment's spin, for the zoomed Sun-angle panel."""
    spin = motion[0].spin_period_s
    if spin is None or not np.isfinite(spin) or 3.0 * spin >= stop_s - start_s:
        return None
    return start_s, start_s + 3.0 * spin


def produce(
    scenario: Scenario,
    out_dir: Path,
    pointing: PointingSpec | None = None,
    source: str = "",
    progress: Progress | None = None,
    plan: RunPlan | None = None,
) -> dict[str, Any]:
    """Propagate ``scenario`` and write its report into ``out_dir``; returns the summary.

    ``pointing``: the pointing outputs asked for; ``source``: the scenario file's
    name, for the headers; ``plan``: the scenario already checked by
    :func:`attitude.run_plan.plan_run` (checked here otherwise).  Raises
    :class:`InputError` (the scenario, or an output folder that holds files this tool
    did not write) before anything is computed or written, and ``OSError`` if the
    files cannot be written.
    """
    progress = progress or Progress()
    pointing = pointing or PointingSpec()
    if plan is None:
        plan = plan_run(scenario, pointing)
    check_fits(plan.budget, out_dir)
    folder = claim(out_dir, OUTPUT_NAMES)
    written: dict[str, Any] = {}

    def build(tmp: Path) -> list[str]:
        written["summary"], files = _build(plan, tmp, source, progress)
        return files

    folder.write(build, source, __version__)
    progress(f"done: {folder.path / 'report.html'}")
    return written["summary"]


def _build(
    plan: RunPlan, tmp: Path, source: str, progress: Progress
) -> tuple[dict[str, Any], list[str]]:
    """Sample ``plan`` and write every output file into ``tmp``: (summary, file names)."""
    scenario, pointing = plan.scenario, plan.pointing
    trajectory, motion = plan.trajectory, plan.motion
    seconds = scenario.output_seconds()
    progress(f"sampling {seconds.size} epochs over {scenario.stop_s:g} s")
    samples = sample(trajectory, seconds)
    columns = trajectory_columns(samples)
    result = analysis = None
    if not pointing.is_empty:
        progress(
            f"pointing: {len(pointing.body_vectors)} body vectors, "
            f"{'Earth centre' if pointing.orbit is None else pointing.orbit.describe()}"
        )
        result = pointing_samples(trajectory, pointing, seconds)
        columns += pointing_columns(result)
        progress("pointing: intervals and extrema on the exact motion")
        analysis = pointing_analysis(trajectory, pointing)
    scale = scenario.time_scale
    preamble = [
        f"attitude {__version__}: {scenario.name} ({source})",
        f"spacecraft: {scenario.spacecraft.name}",
        f"epoch: {scenario.format_epoch(0.0)}; t_s = TT seconds since the epoch",
        f"time_{scale}: ISO 8601 epochs in {scale.upper()}",
        "frames: body = spacecraft body axes; icrf = ICRF axes (GCRS, geocentric)",
        QUATERNION_CONVENTION,
        "units: SI (s, rad/s, N m s, J), angles in deg where the name says _deg",
    ]
    progress("writing timeseries.csv")
    write_csv(tmp / "timeseries.csv", scenario.iso(seconds), f"time_{scale}", columns, preamble)
    rate = np.linalg.norm(samples.angular_velocity, axis=1)
    peak = int(np.argmax(rate))
    summary: dict[str, Any] = {
        "attitude_version": __version__,
        "scenario": _scenario_summary(scenario, source),
        "motion": motion_summary(trajectory, motion),
        "extrema": {
            "max_rate_deg_s": float(np.degrees(rate[peak])),
            "max_rate_at": scenario.format_epoch(float(seconds[peak])),
        },
    }
    files = ["timeseries.csv"]
    if analysis is not None:
        summary["pointing"] = pointing_summary(analysis, scenario.format_epoch)
        write_intervals_csv(
            tmp / "intervals.csv",
            analysis,
            scenario.iso,
            [*preamble[:3], f"interval ends refined to {pointing.interval_precision_s:g} s"],
        )
        files.append("intervals.csv")
    progress("writing attitude.aem (CCSDS AEM 2.0)")
    write_aem(
        tmp / "attitude.aem",
        aem_segments(trajectory, seconds),
        object_name=_aem_text(scenario.spacecraft.name),
        object_id=_object_id(pointing.tle),
        time_scale=scale,
        comments=(_aem_text(scenario.name, upper=False), f"computed by attitude {__version__}"),
    )
    files.append("attitude.aem")
    progress("plotting")
    images = {}
    events = [t for t, _ in scenario.events]
    images["Body angular velocity"] = plot_angular_velocity(
        tmp / "angular_velocity.png", seconds, samples.angular_velocity, events
    )
    images["Angular momentum direction in body axes (polhode)"] = plot_polhode(
        tmp / "polhode.png", samples.angular_momentum, samples.segment
    )
    if result is not None and result.vectors:
        eclipse = result.sunlit_fraction < 1.0 if result.on_orbit else None
        images["Sun angle on the body vectors"] = plot_sun_angles(
            tmp / "sun_angles.png",
            seconds,
            {v.vector.name: np.degrees(v.sun_angle_rad) for v in result.vectors},
            {
                v.vector.name: None
                if v.vector.sun_exclusion_half_angle_rad is None
                else float(np.degrees(v.vector.sun_exclusion_half_angle_rad))
                for v in result.vectors
            },
            eclipse,
            zoom_s=_zoom_window(motion, float(seconds[0]), float(seconds[-1])),
            bin_s=None if motion[0].spin_period_s is None else 2.0 * motion[0].spin_period_s,
        )
    if result is not None and result.on_orbit:
        images["Eclipses"] = plot_eclipse(tmp / "eclipse.png", seconds, result.sunlit_fraction)
    progress("writing summary.json and report.html")
    write_json(tmp / "summary.json", summary)
    files.append("summary.json")
    (tmp / "report.html").write_text(render_page(summary, images, files), encoding="utf-8")
    files.append("report.html")
    files += list(images.values())
    return summary, files
