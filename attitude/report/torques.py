"""What a run says about torques: which were modelled, the method, its step and error.

For ``summary.json`` (``torques``), ``attitude check`` and the HTML report, from the
:class:`~attitude.report.plan.RunPlan`:

- a scenario under torques: the torques (gravity gradient, each burn with its start,
  duration, torque and frame), the splitting method and order, the step (given, or
  chosen for the stated accuracy), the estimated attitude error of each segment under
  torques from its own start state (``attitude.trajectory.torqued``), and the run's, which
  carries the errors through the events
  (:attr:`~attitude.trajectory.trajectory.Trajectory.error_estimate`);
- a torque-free scenario: that the exact solver propagated it, and with an orbit its
  validity horizon (``attitude.trajectory.horizon.validity_horizon``).
"""

from __future__ import annotations

from typing import Any

from attitude.report.plan import RunPlan
from attitude.trajectory.torqued import TorquedMotion

__all__ = ["horizon_text", "torques_lines", "torques_summary"]


def torques_summary(plan: RunPlan) -> dict[str, Any]:
    """The ``torques`` entry of ``summary.json``."""
    scenario = plan.scenario
    settings = scenario.torques
    format_epoch = scenario.format_epoch
    horizon = None if plan.horizon is None else plan.horizon.as_dict(format_epoch)
    if not settings.any:
        return {
            "modelled": [],
            "propagation": "exact torque-free solver (closed form), no step",
            "validity_horizon": horizon,
            "validity_horizon_note": None
            if horizon is not None
            else "no orbit: the gravity gradient that torque-free motion neglects is not known",
        }
    segments = [
        {
            "segment": k,
            "method": segment.solver.method,
            "step_s": segment.solver.step,
            "estimated_error_rad": segment.solver.error_estimate,
        }
        for k, segment in enumerate(plan.trajectory.segments)
        if isinstance(segment.solver, TorquedMotion)
    ]
    return {
        "modelled": settings.modelled(),
        "gravity_gradient": settings.gravity_gradient is not None,
        "burns": [
            {
                "start": format_epoch(placed.start_s),
                "start_s": placed.start_s,
                "duration_s": placed.burn.duration,
                "torque_N_m": placed.torque.tolist(),
                "frame": placed.burn.frame,
                "label": placed.burn.label or None,
            }
            for placed in scenario.burns
        ],
        "propagation": "splitting with the exact free flow (docs/torques.md)",
        "order": settings.order,
        "step": "given" if settings.step is not None else "chosen for the accuracy",
        "accuracy_rad": settings.accuracy_rad,
        "segments": segments,
        "estimated_error_rad": plan.trajectory.error_estimate,
        "estimated_error_note": "segments[].estimated_error_rad: each segment's own, from its "
        "start state; estimated_error_rad: the run's, the scenario rerun at twice each step "
        "through the same events (errors carried into a segment grow with the motion)",
        "validity_horizon": horizon,
        "validity_horizon_note": None if horizon is not None else _horizon_note(settings),
    }


def _horizon_note(settings: Any) -> str:
    """Why a run under torques states no validity horizon."""
    if settings.gravity_gradient is not None:
        return "the gravity gradient is modelled: there is nothing neglected to bound"
    return "no orbit: the gravity gradient that the burns-only motion neglects is not known"


def torques_lines(plan: RunPlan) -> list[str]:
    """The lines of ``attitude check`` (without their indentation)."""
    entry = torques_summary(plan)
    if not entry["modelled"]:
        lines = ["torques     none: the exact torque-free solver"]
        horizon = horizon_text(plan)
        if horizon is not None:
            lines.append(f"horizon     {horizon}")
        return lines
    how = (
        f"step {plan.scenario.torques.step:g} s"
        if entry["step"] == "given"
        else f"step chosen for {entry['accuracy_rad']:g} rad"
    )
    lines = [f"torques     {', '.join(entry['modelled'])}; order {entry['order']}, {how}"]
    for item in entry["segments"]:
        lines.append(
            f"  segment {item['segment']} {item['method']} at a step of {item['step_s']:.6g} s, "
            f"estimated error {item['estimated_error_rad']:.2g} rad from its start"
        )
    lines.append(
        f"  estimated error of the run, through the events: {entry['estimated_error_rad']:.2g} rad"
    )
    horizon = horizon_text(plan)
    if horizon is not None:  # burns alone, on an orbit: the gravity gradient left out
        lines.append(f"horizon     {horizon}")
    return lines


def horizon_text(plan: RunPlan) -> str | None:
    """The validity horizon's sentence, or None."""
    if plan.horizon is None:
        return None
    return plan.horizon.describe(plan.scenario.format_epoch)
