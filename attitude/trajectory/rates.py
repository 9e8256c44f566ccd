"""The largest body rate |ω| of a segment, found on its motion (not on an output grid).

**Torque-free** (closed form).  On the polhode (|m|² = G², Σ mᵢ²/Iᵢ = 2T) the squares
xᵢ = mᵢ² lie on a line, so |ω|² = Σ xᵢ/Iᵢ² is an affine function of any one of them:
along the motion it is monotone between the instants where one of the components
that oscillate vanishes, and its extreme values are those of the polhode's ends,
where one xᵢ = 0 (two linear equations for the other two).  The momentum circulates
about the axis of least inertia a (G²/2T < I_b) or of greatest c; the oscillating
components are then (b, c) or (a, b), each vanishing every half body period.  So the
largest |ω| over [a, b] is the larger polhode end, reached where its component
vanishes, if it vanishes within [a, b]; else the larger of |ω(a)| and |ω(b)|.  A body
with two equal moments, a steady spin or a body at rest has a constant |ω|.  The
separatrix (no period) is searched as under torques.

**Under torques** (:class:`~attitude.trajectory.torqued.TorquedMotion`).  |ω| is
read on the segment's survey (32 samples a turn at the largest rate: the torques
perturb the free motion slowly, so |ω| has no other extrema than the free motion's,
half a body period apart); every local maximum of the samples within 1 % of the
largest, and both ends, is refined by golden-section search on the dense output over
its two neighbouring intervals.  Between samples |ω| can exceed the sampled maximum
by at most the curvature term ½ |d²|ω|/dt²| (Δt/2)² ~ 0.5 % of the nutation
amplitude, far within the 1 % kept.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import brentq

from attitude.solver.euler_solver import EulerSolver
from attitude.trajectory.segments import Segment
from attitude.trajectory.torqued import TorquedMotion

__all__ = ["largest_rate"]

_KEEP = 0.01  # local maxima of the samples within this fraction of the largest are refined
_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0
_GOLDEN_ITERATIONS = 60
_SEPARATRIX_SAMPLES = 4096
_HALF_PERIOD_SAMPLES = 64


def largest_rate(segment: Segment, start_s: float, end_s: float) -> tuple[float, float]:
    """(|ω| in rad/s, the first time it is reached) over [start_s, end_s] ⊂ the segment
    (module docstring)."""
    solver = segment.solver
    if isinstance(solver, TorquedMotion):
        return _torqued(solver, start_s, end_s)
    own = getattr(solver, "largest_rate", None)  # under a law: attitude.trajectory.guided
    if own is not None:
        return own(start_s, end_s)
    if not isinstance(solver, EulerSolver):
        raise TypeError(f"no largest-rate search for a {type(solver).__name__}")
    return _free(segment, solver, start_s, end_s)


def _norm(v: NDArray[np.float64]) -> NDArray[np.float64]:
    """|v| along the last axis, scaled first so that no square overflows or underflows
    (a momentum of 1e160 N m s is a valid state)."""
    scale = np.max(np.abs(v), axis=-1, keepdims=True)
    safe = np.where(scale > 0.0, scale, 1.0)
    return (safe * np.linalg.norm(v / safe, axis=-1, keepdims=True))[..., 0]


def _rate(solver, t: NDArray[np.float64]) -> NDArray[np.float64]:
    return _norm(solver.angular_velocity(np.atleast_1d(t)))


def _principal(segment: Segment, t: NDArray[np.float64]) -> NDArray[np.float64]:
    m = segment.solver.angular_momentum(np.atleast_1d(t))
    axes = segment.state.inertia
    return m if axes.is_diagonal else axes.body_to_principal.apply(m)


def _ends(segment: Segment, start_s: float, end_s: float) -> tuple[float, float]:
    """The larger of |ω| at the two ends, and where."""
    rates = _rate(segment.solver, np.array([start_s, end_s]))
    return (float(rates[0]), start_s) if rates[0] >= rates[1] else (float(rates[1]), end_s)


def _free(
    segment: Segment, solver: EulerSolver, start_s: float, end_s: float
) -> tuple[float, float]:
    moments = segment.state.inertia.moments
    order = np.argsort(moments)
    I_a, I_b, I_c = (float(moments[k]) for k in order)
    if solver.formula in ("rest", "steady") or not I_a < I_b < I_c:
        return float(_rate(solver, np.array([start_s]))[0]), start_s
    if solver.formula == "iii" or not math.isfinite(solver.period):
        return _searched(segment, start_s, end_s)
    m = _principal(segment, np.array([segment.start_s]))[0][order]
    size = float(np.max(np.abs(m)))  # the squares below are of m / size: no overflow
    x = (m / size) ** 2
    G2 = float(np.sum(x))
    twice_T = x[0] / I_a + x[1] / I_b + x[2] / I_c
    # The polhode's ends: (component that vanishes, the other two's squares).
    if G2 < twice_T * I_b:  # about the axis of least inertia: b and c oscillate
        ends = {1: _pair(G2, twice_T, I_a, I_c), 2: _pair(G2, twice_T, I_a, I_b)}
        others = {1: (0, 2), 2: (0, 1)}
    else:  # about the axis of greatest inertia: a and b oscillate
        ends = {0: _pair(G2, twice_T, I_b, I_c), 1: _pair(G2, twice_T, I_a, I_c)}
        others = {0: (1, 2), 1: (0, 2)}
    # |ω|² = Σ xᵢ/Iᵢ² at each end, as (size/Iᵢ)² x̂ᵢ: no square of a huge or tiny moment.
    ratio = size / np.array([I_a, I_b, I_c])
    peaks = {
        k: math.sqrt(max(0.0, u * ratio[others[k][0]] ** 2 + v * ratio[others[k][1]] ** 2))
        for k, (u, v) in ends.items()
    }
    vanishing = max(peaks, key=lambda k: peaks[k])
    found = _first_zero(segment, int(order[vanishing]), start_s, end_s, solver.period / 2.0)
    if found is not None:
        return peaks[vanishing], found
    return _ends(segment, start_s, end_s)


def _pair(G2: float, twice_T: float, I_u: float, I_v: float) -> tuple[float, float]:
    """(x_u, x_v) with x_u + x_v = G², x_u/I_u + x_v/I_v = 2T (the third is zero)."""
    x_v = (twice_T - G2 / I_u) / (1.0 / I_v - 1.0 / I_u)
    return G2 - x_v, x_v


def _first_zero(
    segment: Segment, component: int, start_s: float, end_s: float, half_period: float
) -> float | None:
    """The first time in [start_s, end_s] at which the principal-axes momentum
    ``component`` vanishes (it does every half period), or None."""
    stop = min(end_s, start_s + half_period * (1.0 + 1e-9))
    t = np.linspace(start_s, stop, _HALF_PERIOD_SAMPLES + 1)
    values = _principal(segment, t)[:, component]
    if values[0] == 0.0:
        return start_s
    change = np.flatnonzero(np.signbit(values[1:]) != np.signbit(values[:-1]))
    if change.size == 0:
        return None
    k = int(change[0])

    def f(τ: float) -> float:
        return float(_principal(segment, np.array([τ]))[0, component])

    return float(brentq(f, t[k], t[k + 1], xtol=4.0 * float(np.spacing(max(abs(t[k + 1]), 1.0)))))


def _golden(solver, low: NDArray[np.float64], high: NDArray[np.float64]):
    """The largest |ω| in each [low, high] (unimodal), by golden-section search, all at
    once: (values, times)."""
    a, b = low.copy(), high.copy()
    c = b - _GOLDEN * (b - a)
    d = a + _GOLDEN * (b - a)
    fc, fd = _rate(solver, c), _rate(solver, d)
    for _ in range(_GOLDEN_ITERATIONS):
        left = fc >= fd  # the maximum lies in [a, d]
        b = np.where(left, d, b)
        a = np.where(left, a, c)
        if not np.any(b - a > 4.0 * np.spacing(np.maximum(np.abs(b), 1.0))):
            break
        c_new = np.where(left, b - _GOLDEN * (b - a), d)
        d_new = np.where(left, c, a + _GOLDEN * (b - a))
        # One new evaluation per bracket: the other point is kept.
        f_fresh = _rate(solver, np.where(left, c_new, d_new))
        fc, fd = np.where(left, f_fresh, fd), np.where(left, fc, f_fresh)
        c, d = c_new, d_new
    t = 0.5 * (a + b)
    return _rate(solver, t), t


def _refine(solver, t: NDArray[np.float64], rates: NDArray[np.float64]) -> tuple[float, float]:
    """The largest |ω| near the samples' local maxima within _KEEP of the largest."""
    best = float(np.max(rates))
    inner = (
        np.flatnonzero(
            (rates[1:-1] >= rates[:-2])
            & (rates[1:-1] >= rates[2:])
            & (rates[1:-1] >= best * (1 - _KEEP))
        )
        + 1
    )
    values, times = [rates[0], rates[-1]], [t[0], t[-1]]
    if inner.size:
        found, where = _golden(solver, t[inner - 1], t[inner + 1])
        values += found.tolist()
        times += where.tolist()
    return _first_largest(np.array(values), np.array(times))


