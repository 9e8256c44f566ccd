"""How long a scenario that neglects gravity gradient holds: its validity horizon.

A scenario with an orbit whose ``[torques]`` leave out the gravity gradient (a
torque-free one, or one with burns alone) neglects the gravity-gradient torque of the
Earth.  Its validity horizon is the time until that neglected torque would have moved
the attitude by a threshold (1° by default, ``[torques] horizon_threshold``): the same
scenario (the same events, the same burns) is propagated under gravity gradient too,
alongside the scenario's own trajectory, their attitudes are compared over the whole
span, and the first crossing is refined by bisection to a millisecond; the run
alongside goes no further than the crossing.  An attitude reset puts both on the same
attitude again; the horizon is the first crossing.

The accuracy is that of an estimate, stated with it: :data:`HORIZON_RELATIVE_ACCURACY`
(1 %) of the horizon.  The horizon says when the torque-free answer has expired by a
threshold that is itself a choice (1°): 1 % of a day is 14 minutes, far finer than a
user reads "valid until then".

**Torque-free scenarios** (no burn, no law, no ``[torques]`` step or accuracy), the
default, are first **screened** by :mod:`attitude.trajectory.averaged_kicks`: long
steps set by the size of the perturbation's kick (up to half an orbit), each kick the
torque and the gradient of the potential averaged along the exact free flow, the
events applied to its state as to the scenario's, its attitude compared with the
scenario's at its quadrature nodes (four a turn).  When that run stays below
:data:`SCREEN_FRACTION` (a half) of the threshold over the whole span, the horizon is
beyond the span; that is the answer, without numba, in about 0.1 s of CPU for a day of
a 5 rpm spinner.  Otherwise the horizon is computed as below, by the splitting: every
crossing the summary states comes from it.  The averaged kicks are an estimate whose
error grows with the run (the module's docstring): against DOP853
(``tests/test_validity_horizon_hostile_cases_against_dop853.py``) their crossings
come within 1.3e-3 of themselves on hostile cases of minutes, but the nutating 5 rpm
spinner of ``benchmarks.horizon_share`` crosses 1° 10.6 % late about 2.7 days in.
Hence the factor two: on that spinner over eight days, the averaged run crosses half
of a threshold from 0.25° to 4° at 0.51 to 0.64 of the time the splitting crosses the
threshold, 0.60 to 0.64 over thirty days (8° to 30°), and the Envisat-like tumbler of
``scenarios/tumbling_defunct_satellite.toml`` over three days at 0.23 to 0.49 (1° to
20°; ``tests/test_validity_horizon_screen_against_the_splitting.py``), so a span that
it finds below half the threshold is below the threshold with room to spare.

**The splitting** (burns, laws, a stated step, or a torque-free scenario whose screen
finds half the threshold crossed): the run alongside is the splitting
(``attitude.trajectory.torqued``) at the scenario's ``[torques]`` step or accuracy and
order when it states one; otherwise order 4 at a step of three tenths of the body's
fastest turn (at the bound √(2T/I_min) of its rate), at most a fortieth of the orbit
period; the attitudes are compared at every step, a block of steps at a time
(:func:`attitude.torques.solver.first_crossing` refines).  A segment under a law has
the law's attitude in both runs.  With burns, both runs are splittings at the
scenario's step (or accuracy): the comparison also holds their difference in
splitting error, at most the sum of their errors, which the summary states beside
it.  What limits that estimate is the sampling: the angle between the runs wobbles
within a turn, and a peak between two steps can cross first (the tumbler of
``tests/test_scenario_torques_against_torque_free_and_momentum_laws.py`` with a 5°
threshold comes out 6.8 % late at half a turn, within 0.01 s at three tenths).  With
gravity gradient as its only torque that run takes the compiled splitting loop
(:mod:`attitude.torques.compiled_steps`) past its first
:data:`attitude.torques.solver.PYTHON_LOOP_STEPS` steps.

Both runs read the orbit's position interpolated (cubic Hermite, checked against the
orbit within :data:`ORBIT_TOLERANCE_M`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from attitude.base.hermite import UniformCubicHermite
from attitude.environment.orbit import coverage_seconds
from attitude.environment.timescales import offline_time
from attitude.scenario.events import State
from attitude.scenario.modes import ModeEvent
from attitude.scenario.scenario import Scenario
from attitude.scenario.torques import ScenarioTorques
from attitude.solver.euler_solver import EulerSolver
from attitude.torques.models import GravityGradient
from attitude.torques.solver import angles_between, first_crossing
from attitude.trajectory.averaged_kicks import departure
from attitude.trajectory.modes import uses_laws
from attitude.trajectory.segments import Segment, segments
from attitude.trajectory.torqued import TorquedMotion, scenario_torque_models
from attitude.trajectory.trajectory import Trajectory, propagate

__all__ = [
    "HORIZON_RELATIVE_ACCURACY",
    "ORBIT_TOLERANCE_M",
    "SCREEN_FRACTION",
    "ValidityHorizon",
    "averaged_horizon",
    "screened_horizon",
    "splitting_horizon",
    "validity_horizon",
]

# The horizon is an estimate to this fraction of itself (module docstring).
HORIZON_RELATIVE_ACCURACY = 1e-2
# A torque-free span whose averaged kicks stay below this fraction of the threshold is
# beyond the horizon (module docstring: the averaged run's error stays well within it).
SCREEN_FRACTION = 0.5

_TURN_FRACTION = 0.3
_ORBIT_FRACTION = 1.0 / 40.0
# The orbit's position is interpolated (cubic Hermite on its positions and velocities)
# between nodes at most this far apart (s), closer if needed to keep the interpolation
# within ORBIT_TOLERANCE_M (m), checked at the middle of the intervals: 0.1 m is 1.5e-8
# of a low orbit's radius, a change of the torque's direction far below what a 1°
# threshold can see, and of the order of the orbit's own roughness (a TLE's TEME → GCRS
# rotation, interpolated between hourly nodes, moves it by centimetres).
_ORBIT_NODES_S = 60.0
ORBIT_TOLERANCE_M = 0.1
# The run alongside is compared with the scenario's this many of its steps at a time.
_BLOCK_STEPS = 2048


@dataclass(frozen=True)
class ValidityHorizon:
    """When the neglected gravity gradient moves the attitude by ``threshold_rad``.

    ``horizon_s``: TT seconds after the epoch (to :data:`HORIZON_RELATIVE_ACCURACY`),
    or ``math.inf`` beyond the span; ``searched_s``: how far the comparison went (the
    crossing, or the whole span); ``step_s``, ``order``: the torqued run alongside.
    """

    threshold_rad: float
    horizon_s: float
    searched_s: float
    span_s: float
    step_s: float
    order: int
    method: str = "splitting"

    @property
    def within_span(self) -> bool:
        return math.isfinite(self.horizon_s)

    def describe(self, format_epoch) -> str:
        """One sentence for ``check``, the summary and the report."""
        angle = f"{math.degrees(self.threshold_rad):g} deg"
        if self.within_span:
            return (
                f"the neglected gravity gradient moves the attitude by {angle} after "
                f"{self.horizon_s:.6g} s, at {format_epoch(self.horizon_s)} (to "
                f"{100.0 * HORIZON_RELATIVE_ACCURACY:g} %): the motion without it is valid "
                "until then"
            )
        return (
            f"the neglected gravity gradient moves the attitude by less than {angle} "
            f"over the whole span ({self.span_s:g} s): the horizon is beyond the span"
        )

    def as_dict(self, format_epoch) -> dict[str, Any]:
        return {
            "threshold_deg": math.degrees(self.threshold_rad),
            "horizon_s": self.horizon_s if self.within_span else None,
            "horizon": format_epoch(self.horizon_s) if self.within_span else None,
            "relative_accuracy": HORIZON_RELATIVE_ACCURACY,
            "beyond_span": not self.within_span,
            "searched_s": self.searched_s,
            "torqued_run": {
                "model": "gravity gradient (point-mass Earth)",
                "method": self.method,
                "order": self.order,
                "step_s": self.step_s,
            },
            "description": self.describe(format_epoch),
        }


def _step(trajectory: Trajectory, orbit: Any) -> float:
    """Three tenths of the fastest turn of the body over the segments (at its largest rate,
    |ω| ≤ √(2T/I_min)), at most a fortieth of the orbit period at the epoch (two-body,
    from the radius there)."""
    rates = [
        math.sqrt(
            2.0 * segment.solver.kinetic_energy / float(np.min(segment.solver.moments_of_inertia))
        )
        for segment in trajectory.segments
    ]
    candidates = [2.0 * math.pi / max(rates) * _TURN_FRACTION] if max(rates) > 0.0 else []
    candidates.append(_gradient(trajectory.scenario, orbit)[1] * _ORBIT_FRACTION)
    return min(candidates)


def validity_horizon(trajectory: Trajectory, orbit: Any) -> ValidityHorizon:
    """The validity horizon of ``trajectory`` (torque-free, or under burns alone) on
    ``orbit`` (module docstring); its threshold is the scenario's
    ``torques.horizon_threshold``: the screen's answer when it finds the span clear
    (:func:`screened_horizon`), else the splitting's (:func:`splitting_horizon`)."""
    screened = screened_horizon(trajectory, orbit)
    return screened if screened is not None else splitting_horizon(trajectory, orbit)


