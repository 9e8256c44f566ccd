"""A stretch of a scenario's motion under torques, seen as the layers above see a segment.

Between events, a scenario with torques (``attitude.scenario.torques``) is propagated
by :class:`~attitude.torques.solver.TorquedSolver`.  :class:`TorquedMotion` wraps it
with what the trajectory, the motion analysis, the pointing and the reports ask of a
segment's solver (the interface of :class:`~attitude.solver.euler_solver.EulerSolver`), so
that they need not care which one propagated it:

- the states at any times of the segment (``attitude``, ``attitude_quaternion``,
  ``angular_momentum``, ``angular_velocity``), from the solver's dense output;
- ``formula`` ``"torqued"``, no ``period``, no closed-form flips and no spin-axis
  cone: the motion under a torque is not periodic;
- ``angular_momentum_norm`` and ``kinetic_energy``: what the layers above use them
  for is a bound on the body rate (|ω| ≤ G/I_min, |ω|² ≤ 2T/I_min), so here they are
  the **largest** |m| and T over the segment: the largest at the solver's grid points
  plus twice the largest change between two of them (both change smoothly, by at most
  |τ| h over a step);
- ``error_estimate``: the estimated attitude error over the segment (rad): the step
  search's when the step came from an accuracy, else the same Richardson estimate
  (the run at 2 × step, compared at 32 times, over 2^p − 1).
"""

from __future__ import annotations

import math
from functools import cached_property
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.environment.timescales import offline_time
from attitude.scenario.events import State
from attitude.scenario.scenario import Scenario
from attitude.scenario.torques import MAX_STEPS, ScenarioTorques
from attitude.torques.models import ConstantTorque, GravityGradient, Torque
from attitude.torques.solver import TorquedSolver, angles_between

__all__ = ["TorquedMotion", "scenario_torque_models"]

# A segment shorter than this (s) gets a fixed step: nothing to choose it over.
_SHORTEST_SEARCH_S = 1e-6
_CHECKS = 32


def scenario_torque_models(scenario: Scenario) -> list[tuple[float, float, Torque, str]]:
    """The scenario's torques as models, each with the span [start, stop) it acts in
    (TT seconds since the epoch; the gravity gradient over the whole span) and the
    scenario key that gives it (``torques.burns[2].torque``, ``torques.gravity_gradient``),
    which errors it causes name."""
    torques: ScenarioTorques = scenario.torques
    models: list[tuple[float, float, Torque, str]] = []
    if torques.gravity_gradient is not None:
        gradient = GravityGradient(_position_source(torques.gravity_gradient, scenario))
        models.append((-math.inf, math.inf, gradient, "torques.gravity_gradient"))
    for placed in scenario.burns:
        burn = placed.burn
        model = ConstantTorque(burn.torque, placed.start_s, placed.stop_s, burn.frame)
        models.append(
            (placed.start_s, placed.stop_s, model, f"torques.burns[{placed.index}].torque")
        )
    return models


def _position_source(source: Any, scenario: Scenario) -> Any:
    """The inertial position at TT seconds t since the scenario epoch: an orbit of
    ``attitude.environment.orbit`` read at the two-part TT Julian date (no lossy float JD, no
    ``Time`` built per call); any other orbit object is left to ``GravityGradient`` with
    the scenario epoch as its t = 0; a callable already takes t."""
    if hasattr(source, "state_tt"):
        with offline_time():
            tt = scenario.epoch.tt
        jd1, jd2 = float(tt.jd1), float(tt.jd2)

        def position(t: NDArray[np.float64]) -> NDArray[np.float64]:
            t = np.asarray(t, dtype=np.float64)
            flat = t.ravel()
            r, _ = source.state_tt(np.full(flat.shape, jd1), jd2 + flat / 86400.0)
            return np.asarray(r, dtype=np.float64).reshape((*t.shape, 3))

        return position
    if callable(source):
        return source
    return _OrbitAtEpoch(source, scenario.epoch)


class _OrbitAtEpoch:
    """An orbit object with the scenario epoch as the ``epoch`` its t = 0 stands for."""

    def __init__(self, orbit: Any, epoch: Any) -> None:
        self.orbit, self.epoch = orbit, epoch
        for name in ("position", "position_velocity"):
            if hasattr(orbit, name):
                setattr(self, name, getattr(orbit, name))

    def __repr__(self) -> str:
        return repr(self.orbit)


