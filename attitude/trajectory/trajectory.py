"""The propagated motion of a scenario: exact solver segments between events.

``propagate(scenario)`` applies the events in time order; each starts a new
``EulerSolver`` from the state just after it, or, where the scenario's torques act
(``attitude.scenario.torques``), a :class:`~attitude.trajectory.torqued.TorquedMotion`
(the torqued solver, with the same interface).  The resulting :class:`Trajectory` is
evaluated at any times in [epoch, stop], not only on the output grid: pass an
``astropy.time.Time`` array, or floats (TT seconds since the scenario epoch) to skip
the time-scale conversion.  An output time equal to an event's epoch gets the
post-event state; times within 1 ns of an event's epoch count as that epoch (epochs
carry about 1e-12 s of rounding from their UTC→TT conversion, and a nanosecond of
torque-free motion is far below anything this package reports).
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.environment.timescales import SAME_INSTANT_S, tt_seconds
from attitude.scenario.events import Event, State
from attitude.scenario.scenario import Scenario
from attitude.solver.euler_solver import EulerSolver
from attitude.torques.models import ConstantTorque
from attitude.torques.solver import angles_between
from attitude.trajectory.guided import GuidedMotion
from attitude.trajectory.modes import mode_segments, uses_laws
from attitude.trajectory.torqued import TorquedMotion, scenario_torque_models

if TYPE_CHECKING:  # astropy loads only when a Time is made
    from astropy.time import Time

__all__ = ["Segment", "Trajectory", "propagate"]

# Times this close outside [0, stop], or before an event (TT seconds), count as on it.
_SPAN_TOLERANCE_S = SAME_INSTANT_S


@dataclass(frozen=True)
class Segment:
    """One stretch of torque-free motion: [start_s, end_s] in TT seconds since the epoch.

    ``event`` is the event that started it (None for the first segment); ``before``
    and ``after`` are the states on either side of that event.  ``rate_key``: the
    scenario key that sets how fast the body turns in it, for errors that are about
    that rate (the state's ``initial_state.angular_velocity``, ``events[i].impulse``,
    or the burn that spins it up, ``torques.burns[i].torque``).
    """

    start_s: float
    end_s: float
    solver: EulerSolver | TorquedMotion | GuidedMotion
    state: State
    event: Event | None = None
    before: State | None = None
    rate_key: str | None = None


# The time representation must resolve this fraction of the fastest turn of the body.
_RESOLVED_FRACTION_OF_A_TURN = 1e-3


@dataclass(frozen=True)
class _Where:
    """The state a segment starts from, as errors name it: ``key``, the scenario key
    that gave its rate (``initial_state.angular_velocity``, ``events[2].impulse``), and
    ``text``, the state in words for the reason (empty for the initial state)."""

    key: str
    text: str = ""

    def error(self, reason: str) -> InputError:
        return InputError(f"{self.text}: {reason}" if self.text else reason, key=self.key)


def _initial_where(scenario: Scenario) -> _Where:
    given = "angular_velocity" if scenario.initial_state.angular_velocity is not None else None
    return _Where(f"initial_state.{given or 'angular_momentum'}")


def _event_where(scenario: Scenario, index: int, offset: float, event: Event) -> _Where:
    """events[index]: its key that changed the rate (an impulse, a reset's new rate), or
    the event's table (an inertia change: moments or a tensor)."""
    key = f"events[{index}]"
    if event.kind == "angular_impulse":
        key += ".impulse"
    elif event.kind == "attitude_reset":
        for name in ("angular_velocity", "angular_momentum"):
            if getattr(event, name, None) is not None:
                key += f".{name}"
    return _Where(key, f"the state after the {event.kind} at {scenario.format_epoch(offset)}")


def _acting(models: list, t0: float, end_s: float) -> list[tuple[Any, str]]:
    """The torque models (and their keys) that act within [t0, end_s]."""
    return [(model, key) for start, stop, model, key in models if start < end_s and stop > t0]


def _solver(
    state: State,
    t0: float,
    end_s: float,
    where: _Where,
    scenario: Scenario,
    models: list,
    step: float | None = None,
) -> EulerSolver | TorquedMotion:
    """The exact solver from ``state`` at ``t0``, or the torqued one if a torque acts
    within [t0, end_s] (``models``: (start, stop, torque, key) of the scenario), at
    ``step`` if given, else as the scenario's torques say.  An error that names no key
    (the solver refuses the state) is the state's, ``where``."""
    acting = _acting(models, t0, end_s)
    try:
        if acting:
            _check_resolved_at_start(state, t0, end_s, where)
            settings = scenario.torques
            if step is not None:
                settings = dataclasses.replace(settings, step=step, accuracy=None)
            torques = [model for model, _ in acting]
            return TorquedMotion(state, t0, end_s, torques, settings, [k for _, k in acting])
        return EulerSolver(state.inertia.tensor, state.angular_momentum, state.attitude, t0=t0)
    except InputError as exc:
        if exc.key is not None:  # a torque's key, or the orbit's: the value that is bad
            raise
        raise where.error(exc.reason) from None


def _strongest_burn(models: list, t0: float, end_s: float) -> str | None:
    """The key of the burn that adds the most momentum within [t0, end_s], or None."""
    burns = [
        (float(np.linalg.norm(model.torque)) * (min(model.stop, end_s) - max(model.start, t0)), key)
        for model, key in _acting(models, t0, end_s)
        if isinstance(model, ConstantTorque)
    ]
    return max(burns, key=lambda item: item[0])[1] if burns else None


def _resolution_error(
    where: _Where, G: float, I_min: float, period: float, start_s: float, end_s: float
) -> InputError | None:
    """The error for a motion faster than TT seconds (floats) follow over [start_s,
    end_s], or None.

    The body turns at most at |ω| ≤ G/I_min, once every 2π I_min/G seconds, and m(t)
    repeats every period T.  Where the spacing of floats near end_s exceeds a
    thousandth of the shorter of the two, every output would be noise: the elliptic
    phase λt, exact for the t given, is exact for a t that no one meant.
    """
    if G == 0.0:
        return None
    turn_s = 2.0 * math.pi * (I_min / G)
    fastest = min(turn_s, period)
    resolution = float(np.spacing(max(abs(start_s), abs(end_s))))
    if resolution <= _RESOLVED_FRACTION_OF_A_TURN * fastest:
        return None
    return where.error(
        f"the body turns in {fastest:.3g} s, too fast for TT seconds over "
        f"this span (they resolve {resolution:.3g} s at {end_s:g} s, and a thousandth "
        f"of a turn is needed): give a slower rate or a shorter span"
    )


def _check_resolved_at_start(state: State, start_s: float, end_s: float, where: _Where) -> None:
    """Refuse a state that turns too fast for TT seconds before any torque acts on it
    (:func:`_resolution_error` at the state's own rate): the state, not a torque, is
    what is wrong, and the torqued solver would only spend its step search finding so."""
    G = float(np.linalg.norm(state.angular_momentum))
    if not math.isfinite(G):
        raise where.error("the angular momentum is beyond the float range")
    I_min = float(np.min(state.inertia.moments))
    error = _resolution_error(where, G, I_min, math.inf, start_s, end_s)
    if error is not None:
        raise error


def _check_resolved(
    solver: EulerSolver | TorquedMotion,
    start_s: float,
    end_s: float,
    where: _Where,
    burn: str | None = None,
) -> None:
    """Refuse a motion faster than TT seconds (floats) can follow over [start_s, end_s]
    (:func:`_resolution_error`).  Under torques the bound is the largest over the
    segment: when the state was slow enough at its start (checked before), the burn
    ``burn`` (the key of the segment's strongest) spun it up."""
    if burn is not None:
        where = _Where(burn, "spun up by the burns")
    try:
        G = solver.angular_momentum_norm  # under torques: the grid over the segment
    except InputError as exc:
        raise (exc if exc.key else where.error(exc.reason)) from None
    if not math.isfinite(G):
        raise where.error("under the torques, the angular momentum goes beyond the float range")
    I_min = float(np.min(solver.moments_of_inertia))
    error = _resolution_error(where, G, I_min, solver.period, start_s, end_s)
    if error is not None:
        raise error
    if not math.isfinite(solver.kinetic_energy):
        raise where.error("the kinetic energy is beyond the float range")


def _rate_key(
    solver: EulerSolver | TorquedMotion, state: State, where: _Where, burn: str | None
) -> str:
    """The key that sets the segment's fastest turn: the burn when the burns at least
    double the momentum the segment starts with, else the state's."""
    if burn is not None and solver.angular_momentum_norm > 2.0 * float(
        np.linalg.norm(state.angular_momentum)
    ):
        return burn
    return where.key


def propagate(scenario: Scenario, steps: list[float | None] | None = None) -> Trajectory:
    """The exact motion of ``scenario`` over [epoch, stop], through its events.

    ``steps``: per segment, the torqued solver's step (None: as the scenario says), to
    rerun a torqued trajectory at other steps (:attr:`Trajectory.error_estimate`).
    Raises :class:`InputError` whose ``key`` names what holds the bad value: the
    state (``initial_state.angular_velocity``, ``events[i].impulse``) whose motion the
    solver refuses, or that turns too fast for TT seconds (floats) to follow over the
    span; a burn (``torques.burns[i].torque``) that spins the body up that fast; the
    torques' settings or the orbit the gravity gradient needs.
    """
    models = scenario_torque_models(scenario) if scenario.torques.any else []
    if uses_laws(scenario):  # laws, slews and control losses: attitude.trajectory.modes
        raw = mode_segments(
            scenario,
            steps or [],
            lambda state, t0, end, key, text, step: _solver(
                state, t0, end, _Where(key, text), scenario, models, step
            ),
            lambda solver, t0, end, key, text: _check_resolved(
                solver,
                t0,
                end,
                _Where(key, text),
                # Under a law its controller takes the burns: they spin up free bodies only.
                None if isinstance(solver, GuidedMotion) else _strongest_burn(models, t0, end),
            ),
            models,
        )
        return Trajectory(scenario, [Segment(*item) for item in raw])
    initial = scenario.initial_state
    axes = scenario.spacecraft.principal_axes
    if initial.angular_momentum is not None:
        m0 = initial.angular_momentum
    else:  # InitialState holds exactly one of the two (checked when it is made)
        assert initial.angular_velocity is not None
        m0 = axes.tensor @ initial.angular_velocity
    assert initial.attitude is not None  # without a law, the attitude is given
    state = State(initial.attitude, m0, axes)
    starts: list[tuple[float, State, Event | None, State | None]] = [(0.0, state, None, None)]
    ends = [offset for offset, _ in scenario.events] + [scenario.stop_s]
    steps = steps or [None] * len(ends)
    where = _initial_where(scenario)
    solver = _solver(state, 0.0, ends[0], where, scenario, models, steps[0])
    burn = _strongest_burn(models, 0.0, ends[0])
    _check_resolved(solver, 0.0, ends[0], where, burn)
    solvers = [solver]
    rate_keys = [_rate_key(solver, state, where, burn)]
    indices = getattr(scenario, "event_indices", range(len(scenario.events)))
    for k, ((offset, event), index, end) in enumerate(
        zip(scenario.events, indices, ends[1:], strict=True), start=1
    ):
        before = State(solver.attitude(offset), solver.angular_momentum(offset), state.inertia)
        state = event.apply(before)
        where = _event_where(scenario, index, offset, event)
        solver = _solver(state, offset, end, where, scenario, models, steps[k])
        burn = _strongest_burn(models, offset, end)
        _check_resolved(solver, offset, end, where, burn)
        solvers.append(solver)
        rate_keys.append(_rate_key(solver, state, where, burn))
        starts.append((offset, state, event, before))
    segments = [
        Segment(start, end, solver, state, event, before, rate_key)
        for (start, state, event, before), end, solver, rate_key in zip(
            starts, ends, solvers, rate_keys, strict=True
        )
    ]
    return Trajectory(scenario, segments)


class Trajectory:
    """The exact motion of a scenario; evaluate it at any times within [epoch, stop].

    Every method takes ``times``: an ``astropy.time.Time`` (any scale, scalar or
    1-D), or floats, read as TT seconds since the scenario epoch.  Vectors are in
    body axes unless the name says inertial.
    """

    def __init__(self, scenario: Scenario, segments: list[Segment]) -> None:
        self.scenario = scenario
        self.segments = segments
        # Segment k is in force from _starts[k] on (an event's epoch gets its post-event state).
        self._starts = np.array([segment.start_s for segment in segments]) - _SPAN_TOLERANCE_S
        self._starts[0] = -np.inf

    @property
    def epoch(self) -> Time:
        return self.scenario.epoch

    @property
    def stop_s(self) -> float:
        return self.scenario.stop_s

    def seconds(self, times: Any) -> NDArray[np.float64]:
        """TT seconds since the epoch, checked to lie within [epoch, stop]."""
        from astropy.time import Time

        if isinstance(times, Time):
            τ = tt_seconds(times, self.epoch)
        else:
            τ = np.asarray(times, dtype=np.float64)
        if not np.all(np.isfinite(τ)):
            raise InputError("times must be finite")
        outside = (τ < -_SPAN_TOLERANCE_S) | (τ > self.stop_s + _SPAN_TOLERANCE_S)
        if np.any(outside):
            bad = float(np.asarray(τ)[outside].ravel()[0])
            raise InputError(
                f"time {self.scenario.format_epoch(bad)} ({bad:.9g} s after the epoch) is outside "
                f"the trajectory span [{self.scenario.format_epoch(0.0)}, "
                f"{self.scenario.format_epoch(self.stop_s)}]"
            )
        return τ

    def segment_index(self, times: Any) -> NDArray[np.intp]:
        """Index of the segment in force at each time (the later one at an event epoch)."""
        τ = self.seconds(times)
        return np.searchsorted(self._starts, τ, side="right") - 1

    def _by_segment(self, times: Any, evaluate, width: int) -> NDArray[np.float64]:
        """``evaluate(solver, τ)`` on the times of each segment, assembled in order."""
        τ = self.seconds(times)
        flat = np.ravel(τ)
        out = np.empty((flat.size, width))
        if flat.size > 1 and np.all(flat[1:] >= flat[:-1]):
            # Sorted times (an output grid): each segment is one slice, no masks.
            bounds = np.searchsorted(flat, self._starts[1:], side="left")
            edges = [0, *bounds.tolist(), flat.size]
            for k, (a, b) in enumerate(itertools.pairwise(edges)):
                if b > a:
                    out[a:b] = evaluate(self.segments[k].solver, flat[a:b])
        else:
            index = np.searchsorted(self._starts, flat, side="right") - 1
            for k in np.unique(index):
                mask = index == k
                out[mask] = evaluate(self.segments[k].solver, flat[mask])
        return out.reshape((*np.shape(τ), width))

    def attitude_quaternion(self, times: Any, scalar_first: bool = True) -> NDArray[np.float64]:
        """Unit quaternions body → inertial (ICRF axes), (w, x, y, z) when scalar_first."""
        return self._by_segment(
            times, lambda solver, τ: solver.attitude_quaternion(τ, scalar_first), 4
        )

    def attitude(self, times: Any) -> Rotation:
        """Rotation body → inertial (ICRF axes): one for a scalar time, a stack for 1-D.

        Its ``as_quat()`` is scalar last (scipy's default); ``attitude_quaternion``
        gives the same rotation scalar first (docs/conventions.md)."""
        return Rotation.from_quat(self.attitude_quaternion(times, scalar_first=False))

    def angular_momentum(self, times: Any) -> NDArray[np.float64]:
        """Body angular momentum, N m s."""
        return self._by_segment(times, lambda solver, τ: solver.angular_momentum(τ), 3)

    def angular_velocity(self, times: Any) -> NDArray[np.float64]:
        """Body angular velocity, rad/s."""
        return self._by_segment(times, lambda solver, τ: solver.angular_velocity(τ), 3)

    def inertial_angular_momentum(self, times: Any) -> NDArray[np.float64]:
        """Angular momentum in inertial axes, N m s (constant within a torque-free segment)."""

        def evaluate(solver, τ):
            if isinstance(solver, TorquedMotion | GuidedMotion):
                return solver.inertial_angular_momentum_at(τ)
            return np.tile(solver.inertial_angular_momentum, (τ.size, 1))

        return self._by_segment(times, evaluate, 3)

    def kinetic_energy(self, times: Any) -> NDArray[np.float64]:
        """Rotational kinetic energy, J (constant within a torque-free segment)."""

        def evaluate(solver, τ):
            if isinstance(solver, TorquedMotion | GuidedMotion):
                return solver.kinetic_energy_at(τ)[:, None]
            return np.full((τ.size, 1), solver.kinetic_energy)

        return self._by_segment(times, evaluate, 1)[..., 0]

    @cached_property
    def error_estimate(self) -> float:
        """The estimated worst attitude error of the run (rad); 0 for the exact solver.

        Under torques, the segments' errors carry through the events and grow with the
        motion (an error of the momentum shifts the phase of a tumble), so each
        segment's own estimate does not add up to the run's.  This is the run's:
        the same scenario at twice each segment's step, through the same events,
        compared at 64 times over the span and at each segment's end, the largest angle
        over 2^p − 1 (Richardson, p the order).
        """
        steps = [
            2.0 * s.solver.step if isinstance(s.solver, TorquedMotion) else None
            for s in self.segments
        ]
        if all(step is None for step in steps):
            return 0.0
        coarse = propagate(self.scenario, steps)
        checks = np.unique(
            np.concatenate(
                [
                    np.linspace(0.0, self.stop_s, 65)[1:],
                    [s.end_s for s in self.segments if s.end_s > 0.0],
                ]
            )
        )
        difference = angles_between(
            self.attitude_quaternion(checks), coarse.attitude_quaternion(checks)
        )
        return float(np.max(difference)) / (2.0**self.scenario.torques.order - 1.0)

    def flip_times(self) -> NDArray[np.float64]:
        """All Джанибеков flips over [epoch, stop], TT seconds since the epoch (closed form)."""
        per_segment = [
            segment.solver.flip_times(segment.start_s, segment.end_s) for segment in self.segments
        ]
        return np.unique(np.concatenate(per_segment) if per_segment else np.empty(0))

    def __repr__(self) -> str:
        return f"Trajectory({self.scenario.name!r}, {len(self.segments)} segments)"
