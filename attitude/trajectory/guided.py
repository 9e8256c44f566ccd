"""A stretch of a scenario's motion under an attitude law or a slew: a guided segment,
seen as the layers above see a segment.

On a guided segment the attitude is not propagated: it is the law's (or the slew's,
:mod:`attitude.laws.slews`), with the law's analytic angular velocity and acceleration.
:class:`GuidedMotion` gives what the trajectory, the motion analysis, the pointing and
the reports ask of a segment's solver (the interface of
:class:`~attitude.solver.euler_solver.EulerSolver` and of
:class:`~attitude.trajectory.torqued.TorquedMotion`):

- the states at any times of the segment: ``attitude``, ``attitude_quaternion``,
  ``angular_velocity`` (the law's, body axes), ``angular_momentum`` I·ω (the body's;
  the wheels' momentum is the controller's and is not modelled while a law holds),
  ``inertial_angular_momentum_at``, ``kinetic_energy_at`` (½ ω·Iω), and
  ``angular_acceleration``;
- ``formula`` ``"guided"`` or ``"slew"``, no ``period``, no flips, no spin-axis cone;
- **bounds on the body rate** over the segment, which the exact pointing search and
  the AEM sampling need: :attr:`angular_rate_bound` ≥ |ω(t)| for every t of the
  segment.  The law's ω and ω̇ are sampled at most :data:`RATE_SAMPLE_S` apart (and at
  each instant where the law's two directions come closest, where its rate peaks), and
  the bound is the largest sampled |ω| plus the largest change of ω between
  neighbouring samples; for a slew, never more than the slew's own analytic bound
  (max_rate).  It holds wherever |ω| rises and falls at most once between samples:
  laws change on the orbit's time scale (the fastest, a ground station passed
  overhead, over tens of seconds), and where a law's rate spikes (its directions
  closest) is a sample (``tests/test_guided_rate_bound_against_dense_sampling.py``
  checks it against 10 ms sampling at both).  ``angular_momentum_norm`` (I_max × that
  bound) and ``kinetic_energy`` (½ I_max × its square) are upper bounds of |Iω| and
  ½ω·Iω over the segment, as the torqued segments' are (the layers above use them as
  rate bounds).

A guided segment is refused (one line, naming the law's key and the epoch) where the
law is undefined: its two directions parallel within
:data:`attitude.laws.align_constrain.PARALLEL_LIMIT_RAD` at some instant of the
segment, found by minimizing their separation between samples, not only at samples.
"""

from __future__ import annotations

import math
from functools import cached_property
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.laws.align_constrain import (
    PARALLEL_LIMIT_RAD,
    AlignConstrainLaw,
    BoundLaw,
    DegenerateLawError,
    LawState,
)
from attitude.laws.slews import Slew
from attitude.scenario.events import State
from attitude.solver.inertia import PrincipalAxes

__all__ = ["GUIDED", "RATE_SAMPLE_S", "GuidedMotion"]

# The formulas of the segments whose attitude a law (or a slew onto one) holds.
GUIDED = ("guided", "slew")

# The law's rate is sampled at most this far apart over a segment for its bounds.
RATE_SAMPLE_S = 10.0
# The separation of a law's directions is sampled this far apart, and each local
# minimum refined to this (s).
_SEPARATION_SAMPLE_S = 10.0
_SEPARATION_XTOL_S = 1e-6
# Closer approaches than this (rad) between a law's directions are refined: there the
# law's rate about its primary direction peaks.
_NEAR_RAD = 0.1