def screened_horizon(trajectory: Trajectory, orbit: Any) -> ValidityHorizon | None:
    """The horizon beyond the span, when ``trajectory`` is torque-free (no burn, no law,
    no ``[torques]`` step or accuracy) and its averaged kicks stay below
    :data:`SCREEN_FRACTION` of the threshold over the whole span; else None (the
    splitting is then needed: :func:`splitting_horizon`)."""
    settings = trajectory.scenario.torques
    if settings.step is not None or settings.accuracy is not None:
        return None
    if not _free_only(trajectory):
        return None
    threshold = settings.horizon_threshold
    screen = averaged_horizon(trajectory, orbit, SCREEN_FRACTION * threshold)
    return None if screen.within_span else replace(screen, threshold_rad=threshold)


def splitting_horizon(trajectory: Trajectory, orbit: Any) -> ValidityHorizon:
    """The validity horizon of ``trajectory`` by the splitting alongside it, stopped at
    the crossing (module docstring, "The splitting")."""
    scenario = trajectory.scenario
    settings = scenario.torques
    threshold = settings.horizon_threshold
    given = settings.step is not None or settings.accuracy is not None
    step = settings.step if settings.step is not None else _step(trajectory, orbit)
    torques = ScenarioTorques(
        gravity_gradient=_interpolated(orbit, scenario),
        burns=settings.burns,
        step=step if not given or settings.step is not None else None,
        accuracy=settings.accuracy,
        order=settings.order if given else 4,
        horizon_threshold=threshold,
    )
    alongside = scenario.with_torques(torques)
    if torques.step is not None:  # built segment by segment, as far as the comparison goes
        runs: Iterable[Segment] = segments(
            alongside, scenario_torque_models(alongside), torques.step, checked=False
        )
    else:  # the step the scenario's accuracy needs: the run-level search, over the span
        runs = propagate(alongside).segments
    steps: list[float] = []
    crossing = _first_crossing(runs, trajectory, threshold, steps)
    searched = min(crossing, scenario.stop_s)
    return ValidityHorizon(
        threshold, crossing, searched, scenario.stop_s, max(steps, default=step), torques.order
    )


