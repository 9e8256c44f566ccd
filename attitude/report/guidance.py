"""What a run says about its attitude laws: the law of each segment, the slews, the
control losses and the ground sites' passes.

For ``summary.json`` (``guidance``), ``attitude check`` and the HTML report, from the
:class:`~attitude.report.plan.RunPlan` of a scenario with laws
(:mod:`attitude.trajectory.modes`):

- each segment: guided (the law, its definition, the key that named it), a slew, or
  free (after a control loss: the exact solver, the gyrostat, or the torqued solver);
- each slew: its angle (the eigen-axis rotation left at its start, relative to the
  target law's frame), duration, start and end, limits, the profile's peak rate and
  acceleration, and how far the start-rate correction turns the body off the
  eigen-axis path (:mod:`attitude.laws.slews`);
- each control loss: the wheels, the body rate just after, and the total momentum;
- the ground sites a law tracks: their passes above the horizon over the segment,
  and a note for a site never seen there;
- the notes of the guided segments (a site never seen, the Earth orientation table's
  coverage).
"""

from __future__ import annotations

import math
from html import escape
from typing import TYPE_CHECKING, Any

import numpy as np

from attitude.report.torques import cpu_text
from attitude.scenario.modes import ControlLoss
from attitude.torques.solver import StepChoice, StepPrediction
from attitude.trajectory.guided import GuidedMotion
from attitude.trajectory.modes import uses_laws
from attitude.trajectory.torqued import TorquedMotion

if TYPE_CHECKING:
    from attitude.report.plan import RunPlan

__all__ = ["guidance_lines", "guidance_section", "guidance_summary", "mode_event_entry"]


def mode_event_entry(event: Any) -> dict[str, Any]:
    """What a mode event changes, for the summary's events (``scenario.events``)."""
    entry: dict[str, Any] = {}
    if event.kind in ("mode_change", "control_resume"):
        entry["law"] = event.law.name
        entry["law_description"] = event.law.describe()
        entry["slew"] = "instantaneous switch" if event.slew is None else event.slew.describe()
    elif event.kind == "control_loss":
        entry["wheels"] = event.wheels.case
        entry["wheel_momentum_body_N_m_s"] = event.wheels.momentum_vector
    return entry


def _law_entry(solver: GuidedMotion) -> dict[str, Any]:
    law = solver.law
    parameters = getattr(law, "parameters", None)
    return {
        "law": law.name,
        "law_description": law.describe(),
        "law_key": solver.key,
        "law_parameters": parameters() if callable(parameters) else None,
    }


def guidance_summary(plan: RunPlan) -> dict[str, Any] | None:
    """The ``guidance`` entry of ``summary.json`` (None without laws)."""
    trajectory = plan.trajectory
    if not uses_laws(plan.scenario):
        return None
    fmt = plan.scenario.format_epoch
    segments, slews, losses = [], [], []
    for k, segment in enumerate(trajectory.segments):
        solver = segment.solver
        entry: dict[str, Any] = {
            "segment": k,
            "start": fmt(segment.start_s),
            "end": fmt(segment.end_s),
            "start_s": segment.start_s,
            "end_s": segment.end_s,
            "kind": solver.formula if isinstance(solver, GuidedMotion) else "free",
        }
        if isinstance(solver, GuidedMotion):
            entry.update(_law_entry(solver))
            entry["rate_bound_deg_s"] = math.degrees(solver.angular_rate_bound)
            if solver.passes is not None:
                entry["ground_site_passes"] = [
                    {"start": fmt(a), "end": fmt(b), "duration_s": b - a} for a, b in solver.passes
                ]
                entry["ground_site_visible"] = bool(solver.passes)
            slew = solver.slew
            if slew is not None:
                slews.append(
                    {
                        "segment": k,
                        "start": fmt(slew.start_s),
                        "end": fmt(slew.end_s),
                        "start_s": slew.start_s,
                        "onto": solver.law.describe(),
                        **slew.as_dict(),
                    }
                )
        else:
            entry["propagation"] = _free_text(solver)
            if isinstance(solver, TorquedMotion) and solver.formula == "gyrostat":
                entry["method"] = solver.method
                entry["step_s"] = solver.step
                entry["estimated_error_rad"] = solver.error_estimate
                if isinstance(solver.step_search, StepChoice):  # searched for an accuracy
                    entry["step_search_cpu_s"] = solver.step_search.cpu_s
        segments.append(entry)
        event = segment.event
        if isinstance(event, ControlLoss) and segment.before is not None:
            ω = solver.angular_velocity(np.array([segment.start_s, segment.start_s]))[0]
            losses.append(
                {
                    "segment": k,
                    "epoch": fmt(segment.start_s),
                    "wheels": event.wheels.case,
                    "wheel_momentum_body_N_m_s": event.wheels.momentum_vector,
                    "rate_before_deg_s": np.degrees(
                        np.linalg.solve(
                            segment.before.inertia.tensor, segment.before.angular_momentum
                        )
                    ),
                    "rate_after_deg_s": np.degrees(ω),
                    "total_momentum_body_N_m_s": segment.state.angular_momentum,
                    "description": event.wheels.describe(),
                }
            )
    return {
        "segments": segments,
        "slews": slews,
        "control_losses": losses,
        "notes": list(
            dict.fromkeys(n for s in trajectory.segments for n in getattr(s.solver, "notes", ()))
        ),
        "torques_note": "the scenario's torques act on the free segments only: while a law "
        "holds the attitude, its controller absorbs them",
    }


