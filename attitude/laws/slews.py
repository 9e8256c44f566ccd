"""Slews: the attitude between a start state and a law, eigen-axis and bang–coast–bang,
under a maximum rate and a maximum angular acceleration.

**The profile.**  A slew starts at t₀ from an attitude R₀ turning at ω₀ (body axes:
the state of the law it leaves, or of a tumbling body a controller captures) and ends
on a target law B (attitude R_B(t), rate ω_B, acceleration α_B).  It is written

    R(t) = R_B(t) · E(t) · C(t),
    E(t) = exp((θ − φ(t)) ê),        the eigen-axis rotation, relative to B's frame;
    C(t) = exp(c(t) Δ),              the start-rate correction,

with θ ê = log(R_B(t₀)⁻¹ R₀) (the rotation that remains at t₀, |θ| ≤ π, its axis ê in
body axes), φ(t) a **bang–coast–bang** angle profile from 0 to θ over the slew's
duration T (accelerate at a, coast at the peak rate w, brake at a; no coast when θ <
w²/a: B. Wie, *Space Vehicle Dynamics and Control*, 2nd ed., AIAA 2008, ch. 7, the
rest-to-rest eigen-axis rotation; B. Wie, H. Weiss, A. Arapostathis, "Quaternion
feedback regulator for spacecraft eigenaxis rotations", *J. Guidance, Control, and
Dynamics* 12(3), 1989), and

    Δ = ω₀ − E(t₀)⁻¹ ω_B(t₀),       c(τ) = τ (1 − τ/T_c)²  for τ = t − t₀ < T_c, else 0.

At t₀: E = exp(θê), C = I, φ̇ = 0 and ċ = 1, so R = R₀ and ω = ω₀ exactly.  At t₀ + T:
E = C = I and φ̇ = ċ = 0 (when T_c ≤ T), so R = R_B and ω = ω_B exactly.  Between, relative
to B's frame the body turns about the fixed axis ê by the angle φ: an eigen-axis slew
**relative to the moving target**.  A pure eigen-axis slew cannot also start at ω₀: a
rest-to-rest profile starts at rest relative to B, i.e. at E₀⁻¹ω_B(t₀), and the
start law's rate differs from that by Δ (≈ the difference of the two laws' inertial
rates: ~1 mrad/s between nadir and Sun pointing; the whole tumble when a controller
captures a tumbling body).  The correction C absorbs Δ over T_c: it turns the body
away from the eigen-axis path by at most |Δ| max c = (4/27) T_c |Δ| rad
(:attr:`Slew.correction_bound_rad`), and returns to it; the summary states that bound.

**Rates and accelerations, analytic.**  For a product R = P Q of rotations with body
rates ω_P, ω_Q and accelerations α_P, α_Q:

    ω = Qᵀ ω_P + ω_Q,     α = Qᵀ α_P + (Qᵀ ω_P) × ω_Q + α_Q,

and a rotation exp(f(t) u) about a fixed axis has ω = ḟ u, α = f̈ u.  Applied twice (P =
R_B E, then R = P C) with B's analytic rates (:mod:`attitude.laws.align_constrain`), the
slew's ω and α are exact: no difference is taken.

**Limits.**  With ``max_rate`` Ω and ``max_acceleration`` A, the triangle inequality on
those formulas bounds the body's rate and acceleration:

    |ω| ≤ W_B + φ̇ + |ċ| |Δ|,                          |ċ| ≤ 1,
    |α| ≤ A_B + W_B φ̇ + φ̈ + (W_B + φ̇)|ċ||Δ| + |c̈||Δ|,  |c̈| ≤ 4/T_c,

where W_B and A_B bound B's |ω_B| and |α_B| over the slew (sampled every
:data:`LAW_SAMPLE_S` seconds at most, plus the largest change between neighbouring
samples; over a window from t₀ grown until it holds the slew).  The eigen-axis
profile is then given the peak rate w = Ω − W_B − |Δ| and the
acceleration a = A − A_B − W_B w − (W_B + w)|Δ| − 4|Δ|/T_c, so that the body's rate and
acceleration stay within Ω and A everywhere; T_c = min(T, 4|Δ|/(β (A − K))), K the
terms that do not depend on T_c, β = :data:`CORRECTION_SHARE` (the correction takes at
most that share of the acceleration left).  T is the least duration for which the
profile reaches θ under those limits (a monotone equation in T, solved by
``scipy.optimize.brentq``).  Where no T exists (the target's own rate, or the tumble
to capture, takes all of Ω or A), :class:`Slew` refuses in one line saying which.

An eigen-axis slew is not the time-optimal reorientation of a rigid body (K. D.
Bilimoria, B. Wie, "Time-optimal three-axis reorientation of a rigid spacecraft",
*J. Guidance, Control, and Dynamics* 16(3), 1993); it is what attitude controllers
command (the shortest path, one axis), and what this slew gives.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.base.quantities import as_si_scalar, as_vector3
from attitude.laws.align_constrain import BoundLaw, LawState

__all__ = [
    "CORRECTION_SHARE",
    "LAW_SAMPLE_S",
    "Slew",
    "SlewLimits",
    "bang_coast_bang_duration",
]

# The target law's rate and acceleration are sampled at most this far apart over the slew.
LAW_SAMPLE_S = 5.0
# The share of the acceleration left after the laws' own that the start-rate correction
# may take (the eigen-axis profile keeps the rest).
CORRECTION_SHARE = 0.25
# The target's bounds are taken over a window this much longer than the duration
# last found, until the window holds the slew.
_WINDOW_GROWTH = 1.02
_WINDOW_TRIES = 60


@dataclass(frozen=True)
class SlewLimits:
    """The limits of a slew: ``max_rate`` (rad/s, or an angular velocity Quantity) and
    ``max_acceleration`` (rad/s², or a Quantity such as ``0.05 * u.deg / u.s**2``), both
    on the body's whole angular velocity and acceleration (inertial, any axis)."""

    max_rate: Any
    max_acceleration: Any

    def __post_init__(self) -> None:
        rate = as_si_scalar(self.max_rate, "angular_velocity", "slew.max_rate")
        acceleration = as_si_scalar(
            self.max_acceleration, "angular_acceleration", "slew.max_acceleration"
        )
        for name, value, unit in (
            ("max_rate", rate, "rad/s"),
            ("max_acceleration", acceleration, "rad/s²"),
        ):
            if not value > 0.0:
                raise InputError(
                    f"must be positive, got {value!r} {unit}", key=f"slew.{name}", value=value
                )
            if not value < 1e3:
                raise InputError(
                    f"{value!r} {unit} is beyond any spacecraft (at most 1000)",
                    key=f"slew.{name}",
                    value=value,
                )
        object.__setattr__(self, "max_rate", rate)
        object.__setattr__(self, "max_acceleration", acceleration)

    def describe(self) -> str:
        return (
            f"eigen-axis, bang-coast-bang, at most {math.degrees(self.max_rate):.6g} deg/s "
            f"and {math.degrees(self.max_acceleration):.6g} deg/s²"
        )