def _free_only(trajectory: Trajectory) -> bool:
    """Whether every segment of ``trajectory`` is torque-free (no burn, no law): the
    gravity gradient is then the run alongside's only torque."""
    scenario = trajectory.scenario
    return (
        not scenario.torques.burns
        and not uses_laws(scenario)
        and all(isinstance(segment.solver, EulerSolver) for segment in trajectory.segments)
    )


def _gradient(scenario: Scenario, orbit: Any) -> tuple[GravityGradient, float]:
    """The gravity gradient of ``scenario`` on ``orbit`` and the orbit period (s) at the
    epoch (two-body, from the radius there)."""
    with_orbit = scenario.with_torques(ScenarioTorques(gravity_gradient=orbit))
    gradient = scenario_torque_models(with_orbit)[0][2]
    if not isinstance(gradient, GravityGradient):
        raise TypeError(f"the first torque model is the gravity gradient, got {gradient!r}")
    radius = float(np.linalg.norm(gradient.position(np.array([0.0]))[0]))
    return gradient, 2.0 * math.pi * math.sqrt(radius**3 / gradient.mu)


def averaged_horizon(trajectory: Trajectory, orbit: Any, threshold: float) -> ValidityHorizon:
    """The first time the averaged kicks (:mod:`attitude.trajectory.averaged_kicks`) part
    from a torque-free ``trajectory`` by ``threshold`` rad, segment by segment through
    its events: the screen of :func:`validity_horizon` (at :data:`SCREEN_FRACTION` of
    its threshold), an estimate whose accuracy the module docstring states."""
    scenario = trajectory.scenario
    gradient, period = _gradient(scenario, _interpolated(orbit, scenario))
    largest, crossing = 0.0, math.inf
    state: State | None = None
    for segment in trajectory.segments:
        if segment.event is not None:  # the event, applied to the torqued state before it
            assert state is not None and not isinstance(segment.event, ModeEvent)
            state = segment.event.apply(state)
        else:
            state = segment.state
        assert isinstance(segment.solver, EulerSolver)
        found = departure(
            state, segment.start_s, segment.end_s, segment.solver, gradient, period, threshold
        )
        largest = max(largest, found.largest_step_s)
        if math.isfinite(found.crossing_s):
            crossing = found.crossing_s
            break
        assert found.end_state is not None
        state = found.end_state
    searched = min(crossing, scenario.stop_s)
    return ValidityHorizon(
        threshold, crossing, searched, scenario.stop_s, largest, 2, "averaged kicks"
    )