def _torqued(solver: TorquedMotion, start_s: float, end_s: float) -> tuple[float, float]:
    """The survey's local maxima within _KEEP of its largest, and the ends, refined."""
    ends = _rate(solver, np.array([start_s, end_s]))
    peaks: list[NDArray] = []
    brackets: list[NDArray] = []
    for t, _, ω in solver.survey():
        rate = _norm(ω)
        inner = np.flatnonzero((rate[1:-1] >= rate[:-2]) & (rate[1:-1] >= rate[2:])) + 1
        inner = inner[(t[inner] > start_s) & (t[inner] < end_s)]
        peaks.append(rate[inner])
        brackets.append(np.column_stack([t[inner - 1], t[inner + 1]]))
    values = np.concatenate(peaks)
    around = np.concatenate(brackets) if brackets else np.empty((0, 2))
    best = max(float(np.max(values, initial=0.0)), float(np.max(ends)))
    keep = values >= best * (1.0 - _KEEP)
    found_values, found_times = [float(ends[0]), float(ends[1])], [start_s, end_s]
    if np.any(keep):
        low = np.maximum(around[keep, 0], start_s)
        high = np.minimum(around[keep, 1], end_s)
        refined, where = _golden(solver, low, high)
        found_values += refined.tolist()
        found_times += where.tolist()
    return _first_largest(np.array(found_values), np.array(found_times))


def _first_largest(values: NDArray[np.float64], times: NDArray[np.float64]) -> tuple[float, float]:
    """The largest value and the earliest time at which it is found."""
    top = float(np.max(values))
    return top, float(np.min(times[values == top]))


def _searched(segment: Segment, start_s: float, end_s: float) -> tuple[float, float]:
    """The separatrix: sampled over the span and densely around its turn-over."""
    solver = segment.solver
    t = np.linspace(start_s, end_s, _SEPARATRIX_SAMPLES)
    flips = solver.flip_times(start_s, end_s)
    if flips.size:
        G = solver.angular_momentum_norm
        turn = 2.0 * math.pi * float(np.min(solver.moments_of_inertia)) / G
        near = flips[0] + np.linspace(-8.0 * turn, 8.0 * turn, _SEPARATRIX_SAMPLES)
        t = np.unique(np.concatenate([t, near[(near > start_s) & (near < end_s)]]))
    return _refine(solver, t, _rate(solver, t))
