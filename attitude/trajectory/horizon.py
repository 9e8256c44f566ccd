"""How long a scenario that neglects gravity gradient holds: its validity horizon.

A scenario with an orbit whose ``[torques]`` leave out the gravity gradient (a
torque-free one, or one with burns alone) neglects the gravity-gradient torque of the
Earth.  Its validity horizon is the time until that neglected torque would have moved
the attitude by a threshold (1° by default, ``[torques] horizon_threshold``): the same
scenario (the same events, the same burns) is propagated under gravity gradient too
(``attitude.trajectory.torqued``) alongside the scenario's own trajectory, their
attitudes are compared every step, and the first crossing is refined by bisection to
a millisecond (:func:`attitude.torques.solver.first_crossing`, which
``departure_time`` uses for one solver).  An attitude reset puts both on the same
attitude again; the horizon is the first crossing.  With burns, both runs are
splittings at the scenario's step (or accuracy): the comparison also holds their
difference in splitting error, at most the sum of their errors, which the summary
states beside it.

The torqued run uses the scenario's ``[torques]`` step or accuracy and order when it
states one; otherwise order 4 at a step of a fifth of the body's fastest turn (at the
bound √(2T/I_min) of its rate), at most a fortieth of the orbit period: a degree needs
far less accuracy than the splitting gives there (docs/torques.md, "The scenario
route", measures the horizon against a run at a quarter of that step).  The
search covers the span, but at most :data:`MAX_HORIZON_STEPS` steps of that run: when
the span is longer, the horizon is stated as beyond the time searched.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from attitude.scenario.scenario import Scenario
from attitude.scenario.torques import ScenarioTorques
from attitude.torques.models import MU_EARTH_M3_S2, GravityGradient
from attitude.torques.solver import angles_between, first_crossing
from attitude.trajectory.torqued import scenario_torque_models
from attitude.trajectory.trajectory import Trajectory, propagate

__all__ = ["MAX_HORIZON_STEPS", "ValidityHorizon", "validity_horizon"]

# The torqued run alongside costs about 8 free flows a step: 20,000 steps are ~1.5 s of
# CPU for the one-day 5 rpm spinner with the compiled free flow (docs/torques.md).
MAX_HORIZON_STEPS = 20_000
_TURN_FRACTION = 0.2
_ORBIT_FRACTION = 1.0 / 40.0


@dataclass(frozen=True)
class ValidityHorizon:
    """When the neglected gravity gradient moves the attitude by ``threshold_rad``.

    ``horizon_s``: TT seconds after the epoch, or ``math.inf`` if not within
    ``searched_s`` (the span, or less when the search was capped); ``step_s``,
    ``order``: the torqued run alongside.
    """

    threshold_rad: float
    horizon_s: float
    searched_s: float
    span_s: float
    step_s: float
    order: int

    @property
    def within_span(self) -> bool:
        return math.isfinite(self.horizon_s)

    def describe(self, format_epoch) -> str:
        """One sentence for ``check``, the summary and the report."""
        angle = f"{math.degrees(self.threshold_rad):g} deg"
        if self.within_span:
            return (
                f"the neglected gravity gradient moves the attitude by {angle} after "
                f"{self.horizon_s:.6g} s, at {format_epoch(self.horizon_s)}: the motion without it "
                "is valid until then"
            )
        if self.searched_s >= self.span_s:
            return (
                f"the neglected gravity gradient moves the attitude by less than {angle} "
                f"over the whole span ({self.span_s:g} s): the horizon is beyond the span"
            )
        return (
            f"the neglected gravity gradient moves the attitude by less than {angle} over "
            f"the first {self.searched_s:.6g} s searched (of {self.span_s:g} s): the horizon "
            f"is beyond {format_epoch(self.searched_s)}"
        )

    def as_dict(self, format_epoch) -> dict[str, Any]:
        return {
            "threshold_deg": math.degrees(self.threshold_rad),
            "horizon_s": self.horizon_s if self.within_span else None,
            "horizon": format_epoch(self.horizon_s) if self.within_span else None,
            "beyond_span": not self.within_span and self.searched_s >= self.span_s,
            "searched_s": self.searched_s,
            "torqued_run": {
                "model": "gravity gradient (point-mass Earth)",
                "order": self.order,
                "step_s": self.step_s,
            },
            "description": self.describe(format_epoch),
        }


def _step(trajectory: Trajectory, orbit: Any) -> float:
    """A fifth of the fastest turn of the body over the segments (at its largest rate,
    |ω| ≤ √(2T/I_min)), at most a fortieth of the orbit period at the epoch (two-body,
    from the radius there)."""
    rates = [
        math.sqrt(
            2.0 * segment.solver.kinetic_energy / float(np.min(segment.solver.moments_of_inertia))
        )
        for segment in trajectory.segments
    ]
    candidates = [2.0 * math.pi / max(rates) * _TURN_FRACTION] if max(rates) > 0.0 else []
    scenario = trajectory.scenario
    with_orbit = scenario.with_torques(ScenarioTorques(gravity_gradient=orbit))
    gradient = scenario_torque_models(with_orbit)[0][2]
    if not isinstance(gradient, GravityGradient):
        raise TypeError(f"the first torque model is the gravity gradient, got {gradient!r}")
    radius = float(np.linalg.norm(gradient.position(np.array([0.0]))[0]))
    candidates.append(2.0 * math.pi * math.sqrt(radius**3 / MU_EARTH_M3_S2) * _ORBIT_FRACTION)
    return min(candidates)


def validity_horizon(trajectory: Trajectory, orbit: Any) -> ValidityHorizon:
    """The validity horizon of ``trajectory`` (torque-free, or under burns alone) on
    ``orbit`` (module docstring); its threshold is the scenario's
    ``torques.horizon_threshold``."""
    scenario = trajectory.scenario
    settings = scenario.torques
    threshold = settings.horizon_threshold
    given = settings.step is not None or settings.accuracy is not None
    step = settings.step if settings.step is not None else _step(trajectory, orbit)
    searched = min(scenario.stop_s, MAX_HORIZON_STEPS * step)
    torques = ScenarioTorques(
        gravity_gradient=orbit,
        burns=settings.burns,
        step=step if not given or settings.step is not None else None,
        accuracy=settings.accuracy,
        order=settings.order if given else 4,
        horizon_threshold=threshold,
    )
    torqued = propagate(_truncated(scenario, searched).with_torques(torques))
    # (Segments under a law have no step: their attitude is the law's in both runs.)
    run_step = max(s.solver.step for s in torqued.segments if hasattr(s.solver, "step"))

    def angle(t):
        return angles_between(torqued.attitude_quaternion(t), trajectory.attitude_quaternion(t))

    crossing = first_crossing(angle, 0.0, searched, run_step, threshold)
    return ValidityHorizon(threshold, crossing, searched, scenario.stop_s, run_step, torques.order)


def _truncated(scenario: Scenario, stop_s: float) -> Scenario:
    """``scenario`` over [epoch, stop_s] only (its events up to there)."""
    if stop_s >= scenario.stop_s:
        return scenario
    events = [event for offset, event in scenario.events if offset <= stop_s]
    return Scenario(
        scenario.name,
        scenario.spacecraft,
        scenario.epoch,
        scenario.initial_state,
        events,
        duration=stop_s,
        torques=scenario.torques,
        orbit=getattr(scenario, "orbit", None),
    )