def _first_crossing(
    runs: Iterable[Segment], trajectory: Trajectory, threshold: float, steps: list[float]
) -> float:
    """The first time (TT s) the attitudes of the run alongside (its segments ``runs``)
    and ``trajectory`` differ by ``threshold``, or ``math.inf``: compared at every grid
    point of the run (a step apart, where its state costs one free flow, not a step), a
    block of :data:`_BLOCK_STEPS` at a time, so that no more of the run is computed than
    the crossing needs; then refined by bisection to a millisecond between the last point
    below and the first at or above.  Each segment is compared with the trajectory's
    segment of the same events (at an event's epoch, both before it).  ``steps``: each
    segment's step is appended to it."""
    earlier = 0.0
    for segment, free in zip(runs, trajectory.segments, strict=False):
        if not isinstance(segment.solver, TorquedMotion):
            # A segment under a law: its attitude is the law's in both runs.
            earlier = segment.end_s
            continue
        grid = segment.solver.solver
        steps.append(grid.step)

        def angle(t, torqued=segment.solver, free=free.solver):
            return angles_between(torqued.attitude_quaternion(t), free.attitude_quaternion(t))

        start, end = segment.start_s, segment.end_s
        while start < end:
            block_end = min(end, start + _BLOCK_STEPS * grid.step)
            times = grid.grid_invariants(block_end)[0]
            times = times[(times > start) & (times <= block_end)]
            if times.size == 0:  # the end, a rounding beyond the grid's last point
                times = np.array([block_end])
            beyond = np.flatnonzero(angle(times) >= threshold)
            if beyond.size:
                low = float(times[beyond[0] - 1]) if beyond[0] > 0 else max(start, earlier)
                high = float(times[beyond[0]])
                return first_crossing(angle, low, high, high - low, threshold)
            start = earlier = float(times[-1])
    return math.inf


def _interpolated(orbit: Any, scenario: Scenario) -> Any:
    """The orbit's inertial position at TT seconds since the epoch, interpolated over the
    span (module docstring), for an orbit of ``attitude.environment.orbit`` (which has
    ``state_tt``); any other orbit as it is."""
    if not hasattr(orbit, "state_tt"):
        return orbit

    with offline_time():
        tt = scenario.epoch.tt
    jd1, jd2 = float(tt.jd1), float(tt.jd2)

    def exact(t: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        return orbit.state_tt(np.full(t.shape, jd1), jd2 + t / 86400.0)

    # Kick clocks may fall a step outside the span (negative coefficients): a margin,
    # within what the orbit serves (an orbit file may cover the span exactly; a clock
    # beyond it is then evaluated by the orbit itself, which says so).
    first_s, last_s = coverage_seconds(orbit, (jd1, jd2))
    low = min(max(scenario.start_s - 2.0 * _ORBIT_NODES_S, first_s), scenario.start_s)
    high = max(min(scenario.stop_s + 2.0 * _ORBIT_NODES_S, last_s), scenario.stop_s)

    def fit(spacing: float, end: float) -> tuple[Any, float]:
        """The interpolant on nodes ``spacing`` apart from ``low`` to ``end``, and its
        largest error at the middle of every interval (of every 8th past the first 64)."""
        count = max(2, math.ceil((end - low) / spacing))
        nodes = np.linspace(low, end, count + 1)
        r, v = exact(nodes)
        spline = UniformCubicHermite(low, (end - low) / count, r, v)
        middles = 0.5 * (nodes[1:] + nodes[:-1])
        middles = np.concatenate([middles[:64], middles[64::8]])
        error = float(np.max(np.linalg.norm(spline(middles) - exact(middles)[0], axis=-1)))
        return spline, error

    # A probe over at most 200 nodes sets the spacing (the error goes as its fourth
    # power), with a margin; the interpolant over the span is checked in turn.
    _, probe = fit(_ORBIT_NODES_S, min(high, low + 200.0 * _ORBIT_NODES_S))
    spacing = _ORBIT_NODES_S * min(1.0, 0.7 * (ORBIT_TOLERANCE_M / max(probe, 1e-300)) ** 0.25)
    spline, error = fit(spacing, high)
    if not error <= ORBIT_TOLERANCE_M:
        return orbit  # rougher than the probe said: the orbit as it is

    def position(t: NDArray[np.float64]) -> NDArray[np.float64]:
        t = np.asarray(t, dtype=np.float64)
        inside = (t >= low) & (t <= high)
        if inside.all():
            return spline(t)
        r = np.empty((*t.shape, 3))
        r[inside] = spline(t[inside])
        r[~inside] = exact(t[~inside])[0]
        return r

    return position
