"""The segments of a scenario with attitude laws: guided, slewing, free, torqued.

A scenario that starts under a law (``InitialState(law=...)``) or has mode events
(:mod:`attitude.scenario.modes`) is propagated here, event by event, into segments of
four kinds:

- **guided**: the attitude is a law's (:class:`~attitude.trajectory.guided.GuidedMotion`
  over a :class:`~attitude.laws.align_constrain.BoundLaw`, bound per segment, so that the
  Sun and the Moon are sampled over that segment only);
- **slew**: a :class:`~attitude.laws.slews.Slew` from the state at a ``mode_change``
  or a ``control_resume`` onto the new law, ending before the next event (refused in one
  line otherwise); then the law, guided, to the next event;
- **free**: after a ``control_loss``, the exact hand-off
  (:mod:`attitude.trajectory.handoff`): the exact solver (locked wheels), the splitting
  with the gyroscopic flow (spinning wheels), or the torqued solver where the
  scenario's torques act;
- the scenario's other events act as they do on a free body (an angular impulse, an
  attitude reset, an inertia change); on a guided body only an inertia change is
  accepted (the law holds on; its I·ω changes), the others refused in one line.

The scenario's torques act on the free segments only: while a law holds the
attitude, its controller absorbs them.  Every segment boundary is a non-smooth
instant of the attitude or its rate (a mode change, a slew's start and end, a control
loss or resume), and each is a segment of the AEM.

:func:`mode_segments` returns the segments for :mod:`attitude.trajectory.segments`,
which hands in its own makers of free and torqued solvers and of checked
:class:`~attitude.trajectory.segments.Segment` objects (so that scenarios with and
without laws make them alike, with the same checks and error keys).  A ground site a law tracks is
checked for visibility over its segment (``GuidedMotion.passes``): one that never rises
above the horizon is a note of that segment (``GuidedMotion.notes``, with the Earth
orientation table's coverage), stated by ``check`` and in the summary.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from attitude.base.errors import InputError
from attitude.environment.timescales import SAME_INSTANT_S
from attitude.laws.align_constrain import BoundLaw
from attitude.laws.slews import Slew
from attitude.laws.visibility import ground_site, visible_intervals
from attitude.scenario.events import AttitudeReset, InertiaChange, State
from attitude.scenario.modes import MODE_EVENTS, ControlLoss, ControlResume, ModeChange, Wheels
from attitude.scenario.scenario import Scenario
from attitude.solver.inertia import PrincipalAxes
from attitude.torques.solver import StepChoice, StepPrediction, TorquedSolver
from attitude.trajectory.guided import GuidedMotion
from attitude.trajectory.torqued import TorquedMotion

__all__ = [
    "GYROSTAT_ACCURACY_RAD",
    "GYROSTAT_SEARCH_MAX_STEPS",
    "law_initial_state",
    "mode_segments",
    "uses_laws",
]

# The accuracy (rad) a gyrostat's step is chosen for when [torques] states none: the
# gyroscopic term is not small, and the splitting's dense output bends at each grid
# point by about its local error, which a reader interpolating with the rates
# (Orekit's AEM reader) sees at 3.5 times the accuracy: a tenth of the AEM's default
# tolerance (1e-6 rad) keeps it within (measured: 3.5e-7 rad on the example).
GYROSTAT_ACCURACY_RAD = 1e-7
# A gyrostat segment's step search runs the whole segment at each step it tries (and
# at twice it): one whose first try would take more steps than this (about 10 s of CPU)
# is refused before it starts, so that `check` answers in seconds and an absurd span
# (years of tumbling) is one line, not hours; a given [torques] step has no search.
GYROSTAT_SEARCH_MAX_STEPS = 2e5
# `attitude check` cuts the gyrostat's step search at its CPU budget and predicts the
# rest (TorquedSolver.predict_step); the segment is then propagated at a step long
# enough to take about this much CPU, for the checks that read the motion.
_CHECK_MOTION_S = 0.5


def uses_laws(scenario: Scenario) -> bool:
    """True if the scenario starts under a law or has a mode event."""
    if getattr(scenario.initial_state, "law", None) is not None:
        return True
    return any(event.kind in MODE_EVENTS for _, event in scenario.events)


def _orbit(scenario: Scenario) -> Any:
    """The scenario's orbit (None without one)."""
    return getattr(scenario, "orbit", None)


