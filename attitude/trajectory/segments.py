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

An error a segment's motion causes names the scenario key that holds the bad value
(``InputError.key``): the key that gave the state its rate (:class:`Where`:
``initial_state.angular_velocity``, ``events[2].impulse``) when the state itself is
beyond what the solver or TT seconds follow, and the burn that adds the most momentum
within the segment (``torques.burns[i].torque``) when a state slow enough at its
start is spun up beyond it (:meth:`Segment.refused`).  :attr:`Segment.rate_key` is
the key that sets how fast the body turns in the segment, for the errors about that
rate that the outputs raise (the AEM's time tags).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from functools import partial
from typing import Any

import numpy as np

from attitude.base.errors import InputError
from attitude.scenario.events import Event, State
from attitude.scenario.modes import ModeEvent
from attitude.scenario.scenario import Scenario
from attitude.solver.euler_solver import EulerSolver
from attitude.torques.models import ConstantTorque, Torque
from attitude.trajectory.guided import GuidedMotion
from attitude.trajectory.modes import law_initial_state, mode_segments, uses_laws
from attitude.trajectory.torqued import TorquedMotion

__all__ = ["Breakpoint", "Segment", "Where", "check_resolved", "initial_state", "segments"]

# The time representation must resolve this fraction of the fastest turn of the body.
_RESOLVED_FRACTION_OF_A_TURN = 1e-3


@dataclass(frozen=True)
class Breakpoint:
    """A time inside a segment (TT s since the epoch) where its motion is not smooth,
    and what happens there."""

    time_s: float
    what: str


@dataclass(frozen=True)
class Where:
    """The state a segment starts from, as errors name it: ``key``, the scenario key
    that gave its rate (``initial_state.angular_velocity``, ``events[2].impulse``), and
    ``text``, the state in words for the reason (empty for the initial state), or a
    function that gives it (worded only for an error: an event's epoch costs an
    astropy formatting, and a Monte Carlo sample builds its segments thousands of
    times)."""

    key: str
    text: str | Callable[[], str] = ""

    def error(self, reason: str) -> InputError:
        text = self.text() if callable(self.text) else self.text
        return InputError(f"{text}: {reason}" if text else reason, key=self.key)


def _initial_where(scenario: Scenario) -> Where:
    given = "angular_velocity" if scenario.initial_state.angular_velocity is not None else None
    return Where(f"initial_state.{given or 'angular_momentum'}")


def _event_where(scenario: Scenario, index: int, offset: float, event: Event) -> Where:
    """events[index]: its key that changed the rate (an impulse, a reset's new rate), or
    the event's table (an inertia change: moments or a tensor)."""
    key = f"events[{index}]"
    if event.kind == "angular_impulse":
        key += ".impulse"
    elif event.kind == "attitude_reset":
        for name in ("angular_velocity", "angular_momentum"):
            if getattr(event, name, None) is not None:
                key += f".{name}"
    return Where(key, partial(_event_text, event.kind, scenario, offset))


def _event_text(kind: str, scenario: Scenario, offset: float) -> str:
    return f"the state after the {kind} at {scenario.format_epoch(offset)}"


@dataclass(frozen=True)
class Segment:
    """One stretch of motion between events: [start_s, end_s] in TT seconds since the epoch.

    ``event`` is the event that started it (None for the first segment); ``before``
    and ``after`` are the states on either side of that event.  ``where``: the state
    as errors name it (None: a segment made by hand); ``burn_key``: the key of the
    burn that adds the most momentum within the segment, if one acts.
    """

    start_s: float
    end_s: float
    solver: EulerSolver | TorquedMotion | GuidedMotion
    state: State
    event: Event | ModeEvent | None = None
    before: State | None = None
    where: Where | None = None
    burn_key: str | None = None

    @property
    def rate_key(self) -> str | None:
        """The scenario key that sets how fast the body turns in the segment, for errors
        about that rate: the burn (``torques.burns[i].torque``) when the burns at least
        double the momentum the segment starts with, else the state's
        (``initial_state.angular_velocity``, ``events[i].impulse``).  Under torques
        this propagates the whole segment."""
        if self.burn_key is not None and self.solver.angular_momentum_norm > 2.0 * float(
            np.linalg.norm(self.state.angular_momentum)
        ):
            return self.burn_key
        return None if self.where is None else self.where.key

    def refused(self, exc: InputError, spun_up: str = "") -> InputError:
        """``exc``, raised by the segment's motion, naming what holds the bad value: its
        own key when it has one (a torque's, the orbit's), else the burn when one acts
        (the state was checked slow enough at its start: :func:`segments`), else the
        state.  ``spun_up``: the burn's words for the reason."""
        if exc.key is not None:
            return exc
        if self.burn_key is not None:
            return Where(self.burn_key, spun_up).error(exc.reason)
        return (self.where or Where("")).error(exc.reason)

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
    """The state at the epoch, in body axes (under a law, the law's there)."""
    initial = scenario.initial_state
    if initial.law is not None:
        return law_initial_state(scenario)
    axes = scenario.spacecraft.principal_axes
    if initial.angular_momentum is not None:
        m0 = initial.angular_momentum
    else:  # InitialState holds exactly one of the two (checked when it is made)
        assert initial.angular_velocity is not None
        m0 = axes.tensor @ initial.angular_velocity
    assert initial.attitude is not None  # without a law, the attitude is given
    return State(initial.attitude, m0, axes)


def _acting(
    models: list[tuple[float, float, Torque, str]], t0: float, end_s: float
) -> list[tuple[Torque, str]]:
    """The torque models (and their keys) that act within [t0, end_s]."""
    return [(model, key) for start, stop, model, key in models if start < end_s and stop > t0]


def _strongest_burn(acting: list[tuple[Torque, str]], t0: float, end_s: float) -> str | None:
    """The key of the burn that adds the most momentum within [t0, end_s], or None."""
    burns = [
        (float(np.linalg.norm(model.torque)) * (min(model.stop, end_s) - max(model.start, t0)), key)
        for model, key in acting
        if isinstance(model, ConstantTorque)
    ]
    return max(burns, key=lambda item: item[0])[1] if burns else None


def _solver(
    state: State,
    t0: float,
    end_s: float,
    where: Where,
    acting: list[tuple[Torque, str]],
    step: float | None,
    order: int,
) -> EulerSolver | TorquedMotion:
    """The exact solver from ``state`` at ``t0``, or the torqued one at ``step`` if a
    torque acts within [t0, end_s] (``acting``: (torque, key)).  An error that names no
    key (the solver refuses the state) is the state's, ``where``."""
    if acting and step is None:
        raise ValueError("a torque acts but no step was given")  # a bug of the caller
    try:
        if acting:
            _check_resolved_at_start(state, t0, end_s, where)
            assert step is not None
            torques = [model for model, _ in acting]
            return TorquedMotion(state, t0, end_s, torques, step, order)
        return EulerSolver(state.inertia.tensor, state.angular_momentum, state.attitude, t0=t0)
    except InputError as exc:
        raise (exc if exc.key is not None else where.error(exc.reason)) from None


def _unresolved(G: float, I_min: float, period: float, start_s: float, end_s: float) -> str | None:
    """The reason to refuse a motion faster than TT seconds (floats) follow over
    [start_s, end_s], or None.

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
    return (
        f"the body turns in {fastest:.3g} s, too fast for TT seconds over "
        f"this span (they resolve {resolution:.3g} s at {end_s:g} s, and a thousandth "
        f"of a turn is needed): give a slower rate or a shorter span"
    )


def _check_resolved_at_start(state: State, start_s: float, end_s: float, where: Where) -> None:
    """Refuse a state that turns too fast for TT seconds before any torque acts on it
    (:func:`_unresolved` at the state's own rate): the state, not a torque, is
    what is wrong, and propagating it under the torques would only find so later."""
    G = float(np.linalg.norm(state.angular_momentum))
    if not math.isfinite(G):
        raise where.error("the angular momentum is beyond the float range")
    I_min = float(np.min(state.inertia.moments))
    reason = _unresolved(G, I_min, math.inf, start_s, end_s)
    if reason is not None:
        raise where.error(reason)


_SPUN_UP = "spun up by the burns"


def check_resolved(segment: Segment) -> None:
    """Refuse a motion faster than TT seconds (floats) can follow over the segment
    (:func:`_unresolved`), naming the state, or the burn that spun it up
    (:meth:`Segment.refused`).  Under torques this propagates the whole segment (G is
    the largest over it)."""
    solver, start_s, end_s = segment.solver, segment.start_s, segment.end_s
    try:
        G = solver.angular_momentum_norm  # under torques: the grid over the segment
    except InputError as exc:
        raise segment.refused(exc) from None

    def refused(reason: str) -> InputError:
        return segment.refused(InputError(reason), _SPUN_UP)

    if not math.isfinite(G):
        raise refused("under the torques, the angular momentum goes beyond the float range")
    I_min = float(np.min(solver.moments_of_inertia))
    reason = _unresolved(G, I_min, solver.period, start_s, end_s)
    if reason is not None:
        raise refused(reason)
    if not math.isfinite(solver.kinetic_energy):
        raise refused("the kinetic energy is beyond the float range")


def _segment(
    scenario: Scenario,
    models: list[tuple[float, float, Torque, str]],
    start_s: float,
    end_s: float,
    state: State,
    where: Where,
    step: float | None,
    **event: Any,
) -> Segment:
    """The segment from ``state`` at ``start_s`` to ``end_s`` (``event``: the event
    that started it and the state before it)."""
    acting = _acting(models, start_s, end_s)
    order = scenario.torques.order
    solver = _solver(state, start_s, end_s, where, acting, step, order)
    burn = _strongest_burn(acting, start_s, end_s)
    return Segment(start_s, end_s, solver, state, where=where, burn_key=burn, **event)


def segments(
    scenario: Scenario,
    models: list[tuple[float, float, Torque, str]],
    step: float | Sequence[float | None] | None,
    checked: bool = True,
    check_budget_s: float | None = None,
) -> Iterator[Segment]:
    """The segments of ``scenario`` in time order, built one at a time: the next is
    made when it is asked for, from this one's state at its end.

    ``models``: the scenario's torques (``scenario_torque_models``); ``step``: the
    torqued segments' step (s), or one per segment (None where no torque acts: a run
    made before, rerun at its own steps).  ``checked``: refuse a segment that turns faster than
    TT seconds follow (:func:`check_resolved`) before yielding it, which propagates a
    torqued one to its end; a caller that compares runs as they go checks later.
    ``check_budget_s``: for `attitude check`, the CPU time that the step searches of
    gyrostat segments (spinning wheels after a control loss, no torque acting) may take
    together, beyond which they are predicted (:mod:`attitude.trajectory.modes`).
    Errors are :class:`InputError` whose ``key`` names the state whose motion the
    solver refuses, or the burn that spins it up (:meth:`Segment.refused`).
    """
    if uses_laws(scenario):  # laws, slews, control losses: attitude.trajectory.modes
        yield from _law_segments(scenario, models, step, checked, check_budget_s)
        return
    ends = [offset for offset, _ in scenario.events] + [scenario.stop_s]
    state = initial_state(scenario)
    per_segment: list[float | None] = (
        [step] * (len(scenario.events) + 1)
        if step is None or isinstance(step, int | float)
        else list(step)
    )
    where = _initial_where(scenario)
    segment = _segment(scenario, models, 0.0, ends[0], state, where, per_segment[0])
    if checked:
        check_resolved(segment)
    yield segment
    indices = getattr(scenario, "event_indices", range(len(scenario.events)))
    for k, ((offset, event), index, end) in enumerate(
        zip(scenario.events, indices, ends[1:], strict=True), start=1
    ):
        solver = segment.solver
        try:  # the segment before, propagated to its end
            before = State(solver.attitude(offset), solver.angular_momentum(offset), state.inertia)
        except InputError as exc:
            raise segment.refused(exc) from None
        state = event.apply(before)
        where = _event_where(scenario, index, offset, event)
        segment = _segment(
            scenario, models, offset, end, state, where, per_segment[k], event=event, before=before
        )
        if checked:
            check_resolved(segment)
        yield segment


def _law_segments(
    scenario: Scenario,
    models: list[tuple[float, float, Torque, str]],
    step: float | Sequence[float | None] | None,
    checked: bool,
    check_budget_s: float | None = None,
) -> Iterator[Segment]:
    """The segments of a scenario with laws (:func:`attitude.trajectory.modes.mode_segments`),
    with this module's solvers for the free stretches and its checks; the walk is made
    whole before the first is yielded (a free stretch's start is the guided one's end)."""
    order = scenario.torques.order

    def free_solver(
        state: State, t0: float, end_s: float, where: Where, step: float | None
    ) -> EulerSolver | TorquedMotion:
        return _solver(state, t0, end_s, where, _acting(models, t0, end_s), step, order)

    def make(raw: tuple, where: Where) -> Segment:
        start_s, end_s, solver, state, event, before = raw
        # Under a law its controller takes the burns: they spin up free bodies only.
        burn = (
            None
            if isinstance(solver, GuidedMotion)
            else _strongest_burn(_acting(models, start_s, end_s), start_s, end_s)
        )
        segment = Segment(start_s, end_s, solver, state, event, before, where, burn)
        if checked:
            check_resolved(segment)
        return segment

    yield from mode_segments(scenario, models, step, free_solver, make, Where, check_budget_s)
