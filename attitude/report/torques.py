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
  validity horizon (``attitude.trajectory.horizon.validity_horizon``);
- what each run is, in one line (:func:`propagation_text`, the page's head and
  ``torques.propagation``): guided by attitude laws, exact torque-free motion, a
  gyrostat or torques by splitting with its estimated error, in the order they come.
"""

from __future__ import annotations

from typing import Any

from attitude.report.plan import RunPlan
from attitude.trajectory.guided import GUIDED
from attitude.trajectory.steps import CHECK_BUDGET_S
from attitude.trajectory.torqued import TorquedMotion

__all__ = [
    "cpu_text",
    "horizon_text",
    "is_exact",
    "propagation_text",
    "run_cost_s",
    "torques_lines",
    "torques_summary",
]


def _kind(plan: RunPlan, solver: Any) -> str:
    """How one segment is propagated, in words."""
    if getattr(solver, "formula", "") in GUIDED:
        return "guided by attitude laws (closed form)"
    if not isinstance(solver, TorquedMotion):
        return "exact torque-free motion (closed form, no integration)"
    error = solver.error_estimate
    if solver.formula == "gyrostat":
        said = "" if error is None else f", estimated error {error:.2g} rad"
        return f"a gyrostat by splitting with the exact gyroscopic flow{said}"
    steps = plan.trajectory.steps
    estimate = None if steps is None else steps.estimate_rad
    said = "" if estimate is None else f", estimated error {estimate:.2g} rad over the run"
    modelled = ", ".join(plan.scenario.torques.modelled())
    return f"under {modelled}: splitting with the exact free flow{said}"


def propagation_text(plan: RunPlan) -> str:
    """What the run is, segment kinds in the order they first come: ``guided by attitude
    laws (closed form), then a gyrostat by splitting with the exact gyroscopic flow,
    estimated error 8.3e-08 rad``."""
    kinds = dict.fromkeys(_kind(plan, s.solver) for s in plan.trajectory.segments)
    return ", then ".join(kinds)


def is_exact(plan: RunPlan) -> bool:
    """Whether every segment is closed form (laws, slews, the torque-free solver)."""
    return not any(isinstance(s.solver, TorquedMotion) for s in plan.trajectory.segments)


def _no_horizon_note(plan: RunPlan, neglecting: str) -> str:
    """Why a run that models no gravity gradient states no validity horizon."""
    if all(getattr(s.solver, "formula", "") in GUIDED for s in plan.trajectory.segments):
        return (
            "guided by attitude laws over the whole span: their controller holds the "
            "attitude, so no torque is neglected"
        )
    if plan.pointing.orbit is None:
        return f"no orbit: the gravity gradient that {neglecting} neglects is not known"
    return "not computed (the run computes it beside its outputs)"


def torques_summary(plan: RunPlan) -> dict[str, Any]:
    """The ``torques`` entry of ``summary.json``."""
    scenario = plan.scenario
    settings = scenario.torques
    format_epoch = scenario.format_epoch
    horizon = None if plan.horizon is None else plan.horizon.as_dict(format_epoch)
    if not settings.any:
        return {
            "modelled": [],
            "propagation": propagation_text(plan),
            "validity_horizon": horizon,
            "validity_horizon_note": None
            if horizon is not None
            else _no_horizon_note(plan, "torque-free motion"),
        }
    steps = plan.trajectory.steps
    found = None if steps is None else steps.measurement
    estimate = None if steps is None else steps.estimate_rad
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
    accuracy = settings.accuracy_rad
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
        "propagation": propagation_text(plan),
        "order": settings.order,
        "step": "given" if settings.step is not None else "chosen for the accuracy",
        "step_s": None if steps is None else steps.step_s,
        "accuracy_rad": accuracy,
        "segments": segments,
        "estimated_error_rad": estimate,
        "estimated_error_measured_over_s": None if found is None else found.until_s,
        "estimated_error_predicted": None if found is None else not found.complete,
        "accuracy_met": None
        if accuracy is None or estimate is None
        else bool(estimate <= accuracy),
        "estimated_error_note": "estimated_error_rad: the run's, the scenario rerun at twice "
        "the step through the same events and compared over the span (errors carried into "
        "a segment grow with the motion); segments[].estimated_error_rad: the same within "
        "each segment, the errors carried into it included",
        "step_search": None
        if steps is None or steps.given
        else [
            {"step_s": step, "estimated_error_rad": error, "ended": ended}
            for step, error, ended in steps.tried
        ],
        "validity_horizon": horizon,
        "validity_horizon_note": None if horizon is not None else _horizon_note(plan),
    }


def _horizon_note(plan: RunPlan) -> str:
    """Why a run under torques states no validity horizon."""
    if plan.scenario.torques.gravity_gradient is not None:
        return "the gravity gradient is modelled: there is nothing neglected to bound"
    return _no_horizon_note(plan, "the burns-only motion")


def cpu_text(seconds: float) -> str:
    """A duration of CPU for `attitude check`: 0.4 s, 25 s, 3.2 min, 1.5 h."""
    if seconds < 60.0:
        return f"{seconds:.2g} s" if seconds < 10.0 else f"{seconds:.0f} s"
    if seconds < 3600.0:
        return f"{seconds / 60.0:.2g} min"
    return f"{seconds / 3600.0:.2g} h"


def run_cost_s(plan: RunPlan) -> float | None:
    """The CPU time (s) that the run spends on the motion under torques, from the cost
    of a step measured here: the step search (as here; when check's budget stopped it,
    about two more tries of the whole span, 1.5 runs each), or with a given step, the
    run and its rerun at twice the step (1.5 runs).  None when no step was measured."""
    steps = plan.trajectory.steps
    if steps is None or steps.cpu_per_step_s <= 0.0:
        return None
    whole = 1.5 * steps.grid_steps * steps.cpu_per_step_s
    if steps.given:
        return whole
    return steps.search_cpu_s + (0.0 if steps.settled else 2.0 * whole)


def torques_lines(plan: RunPlan) -> list[str]:
    """The lines of ``attitude check`` (without their indentation)."""
    entry = torques_summary(plan)
    if not entry["modelled"]:
        lines = [f"torques     none: {entry['propagation']}"]
        horizon = horizon_text(plan)
        if horizon is not None:
            lines.append(f"horizon     {horizon}")
        return lines
    steps = plan.trajectory.steps
    assert steps is not None
    how = (
        f"step {plan.scenario.torques.step:g} s"
        if entry["step"] == "given"
        else f"step chosen for {entry['accuracy_rad']:g} rad"
    )
    lines = [f"torques     {', '.join(entry['modelled'])}; order {entry['order']}, {how}"]
    count = len(steps.tried)
    tries = f"{count} {_plural(count, 'try', 'tries')}"
    found = steps.measurement
    if not steps.settled:
        assert found is not None
        within = found.predicted_rad <= entry["accuracy_rad"]
        lines += [
            f"  step        the search stopped at check's {CHECK_BUDGET_S:g} s budget after "
            f"{tries}; the run finishes it over the whole span",
            f"  at a step of {found.step_s:.4g} s the run's error is predicted at "
            f"{found.predicted_rad:.2g} rad (from its first {found.until_s:.6g} s, growing as "
            f"t^{found.growth:.2g}), {'within' if within else 'beyond'} "
            f"{entry['accuracy_rad']:g} rad: the step will be near {steps.step_s:.4g} s",
        ]
    else:
        how_chosen = "" if steps.given else f" ({tries})"
        lines.append(
            f"  step        {steps.step_s:.4g} s in every segment under torques{how_chosen}"
        )
        if found is not None and found.complete:
            for item in entry["segments"]:
                error = item["estimated_error_rad"]
                lines.append(
                    f"  segment {item['segment']} {item['method']}: estimated error "
                    + ("none" if error is None else f"{error:.2g} rad")
                    + " (the run's, within it)"
                )
        if found is not None:
            verdict = ""
            if entry["accuracy_met"] is not None:
                verdict = (
                    f", within {entry['accuracy_rad']:g} rad"
                    if entry["accuracy_met"]
                    else f", beyond {entry['accuracy_rad']:g} rad"
                )
            if found.complete:
                where = "measured over the whole span"
            else:
                where = (
                    f"predicted from its first {found.until_s:.6g} s (growing as "
                    f"t^{found.growth:.2g}); the run measures it over the whole span"
                )
            lines.append(
                f"  estimated error of the run: {entry['estimated_error_rad']:.2g} rad"
                f"{verdict}, {where}"
            )
    if plan.trajectory.approximate:
        lines.append(
            f"  the motion below was propagated at {plan.trajectory.approximate_step_s:.4g} s "
            f"({steps.grid_steps} steps at the run's step): its sizes are close, not exact"
        )
    cost = run_cost_s(plan)
    if cost is not None:
        lines.append(
            f"  run cost    about {cpu_text(cost)} of CPU for the motion under torques "
            f"({steps.grid_steps} steps at {steps.step_s:.4g} s, and the error estimate)"
        )
    horizon = horizon_text(plan)
    if horizon is not None:  # burns alone, on an orbit: the gravity gradient left out
        lines.append(f"horizon     {horizon}")
    return lines


def _plural(count: int, one: str, many: str) -> str:
    return one if count == 1 else many


def horizon_text(plan: RunPlan) -> str | None:
    """The validity horizon's sentence, or None."""
    if plan.horizon is None:
        return None
    return plan.horizon.describe(plan.scenario.format_epoch)
