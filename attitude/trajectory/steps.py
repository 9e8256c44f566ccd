"""The step of a scenario's torqued segments, and the run's error estimate.

**The run's estimate** (Richardson, over the whole run).  The scenario is propagated
twice through the same events, every torqued segment at the step h and at 2h; their
attitudes are compared at :data:`CHECKS` times spread over the span and at each
segment's end, and the largest angle over 2^p − 1 (p the method's order) estimates
the error of the run at h.  Both runs carry their own errors through every event, and
those errors grow afterwards with the motion (an error of the momentum shifts the
phase of a tumble): so this is the error of the run, which each segment's error from
its own start state is not.  :class:`Measurement` holds it, and for each segment the
largest within it.  Where the torques' switches cut both runs' steps alike (a burn
shorter than the step), the two runs agree there and the estimate omits that part,
whose steps are short.

**The search** (``[torques] accuracy``).  One step for every torqued segment, chosen
so that the run's estimate meets the accuracy: it starts from half a quarter turn at
the body's largest rate (at most a fortieth of the orbit), moves with the error model
C h^p (at most 8× down or 4× up a try), and once a passing and a failing step bracket
the answer, bisects in log h until they are within 1.25; it adopts the largest step
that passed, and its run.  A try stops as soon as its estimate exceeds
:data:`STOP_FACTOR` times the accuracy (it has failed, and the model moves on from
what it saw), so a step far too long costs little.  A step with more than
``MAX_STEPS`` steps over the span is refused with the last estimate, naming the burn
that spins the body up (``torques.burns[i].torque``) when the body would be slow
enough without it, else ``torques.accuracy``.

**Check's budget.**  ``attitude check`` answers in seconds: it runs the same search
with a budget of CPU time (:data:`CHECK_BUDGET_S`).  Its tries are the run's own
until one reaches the budget before the end of the span; the search stops there (what
it refused before, the run refuses too), and the estimate of that last try is
predicted over the span: the largest estimate up to t, e(t), grows as t^k over the
last three quarters of the span it covered (k fitted there, between 1 and 3), so
e(span) = e(P) (span/P)^k; the tries before it, extrapolated the same way and scaled
to its step as h^p, bound it from below (an earlier, longer step may have seen the
error grow further).  The run (``propagate``) has no budget: it searches over the
whole span and adopts only a step whose whole run met the accuracy; a run never
reports success on an accuracy that its own estimate says is missed.
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from attitude.base.errors import InputError
from attitude.scenario.scenario import Scenario
from attitude.torques.models import ConstantTorque, Torque
from attitude.torques.solver import (
    MAX_STEPS,
    angles_between,
    error_growth,
    next_search_step,
    search_start_step,
)
from attitude.trajectory.segments import Segment, check_resolved, initial_state, segments
from attitude.trajectory.torqued import TorquedMotion

__all__ = [
    "CHECKS",
    "CHECK_BUDGET_S",
    "STOP_FACTOR",
    "Measurement",
    "RunSteps",
    "choose_steps",
    "measure",
    "predicted_steps",
]

CHECKS = 256
STOP_FACTOR = 64.0
CHECK_BUDGET_S = 3.0
_CHUNK = 4  # checks compared at a time: a try stops within 1/64 of the span
_MAX_TRIES = 12


@dataclass(frozen=True)
class Measurement:
    """The run's estimate at ``step_s`` (module docstring), as far as it was compared.

    ``estimate_rad``: the largest angle over 2^p − 1 at the checks compared, up to
    ``until_s``; ``ended``: ``"span"`` (every check), ``"exceeded"`` (stopped above
    ``STOP_FACTOR`` × the accuracy) or ``"budget"`` (stopped at check's budget);
    ``growth``: the exponent k of e(t) ~ t^k fitted on the span covered;
    ``per_segment``: the largest estimate within each segment compared (None where no
    check fell); ``steps``: the grid steps both runs took; ``cpu_s``: their CPU time;
    ``predicted_rad``: over the whole span (the estimate itself when complete).
    """

    step_s: float
    estimate_rad: float
    until_s: float
    span_s: float
    ended: str
    growth: float
    per_segment: tuple[float | None, ...]
    steps: int
    cpu_s: float
    predicted_rad: float

    @property
    def complete(self) -> bool:
        return self.ended == "span"

    def extrapolated(self) -> float:
        """e(span) from the span covered, e(P) (span/P)^k (module docstring)."""
        if self.complete:
            return self.estimate_rad
        if self.until_s <= 0.0:
            return math.inf
        return self.estimate_rad * (self.span_s / self.until_s) ** self.growth


@dataclass(frozen=True)
class RunSteps:
    """How the torqued segments' step was set, and the run's estimated error.

    ``step_s``: the step of every torqued segment; ``given``: from ``[torques] step``
    (else chosen for ``accuracy_rad``); ``measurement``: the run's estimate at that
    step (None when not measured yet); ``tried``: (step, estimate, how the try ended) of
    every try of the search; ``settled``: False when check's budget stopped the search
    (``step_s`` is then its last candidate); ``grid_steps``: the steps of one run over
    the span (counted when it ran, else predicted); ``cpu_per_step_s``: measured;
    ``search_cpu_s``: the search's CPU time.
    """

    step_s: float
    order: int
    given: bool
    accuracy_rad: float | None
    measurement: Measurement | None = None
    tried: tuple[tuple[float, float, str], ...] = field(default=())
    settled: bool = True
    grid_steps: int = 0
    cpu_per_step_s: float = 0.0
    search_cpu_s: float = 0.0

    @property
    def estimate_rad(self) -> float | None:
        """The run's estimate (predicted when the measurement is not complete)."""
        return None if self.measurement is None else self.measurement.predicted_rad

    @property
    def predicted(self) -> bool:
        """True when the estimate is predicted from part of the span."""
        return self.measurement is not None and not self.measurement.complete


def _check_times(scenario: Scenario) -> NDArray[np.float64]:
    """Where the two runs are compared: CHECKS times over the span and every
    segment's end (an event's epoch is compared in the segment it ends)."""
    ends = [offset for offset, _ in scenario.events] + [scenario.stop_s]
    times = np.concatenate([np.linspace(0.0, scenario.stop_s, CHECKS + 1)[1:], ends])
    return np.unique(times[times > 0.0])


def _torqued_steps(items: Iterable[Segment]) -> int:
    return sum(s.solver.steps_computed for s in items if isinstance(s.solver, TorquedMotion))


def measure(
    scenario: Scenario,
    models: list[tuple[float, float, Torque, str]],
    step: float | list[float | None],
    *,
    fine: list[Segment] | None = None,
    budget_s: float | None = None,
    stop_above: float | None = None,
) -> tuple[Measurement, list[Segment] | None]:
    """The run's estimate at ``step`` (module docstring): (measurement, the run at
    ``step`` as its segments, or None when it stopped early).

    ``fine``: the run at ``step`` already made (a trajectory's), compared as it is;
    ``budget_s``: stop after this much CPU time; ``stop_above``: stop as soon as the
    estimate exceeds this (rad).  A run that the torques drive beyond what floats
    follow is refused, naming its state or the burn that spins it up (an
    :class:`InputError`, ``Segment.refused``); when only the run at 2 × step does, the
    estimate is infinite.
    """
    started = time.process_time()
    scale = 2.0**scenario.torques.order - 1.0
    checks = _check_times(scenario)
    given = fine is not None
    fine_runs: Iterator[Segment] = (
        iter(fine) if fine is not None else segments(scenario, models, step, checked=False)
    )
    coarse: float | list[float | None] = (
        [None if h is None else 2.0 * h for h in step] if isinstance(step, list) else 2.0 * step
    )
    coarse_runs = segments(scenario, models, coarse, checked=False)
    done: list[Segment] = []
    done_steps = 0
    per_segment: list[float | None] = []
    times: list[float] = []
    envelope: list[float] = []
    worst = 0.0

    def result(ended: str, until: float, steps: int) -> Measurement:
        growth = error_growth(times, envelope, until) if ended != "span" else 1.0
        found = Measurement(
            max((h for h in step if h is not None), default=0.0)
            if isinstance(step, list)
            else step,
            worst,
            until,
            scenario.stop_s,
            ended,
            growth,
            tuple(per_segment),
            steps,
            time.process_time() - started,
            worst,
        )
        if ended == "budget":
            return Measurement(**{**found.__dict__, "predicted_rad": found.extrapolated()})
        return found

    def out_of_time() -> bool:
        return budget_s is not None and time.process_time() - started > budget_s

    for fine_segment, coarse_segment in zip(fine_runs, coarse_runs, strict=True):
        τ = checks[(checks > fine_segment.start_s) & (checks <= fine_segment.end_s)]
        own: float | None = None
        for first in range(0, τ.size, _CHUNK):
            chunk = τ[first : first + _CHUNK]
            try:
                q_fine = fine_segment.solver.attitude_quaternion(chunk)
            except InputError as exc:
                raise fine_segment.refused(exc) from None
            try:
                q_coarse = coarse_segment.solver.attitude_quaternion(chunk)
                found = float(np.max(angles_between(q_fine, q_coarse))) / scale
            except InputError:
                found = math.inf  # the run at 2 × step runs away: the step is far too long
            if not math.isfinite(found):
                found = math.inf
            worst = max(worst, found)
            own = found if own is None else max(own, found)
            times.append(float(chunk[-1]))
            envelope.append(worst)
            steps = done_steps + _torqued_steps(
                [coarse_segment] if given else [fine_segment, coarse_segment]
            )
            if stop_above is not None and worst > stop_above:
                per_segment.append(own)
                return result("exceeded", float(chunk[-1]), steps), None
            if out_of_time() and first + _CHUNK < τ.size:
                per_segment.append(own)
                return result("budget", float(chunk[-1]), steps), None
        if not given:
            check_resolved(fine_segment)
        done_steps += _torqued_steps([coarse_segment] if given else [fine_segment, coarse_segment])
        per_segment.append(own)
        done.append(fine_segment)
        if out_of_time() and len(done) < len(scenario.events) + 1:
            return result("budget", fine_segment.end_s, done_steps), None
    return result("span", scenario.stop_s, done_steps), done


def _impulses(
    scenario: Scenario, models: list[tuple[float, float, Torque, str]]
) -> list[tuple[float, str]]:
    """(angular impulse |τ| Δt within the span, N m s; key) of each burn."""
    return [
        (float(np.linalg.norm(torque.torque)) * (min(stop, scenario.stop_s) - max(start, 0.0)), key)
        for start, stop, torque, key in models
        if isinstance(torque, ConstantTorque)
    ]


def _largest_rate(
    scenario: Scenario, models: list[tuple[float, float, Torque, str]], burns: bool = True
) -> float:
    """A bound on the body's rate over the span (rad/s): |ω| ≤ √(2T/I_min) at the
    start, and, with ``burns``, |ω| ≤ (|m0| + ∫|τ| dt)/I_min with the burns' impulse
    (a burn may spin the body up)."""
    state = initial_state(scenario)
    least = float(np.min(state.inertia.moments))
    rate = math.sqrt(2.0 * state.kinetic_energy / least)
    impulse = sum(size for size, _ in _impulses(scenario, models)) if burns else 0.0
    if impulse > 0.0:
        rate = max(rate, (float(np.linalg.norm(state.angular_momentum)) + impulse) / least)
    return rate


def _initial_step(
    scenario: Scenario, models: list[tuple[float, float, Torque, str]], burns: bool = True
) -> float:
    """Half the solver's first try (:func:`attitude.torques.solver.search_start_step`:
    a quarter turn, at most a twentieth of the orbit) at the body's largest rate over
    the span (:func:`_largest_rate`; ``burns``: with the burns' impulse), at most half
    the span."""
    rate = _largest_rate(scenario, models, burns)
    start = search_start_step(rate, (torque for _, _, torque, _ in models), 0.0)
    return 0.5 * min(start, scenario.stop_s)


def predicted_steps(
    scenario: Scenario, models: list[tuple[float, float, Torque, str]], step: float
) -> int:
    """The grid steps of one run at ``step`` over the span: the span over the step, and
    one more at each torque switch within it (a step ends there)."""
    switches = {
        b for _, _, torque, _ in models for b in torque.breakpoints if 0.0 < b < scenario.stop_s
    }
    return math.ceil(scenario.stop_s / step) + len(switches)


def _accuracy_refused(
    scenario: Scenario, models: list[tuple[float, float, Torque, str]], step: float, reason: str
) -> InputError:
    """The refusal of an accuracy that needs a step near ``step`` (more than MAX_STEPS
    over the span), for ``reason``, naming what holds the bad value: the burn that adds
    the most momentum (``torques.burns[i].torque``) when, without the burns' impulse,
    the body would be slow enough (the step scaled by the first try's without and
    with it, a step ∝ 1/|ω| at the body's rate, within MAX_STEPS), else
    ``torques.accuracy``: a hopeless accuracy for a body that slow."""
    impulses = _impulses(scenario, models)
    if impulses:
        faster = _initial_step(scenario, models, burns=False) / _initial_step(scenario, models)
        if scenario.stop_s / (step * faster) <= MAX_STEPS:
            size, key = max(impulses)
            return InputError(
                f"the burns spin the body up to {_largest_rate(scenario, models):.3g} rad/s "
                f"(this one adds {size:.3g} N m s): {reason}: give a smaller torque, "
                "torques.step, a looser accuracy or a shorter span",
                key=key,
            )
    return InputError(
        f"{reason}: give torques.step, a looser accuracy or a shorter span",
        key="torques.accuracy",
        value=scenario.torques.accuracy_rad,
    )


def _too_many_steps(
    scenario: Scenario, models: list[tuple[float, float, Torque, str]], step: float, tried
) -> InputError:
    last = (
        f"; the run's estimate was {tried[-1][1]:.3g} rad at {tried[-1][0]:.3g} s" if tried else ""
    )
    return _accuracy_refused(
        scenario,
        models,
        step,
        f"{scenario.torques.accuracy_rad:g} rad over {scenario.stop_s:g} s would need a step "
        f"below {step:.3g} s, more than {MAX_STEPS:g} steps{last}",
    )


def _predicted(found: Measurement, before: list[Measurement], order: int) -> float:
    """A budget-cut try's estimate over the span: its own extrapolation, and those of
    the tries before it scaled to its step as h^p (module docstring)."""
    scaled = [
        item.extrapolated() * (found.step_s / item.step_s) ** order
        for item in before
        if item.estimate_rad > 0.0
    ]
    return max([found.extrapolated(), *scaled])


def _needed_step(
    scenario: Scenario,
    models: list[tuple[float, float, Torque, str]],
    found: Measurement,
    tried: list[tuple[float, float, str]],
    accuracy: float,
    order: int,
) -> float:
    """The step that the error model C h^p says meets the accuracy with a margin of 2,
    from a try's estimate over the span (extrapolated when the try stopped early), no
    longer than the try's step; an InputError when it takes more than MAX_STEPS steps
    (the search would only shrink the step until it did)."""
    predicted = found.predicted_rad if found.ended == "budget" else found.extrapolated()
    step = found.step_s * min(1.0, (0.5 * accuracy / max(predicted, 1e-300)) ** (1.0 / order))
    if scenario.stop_s / step > MAX_STEPS:
        where = (
            "over the whole span"
            if found.complete
            else f"by {found.until_s:.6g} s, growing as t^{found.growth:.2g}"
        )
        raise _accuracy_refused(
            scenario,
            models,
            step,
            f"{accuracy:g} rad over {scenario.stop_s:g} s would need a step near {step:.3g} "
            f"s, more than {MAX_STEPS:g} steps: the run's estimate was "
            f"{found.estimate_rad:.3g} rad at a step of {found.step_s:.3g} s {where}",
        )
    return step


def choose_steps(
    scenario: Scenario,
    models: list[tuple[float, float, Torque, str]],
    budget_s: float | None = None,
) -> tuple[RunSteps, list[Segment] | None]:
    """The step for ``[torques] accuracy`` (module docstring): (how it was chosen, the
    run at that step, or None when check's ``budget_s`` stopped the search)."""
    accuracy = scenario.torques.accuracy_rad
    assert accuracy is not None  # an accuracy, or the default one
    order = scenario.torques.order
    span = scenario.stop_s
    step = _initial_step(scenario, models)
    good: tuple[float, Measurement, list] | None = None
    bad = math.inf
    tried: list[tuple[float, float, str]] = []
    seen: list[Measurement] = []
    started = time.process_time()
    for _ in range(_MAX_TRIES):
        if span / step > MAX_STEPS:
            raise _too_many_steps(scenario, models, step, tried)
        left = None if budget_s is None else max(budget_s - (time.process_time() - started), 0.0)
        found, run = measure(
            scenario, models, step, budget_s=left, stop_above=STOP_FACTOR * accuracy
        )
        if found.ended == "budget":  # check: the search stops here, its estimate predicted
            predicted = _predicted(found, seen, order)
            found = Measurement(**{**found.__dict__, "predicted_rad": predicted})
            tried.append((step, predicted, found.ended))
            needed = _needed_step(scenario, models, found, tried, accuracy, order)
            cpu = time.process_time() - started
            per_step = found.cpu_s / found.steps if found.steps else 0.0
            grid = predicted_steps(scenario, models, needed)
            choice = RunSteps(
                needed, order, False, accuracy, found, tuple(tried), False, grid, per_step, cpu
            )
            return choice, None
        seen.append(found)
        error = found.estimate_rad
        tried.append((step, error, found.ended))
        if error > accuracy:
            _needed_step(scenario, models, found, tried, accuracy, order)  # refuses a hopeless one
        if error <= accuracy:
            assert run is not None
            if good is None or step > good[0]:
                good = (step, found, run)
        else:
            bad = min(bad, step)
        following = next_search_step(
            step, error, accuracy, order, span, None if good is None else good[0], bad
        )
        if following is None:
            break
        step = following
    cpu = time.process_time() - started
    if good is None:
        raise InputError(
            f"{accuracy:g} rad over {span:g} s not reached: the run's estimate was "
            f"{tried[-1][1]:.3g} rad at a step of {tried[-1][0]:.3g} s",
            key="torques.accuracy",
            value=accuracy,
        )
    step, found, run = good
    grid = _torqued_steps(run)
    per_step = found.cpu_s / found.steps if found.steps else 0.0
    return RunSteps(
        step, order, False, accuracy, found, tuple(tried), True, grid, per_step, cpu
    ), run
