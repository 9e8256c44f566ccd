"""The run's summary (``summary.json``, and the report page built from it): what each
part of it says, from the objects that hold it.

- :func:`scenario_summary`: the scenario as the user gave it (epoch, span, output
  grid, spacecraft, events);
- :func:`motion_summary`: each segment of the exact motion (its closed form, periods,
  nutation, energy and momentum) and the flips;
- :func:`pointing_summary`: the pointing's extrema with their times, constraint and
  visibility totals (each exclusion's, their union "blinded", the Sun in a Sun
  sensor's view) and eclipses, all from :func:`attitude.pointing.search.pointing_analysis`
  on the exact motion, none from the output grid;
- :func:`outputs_summary`: the formats written, and the AEM's sampling and accuracy.

Values are SI or say their unit in their key (``_deg``, ``_s``); epochs are ISO texts
in the scenario's time scale (``Scenario.format_epoch``).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from attitude.outputs.aem_sampling import INTERPOLATION_METHOD
from attitude.pointing.intervals import Interval, total_duration
from attitude.pointing.search import PointingAnalysis
from attitude.report.guidance import mode_event_entry
from attitude.scenario.modes import MODE_EVENTS
from attitude.scenario.scenario import Scenario
from attitude.trajectory.motion import LISTED_FLIPS, SegmentMotion
from attitude.trajectory.trajectory import Trajectory

if TYPE_CHECKING:
    from attitude.report.plan import RunPlan

__all__ = [
    "motion_summary",
    "outputs_summary",
    "pointing_summary",
    "scenario_summary",
    "to_json",
    "write_json",
]


def scenario_summary(scenario: Scenario, source: str) -> dict[str, Any]:
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
    elif event.kind in MODE_EVENTS:
        entry.update(mode_event_entry(event))
    else:
        if event.attitude is not None:
            entry["q_body_to_icrf_wxyz"] = event.attitude.as_quat(scalar_first=True)
        if event.angular_velocity is not None:
            entry["angular_velocity_body_rad_s"] = event.angular_velocity
        if event.angular_momentum is not None:
            entry["angular_momentum_body_N_m_s"] = event.angular_momentum
    return entry


_MOTION_TEXT = {
    "periodic": "periodic: m(t) repeats every body period",
    "steady spin": "steady spin: m is fixed in the body and the body turns about it; "
    "no period of m, no flips, no nutation",
    "separatrix": "separatrix: no period; m leaves the intermediate axis and returns to it "
    "asymptotically, so the body turns over at most once",
    "rest": "at rest: no motion",
    "torqued": "under torques (propagated by splitting with the exact free flow): no "
    "period; flips located on the propagated motion (the momentum crossing the "
    "intermediate axis); the kinetic energy and momentum are those at its start",
    "gyrostat": "spinning wheels after a control loss (a gyrostat, propagated by splitting "
    "with the exact free and gyroscopic flows): no period; flips located on the propagated "
    "motion; the momentum is the total, body plus wheels, and the kinetic energy the "
    "body's, at its start",
    "guided": "under an attitude law: the attitude is the law's (guidance.segments names "
    "it); the kinetic energy and momentum I·ω are those at its start",
    "slew": "a slew onto a law (guidance.slews); the kinetic energy and momentum I·ω are "
    "those at its start",
}


def _flips_summary(scenario, motion: list[SegmentMotion], epochs: bool) -> dict[str, Any]:
    """All flips: their count, and their times up to LISTED_FLIPS (an event's epoch can
    end one segment and start the next with the same flip: it counts once; ``epochs``:
    also as dates).  When a segment's flips were not located, the count is None and
    the note says why."""
    format_epoch = scenario.format_epoch if epochs else None
    missing = [item.flips_note for item in motion if item.flip_count is None]
    listed = np.concatenate([item.flip_times_s for item in motion]) if motion else np.empty(0)
    listed, repeated = np.unique(listed, return_counts=True)
    listed = listed[:LISTED_FLIPS]
    if missing:
        return {
            "count": None,
            "times_s": listed,
            "times": _dates(format_epoch, listed[:1000]),
            "note": f"flips of segments under torques {missing[0]}",
        }
    count = sum(int(item.flip_count or 0) for item in motion) - int(np.sum(repeated - 1))
    complete = listed.size == count
    return {
        "count": count,
        "times_s": listed,
        "times": _dates(format_epoch, listed[:1000]),
        "note": None if complete else f"times_s lists the first {listed.size} of {count} flips",
    }


def _dates(format_epoch, seconds) -> list[str] | None:
    return None if format_epoch is None else [format_epoch(t) for t in seconds]


def motion_summary(
    trajectory: Trajectory, motion: list[SegmentMotion], epochs: bool = True
) -> dict[str, Any]:
    """The JSON summary of the motion: segments, events, flips, precession, nutation.
    ``epochs=False``: the numbers alone, the dates (``start``, the flips' ``times``)
    None (a Monte Carlo sample's metrics: an astropy formatting each)."""
    scenario = trajectory.scenario
    segments = []
    for k, (segment, item) in enumerate(zip(trajectory.segments, motion, strict=True)):
        event = segment.event
        segments.append(
            {
                "index": k,
                "start": scenario.format_epoch(item.start_s) if epochs else None,
                "start_s": item.start_s,
                "end_s": item.end_s,
                "started_by": None
                if event is None
                else {"type": event.kind, "label": event.label or None},
                "formula": item.formula,
                "motion": item.motion,
                "motion_description": _MOTION_TEXT[item.motion],
                "body_period_s": item.period_s,
                "flip_period_s": item.flip_period_s,
                "flip_count": item.flip_count,
                "flips_note": item.flips_note,
                "spin_axis_body": item.spin_axis_body,
                "nutation_angle_min_deg": None
                if item.nutation_min_rad is None
                else math.degrees(item.nutation_min_rad),
                "nutation_angle_max_deg": None
                if item.nutation_max_rad is None
                else math.degrees(item.nutation_max_rad),
                "nutation_period_s": item.nutation_period_s,
                "spin_period_s": item.spin_period_s,
                "precession_period_s": item.precession_period_s,
                "kinetic_energy_J": item.kinetic_energy_J,
                "angular_momentum_icrf_N_m_s": item.inertial_angular_momentum_N_m_s,
                "angular_momentum_norm_N_m_s": item.angular_momentum_norm_N_m_s,
            }
        )
    return {"segments": segments, "flips": _flips_summary(scenario, motion, epochs)}


def _interval_totals(intervals: list[Interval], format_epoch=None) -> dict[str, Any]:
    totals: dict[str, Any] = {
        "count": len(intervals),
        "total_s": total_duration(intervals),
        "longest_s": max((i.duration_s for i in intervals), default=0.0),
    }
    if format_epoch is not None:
        totals["first"] = [
            {
                "start": format_epoch(i.start_s),
                "end": format_epoch(i.end_s),
                "duration_s": i.duration_s,
            }
            for i in intervals[:20]
        ]
    return totals


def _fraction(intervals: list[Interval], span_s: float) -> float:
    """The fraction of the span the intervals cover (0 for an empty span)."""
    return total_duration(intervals) / span_s if span_s > 0.0 else 0.0


# The extrema in the summary: (key in VectorAnalysis.extrema, summary name, in degrees).
_EXTREMA = (
    ("sun_angle", "sun_angle", True),
    ("moon_angle", "moon_angle", True),
    ("nadir_angle", "nadir_angle", True),
    ("earth_limb_angle", "earth_limb_angle", True),
    ("cos_incidence", "cos_incidence", False),
)


def pointing_summary(analysis: PointingAnalysis, format_epoch) -> dict[str, Any]:
    """Extrema with their times, constraint and visibility totals, eclipses: all found
    on the exact motion over the analysed span (``attitude.pointing.search.pointing_analysis``),
    none from the output grid."""
    vectors = {}
    for item in analysis.vectors:
        v = item.vector
        entry: dict[str, Any] = {"kind": v.kind, "vector_body": v.vector}
        for key, name, degrees in _EXTREMA:
            if key not in item.extrema:
                continue
            low, high = item.extrema[key]
            unit = "_deg" if degrees else ""
            convert = math.degrees if degrees else float
            entry[f"{name}_min{unit}"] = convert(low.value)
            entry[f"{name}_min_at"] = format_epoch(low.time_s)
            entry[f"{name}_max{unit}"] = convert(high.value)
            entry[f"{name}_max_at"] = format_epoch(high.time_s)
        entry["mean_cos_incidence"] = item.mean_cos_incidence
        entry["sun_visible"] = _interval_totals(item.sun_visible)
        for constraint, angle in (
            ("sun_exclusion", "sun_exclusion_half_angle_deg"),
            ("moon_exclusion", "moon_exclusion_half_angle_deg"),
            ("earth_limb_exclusion", "earth_limb_exclusion_angle_deg"),
        ):
            if getattr(v, angle) is not None:
                entry[angle] = getattr(v, angle)
                entry[constraint] = _interval_totals(getattr(item, constraint), format_epoch)
        span = analysis.stop_s - analysis.start_s
        if v.exclusions:
            # Blinded by any: the union of the exclusions, not the sum of their totals.
            entry["blinded"] = {
                "by": v.exclusions,
                **_interval_totals(item.blinded, format_epoch),
                "fraction_of_span": _fraction(item.blinded, span),
            }
        if v.sun_inclusion_half_angle_deg is not None:
            entry["sun_inclusion_half_angle_deg"] = v.sun_inclusion_half_angle_deg
            entry["sun_in_view"] = {
                **_interval_totals(item.sun_in_view, format_epoch),
                "fraction_of_span": _fraction(item.sun_in_view, span),
            }
        vectors[v.name] = entry
    summary: dict[str, Any] = {
        "position": analysis.orbit,
        "span": {"start": format_epoch(analysis.start_s), "stop": format_epoch(analysis.stop_s)},
        "interval_precision_s": analysis.precision_s,
        "search_step_s": analysis.grid.step_s,
        "body_vectors": vectors,
    }
    if analysis.on_orbit:
        summary["eclipses"] = {
            "shadow": _interval_totals(analysis.shadow),
            "umbra": _interval_totals(analysis.umbra),
            "sunlit_fraction_of_span": analysis.sunlit_fraction_mean,
        }
        summary["moon_behind_earth"] = _interval_totals(analysis.moon_hidden)
    return summary


def outputs_summary(plan: RunPlan) -> dict[str, Any]:
    """The formats written, and the AEM's sampling and its error measured on the file
    (``attitude.outputs.aem_sampling``: every interval read as declared where the
    interpolation error peaks, when the records are written)."""
    entry: dict[str, Any] = {"formats": list(plan.outputs.formats)}
    if "aem" in plan.outputs and plan.aem is not None:
        entry["aem"] = {
            "tolerance_rad": plan.aem.tolerance_rad,
            "interpolation": f"{INTERPOLATION_METHOD}, degree as declared per segment: "
            "each of Q1..QC interpolated over the degree + 1 records centred on the "
            "interval, then normalized",
            "records": plan.aem.records,
            "largest_error_rad": plan.aem.measured_error_rad,
            "largest_error_note": "measured on the records written: every interval read as "
            "declared where the interpolation error peaks (the extremum of the node "
            "polynomial) against the propagated attitude, the largest times 1 + |omega| h/18 "
            "for the rest of the interval, plus |omega| x 0.5 ns for the 1 ns time tags",
            "segments": [
                {
                    "segment": item.segment,
                    "start": plan.scenario.format_epoch(item.start_s),
                    "starts_where": item.started_by,
                    "records": item.count,
                    "step_s": item.step_s,
                    "interpolation_degree": item.degree,
                    "largest_error_rad": item.measured_error_rad,
                }
                for item in plan.aem.segments
            ],
        }
    return entry


def to_json(value: Any) -> Any:
    """``value`` with numpy arrays and scalars made JSON-serializable (inf/nan as None)."""
    if isinstance(value, dict):
        return {str(k): to_json(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [to_json(v) for v in value]
    if isinstance(value, np.ndarray):
        return to_json(value.tolist())
    if isinstance(value, np.generic):
        return to_json(value.item())
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def write_json(path: Path, data: dict[str, Any]) -> None:
    path.write_text(
        json.dumps(to_json(data), indent=2, ensure_ascii=False) + "\n", encoding="utf-8"
    )