class _Builder:
    """Walks the events, keeping the mode (guided or free) and the segments made."""

    def __init__(
        self,
        scenario: Scenario,
        step: float | Sequence[float | None] | None,
        free_solver: Callable[..., Any],
        make: Callable[..., Any],
        where: Callable[..., Any],
        check_budget_s: float | None = None,
    ) -> None:
        self.scenario = scenario
        # `attitude check`: the CPU time left for the gyrostats' step searches (None: run).
        self.budget_left = check_budget_s
        self.step = step
        self.free_solver = free_solver
        self.make = make
        self.where = where
        self.orbit = _orbit(scenario)
        self.segments: list[Any] = []
        self.wheels: Wheels | None = None  # spinning wheels of the free body, or None
        self.law_key = ""
        # Why the body is free, for refusals: since a control_loss, or from the epoch.
        self.free_since = "from the epoch: [initial_state] gives no law"

    # ---- helpers

    def at(self, event: Any, offset: float) -> str:
        """An event in words, for reasons: "the control_loss at 2025-05-01T11:50:00 UTC"."""
        return f"the {event.kind} at {self.scenario.format_epoch(offset)}"

    def step_for(self) -> float | None:
        """The torqued step of the next segment: the run's, or a run's own per segment."""
        if self.step is None or isinstance(self.step, int | float):
            return self.step
        k = len(self.segments)
        return self.step[k] if k < len(self.step) else None

    def add(
        self,
        start: float,
        end: float,
        solver: Any,
        state: State,
        event: Any,
        before: State | None,
        key: str,
        text: str = "",
    ) -> None:
        """The segment made and checked (``key``, ``text``: what errors about its
        motion name: the key that set its rate, the state in words)."""
        raw = (start, end, solver, state, event, before)
        self.segments.append(self.make(raw, self.where(key, text)))

    def bind(self, law: Any, start: float, end: float, key: str) -> BoundLaw:
        return law.bind(self.scenario.epoch, start, end, self.orbit, key)

    def visibility(self, motion: GuidedMotion) -> None:
        """The ground site of a target law: its passes over the segment
        (``motion.passes``); a note when it never rises above the horizon there."""
        bound = motion.bound_law
        try:
            site = ground_site(bound)
        except InputError:
            return
        a, b = motion.t0, motion.end_s
        if b - a <= SAME_INSTANT_S:
            return
        motion.passes = [
            (max(p0, a), min(p1, b))
            for p0, p1 in visible_intervals(bound, 0.0)
            if p1 > a and p0 < b
        ]
        if not motion.passes:
            fmt = self.scenario.format_epoch
            motion.notes.append(
                f"{motion.key}: {site.name} never rises above the horizon between {fmt(a)} and "
                f"{fmt(b)}: the law points the body through the Earth at it the whole time"
            )

    # ---- the law's stretches

    def law_stretch(
        self,
        law: Any,
        key: str,
        inertia: PrincipalAxes,
        start: float,
        end: float,
        event: Any,
        before: State | None,
        limits: Any = None,
        deadline_text: str = "",
    ) -> State:
        """The law from ``start`` to ``end``: first a slew within ``limits`` from the
        state ``before`` (its attitude, and the rate the last segment ended with) when
        limits are given, then the law itself.  Returns the state at ``end``."""
        bound = self.bind(law, start, end, key)
        t = start
        if limits is not None and before is not None:
            slew = Slew(
                start,
                before.attitude,
                self.rate_before,
                bound,
                limits,
                end,
                key=f"{key.rsplit('.', 1)[0]}.slew",
                deadline_text=deadline_text,
                format_epoch=self.scenario.format_epoch,
            )
            if slew.duration_s > SAME_INSTANT_S:  # else already on the law, at its rate
                motion = GuidedMotion(slew, inertia, start, slew.end_s, key)
                self.add(start, slew.end_s, motion, motion.state, event, before, slew.key)
                t = slew.end_s
        if t == start or end - t > SAME_INSTANT_S:
            motion = GuidedMotion(bound, inertia, t, end, key)
            # After a slew the law takes over without an event of its own.
            self.add(t, end, motion, motion.state, event, before if t == start else None, key)
            self.visibility(motion)
        return self.state_at(end)

    def state_at(self, t: float) -> State:
        """The state at ``t`` of the last segment (the state just before an event)."""
        last = self.segments[-1]
        pair = np.array([t, t])
        try:
            attitude = last.solver.attitude(pair)[0]
            momentum = last.solver.angular_momentum(pair)[0]
            self.rate_before = last.solver.angular_velocity(pair)[0]
        except InputError as exc:
            raise last.refused(exc) from None
        return State(attitude, momentum, last.state.inertia)

    # ---- the free stretches

    def free_stretch(
        self,
        state: State,
        start: float,
        end: float,
        where: tuple[str, str],
        event: Any,
        before: State | None,
    ) -> State:
        """The free (or torqued) motion from ``state``; ``where``: (key, text), the key
        that set its rate and the state in words, for errors about it."""
        if self.wheels is not None:
            solver = self.gyrostat(state, start, end, where)
        else:
            solver = self.free_solver(state, start, end, self.where(*where), self.step_for())
        self.add(start, end, solver, state, event, before, *where)
        return self.state_at(end)

    def gyrostat(
        self, state: State, start: float, end: float, where: tuple[str, str]
    ) -> TorquedMotion:
        """The free body with spinning wheels from ``state`` (M total): the splitting
        with the gyroscopic flow, under the scenario's torques acting in [start, end],
        at the run's step, or (none: no torque acts) at a step of its own chosen for
        the ``[torques]`` step or accuracy, else :data:`GYROSTAT_ACCURACY_RAD`."""
        assert self.wheels is not None
        acting = [(m, k) for a, b, m, k in self.models if a < end and b > start]
        settings = self.scenario.torques
        key, text = where
        if settings.order == 6:
            raise InputError(
                f"6 keeps its order only without a gyroscopic term, and {text} leaves the "
                "wheels spinning: give order 2 or 4",
                key="torques.order",
                value=6,
            )
        h = self.wheels.momentum_vector
        torques = [m for m, _ in acting]
        try:
            step = self.step_for()
            if step is None and settings.step is not None:
                step = float(settings.step)
            search: StepChoice | StepPrediction | None = None
            if step is None:
                started = time.process_time()
                search = _gyrostat_step(state, start, end, torques, settings, h, self.budget_left)
                if self.budget_left is not None:
                    self.budget_left -= time.process_time() - started
                step = _motion_step(search, end - start)
            motion = TorquedMotion(state, start, end, torques, step, settings.order, h)
        except InputError as exc:
            if exc.key == "accuracy":  # the step search's refusal: the scenario's key
                raise InputError(
                    f"{text}: {exc.reason}", key="torques.accuracy", value=exc.value
                ) from None
            if exc.key is not None:
                raise
            raise InputError(f"{text}: {exc.reason}", key=key) from None
        if search is not None:
            motion.step_search = search
            if isinstance(search, StepPrediction):
                # The error model C h^p, from the cut try to the step predicted.
                shrink = (search.step / search.cut_step) ** settings.order
                motion.error_estimate = search.predicted_error * shrink
                if step != search.step:
                    motion.approximate_step_s = step
            else:
                motion.error_estimate = search.error_estimate
        return motion

    # ---- the walk

    def build(self, models: list) -> list[Any]:
        scenario = self.scenario
        self.models = models
        initial = scenario.initial_state
        axes = scenario.spacecraft.principal_axes
        self.inertia0 = axes
        ends = [offset for offset, _ in scenario.events] + [scenario.stop_s]
        indices = list(getattr(scenario, "event_indices", range(len(scenario.events))))
        law = getattr(initial, "law", None)
        first_end = ends[0]
        if law is not None:
            self.law_key = "initial_state.law"
            state = self.law_stretch(law, self.law_key, axes, 0.0, first_end, None, None)
            guided = True
        else:  # InitialState holds an attitude and one rate (checked when it is made)
            assert initial.attitude is not None
            if initial.angular_momentum is not None:
                m0 = initial.angular_momentum
            else:
                assert initial.angular_velocity is not None
                m0 = axes.tensor @ initial.angular_velocity
            given = (
                "angular_velocity" if initial.angular_velocity is not None else "angular_momentum"
            )
            where = (f"initial_state.{given}", "")
            state = self.free_stretch(
                State(initial.attitude, m0, axes), 0.0, first_end, where, None, None
            )
            guided = False
        for k, ((offset, event), index) in enumerate(zip(scenario.events, indices, strict=True)):
            end = ends[k + 1]
            following = (
                f"the next event, events[{indices[k + 1]}]"
                if k + 1 < len(indices)
                else "the end of the span"
            )
            before = state
            if guided:
                state, guided = self.on_guided(event, index, before, offset, end, following)
            else:
                state, guided = self.on_free(event, index, before, offset, end, following)
        return self.segments

    def on_guided(self, event, index, before, offset, end, following):
        key = f"events[{index}]"
        if isinstance(event, ModeChange):
            self.law_key = f"{key}.law"
            state = self.law_stretch(
                event.law,
                self.law_key,
                before.inertia,
                offset,
                end,
                event,
                before,
                event.slew,
                following,
            )
            return state, True
        if isinstance(event, InertiaChange):  # the law holds on, with the new I·ω
            law = self.segments[-1].solver.law
            state = self.law_stretch(law, self.law_key, event.inertia, offset, end, event, before)
            return state, True
        if isinstance(event, ControlLoss):
            wheels = event.wheels
            wheels.check_against(before.inertia.tensor, key)
            rate = self.rate_before
            momentum = before.inertia.tensor @ rate + wheels.momentum_vector
            after = State(before.attitude, momentum, before.inertia)
            self.wheels = wheels if wheels.case == "spinning" else None
            self.free_since = f"since {self.at(event, offset)}"
            where = (f"{key}.wheels", f"the state after {self.at(event, offset)}")
            return self.free_stretch(after, offset, end, where, event, before), False
        if isinstance(event, ControlResume):
            raise InputError(
                f"{self.at(event, offset)}: control is not lost there (a law holds the "
                "attitude): use mode_change to change law",
                key=key,
            )
        raise InputError(
            f"{self.at(event, offset)}: an {event.kind} needs a free body, and a law holds "
            "the attitude there (its controller would absorb it): put a control_loss before it",
            key=key,
        )

    def on_free(self, event, index, before, offset, end, following):
        key = f"events[{index}]"
        if isinstance(event, ControlResume):
            self.wheels = None  # the controller has the wheels again
            self.law_key = f"{key}.law"
            state = self.law_stretch(
                event.law,
                self.law_key,
                before.inertia,
                offset,
                end,
                event,
                before,
                event.slew,
                following,
            )
            return state, True
        if isinstance(event, ModeChange | ControlLoss):
            advice = (
                "use control_resume to give the body a law"
                if isinstance(event, ModeChange)
                else "control is already lost"
            )
            raise InputError(
                f"{self.at(event, offset)}: no law holds the attitude there "
                f"({self.free_since}): {advice}",
                key=key,
            )
        after = event.apply(before)
        if (
            self.wheels is not None
            and isinstance(event, AttitudeReset)
            and event.angular_velocity is not None
        ):  # the total momentum of a gyrostat turning at ω is Iω + h
            momentum = after.angular_momentum + self.wheels.momentum_vector
            after = State(after.attitude, momentum, after.inertia)
        where = (_rate_key(key, event), f"the state after {self.at(event, offset)}")
        state = self.free_stretch(after, offset, end, where, event, before)
        return state, False