class GuidedMotion:
    """One segment [t0, end_s] whose attitude follows ``profile`` (a
    :class:`~attitude.laws.align_constrain.BoundLaw` or a
    :class:`~attitude.laws.slews.Slew`) for a body of inertia ``inertia``.

    ``key``: the scenario key of the law (``initial_state.law``, ``events[2].law``),
    named in refusals.  Times within a nanosecond before ``t0`` (which the trajectory
    counts as ``t0``) are evaluated at ``t0``.
    """

    period = math.inf

    def __init__(
        self,
        profile: BoundLaw | Slew,
        inertia: PrincipalAxes,
        t0: float,
        end_s: float,
        key: str,
    ) -> None:
        self.profile = profile
        self.inertia = inertia
        self._t0 = float(t0)
        self.end_s = float(end_s)
        self.key = key
        self.formula = "slew" if isinstance(profile, Slew) else "guided"
        self._last: tuple[NDArray[np.float64], LawState] | None = None
        # What the run should say about the segment (the Earth orientation table's
        # coverage, a ground site never seen), and the passes of a ground site the law
        # tracks (attitude.trajectory.modes fills them).
        self.notes: list[str] = list(self.bound_law.notes)
        self.passes: list[tuple[float, float]] | None = None
        self._check_defined()
        start = self._state(np.array([self._t0, self._t0]))
        self.state = State(
            start.attitude[0],
            inertia.tensor @ start.angular_velocity[0],
            inertia,
        )

    # ---- what the law is

    @property
    def law(self) -> Any:
        """The law followed (for a slew, the law it slews onto)."""
        return self.profile.target.law if isinstance(self.profile, Slew) else self.profile.law

    @property
    def bound_law(self) -> BoundLaw:
        return self.profile.target if isinstance(self.profile, Slew) else self.profile

    @property
    def slew(self) -> Slew | None:
        return self.profile if isinstance(self.profile, Slew) else None

    def describe(self) -> str:
        if isinstance(self.profile, Slew):
            return self.profile.describe()
        return f"{self.law.name}: {self.law.describe()}"

    # ---- the law where it is undefined

    def _separation_minima(self) -> list[float]:
        """The instants of the segment where an align-and-constrain law's directions
        come closest to parallel or opposite (min(angle, π − angle) sampled, its local
        minima below :data:`_NEAR_RAD` refined)."""
        bound = self.bound_law
        if not isinstance(bound.law, AlignConstrainLaw) or self.end_s <= self._t0:
            return []
        a, b = self._t0, self.end_s
        count = max(math.ceil((b - a) / _SEPARATION_SAMPLE_S), 2) + 1
        grid = np.linspace(a, b, count)

        def closeness(t: ArrayLike) -> NDArray[np.float64]:
            angle = bound.separation(t)
            return np.minimum(angle, math.pi - angle)

        values = closeness(grid)
        padded = np.concatenate([[np.inf], values, [np.inf]])
        left, right = padded[:-2], padded[2:]
        minima = np.flatnonzero(
            (values <= left) & (values <= right) & ((values < left) | (values < right))
        )
        found = []
        from scipy.optimize import minimize_scalar  # here: only a run with a guided law

        for k in minima[values[minima] < _NEAR_RAD]:
            low, high = grid[max(k - 1, 0)], grid[min(k + 1, count - 1)]
            result = minimize_scalar(
                lambda t: float(closeness([t])[0]),
                bounds=(low, high),
                method="bounded",
                options={"xatol": _SEPARATION_XTOL_S},
            )
            better = float(result.x) if result.fun < values[k] else float(grid[k])
            found.append(better)
        return found

    def _check_defined(self) -> None:
        """Refuse the segment where its law is undefined (module notes)."""
        bound = self.bound_law
        self._closest = self._separation_minima()
        if not self._closest:
            return
        values = bound.separation(self._closest)
        worst = int(np.argmin(np.minimum(values, math.pi - values)))
        angle = float(values[worst])
        law = bound.law
        if min(angle, math.pi - angle) < PARALLEL_LIMIT_RAD and isinstance(law, AlignConstrainLaw):
            raise DegenerateLawError(
                f"the {law.name} law is undefined at "
                f"{bound.epoch_text(self._closest[worst])} (t = {self._closest[worst]:.9g} s): "
                f"its primary direction ({law.primary.describe()}) and secondary direction "
                f"({law.secondary.describe()}) come within {angle:.3g} rad of each other "
                f"(parallel within {PARALLEL_LIMIT_RAD:g} rad)",
                key=self.key,
            )

    # ---- states

    def _state(self, t: ArrayLike) -> LawState:
        """The profile's state at ``t`` (1-D), kept for the last ``t``: a chunk of the
        output grid asks for five quantities at the same times."""
        τ = np.clip(np.ravel(np.asarray(t, dtype=np.float64)), self._t0, None)
        last = self._last
        if last is not None and last[0].shape == τ.shape and np.array_equal(last[0], τ):
            return last[1]
        if τ.size == 0:
            empty = LawState(τ, Rotation.identity(0), np.zeros((0, 3)), np.zeros((0, 3)))
            return empty
        try:
            state = self.profile.state(τ)
        except InputError as exc:  # the law's own, named after its key
            if exc.key or str(exc).startswith(self.key):
                raise
            raise exc.located(key=self.key) from None
        self._last = (τ.copy(), state)
        return state

    def attitude_quaternion(self, t: ArrayLike, scalar_first: bool = True) -> NDArray[np.float64]:
        q = self._state(t).attitude.as_quat(scalar_first=scalar_first)
        return q.reshape((*np.shape(t), 4))

    def attitude(self, t: ArrayLike) -> Rotation:
        if np.ndim(t) > 1:
            raise InputError(f"t must be a scalar or a 1-D array for attitude(), got {np.shape(t)}")
        R = self._state(t).attitude
        return R[0] if np.ndim(t) == 0 else R

    def angular_velocity(self, t: ArrayLike) -> NDArray[np.float64]:
        return self._state(t).angular_velocity.reshape((*np.shape(t), 3)).copy()

    def angular_acceleration(self, t: ArrayLike) -> NDArray[np.float64]:
        return self._state(t).angular_acceleration.reshape((*np.shape(t), 3)).copy()

    def angular_momentum(self, t: ArrayLike) -> NDArray[np.float64]:
        """I·ω, body axes, N m s."""
        return self.angular_velocity(t) @ self.inertia.tensor.T

    def inertial_angular_momentum_at(self, t: ArrayLike) -> NDArray[np.float64]:
        """R(t) I ω(t), N m s, inertial axes."""
        state = self._state(t)
        m = state.angular_velocity @ self.inertia.tensor.T
        return state.attitude.apply(m).reshape((*np.shape(t), 3))

    def kinetic_energy_at(self, t: ArrayLike) -> NDArray[np.float64]:
        """½ ω·Iω, J."""
        ω = self._state(t).angular_velocity
        return (0.5 * np.sum(ω * (ω @ self.inertia.tensor.T), axis=-1)).reshape(np.shape(t))

    # ---- what the closed form has and this motion has not

    def flip_times(self, t_start: float, t_end: float) -> NDArray[np.float64]:
        return np.empty(0)

    def spin_axis_cone(self) -> None:
        return None

    # ---- bounds for the layers above

    @property
    def t0(self) -> float:
        return self._t0

    @property
    def moments_of_inertia(self) -> NDArray[np.float64]:
        return self.inertia.moments

    @property
    def inertia_tensor(self) -> NDArray[np.float64]:
        return self.inertia.tensor

    @cached_property
    def _samples(self) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """(t, ω, ω̇) every RATE_SAMPLE_S at most and at the closest approaches."""
        a, b = self._t0, self.end_s
        count = max(math.ceil((b - a) / RATE_SAMPLE_S), 1) + 1
        t = np.unique(np.concatenate([np.linspace(a, b, count), self._closest]))
        state = self.profile.state(t)
        return t, state.angular_velocity, state.angular_acceleration

    @cached_property
    def angular_rate_bound(self) -> float:
        """A bound on |ω| over the segment, rad/s (module notes)."""
        _, ω, _ = self._samples
        change = np.linalg.norm(np.diff(ω, axis=0), axis=-1)
        bound = float(np.max(np.linalg.norm(ω, axis=-1)) + (np.max(change) if change.size else 0.0))
        if isinstance(self.profile, Slew):
            bound = min(bound, self.profile.rate_bound)
        return bound

    def largest_rate(self, start_s: float, end_s: float) -> tuple[float, float]:
        """(|ω| in rad/s, when it is reached) over [start_s, end_s]: the largest of the
        samples (and both ends), refined by Brent's bounded search between its
        neighbouring samples."""
        t = self._samples[0]
        inside = (t >= start_s) & (t <= end_s)
        grid = np.unique(np.concatenate([[start_s, end_s], t[inside]]))
        rates = np.linalg.norm(self.angular_velocity(grid), axis=-1)
        k = int(np.argmax(rates))
        best = (float(rates[k]), float(grid[k]))
        low, high = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
        if high > low:
            from scipy.optimize import minimize_scalar  # here: only a run with a guided law

            found = minimize_scalar(
                lambda s: -float(np.linalg.norm(self.angular_velocity(np.array([s, s]))[0])),
                bounds=(low, high),
                method="bounded",
                options={"xatol": 1e-6},
            )
            if -found.fun > best[0]:
                best = (float(-found.fun), float(found.x))
        return best

    @property
    def angular_momentum_norm(self) -> float:
        """An upper bound of |Iω| over the segment, N m s."""
        return float(np.max(self.inertia.moments)) * self.angular_rate_bound

    @property
    def kinetic_energy(self) -> float:
        """An upper bound of ½ ω·Iω over the segment, J."""
        return 0.5 * float(np.max(self.inertia.moments)) * self.angular_rate_bound**2

    @property
    def initial_kinetic_energy(self) -> float:
        return self.state.kinetic_energy

    @property
    def initial_inertial_angular_momentum(self) -> NDArray[np.float64]:
        return self.state.attitude.apply(self.state.angular_momentum)

    error_estimate = 0.0  # the law's attitude is evaluated, not propagated

    def breakpoints(self, start_s: float, end_s: float) -> list[tuple[float, str]]:
        """Where the motion inside [start_s, end_s] is not smooth: a slew's switches of
        acceleration (coast, braking, the end of the start-rate correction), in time
        order; a law has none."""
        slew = self.slew
        if slew is None:
            return []
        points = [
            (slew.start_s + slew.accelerating_s, "slew: coasting begins"),
            (slew.end_s - slew.accelerating_s, "slew: braking begins"),
            (slew.start_s + slew.correction_s, "slew: the start-rate correction ends"),
        ]
        inside = [(t, what) for t, what in points if start_s < t < end_s]
        return sorted(inside)

    def __repr__(self) -> str:
        return f"GuidedMotion([{self._t0:g}, {self.end_s:g}] s, {self.describe()})"