def bang_coast_bang_duration(angle: float, rate: float, acceleration: float) -> float:
    """The least time to turn ``angle`` (rad) from rest to rest with at most ``rate`` and
    ``acceleration``: θ/w + w/a with a coast, 2√(θ/a) without (θ < w²/a)."""
    if angle <= 0.0:
        return 0.0
    if not (rate > 0.0 and acceleration > 0.0):
        return math.inf
    if angle >= rate * rate / acceleration:
        return angle / rate + rate / acceleration
    return 2.0 * math.sqrt(angle / acceleration)


def _rotation_angle(R: Rotation) -> float:
    return float(R.magnitude())


class Slew:
    """A slew from ``attitude`` (body → ICRF) and ``angular_velocity`` (body axes,
    rad/s) at ``start_s`` onto the bound law ``target``, under ``limits`` (module notes).

    ``deadline_s``: the slew must end by then (the next event, or the end of the span;
    ``target`` must be bound up to it); ``key``: names the slew in messages;
    ``deadline_text``: what the deadline is, in words, for the refusal.  Raises
    :class:`InputError` in one line when no slew within the limits ends by the deadline.
    """

    def __init__(
        self,
        start_s: float,
        attitude: Rotation,
        angular_velocity: ArrayLike,
        target: BoundLaw,
        limits: SlewLimits,
        deadline_s: float,
        *,
        key: str = "slew",
        deadline_text: str = "the end of the span",
        format_epoch: Any = None,
    ) -> None:
        self.start_s = float(start_s)
        self.target = target
        self.limits = limits
        self.key = key
        self._format = format_epoch or (lambda s: f"t = {s:.9g} s")
        self.start_attitude = attitude
        self.start_rate = as_vector3(angular_velocity, "angular_velocity", f"{key}: start rate")
        b0 = target.state([self.start_s])
        self.offset = b0.attitude[0].inv() * attitude  # E₀ = R_B(t₀)⁻¹ R₀
        rotvec = self.offset.as_rotvec()
        self.angle_rad = float(np.linalg.norm(rotvec))
        self.axis = rotvec / self.angle_rad if self.angle_rad > 0.0 else np.array([1.0, 0.0, 0.0])
        self.mismatch = self.start_rate - self.offset.inv().apply(b0.angular_velocity[0])
        self.mismatch_rad_s = float(np.linalg.norm(self.mismatch))
        self._plan(float(deadline_s), deadline_text)

    # ---- the duration

    def _target_bounds(self, stop_s: float) -> tuple[float, float]:
        """W_B and A_B over [start, stop]: the largest sampled |ω_B|, |α_B| plus the
        largest change between neighbouring samples."""
        span = max(stop_s - self.start_s, 0.0)
        count = max(math.ceil(span / LAW_SAMPLE_S), 1) + 1
        state = self.target.state(np.linspace(self.start_s, self.start_s + span, count))
        rate = np.linalg.norm(state.angular_velocity, axis=-1)
        acceleration = np.linalg.norm(state.angular_acceleration, axis=-1)

        def bound(values: NDArray[np.float64], vectors: NDArray[np.float64]) -> float:
            change = np.linalg.norm(np.diff(vectors, axis=0), axis=-1)
            return float(np.max(values) + (np.max(change) if change.size else 0.0))

        return bound(rate, state.angular_velocity), bound(acceleration, state.angular_acceleration)

    def _plan(self, deadline_s: float, deadline_text: str) -> None:
        limits = self.limits
        Ω, A = limits.max_rate, limits.max_acceleration
        D = self.mismatch_rad_s
        θ = self.angle_rad
        if not deadline_s > self.start_s:
            raise InputError(
                f"the slew has no time: {deadline_text} is at the same epoch", key=self.key
            )
        # W_B and A_B are bounds over the slew itself: from the shortest duration the
        # limits allow, the window grows to the duration found until it covers it.
        window_end = min(deadline_s, self.start_s + bang_coast_bang_duration(θ, Ω, A))
        for _ in range(_WINDOW_TRIES):
            W_B, A_B = self._target_bounds(window_end)
            duration, rate, acceleration, T_c = self._solve(θ, D, Ω, A, W_B, A_B)
            if self.start_s + duration <= window_end or window_end >= deadline_s:
                break
            window_end = min(deadline_s, self.start_s + duration * _WINDOW_GROWTH)
        else:  # not settled: the bounds over the whole time to the deadline
            W_B, A_B = self._target_bounds(deadline_s)
            duration, rate, acceleration, T_c = self._solve(θ, D, Ω, A, W_B, A_B)
        if self.start_s + duration > deadline_s:
            raise InputError(
                f"the slew of {math.degrees(θ):.4g} deg from "
                f"{self._format(self.start_s)} takes {duration:.6g} s within "
                f"{math.degrees(Ω):.6g} deg/s and {math.degrees(A):.6g} deg/s², and would end at "
                f"{self._format(self.start_s + duration)}, after {deadline_text} at "
                f"{self._format(deadline_s)}: give larger limits or more time",
                key=self.key,
            )
        self.duration_s = duration
        self.end_s = self.start_s + duration
        self.profile_rate = rate
        self.profile_acceleration = acceleration
        self.correction_s = T_c
        self.target_rate_bound = W_B
        self.target_acceleration_bound = A_B
        # φ: accelerate over t_a, coast, brake over t_a (t_a from θ = a t_a (T − t_a)).
        if θ > 0.0 and duration > 0.0:
            disc = max(duration * duration - 4.0 * θ / acceleration, 0.0)
            self._t_a = 0.5 * (duration - math.sqrt(disc))
        else:
            self._t_a = 0.0
        self._peak = acceleration * self._t_a

    def _solve(
        self, θ: float, D: float, Ω: float, A: float, W_B: float, A_B: float
    ) -> tuple[float, float, float, float]:
        """(T, w, a, T_c): the least duration and the profile's peak rate, acceleration
        and correction time (module notes); InputError where none exists."""
        fmt = math.degrees
        rate = Ω - W_B - D
        if not rate > 0.0:
            if W_B >= Ω:
                why = (
                    f"the target law itself turns at up to {fmt(W_B):.4g} deg/s, beyond "
                    f"max_rate {fmt(Ω):.4g} deg/s: no slew within it can join the law"
                )
            else:
                why = (
                    f"the body turns at {fmt(D):.4g} deg/s relative to the target law, which "
                    f"turns at up to {fmt(W_B):.4g} deg/s: max_rate {fmt(Ω):.4g} deg/s cannot "
                    "capture it"
                )
            raise InputError(f"{why}; give a larger max_rate", key=f"{self.key}.max_rate")
        K = A_B + W_B * rate + (W_B + rate) * D
        available = A - K
        if not available > 0.0:
            raise InputError(
                f"the target law's own acceleration and rate, and the start rate "
                f"to absorb ({fmt(D):.4g} deg/s), take {fmt(K):.4g} deg/s² of max_acceleration "
                f"{fmt(A):.4g} deg/s²: nothing is left for the slew; give a larger "
                "max_acceleration",
                key=f"{self.key}.max_acceleration",
            )
        if D == 0.0:
            T = bang_coast_bang_duration(θ, rate, available)
            return T, rate, available, 0.0
        T_star = 4.0 * D / (CORRECTION_SHARE * available)

        def acceleration(T: float) -> float:
            return available - 4.0 * D / min(T, T_star)

        def excess(T: float) -> float:
            a = acceleration(T)
            needed = bang_coast_bang_duration(θ, rate, a) if a > 0.0 else math.inf
            return T - min(needed, 1e300)

        low = 4.0 * D / available
        high = max(T_star, bang_coast_bang_duration(θ, rate, acceleration(T_star)))
        if θ == 0.0 or excess(low) >= 0.0:
            T = low
        else:
            from scipy.optimize import brentq  # here: a run without a slew never needs it

            T = brentq(excess, low, high, xtol=1e-12 * high, rtol=1e-14)
            while excess(T) < 0.0:  # the root from above: the profile must fit in T
                T = math.nextafter(T, math.inf) * (1.0 + 1e-15)
        return T, rate, max(acceleration(T), 0.0), min(T, T_star)

    # ---- evaluation

    def _phi(self, τ: NDArray[np.float64]) -> tuple[NDArray, NDArray, NDArray]:
        """φ, φ̇, φ̈ of the bang–coast–bang profile at τ = t − t₀ (clipped to [0, T])."""
        T, t_a, a, w = self.duration_s, self._t_a, self.profile_acceleration, self._peak
        θ = self.angle_rad
        τ = np.clip(τ, 0.0, T)
        rise = τ < t_a
        fall = τ > T - t_a
        back = T - τ
        coast = 0.5 * a * t_a * t_a + w * (τ - t_a)
        phi = np.where(rise, 0.5 * a * τ * τ, np.where(fall, θ - 0.5 * a * back * back, coast))
        rate = np.where(rise, a * τ, np.where(fall, a * back, w))
        accel = np.where(rise, a, np.where(fall, -a, 0.0))
        if θ == 0.0 or T == 0.0:
            phi, rate, accel = np.zeros_like(τ), np.zeros_like(τ), np.zeros_like(τ)
        return phi, rate, accel

    def _c(self, τ: NDArray[np.float64]) -> tuple[NDArray, NDArray, NDArray]:
        """c, ċ, c̈ of the correction at τ (zero from T_c on)."""
        T_c = self.correction_s
        if T_c <= 0.0:
            zero = np.zeros_like(τ)
            return zero, zero, zero
        x = np.clip(τ, 0.0, T_c) / T_c
        inside = τ < T_c
        c = np.where(inside, T_c * x * (1.0 - x) ** 2, 0.0)
        c_dot = np.where(inside, (1.0 - x) * (1.0 - 3.0 * x), 0.0)
        c_ddot = np.where(inside, (-4.0 + 6.0 * x) / T_c, 0.0)
        return c, c_dot, c_ddot

    def state(self, seconds: ArrayLike) -> LawState:
        """Attitude, angular velocity and acceleration (body axes) at TT seconds in
        [start, end] (module notes)."""
        s = np.atleast_1d(np.asarray(seconds, dtype=np.float64))
        target = self.target.state(s)
        τ = s - self.start_s
        phi, phi_dot, phi_ddot = self._phi(τ)
        c, c_dot, c_ddot = self._c(τ)
        e = self.axis
        E = Rotation.from_rotvec(np.outer(self.angle_rad - phi, e))
        ω_E = -phi_dot[:, None] * e
        α_E = -phi_ddot[:, None] * e
        # P = R_B E
        ω_B = E.inv().apply(target.angular_velocity)
        ω_P = ω_B + ω_E
        α_P = E.inv().apply(target.angular_acceleration) + np.cross(ω_B, ω_E) + α_E
        # R = P C
        C = Rotation.from_rotvec(c[:, None] * self.mismatch)
        ω_C = c_dot[:, None] * self.mismatch
        α_C = c_ddot[:, None] * self.mismatch
        ω_PC = C.inv().apply(ω_P)
        ω = ω_PC + ω_C
        α = C.inv().apply(α_P) + np.cross(ω_PC, ω_C) + α_C
        return LawState(s, target.attitude * E * C, ω, α)

    # ---- what the summary states

    @property
    def accelerating_s(self) -> float:
        """How long the profile accelerates (and brakes), s."""
        return self._t_a

    @property
    def correction_bound_rad(self) -> float:
        """The most the start-rate correction turns the body off the eigen-axis path."""
        return 4.0 / 27.0 * self.correction_s * self.mismatch_rad_s

    @property
    def rate_bound(self) -> float:
        """A bound on |ω| over the slew, rad/s (module notes)."""
        return self.target_rate_bound + self._peak + self.mismatch_rad_s

    def describe(self) -> str:
        return (
            f"{math.degrees(self.angle_rad):.6g} deg in {self.duration_s:.6g} s, "
            f"{self.limits.describe()}, onto {self.target.law.name}: "
            f"{self.target.law.describe()}"
        )

    def as_dict(self) -> dict[str, Any]:
        """The slew's numbers, for summaries (SI, degrees where the key says so)."""
        return {
            "angle_deg": math.degrees(self.angle_rad),
            "duration_s": self.duration_s,
            "eigen_axis_body": self.axis,
            "max_rate_deg_s": math.degrees(self.limits.max_rate),
            "max_acceleration_deg_s2": math.degrees(self.limits.max_acceleration),
            "profile_peak_rate_deg_s": math.degrees(self._peak),
            "profile_acceleration_deg_s2": math.degrees(self.profile_acceleration),
            "start_rate_mismatch_deg_s": math.degrees(self.mismatch_rad_s),
            "start_rate_correction_s": self.correction_s,
            "off_eigen_axis_at_most_deg": math.degrees(self.correction_bound_rad),
            "target_rate_bound_deg_s": math.degrees(self.target_rate_bound),
            "target_acceleration_bound_deg_s2": math.degrees(self.target_acceleration_bound),
        }
