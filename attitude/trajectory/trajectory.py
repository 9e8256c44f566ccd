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

import itertools
from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.environment.timescales import SAME_INSTANT_S, tt_seconds
from attitude.scenario.scenario import Scenario
from attitude.trajectory.guided import GuidedMotion
from attitude.trajectory.segments import Breakpoint, Segment, segments
from attitude.trajectory.steps import (
    CHECK_BUDGET_S,
    RunSteps,
    choose_steps,
    measure,
    predicted_steps,
)
from attitude.trajectory.torqued import TorquedMotion, scenario_torque_models

if TYPE_CHECKING:  # astropy loads only when a Time is made
    from astropy.time import Time

__all__ = ["Segment", "Trajectory", "propagate"]

# Times this close outside [0, stop], or before an event (TT seconds), count as on it.
_SPAN_TOLERANCE_S = SAME_INSTANT_S
# `attitude check` propagates a torqued run longer than its budget at a longer step,
# one that takes about this much CPU, for the checks that read the motion.
_CHECK_TRAJECTORY_S = 1.0


def propagate(
    scenario: Scenario, steps: list[float | None] | None = None, *, check: bool = False
) -> Trajectory:
    """The motion of ``scenario`` over [epoch, stop], through its events.

    Without torques, the exact solver between events.  Under torques
    (``attitude.scenario.torques``), the torqued segments at ``[torques] step``, or at
    the step chosen for ``[torques] accuracy`` so that the run's estimated error meets
    it (``attitude.trajectory.steps``): :attr:`Trajectory.steps` says how.

    ``steps``: per segment, the torqued step to use (None where no torque acts), as
    a run made before chose them (``[s.solver.step for s in trajectory.segments]``): the
    same motion again, for a fit that varies the state and not the method.

    ``check``: what ``attitude check`` needs, within seconds: the search (or, with a
    given step, the run's estimate) within check's CPU budget; when that does not
    cover the whole run, the estimate is predicted, and the motion is propagated at a
    longer step for the checks that read it (:attr:`Trajectory.approximate`).  Without
    torques, a gyrostat segment's own step search (:mod:`attitude.trajectory.modes`) is
    cut at the same budget and predicted beyond it.

    Raises :class:`InputError` whose ``key`` names what holds the bad value: the
    state (``initial_state.angular_velocity``, ``events[i].impulse``) whose motion the
    solver refuses, or that turns too fast for TT seconds (floats) to follow over the
    span; a burn (``torques.burns[i].torque``) that spins the body up that fast, or so
    fast that no step meets the accuracy; ``torques.accuracy`` when the run cannot
    meet it otherwise; the orbit the gravity gradient needs.
    """
    models = scenario_torque_models(scenario) if scenario.torques.any else []
    if not models:  # check: a gyrostat's own step search within check's budget
        budget = CHECK_BUDGET_S if check else None
        return Trajectory(scenario, list(segments(scenario, models, None, check_budget_s=budget)))
    settings = scenario.torques
    if steps is not None:
        given = [h for h in steps if h is not None]
        choice = RunSteps(
            max(given, default=0.0),
            settings.order,
            True,
            None,
            grid_steps=sum(predicted_steps(scenario, models, h) for h in set(given)),
        )
        again = list(segments(scenario, models, list(steps)))
        return Trajectory(scenario, again, choice, given_steps=list(steps))
    if settings.step is not None:
        step = float(settings.step)
        choice = RunSteps(
            step, settings.order, True, None, grid_steps=predicted_steps(scenario, models, step)
        )
        if not check:
            return Trajectory(scenario, list(segments(scenario, models, step)), choice)
        found, run = measure(scenario, models, step, budget_s=CHECK_BUDGET_S)
        choice = replace(
            choice,
            measurement=found,
            cpu_per_step_s=found.cpu_s / found.steps if found.steps else 0.0,
        )
    else:
        choice, run = choose_steps(scenario, models, CHECK_BUDGET_S if check else None)
    if run is None:
        return _approximate(scenario, models, choice)
    return Trajectory(scenario, run, choice)