def _free_text(solver: Any) -> str:
    formula = getattr(solver, "formula", "")
    if formula == "gyrostat":
        return "gyrostat (spinning wheels): splitting with the exact gyroscopic flow"
    if formula == "torqued":
        return "under torques: splitting with the exact free flow"
    return "torque-free: the exact solver (closed form)"


def guidance_lines(plan: RunPlan) -> list[str]:
    """What ``attitude check`` says about the laws: slews and control losses."""
    summary = guidance_summary(plan)
    if summary is None:
        return []
    lines = []
    for slew in summary["slews"]:
        lines.append(
            f"slew        segment {slew['segment']}: {slew['angle_deg']:.4g} deg in "
            f"{slew['duration_s']:.6g} s, {slew['start']} to {slew['end']} (peak "
            f"{slew['profile_peak_rate_deg_s']:.4g} deg/s; off the eigen axis by at most "
            f"{slew['off_eigen_axis_at_most_deg']:.3g} deg)"
        )
    for loss in summary["control_losses"]:
        rate = np.linalg.norm(loss["rate_after_deg_s"])
        lines.append(
            f"control loss at {loss['epoch']}: {loss['description']}; the body turns at "
            f"{rate:.4g} deg/s just after"
        )
    for item, segment in zip(summary["segments"], plan.trajectory.segments, strict=True):
        if "step_s" in item:
            lines += _gyrostat_lines(item, segment.solver)
    return lines


def _gyrostat_lines(item: dict[str, Any], solver: Any) -> list[str]:
    """What check says of a gyrostat segment: its step, its error and what its step
    search costs the run (predicted past check's budget: TorquedSolver.predict_step)."""
    search = solver.step_search
    head = f"  segment {item['segment']} gyrostat, {item['method']}"
    if not isinstance(search, StepPrediction):
        lines = [
            f"{head} at a step of {item['step_s']:.6g} s, estimated error "
            f"{item['estimated_error_rad']:.2g} rad from its start"
        ]
        if isinstance(search, StepChoice) and search.cpu_s > 0.0:
            tries = len(search.tried)
            lines.append(
                f"    run cost    about {cpu_text(search.cpu_s)} of CPU for its step search "
                f"({tries} {'try' if tries == 1 else 'tries'} over its {search.span:.6g} s, "
                "as here)"
            )
        return lines
    tries = len(search.tried)
    lines = [
        f"{head}: the step search for {search.accuracy:g} rad stopped at check's budget after "
        f"{tries} {'try' if tries == 1 else 'tries'}; the run finishes it over the segment",
        f"    at a step of {search.cut_step:.4g} s the error is predicted at "
        f"{search.predicted_error:.2g} rad (from its first {search.until:.6g} s, growing as "
        f"t^{search.growth:.2g}): the step will be near {search.step:.4g} s, "
        f"{search.span / search.step:.3g} steps",
        f"    run cost    about {cpu_text(search.search_cpu_s)} of CPU for its step search "
        f"(predicted from {search.cpu_per_step * 1e6:.3g} µs a step measured here)",
    ]
    if solver.approximate_step_s is not None:
        lines.append(
            f"    the motion below was propagated at {solver.approximate_step_s:.4g} s: its "
            "sizes are close, not exact"
        )
    return lines


def guidance_section(guidance: dict[str, Any] | None, table: Any) -> list[str]:
    """The report page's section on the laws (``table``: the page's table maker)."""
    if not guidance:
        return []
    parts = [
        "<h2>Attitude laws</h2>",
        table(
            ["segment", "from", "to", "kind", "law or motion"],
            [
                [
                    s["segment"],
                    s["start"],
                    s["end"],
                    s["kind"],
                    (
                        f"onto {s['law_description']}"
                        if s["kind"] == "slew"
                        else s.get("law_description") or s.get("propagation")
                    ),
                ]
                for s in guidance["segments"]
            ],
        ),
    ]
    if guidance["slews"]:
        parts.append(
            table(
                [
                    "slew (segment)",
                    "from",
                    "angle (deg)",
                    "duration (s)",
                    "peak rate (deg/s)",
                    "off the eigen axis, at most (deg)",
                ],
                [
                    [
                        s["segment"],
                        s["start"],
                        s["angle_deg"],
                        s["duration_s"],
                        s["profile_peak_rate_deg_s"],
                        s["off_eigen_axis_at_most_deg"],
                    ]
                    for s in guidance["slews"]
                ],
            )
        )
    for loss in guidance["control_losses"]:
        parts.append(
            f"<p>Control loss at {escape(loss['epoch'])}: {escape(loss['description'])}.</p>"
        )
    parts += [f"<p class='note'>{escape(note)}</p>" for note in guidance["notes"]]
    return parts
