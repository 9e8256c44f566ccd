"""The segments of a scenario's motion, built one after another through its events.

Each event starts a new segment from the state just after it: an ``EulerSolver``
(the exact torque-free motion), or, where the scenario's torques act within the
segment, a :class:`~attitude.trajectory.torqued.TorquedMotion` at the step the run
chose.  :func:`segments` builds them lazily, in time order, so that a search for that
step (``attitude.trajectory.steps``) can stop a run as soon as it has seen enough:
segment k + 1 needs segment k only at its end, where the event applies.

A segment's motion is smooth inside it except at its **breakpoints**
(:meth:`Segment.breakpoints`): the times where its solver says the motion changes
law (a torque switching on or off; a guidance mode, for a solver that has one).  A
solver declares them with a method ``breakpoints(start_s, end_s)`` returning
(time, what) pairs; the exact torque-free solver has none.  The outputs that
interpolate the motion (the AEM) end their pieces there.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import numpy as np

from attitude.base.errors import InputError
from attitude.scenario.events import Event, State
from attitude.scenario.scenario import Scenario
from attitude.solver.euler_solver import EulerSolver
from attitude.torques.models import Torque
from attitude.trajectory.torqued import TorquedMotion

__all__ = ["Breakpoint", "Segment", "check_resolved", "initial_state", "segments"]

# The time representation must resolve this fraction of the fastest turn of the body.
_RESOLVED_FRACTION_OF_A_TURN = 1e-3


@dataclass(frozen=True)
class Breakpoint:
    """A time inside a segment (TT s since the epoch) where its motion is not smooth,
    and what happens there."""

    time_s: float
    what: str


@dataclass(frozen=True)
class Segment:
    """One stretch of motion between events: [start_s, end_s] in TT seconds since the epoch.

    ``event`` is the event that started it (None for the first segment); ``before``
    and ``after`` are the states on either side of that event.
    """

    start_s: float
    end_s: float
    solver: EulerSolver | TorquedMotion
    state: State
    event: Event | None = None
    before: State | None = None

    def breakpoints(self) -> list[Breakpoint]:
        """Where the motion inside (start_s, end_s) is not smooth, in time order: what
        the segment's solver declares (module docstring)."""
        declare = getattr(self.solver, "breakpoints", None)
        if declare is None:
            return []
        return [
            Breakpoint(float(t), what)
            for t, what in declare(self.start_s, self.end_s)
            if self.start_s < t < self.end_s
        ]


def initial_state(scenario: Scenario) -> State:
    """The state at the epoch, in body axes."""
    initial = scenario.initial_state
    axes = scenario.spacecraft.principal_axes
    if initial.angular_momentum is not None:
        m0 = initial.angular_momentum
    else:  # InitialState holds exactly one of the two (checked when it is made)
        assert initial.angular_velocity is not None
        m0 = axes.tensor @ initial.angular_velocity
    return State(initial.attitude, m0, axes)


def _solver(
    state: State,
    t0: float,
    end_s: float,
    where: str,
    models: list[tuple[float, float, Torque]],
    step: float | None,
    order: int,
) -> EulerSolver | TorquedMotion:
    """The exact solver from ``state`` at ``t0``, or the torqued one at ``step`` if a
    torque acts within [t0, end_s] (``models``: (start, stop, torque) of the scenario)."""
    acting = [model for start, stop, model in models if start < end_s and stop > t0]
    try:
        if acting:
            if step is None:
                raise InputError("a torque acts but no step was given")  # a bug of the caller
            return TorquedMotion(state, t0, end_s, acting, step, order)
        return EulerSolver(state.inertia.tensor, state.angular_momentum, state.attitude, t0=t0)
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None


def check_resolved(segment: Segment, where: str) -> None:
    """Refuse a motion faster than TT seconds (floats) can follow over the segment.

    The body turns at most at |ω| ≤ G/I_min, once every 2π I_min/G seconds, and m(t)
    repeats every period T.  Where the spacing of floats near end_s exceeds a
    thousandth of the shorter of the two, every output would be noise: the elliptic
    phase λt, exact for the t given, is exact for a t that no one meant.  Under
    torques this propagates the whole segment (G is the largest over it).
    """
    solver, start_s, end_s = segment.solver, segment.start_s, segment.end_s
    try:
        G = solver.angular_momentum_norm  # under torques: the grid over the segment
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None
    if not math.isfinite(G):
        raise InputError(
            f"{where}: under the torques, the angular momentum goes beyond the float range"
        )
    if G == 0.0:
        return
    turn_s = 2.0 * math.pi * (float(np.min(solver.moments_of_inertia)) / G)
    fastest = min(turn_s, solver.period)
    resolution = float(np.spacing(max(abs(start_s), abs(end_s))))
    if not resolution <= _RESOLVED_FRACTION_OF_A_TURN * fastest:
        raise InputError(
            f"{where}: the body turns in {fastest:.3g} s, too fast for TT seconds over "
            f"this span (they resolve {resolution:.3g} s at {end_s:g} s, and a thousandth "
            f"of a turn is needed): give a slower rate or a shorter span"
        )
    if not math.isfinite(solver.kinetic_energy):
        raise InputError(f"{where}: the kinetic energy is beyond the float range")


def segments(
    scenario: Scenario,
    models: list[tuple[float, float, Torque]],
    step: float | Sequence[float | None] | None,
    checked: bool = True,
) -> Iterator[tuple[Segment, str]]:
    """The segments of ``scenario`` in time order, each with the name of the state that
    started it (``initial_state``, or the state after ``events[i]``), built one at a
    time: the next is made when it is asked for, from this one's state at its end.

    ``models``: the scenario's torques (``scenario_torque_models``); ``step``: the
    torqued segments' step (s), or one per segment (None where no torque acts: a run
    made before, rerun at its own steps).  ``checked``: refuse a segment that turns faster than
    TT seconds follow (:func:`check_resolved`) before yielding it, which propagates a
    torqued one to its end; a caller that compares runs as they go checks later.
    Errors are :class:`InputError` naming the state whose motion the solver refuses.
    """
    order = scenario.torques.order
    ends = [offset for offset, _ in scenario.events] + [scenario.stop_s]
    state = initial_state(scenario)
    where = "initial_state"
    per_segment = (
        list(step) if isinstance(step, list | tuple) else [step] * (len(scenario.events) + 1)
    )
    solver = _solver(state, 0.0, ends[0], where, models, per_segment[0], order)
    segment = Segment(0.0, ends[0], solver, state)
    if checked:
        check_resolved(segment, where)
    yield segment, where
    indices = getattr(scenario, "event_indices", range(len(scenario.events)))
    for k, ((offset, event), index, end) in enumerate(
        zip(scenario.events, indices, ends[1:], strict=True), start=1
    ):
        named = f"events[{index}] ({event.kind} at {scenario.format_epoch(offset)})"
        try:  # the segment before, propagated to its end
            before = State(solver.attitude(offset), solver.angular_momentum(offset), state.inertia)
        except InputError as exc:
            raise InputError(f"{where}: {exc}") from None
        state = event.apply(before)
        where = f"the state after {named}"
        solver = _solver(state, offset, end, where, models, per_segment[k], order)
        segment = Segment(offset, end, solver, state, event, before)
        if checked:
            check_resolved(segment, where)
        yield segment, where