def _approximate(scenario: Scenario, models, choice: RunSteps) -> Trajectory:
    """`attitude check`'s run when its own would take longer than check's budget: at a
    step long enough that it takes about _CHECK_TRAJECTORY_S of CPU."""
    affordable = _CHECK_TRAJECTORY_S / choice.cpu_per_step_s if choice.cpu_per_step_s else 1e4
    step = max(choice.step_s, scenario.stop_s / max(affordable, 1.0))
    run = list(segments(scenario, models, step))
    exact = step == choice.step_s  # the run's own step after all
    return Trajectory(scenario, run, choice, approximate_step_s=None if exact else step)


class Trajectory:
    """The exact motion of a scenario; evaluate it at any times within [epoch, stop].

    Every method takes ``times``: an ``astropy.time.Time`` (any scale, scalar or
    1-D), or floats, read as TT seconds since the scenario epoch.  Vectors are in
    body axes unless the name says inertial.
    """

    def __init__(
        self,
        scenario: Scenario,
        run: list[Segment],
        steps: RunSteps | None = None,
        approximate_step_s: float | None = None,
        given_steps: list[float | None] | None = None,
    ) -> None:
        self.scenario = scenario
        self.segments = list(run)
        # How the torqued segments' step was set, and the run's estimate (None: no torques).
        self.steps = steps
        # Set when `attitude check` propagated at a longer step than the run's.
        self.approximate_step_s = approximate_step_s
        self._given_steps = given_steps  # per segment, when propagate was given them
        if steps is not None and steps.measurement is not None:
            self._share_estimates(steps)
        # Segment k is in force from _starts[k] on (an event's epoch gets its post-event state).
        self._starts = np.array([s.start_s for s in self.segments]) - _SPAN_TOLERANCE_S
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

    @property
    def approximate(self) -> bool:
        """True for `attitude check`'s propagation at a longer step than the run's."""
        return self.approximate_step_s is not None

    def _share_estimates(self, steps: RunSteps) -> None:
        """Each torqued segment's ``error_estimate``: the run's, within it."""
        assert steps.measurement is not None
        for segment, own in zip(self.segments, steps.measurement.per_segment, strict=False):
            if isinstance(segment.solver, TorquedMotion):
                segment.solver.error_estimate = own

    def measured(self) -> RunSteps | None:
        """:attr:`steps` with the run's estimate (``attitude.trajectory.steps``),
        measured now over the whole span if it was not (a given step); ``attitude
        check``'s estimate (possibly predicted) is kept as it is.  None without
        torques."""
        steps = self.steps
        if steps is None:
            return None
        found = steps.measurement
        if found is not None and (found.complete or self.approximate or not steps.settled):
            return steps
        models = scenario_torque_models(self.scenario)
        step = steps.step_s if self._given_steps is None else self._given_steps
        found, _ = measure(self.scenario, models, step, fine=self.segments)
        steps = replace(
            steps,
            measurement=found,
            cpu_per_step_s=found.cpu_s / found.steps if found.steps else steps.cpu_per_step_s,
        )
        self.steps = steps
        self._share_estimates(steps)
        return steps

    @property
    def error_estimate(self) -> float:
        """The estimated worst attitude error of the run (rad); 0 for the exact solver.

        Under torques, the segments' errors carry through the events and grow with the
        motion (an error of the momentum shifts the phase of a tumble), so each
        segment's own estimate does not add up to the run's.  This is the run's, the
        same scenario at twice the step through the same events
        (``attitude.trajectory.steps``), measured now if it was not.
        """
        steps = self.measured()
        if steps is None:
            return 0.0
        estimate = steps.estimate_rad
        return float("inf") if estimate is None else estimate

    def breakpoints(self) -> list[Breakpoint]:
        """Every time inside a segment where the motion is not smooth (a torque
        switching), in time order (:meth:`Segment.breakpoints`)."""
        return [b for segment in self.segments for b in segment.breakpoints()]

    def flip_times(self) -> NDArray[np.float64]:
        """All Джанибеков flips over [epoch, stop], TT seconds since the epoch (closed form)."""
        per_segment = [
            segment.solver.flip_times(segment.start_s, segment.end_s) for segment in self.segments
        ]
        return np.unique(np.concatenate(per_segment) if per_segment else np.empty(0))

    def __repr__(self) -> str:
        return f"Trajectory({self.scenario.name!r}, {len(self.segments)} segments)"
