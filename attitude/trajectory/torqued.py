"""A stretch of a scenario's motion under torques, seen as the layers above see a segment.

Between events, a scenario with torques (``attitude.scenario.torques``) is propagated
by :class:`~attitude.torques.solver.TorquedSolver` at the step the run chose
(``attitude.trajectory.steps``).  :class:`TorquedMotion` wraps it with what the
trajectory, the motion analysis, the pointing and the reports ask of a segment's
solver (the interface of :class:`~attitude.solver.euler_solver.EulerSolver`), so that
they need not care which one propagated it:

- the states at any times of the segment (``attitude``, ``attitude_quaternion``,
  ``angular_momentum``, ``angular_velocity``), from the solver's dense output;
- ``formula`` ``"torqued"``, no ``period`` and no spin-axis cone: the motion under a
  torque is not periodic;
- ``flip_times``: the flips located on the propagated motion (:meth:`flip_times`);
- ``breakpoints``: where the motion is not smooth inside the segment (a torque
  switching on or off), for the outputs that interpolate it (the AEM);
- ``angular_momentum_norm`` and ``kinetic_energy``: what the layers above use them
  for is a bound on the body rate (|ω| ≤ G/I_min, |ω|² ≤ 2T/I_min), so here they are
  the **largest** |m| and T over the segment: the largest at the solver's grid points
  plus twice the largest change between two of them (both change smoothly, by at most
  |Γ| h over a step);
- ``error_estimate``: the run's estimated attitude error within the segment (rad),
  errors carried from earlier segments included, set by the trajectory.

:meth:`TorquedMotion.survey` samples the body momentum densely enough to resolve the
motion (``SURVEY_PER_TURN`` samples per turn at the fastest rate); the flips, the
largest rate and the report's figure all read it, so the dense output is evaluated
once for them (for up to a million samples; beyond, once each, in bounded memory).
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from functools import cached_property
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from attitude.environment.timescales import offline_time
from attitude.scenario.events import State
from attitude.scenario.scenario import Scenario
from attitude.scenario.torques import ScenarioTorques
from attitude.torques.models import ConstantTorque, GravityGradient, Torque
from attitude.torques.solver import StepChoice, StepPrediction, TorquedSolver

__all__ = ["SURVEY_PER_TURN", "TorquedMotion", "flip_amplitude_exceeds", "scenario_torque_models"]

# Samples of the survey per turn of the body at its largest rate over the segment: the
# momentum's direction moves by at most 2π/32 in the body between two of them.
SURVEY_PER_TURN = 32
# The survey is evaluated this many samples at a time, and kept when no longer than
# _SURVEY_KEPT (t, m and ω: 56 bytes a sample).
_SURVEY_CHUNK = 1 << 16
_SURVEY_KEPT = 1 << 20
# Flip times are refined until their bracket is this many float spacings wide.
_FLIP_SPACINGS = 4.0
_FLIP_ITERATIONS = 80


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


def flip_amplitude_exceeds(
    m: NDArray[np.float64], moments: NDArray[np.float64]
) -> NDArray[np.bool_]:
    """Whether the free motion through each principal-axes momentum ``m`` (…, 3) swings
    its intermediate component beyond G/√2: what makes a sign change of that component
    a flip (``EulerSolver.flip_times``), rather than part of a nutation.

    On the polhode (|m|² = G², Σ mᵢ²/Iᵢ = 2T; I_a < I_b < I_c) the intermediate
    component is largest where one of the others vanishes: where m_c = 0 when the
    momentum circulates about the axis of least inertia (G²/2T < I_b), then
    m_b² = (G²/I_a − 2T)/(1/I_a − 1/I_b); where m_a = 0 otherwise, then
    m_b² = (2T − G²/I_c)/(1/I_b − 1/I_c).  False for a body without a distinct
    intermediate axis.
    """
    order = np.argsort(moments)
    I_a, I_b, I_c = (float(moments[k]) for k in order)
    if not I_a < I_b < I_c:
        return np.zeros(m.shape[:-1], dtype=bool)
    x = m[..., order] ** 2
    G2 = np.sum(x, axis=-1)
    twice_T = x[..., 0] / I_a + x[..., 1] / I_b + x[..., 2] / I_c
    about_least = G2 < twice_T * I_b  # G²/2T < I_b
    peak = np.where(
        about_least,
        (G2 / I_a - twice_T) / (1.0 / I_a - 1.0 / I_b),
        (twice_T - G2 / I_c) / (1.0 / I_b - 1.0 / I_c),
    )
    return peak > 0.5 * G2


class TorquedMotion:
    """One segment [t0, end_s] under ``torques`` (models), from ``state`` at ``t0``, by
    splitting at ``step`` (s) with the method of ``order``.

    ``wheel_momentum``: wheels spinning at constant speed relative to the body, their
    momentum h (body axes, N m s): a gyrostat (:mod:`attitude.torques.gyrostat`), whose
    ``state.angular_momentum`` is the total M = Iω + h (``formula`` ``"gyrostat"``
    without torques).  Times within a nanosecond before ``t0`` (which the trajectory
    counts as ``t0``) are evaluated at ``t0``.
    """

    formula = "torqued"
    period = math.inf

    def __init__(
        self,
        state: State,
        t0: float,
        end_s: float,
        torques: list[Torque],
        step: float,
        order: int,
        wheel_momentum: NDArray[np.float64] | None = None,
    ) -> None:
        self.state = state
        self.wheel_momentum = wheel_momentum
        # Spinning wheels alone: the torque-free gyrostat (attitude.torques.gyrostat).
        self.formula = "gyrostat" if wheel_momentum is not None and not torques else "torqued"
        self.end_s = float(end_s)
        self.torques = tuple(torques)
        self.order = int(order)
        self.solver = TorquedSolver(
            state.inertia.tensor,
            state.angular_momentum,
            state.attitude,
            t0,
            list(torques),
            step=step,
            order=order,
            wheel_momentum=wheel_momentum,
        )
        # The run's estimated error within this segment (attitude.trajectory.steps).
        self.error_estimate: float | None = None
        # A gyrostat's own step search (attitude.trajectory.modes): chosen, or predicted
        # by `attitude check` past its budget, when the motion is then propagated at
        # the longer approximate_step_s.
        self.step_search: StepChoice | StepPrediction | None = None
        self.approximate_step_s: float | None = None
        self._last: tuple[NDArray, NDArray, NDArray] | None = None
        self._survey: tuple[NDArray, NDArray, NDArray] | None = None

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
        ω = np.linalg.solve(self.state.inertia.tensor, m[..., None])[..., 0]
        return ω.astype(np.float64, copy=False)

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

    def principal_momentum(self, t: ArrayLike) -> NDArray[np.float64]:
        """The body momentum at ``t`` in principal axes (N m s), the order of
        ``moments_of_inertia``."""
        m = self._states(t)[0]
        axes = self.state.inertia
        return (
            m
            if axes.is_diagonal
            else axes.body_to_principal.apply(m.reshape(-1, 3)).reshape(m.shape)
        )

    # ---- where the motion is not smooth

    def breakpoints(self, start_s: float, end_s: float) -> list[tuple[float, str]]:
        """The times in (start_s, end_s) where a torque switches on or off, with what
        happens there (the hook ``attitude.trajectory.segments.Segment.breakpoints``
        reads): the rate is continuous there, its derivative is not."""
        found: dict[float, list[str]] = {}
        for torque in self.torques:
            marks = (
                [
                    (torque.start, "a constant torque starts"),
                    (torque.stop, "a constant torque ends"),
                ]
                if isinstance(torque, ConstantTorque)
                else [(b, f"{torque!r} switches") for b in torque.breakpoints]
            )
            for time_s, what in marks:
                if start_s < time_s < end_s:
                    found.setdefault(float(time_s), []).append(what)
        return [(t, "; ".join(sorted(set(found[t])))) for t in sorted(found)]

    # ---- the survey, and what is found on it

    def _survey_grid(self) -> tuple[int, float]:
        """(count, spacing) of the survey's evenly spaced times over the segment."""
        span = self.end_s - self.t0
        G = self.angular_momentum_norm
        if span <= 0.0:
            return 1, 0.0
        if G == 0.0:
            return 2, span
        spacing = 2.0 * math.pi * float(np.min(self.moments_of_inertia)) / G / SURVEY_PER_TURN
        count = max(2, math.ceil(span / spacing) + 1)
        return count, span / (count - 1)

    def survey(self) -> Iterator[tuple[NDArray, NDArray, NDArray]]:
        """The survey in chunks, in time order: (t, principal-axes momentum, body angular
        velocity) at evenly spaced times over the segment, ``SURVEY_PER_TURN`` a turn at
        the largest rate over it (|ω| ≤ G_max/I_min), both ends included.  Consecutive
        chunks share their last two samples with the next one's first two (a sample
        and its neighbours are then always in one chunk).  Kept once computed when it
        has at most _SURVEY_KEPT samples (64 MB), so that the flips, the largest rate
        and the figure read one evaluation of the dense output; a longer one is
        computed again for each, a chunk at a time, in bounded memory."""
        if self._survey is not None:
            yield self._survey
            return
        count, spacing = self._survey_grid()
        kept: list[tuple[NDArray, NDArray, NDArray]] = []
        first = 0
        while True:
            stop = min(first + _SURVEY_CHUNK, count)
            t = self.t0 + spacing * np.arange(first, stop, dtype=np.float64)
            if stop == count:
                t[-1] = self.end_s
            m, ω = self.principal_momentum(t), self.angular_velocity(t)
            chunk = (t, m, ω)
            if count <= _SURVEY_KEPT:
                kept.append(chunk if first == 0 else (t[2:], m[2:], ω[2:]))
            yield chunk
            if stop == count:
                break
            first = stop - 2
        if kept:
            times, momenta, rates = (np.concatenate(parts) for parts in zip(*kept, strict=True))
            self._survey = (times, momenta, rates)

    def flip_times(self, t_start: float, t_end: float) -> NDArray[np.float64]:
        """The flips in [t_start, t_end] on the propagated motion (TT s): the times at
        which the momentum crosses from one side of the intermediate axis to the other
        (its component along that axis changes sign) while the free motion through the
        state there swings that axis beyond 45° of the momentum
        (:func:`flip_amplitude_exceeds`), as ``EulerSolver.flip_times`` defines a flip.

        Found on :meth:`survey` (a sign change between samples a fraction of a turn
        apart; two flips are half a body period apart) and refined by bisection on the
        dense output to a few float spacings.  Empty for a body without a distinct
        intermediate axis.
        """
        moments = self.moments_of_inertia
        ranked = np.argsort(moments)
        if not moments[ranked[0]] < moments[ranked[1]] < moments[ranked[2]]:
            return np.empty(0)
        middle = int(ranked[1])
        lows, highs, signs = [], [], []
        for t, m, _ in self.survey():
            component = m[:, middle]
            change = np.flatnonzero(np.signbit(component[1:]) != np.signbit(component[:-1]))
            if t[-1] < self.end_s:  # the last pair is the next chunk's first
                change = change[change < t.size - 2]
            lows.append(t[change])
            highs.append(t[change + 1])
            signs.append(np.signbit(component[change]))
        low, high = np.concatenate(lows), np.concatenate(highs)
        if low.size == 0:
            return np.empty(0)
        low_sign = np.concatenate(signs)
        for _ in range(_FLIP_ITERATIONS):
            wide = high - low > _FLIP_SPACINGS * np.spacing(np.abs(high))
            if not np.any(wide):
                break
            mid = 0.5 * (low + high)
            same = np.signbit(self.principal_momentum(mid[wide])[:, middle]) == low_sign[wide]
            low[wide] = np.where(same, mid[wide], low[wide])
            high[wide] = np.where(same, high[wide], mid[wide])
        times = 0.5 * (low + high)
        flips = flip_amplitude_exceeds(self.principal_momentum(times), moments)
        times = times[flips]
        return times[(times >= t_start) & (times <= t_end)]

    # ---- numbers for the layers above

    @property
    def t0(self) -> float:
        return self.solver.t0

    @property
    def moments_of_inertia(self) -> NDArray[np.float64]:
        return self.state.inertia.moments

    def spin_axis_cone(self) -> None:
        return None

    @cached_property
    def _bounds(self) -> tuple[float, float]:
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

    @property
    def steps_computed(self) -> int:
        """Grid steps propagated so far (the cost of the segment, for a budget)."""
        return self.solver.steps_computed

    def __repr__(self) -> str:
        return (
            f"TorquedMotion([{self.t0:g}, {self.end_s:g}] s, {self.method}, "
            f"step {self.step:g} s, {len(self.torques)} torques)"
        )