def _refuse_a_long_search(
    state: State,
    t0: float,
    span: float,
    torques,
    keys: list[str | None],
    wheel_momentum: NDArray | None = None,
) -> None:
    """Refuse a step search whose first try alone would take more than MAX_STEPS steps.

    The search (``TorquedSolver``) first runs the span at half a quarter turn of the
    body (at most a fortieth of the orbit) and at twice that; the body's fastest turn
    is bounded by |ω| ≤ √(2T/I_min) at the start, and by |ω| ≤ |m|/I_min with
    |m| ≤ |m0| + ∫|τ| dt later: the burns within the span may spin the body up.
    The error names the burn (its key in ``keys``, beside ``torques``) when the body
    would be slow enough without the burns' impulse, else ``torques.accuracy``: the
    accuracy asked for over this span.
    """
    I_min = float(np.min(state.inertia.moments))
    own_rate = math.sqrt(2.0 * state.kinetic_energy / I_min)
    if wheel_momentum is not None:  # the gyroscopic turn |I⁻¹h| (attitude.torques.gyrostat)
        gyroscopic = np.linalg.solve(state.inertia.tensor, wheel_momentum)
        own_rate = max(own_rate, float(np.linalg.norm(gyroscopic)))
    impulses = [
        (
            float(np.linalg.norm(torque.torque))
            * max(0.0, min(torque.stop, t0 + span) - max(torque.start, t0)),
            key,
        )
        for torque, key in zip(torques, keys, strict=True)
        if isinstance(torque, ConstantTorque)
    ]
    impulse = sum(size for size, _ in impulses)
    rate = own_rate
    if impulse > 0.0:
        rate = max(rate, (float(np.linalg.norm(state.angular_momentum)) + impulse) / I_min)

    def quarter_turns(rate: float) -> list[float]:
        return [0.5 * 2.0 * math.pi / rate / 4.0] if rate > 0.0 else []

    orbits = [
        0.5 * 2.0 * math.pi * math.sqrt(radius**3 / torque.mu) / 20.0
        for torque in torques
        if isinstance(torque, GravityGradient)
        for radius in [float(np.linalg.norm(torque.position(np.array([t0]))[0]))]
    ]
    first = quarter_turns(rate) + orbits
    if not (first and span / min(first) * 1.5 > MAX_STEPS):
        return
    steps = f"{span / min(first) * 1.5:.3g} steps of {min(first):.3g} s (more than {MAX_STEPS:g})"
    without_burns = quarter_turns(own_rate) + orbits
    burn_size, burn_key = max(impulses, key=lambda item: item[0], default=(0.0, None))
    if burn_key and not (without_burns and span / min(without_burns) * 1.5 > MAX_STEPS):
        raise InputError(
            f"the burns spin the body up to {rate:.3g} rad/s (this one adds {burn_size:.3g} "
            f"N m s): choosing the step for torques.accuracy over {span:g} s would start "
            f"with {steps}: give a smaller torque, torques.step, or a shorter span",
            key=burn_key,
        )
    raise InputError(
        f"choosing the step over {span:g} s would start with {steps}: give torques.step, "
        "or a shorter span",
        key="torques.accuracy",
    )