def _rate_key(key: str, event: Any) -> str:
    """The key of an event that set the free body's rate (an impulse, a reset's rate),
    or the event's table."""
    if event.kind == "angular_impulse":
        return f"{key}.impulse"
    for name in ("angular_velocity", "angular_momentum"):
        if event.kind == "attitude_reset" and getattr(event, name, None) is not None:
            return f"{key}.{name}"
    return key


def _gyrostat_step(
    state: State,
    start: float,
    end: float,
    torques: list,
    settings: Any,
    wheels: Any,
    budget_s: float | None = None,
) -> StepChoice | StepPrediction:
    """How the step of a gyrostat segment that neither the run nor ``[torques]`` gives
    is chosen: by the splitting's search for the ``[torques]`` accuracy
    (:data:`GYROSTAT_ACCURACY_RAD` when none is given) over the segment.  With
    ``budget_s`` (`attitude check`), the search is cut when it has spent that much CPU
    and the rest predicted (:meth:`TorquedSolver.predict_step`): what the prediction
    refuses, the search refuses too."""
    span = end - start
    accuracy = settings.accuracy if settings.accuracy is not None else GYROSTAT_ACCURACY_RAD
    if span <= SAME_INSTANT_S:
        return StepChoice(max(span, 1.0), 0.0, accuracy, span)
    # The search's first step (TorquedSolver's): half a quarter turn at the faster of
    # the body's rate I⁻¹M and the gyroscopic turn |I⁻¹h|.
    tensor = state.inertia.tensor
    rate = max(
        float(np.linalg.norm(np.linalg.solve(tensor, state.angular_momentum))),
        float(np.linalg.norm(np.linalg.solve(tensor, np.asarray(wheels, dtype=np.float64)))),
    )
    first = min(0.5 * span, math.pi / (4.0 * rate)) if rate > 0.0 else 0.5 * span
    if span / first > GYROSTAT_SEARCH_MAX_STEPS:
        raise InputError(
            f"choosing the gyrostat's step for {accuracy:g} rad over its {span:.6g} s would "
            f"start at {first:.3g} s, {span / first:.3g} steps a try (at most "
            f"{GYROSTAT_SEARCH_MAX_STEPS:g}): give [torques] step, or a shorter span"
        )
    if budget_s is not None:
        solver = TorquedSolver(
            tensor,
            state.angular_momentum,
            state.attitude,
            start,
            torques,
            step=first,
            order=settings.order,
            wheel_momentum=wheels,
        )
        return solver.predict_step(accuracy, span, max(budget_s, 0.0))
    chooser = TorquedSolver(
        tensor,
        state.angular_momentum,
        state.attitude,
        start,
        torques,
        order=settings.order,
        accuracy=accuracy,
        span=span,
        wheel_momentum=wheels,
    )
    choice = chooser.step_choice
    assert choice is not None  # an accuracy and a gyroscopic term: the step is searched
    return choice