class TorquedMotion:
    """One segment [t0, end_s] under ``torques`` (models), from ``state`` at ``t0``.

    ``settings``: the scenario's :class:`ScenarioTorques` (step or accuracy, order).
    ``wheel_momentum``: wheels spinning at constant speed relative to the body, their
    momentum h (body axes, N m s): a gyrostat (:mod:`attitude.torques.gyrostat`), whose
    ``state.angular_momentum`` is the total M = Iω + h.  Times within a nanosecond
    before ``t0`` (which the trajectory counts as ``t0``) are evaluated at ``t0``.
    """

    formula = "torqued"
    period = math.inf

    def __init__(
        self,
        state: State,
        t0: float,
        end_s: float,
        torques: list[Torque],
        settings: ScenarioTorques,
        keys: list[str | None] | None = None,
        wheel_momentum: NDArray[np.float64] | None = None,
    ) -> None:
        self.state = state
        self.wheel_momentum = wheel_momentum
        # Spinning wheels alone: the torque-free gyrostat (attitude.torques.gyrostat).
        self.formula = "gyrostat" if wheel_momentum is not None and not torques else "torqued"
        self.end_s = float(end_s)
        self.torques = tuple(torques)
        self.settings = settings
        span = self.end_s - t0
        options: dict[str, Any] = {"order": settings.order}
        if settings.step is None and span > _SHORTEST_SEARCH_S:
            keys = list(keys) if keys is not None else [None] * len(self.torques)
            _refuse_a_long_search(state, t0, span, self.torques, keys, wheel_momentum)
            options.update(tolerance=settings.accuracy_rad, span=span)
        else:
            options["step"] = settings.step if settings.step is not None else max(span, 1.0)
        try:
            self.solver = TorquedSolver(
                state.inertia.tensor,
                state.angular_momentum,
                state.attitude,
                t0,
                list(torques),
                wheel_momentum=wheel_momentum,
                **options,
            )
        except InputError as exc:  # the solver's names for the scenario's settings
            named = {"tolerance": "torques.accuracy", "step": "torques.step"}
            raise (exc.located(key=named[exc.key]) if exc.key in named else exc) from None
        self._last: tuple[NDArray, NDArray, NDArray] | None = None

    # ---- states

    def _states(self, t: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Body momentum and quaternions (scalar first) at ``t``, kept for the last ``t``:
        a chunk of the output grid asks for five quantities at the same times."""
        τ = np.maximum(np.asarray(t, dtype=np.float64), self.solver.t0)
        last = self._last
        if last is not None and last[0].shape == τ.shape and np.array_equal(last[0], τ):
            return last[1], last[2]
        m, q = self.solver.states(τ)
        self._last = (τ.copy(), m, q)
        return m, q

    def attitude_quaternion(self, t: ArrayLike, scalar_first: bool = True) -> NDArray[np.float64]:
        q = self._states(t)[1]
        return q.copy() if scalar_first else q[..., [1, 2, 3, 0]]

    def attitude(self, t: ArrayLike) -> Rotation:
        return Rotation.from_quat(self._states(t)[1], scalar_first=True)

    def angular_momentum(self, t: ArrayLike) -> NDArray[np.float64]:
        return self._states(t)[0].copy()

    def angular_velocity(self, t: ArrayLike) -> NDArray[np.float64]:
        m = self._states(t)[0]
        if self.wheel_momentum is not None:  # a gyrostat: ω = I⁻¹(M − h)
            m = m - self.wheel_momentum
        return np.linalg.solve(self.state.inertia.tensor, m[..., None])[..., 0]

    def inertial_angular_momentum_at(self, t: ArrayLike) -> NDArray[np.float64]:
        """R(t) m(t), N m s, inertial axes: it changes under the torques."""
        m, q = self._states(t)
        return (
            Rotation.from_quat(q.reshape(-1, 4), scalar_first=True)
            .apply(m.reshape(-1, 3))
            .reshape(m.shape)
        )

    def kinetic_energy_at(self, t: ArrayLike) -> NDArray[np.float64]:
        """½ ω(t)·Iω(t), J: ½ m·ω, the body's with spinning wheels (m − h = Iω)."""
        m = self.angular_momentum(t)
        if self.wheel_momentum is not None:
            m = m - self.wheel_momentum
        return 0.5 * np.sum(m * self.angular_velocity(t), axis=-1)

    # ---- what the closed form has and this motion has not

    def flip_times(self, t_start: float, t_end: float) -> NDArray[np.float64]:
        """None located: flips are a feature of the torque-free closed form."""
        return np.empty(0)

    def spin_axis_cone(self) -> None:
        return None

    # ---- numbers for the layers above

    @property
    def t0(self) -> float:
        return self.solver.t0

    @property
    def moments_of_inertia(self) -> NDArray[np.float64]:
        return self.state.inertia.moments

    @cached_property
    def _bounds(self) -> tuple[float, float]:
        with np.errstate(over="ignore", invalid="ignore"):  # refused above, by the caller
            _, G, T = self.solver.grid_invariants(self.end_s)
        G = np.append(G, np.linalg.norm(self.state.angular_momentum))
        T = np.append(T, self.initial_kinetic_energy)
        dG = float(np.max(np.abs(np.diff(G)))) if G.size > 1 else 0.0
        dT = float(np.max(np.abs(np.diff(T)))) if T.size > 1 else 0.0
        return float(np.max(G)) + 2.0 * dG, float(np.max(T)) + 2.0 * dT

    @property
    def angular_momentum_norm(self) -> float:
        """The largest |m| over the segment, N m s (see the module docstring)."""
        return self._bounds[0]

    @property
    def kinetic_energy(self) -> float:
        """The largest kinetic energy over the segment, J (see the module docstring)."""
        return self._bounds[1]

    @property
    def initial_kinetic_energy(self) -> float:
        if self.wheel_momentum is not None:
            ω = self.angular_velocity(np.array([self.t0, self.t0]))[0]
            return 0.5 * float(ω @ self.state.inertia.tensor @ ω)
        return self.state.kinetic_energy

    @property
    def initial_inertial_angular_momentum(self) -> NDArray[np.float64]:
        return self.state.attitude.apply(self.state.angular_momentum)

    @property
    def step(self) -> float:
        return self.solver.step

    @property
    def method(self) -> str:
        return self.solver.method.name

    @cached_property
    def error_estimate(self) -> float:
        """The estimated worst attitude error over the segment, rad (module docstring)."""
        choice = self.solver.step_choice
        if choice is not None:
            return choice.error_estimate
        span = self.end_s - self.t0
        if span <= 0.0:
            return 0.0
        coarse = TorquedSolver(
            self.state.inertia.tensor,
            self.state.angular_momentum,
            self.state.attitude,
            self.t0,
            list(self.torques),
            step=2.0 * self.solver.step,
            order=self.settings.order,
            wheel_momentum=self.wheel_momentum,
        )
        checks = self.t0 + span * np.linspace(1.0 / _CHECKS, 1.0, _CHECKS)
        difference = angles_between(
            self.solver.attitude_quaternion(checks), coarse.attitude_quaternion(checks)
        )
        return float(np.max(difference)) / (2.0**self.solver.order - 1.0)

    def __repr__(self) -> str:
        return (
            f"TorquedMotion([{self.t0:g}, {self.end_s:g}] s, {self.method}, "
            f"step {self.step:g} s, {len(self.torques)} torques)"
        )