def _motion_step(search: StepChoice | StepPrediction, span: float) -> float:
    """The step the segment is propagated at: the search's, or for a search that check's
    budget cut, the predicted step or a longer one that takes about _CHECK_MOTION_S of
    CPU (the checks that read the motion need its sizes, not its last digits)."""
    if isinstance(search, StepChoice):
        return search.step
    affordable = _CHECK_MOTION_S / search.cpu_per_step if search.cpu_per_step > 0.0 else 1e4
    return max(search.step, span / max(affordable, 1.0))


def law_initial_state(scenario: Scenario) -> State:
    """The state at the epoch of a scenario that starts under a law: the law's attitude
    and momentum I·ω there."""
    law = scenario.initial_state.law
    bound = law.bind(scenario.epoch, 0.0, 0.0, _orbit(scenario), "initial_state.law")
    state = bound.state([0.0, 0.0])
    axes = scenario.spacecraft.principal_axes
    return State(state.attitude[0], axes.tensor @ state.angular_velocity[0], axes)


def mode_segments(
    scenario: Scenario,
    models: list,
    step: float | Sequence[float | None] | None,
    free_solver: Callable[..., Any],
    make: Callable[..., Any],
    where: Callable[..., Any],
    check_budget_s: float | None = None,
) -> list[Any]:
    """The segments of ``scenario`` (which uses laws: :func:`uses_laws`), in time order.

    ``models``: the scenario's torques as (start, stop, model, key); ``step``: the
    torqued segments' step, or one per segment (a run made before), or None (no torque
    acts); ``free_solver(state, t0, end, where, step)``: the free or torqued solver from
    a state; ``make(raw, where)``: the checked segment of ``raw`` = (start, end, solver,
    state, event, before); ``where(key, text)``: what errors about a segment's motion
    name (the key that set its rate, the state in words); ``check_budget_s``: for
    `attitude check`, the CPU time the gyrostats' step searches may take together,
    beyond which they are predicted (:func:`_gyrostat_step`).  The errors are
    :class:`InputError` whose ``key`` names what holds the bad value.
    """
    return _Builder(scenario, step, free_solver, make, where, check_budget_s).build(models)
