"""The pointing search on a torque-free segment: values at nodes, rigorous bounds between
them, and refinement only where something can happen.

On a torque-free segment the attitude is Q(t) = R·Y(ψ(t))·P(t)·S (docs/derivation.md):
the body's momentum m(t), hence P(t), repeats with the period of the motion, and ψ
turns at a steady rate plus a periodic part.  So for a body vector b and a direction s
that moves slowly (the Sun, the Moon, nadir), the cosine of their angle is

    f(t) = s·Q b = B(t) + A(t) cos(ψ(t) − φ(t)),   B = (s·Ĥ)(b·m̂),  A = |s × Ĥ| |b × m̂|,

with A, B and φ periodic in the body's phase (Ĥ the inertial direction of the
momentum, m̂ = m/|m| in the body).  How fast f can bend is set by that structure: with
d = Q b, ḋ = ω × d and d̈ = Q(α × b + ω × (ω × b)) (α = ω̇, body axes),

    f'' = s̈·d + 2 ṡ·ḋ + s·d̈,   |f''| ≤ M = |s̈|max + 2 |ṡ|max W + K,

W = max |ω × b| and K = max |α × b + ω × (ω × b)| over the segment (:func:`vector_motion`:
functions of m(t) alone, sampled over one period with the Taylor remainder between
samples, and never above their analytic bounds Ω and A + Ω W, Ω = √(2T/I_min) and
|α| ≤ ((I3 − I1)/I1) Ω²/√3); |ṡ| and |s̈| come from the interpolated surroundings
(:meth:`attitude.pointing.shared_surroundings.SharedSurroundings.rate_bounds`).  A vector
near the spin axis has small W and K: its cosine bends slowly, whatever the body's
rate; a body at rest has W = K = 0, and only the sky moves.

**Nodes and cells.**  f and f' are evaluated exactly (the solver's attitude and ω,
the interpolated surroundings) at nodes every h = √(8 δ/M) (δ = 0.05: between nodes the
bound below exceeds the values by at most δ; the densest pair of vector and target sets
h for the segment).  Between nodes a and b = a + h, f lies under both parabolas
f(a) + f'(a)x + Mx²/2 and f(b) − f'(b)(h − x) + M(h − x)²/2, so under the greatest of
their lower envelope (:func:`_upper`, at one of three points), and above the mirror
bound; and f' lies within (f'(a) + f'(b) ∓ Mh)/2.  For a condition f − c > 0 each cell
is then settled: false throughout (upper bound below c), true throughout (lower bound
above), or one crossing (a change of sign where f' cannot vanish).  A cell that none of
these proves is cut at the extremum (or the root) of the cubic through its ends'
values and slopes, where the question is decided, and both parts are examined again:
a grazing pass is followed down to the float spacing of the times (4 ulps), so that no
interval is missed however short.  Each crossing is then refined from the cubic's root
by the probes of :func:`attitude.pointing.intervals._refine` (two evaluations when the
estimate is within 0.49 of the precision, regula falsi and bisection otherwise).

**Extrema** of the angles, the limb angle and the incidence: the bounds of each cell
give bounds on them; a cell that cannot improve on the best value found (by more than
the tolerance) is dropped, and the others are narrowed by golden-section search
(:func:`attitude.pointing.extrema.least_in_brackets`), as on the grid.

**The mean incidence** integrates max(f, 0) times the lit fraction over each cell of
the Sun visibility's partition (lit throughout, dark throughout, or cut at its refined
crossing) on the cubic through the ends (Gauss–Legendre, exact for it), with the lit
fraction of the surroundings where the cell meets the Earth's shadow.

**The envelope.**  |f − B| ≤ A: a vector whose Sun cosine cannot change sign (|B| > A
throughout: a panel on the spin axis), or a cone the Sun cannot reach, is settled for
the whole segment without a node; see :func:`_settled_by_envelope`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from attitude.pointing.extrema import Extremum, Problem, least_in_brackets
from attitude.pointing.intervals import Interval, _assemble, _refine
from attitude.pointing.shared_surroundings import SharedSurroundings
from attitude.pointing.spec import PointingSpec
from attitude.pointing.surroundings import unit_angle
from attitude.solver.euler_solver import EulerSolver

__all__ = [
    "FreePlan",
    "FreeResult",
    "VectorMotion",
    "free_plan",
    "search_free",
    "vector_motion",
]

# Nodes: the curvature bound's overshoot between nodes, M h²/8, at most this (a
# cosine), and at most this step (s).
_OVERSHOOT = 0.1
_LONGEST_STEP_S = 3600.0
# A window holds at most this many nodes (bounded memory).
WINDOW_NODES = 65_536
# vector_motion samples ω this many times over a period (or over the segment).
_MOTION_SAMPLES = 16_384
# A cell is cut at the cubic's extremum or root, kept within this fraction of its ends.
_CUT = 0.1
TARGETS = ("sun", "moon", "nadir")
# The envelope's bounds are widened by this (rad): the rounding of the arc cosines
# it compares (~1e-12 rad near 0 and π) and of the directions it takes.
_ENVELOPE_MARGIN = 1e-9


class _PeriodicRange:
    """The least and greatest of a sampled function over any time window: values at
    ``start_s + k·spacing`` (k < n), periodic with period n·spacing when ``periodic``,
    each within ``slack`` of the function between its neighbouring samples.  Range
    queries on a sparse table (each level the min and max of 2^level samples), so that a
    window costs two lookups whatever its length."""

    def __init__(self, values, start_s: float, spacing: float, periodic: bool, slack: float):
        self.start_s, self.spacing, self.periodic, self.slack = start_s, spacing, periodic, slack
        self.n = values.size
        lows, highs = [values], [values]
        width = 1
        while 2 * width <= self.n:
            lows.append(np.minimum(lows[-1][:-width], lows[-1][width:]))
            highs.append(np.maximum(highs[-1][:-width], highs[-1][width:]))
            width *= 2
        self.lows, self.highs = lows, highs
        self.whole = (float(values.min()) - slack, float(values.max()) + slack)

    def _query(self, i, j):
        """min and max of samples i..j (inclusive, 0 ≤ i ≤ j < n), vectorized."""
        level = np.floor(np.log2(np.maximum(j - i + 1, 1))).astype(np.intp)
        low = np.empty(i.shape)
        high = np.empty(i.shape)
        for k in np.unique(level).tolist():
            mine = level == k
            a, b = i[mine], j[mine] - (1 << k) + 1
            low[mine] = np.minimum(self.lows[k][a], self.lows[k][b])
            high[mine] = np.maximum(self.highs[k][a], self.highs[k][b])
        return low, high

    def over(self, t0: NDArray[np.float64], t1: NDArray[np.float64]):
        """Bounds (low, high) of the function over each window [t0, t1]."""
        n = self.n
        first = np.floor((t0 - self.start_s) / self.spacing).astype(np.int64)
        last = np.ceil((t1 - self.start_s) / self.spacing).astype(np.int64)
        low = np.full(first.shape, self.whole[0])
        high = np.full(first.shape, self.whole[1])
        if self.periodic:
            whole = last - first + 1 >= n
            shift = np.floor_divide(first, n) * n
            first, last = first - shift, last - shift
        else:
            whole = np.zeros(first.shape, dtype=bool)
            first, last = np.clip(first, 0, n - 1), np.clip(last, 0, n - 1)
        inside = ~whole & (last < n)
        if np.any(inside):
            lo, hi = self._query(first[inside], last[inside])
            low[inside], high[inside] = lo - self.slack, hi + self.slack
        wraps = ~whole & (last >= n)
        if np.any(wraps):
            lo1, hi1 = self._query(first[wraps], np.full(int(wraps.sum()), n - 1))
            lo2, hi2 = self._query(np.zeros(int(wraps.sum()), np.int64), last[wraps] - n)
            low[wraps] = np.minimum(lo1, lo2) - self.slack
            high[wraps] = np.maximum(hi1, hi2) + self.slack
        return low, high


@dataclass(frozen=True)
class VectorMotion:
    """How a body vector b moves over a segment: ``rate`` ≥ |ḋ| = |ω × b| and ``bend`` ≥
    |d̈| = |α × b + ω × (ω × b)| of its inertial direction d = Q b, and ``tilt``, b·m̂
    (the cosine of its angle β to the momentum, body axes, periodic in the motion)
    over any window: the envelope of the module notes (None at rest)."""

    rate: float
    bend: float
    tilt: _PeriodicRange | None = field(default=None, compare=False)


def vector_motion(
    solver: EulerSolver, vectors: list[tuple[str, NDArray[np.float64]]], start_s: float, end_s: float
) -> dict[str, VectorMotion]:
    """:class:`VectorMotion` of each (name, body vector) over [start_s, end_s].

    ω(t) is sampled :data:`_MOTION_SAMPLES` times over one period of the body's motion
    (in which it takes all its values) or over the segment if that is shorter; α =
    I⁻¹(m × ω) (Euler's equations) at the same samples.  Between samples Δ apart, each
    quantity changes by at most its rate bound times Δ/2: |d/dt (ω × b)| ≤ |α| ≤ A and
    |d/dt (α × b + ω × (ω × b))| ≤ |α̇| + 2AΩ with |α̇| = |I⁻¹((m × ω) × ω + m × α)| ≤
    G(Ω² + A)/I_min.  Each result is also capped by its analytic bound (module notes).
    """
    moments = np.sort(np.asarray(solver.moments_of_inertia, dtype=np.float64))
    G = float(solver.angular_momentum_norm)
    least = float(moments[0])
    if G == 0.0:
        return {name: VectorMotion(0.0, 0.0) for name, _ in vectors}
    fastest = math.sqrt(max(2.0 * solver.kinetic_energy, 0.0) / least)
    spin_accel = (float(moments[2]) - least) / least * fastest * fastest / math.sqrt(3.0)
    period = solver.period
    periodic = math.isfinite(period) and period < end_s - start_s
    window = period if periodic else max(end_s - start_s, 0.0)
    samples = _MOTION_SAMPLES
    t = start_s + window * np.arange(samples + 1.0) / samples
    ω = solver.angular_velocity(t)
    tensor = solver.inertia_tensor
    m = ω @ tensor.T
    α = np.linalg.solve(tensor, np.cross(m, ω).T).T
    spacing = window / samples
    gap = 0.5 * spacing
    jerk = G * (fastest * fastest + spin_accel) / least + 2.0 * spin_accel * fastest
    m_hat = m / np.linalg.norm(m, axis=1)[:, None]
    drift = np.cross(m_hat, ω)  # dm̂/dt in the body (ṁ = m × ω)
    out = {}
    for name, b in vectors:
        ωb = np.cross(ω, b)
        bend = np.cross(α, b) + np.cross(ω, ωb)
        rate = min(float(np.max(np.linalg.norm(ωb, axis=1))) + spin_accel * gap, fastest)
        bent = float(np.max(np.linalg.norm(bend, axis=1))) + jerk * gap
        tilt = m_hat @ b
        # |d/dt (b·m̂)| = |b·(m̂ × ω)|, whose own rate is at most Ω² + A.
        tilt_rate = float(np.max(np.abs(drift @ b))) + (fastest * fastest + spin_accel) * gap
        table = None
        if window > 0.0:
            values = tilt[:-1] if periodic else tilt
            table = _PeriodicRange(values, start_s, spacing, periodic, tilt_rate * gap)
        out[name] = VectorMotion(rate, min(bent, spin_accel + fastest * rate), table)
    return out


@dataclass(frozen=True)
class FreePlan:
    """How :func:`search_free` searches one torque-free segment over [start_s, end_s]:
    its node ``step_s`` and node ``count``, and the bound M on |f''| of each (vector,
    target) cosine, ``bend[(name, target)]``, and of each limb condition."""

    start_s: float
    end_s: float
    step_s: float
    count: int
    bend: dict[tuple[str, str], float] = field(compare=False)
    limb_bend: float = 0.0
    motion: dict[str, VectorMotion] = field(default_factory=dict, compare=False)
    sky: dict[str, float] = field(default_factory=dict, compare=False)


def free_plan(
    solver: EulerSolver,
    spec: PointingSpec,
    shared: SharedSurroundings,
    start_s: float,
    end_s: float,
) -> FreePlan | None:
    """The :class:`FreePlan` of a segment, or None when a bound is not finite (a piece
    of the surroundings evaluated exactly, an orbit inside the limb's sphere): the
    segment is then searched on a grid (:mod:`attitude.pointing.search`)."""
    vectors = [(v.name, v.vector) for v in spec.body_vectors]
    motion = vector_motion(solver, vectors, start_s, end_s)
    sky = shared.rate_bounds()
    targets = [t for t in TARGETS if f"{t}_1" in sky]
    bend = {}
    for name, _ in vectors:
        for target in targets:
            bend[(name, target)] = (
                sky[f"{target}_2"] + 2.0 * sky[f"{target}_1"] * motion[name].rate + motion[name].bend
            )
    limb_bend = sky.get("limb_2", 0.0) + sky.get("limb_1", 0.0) ** 2
    values = [*bend.values(), limb_bend]
    if not all(math.isfinite(v) for v in values):
        return None
    largest = max([*bend.values(), limb_bend, 1e-300])
    step = min(math.sqrt(8.0 * _OVERSHOOT / largest), _LONGEST_STEP_S, max(end_s - start_s, 1e-9))
    count = max(math.ceil((end_s - start_s) / step), 1) + 1
    return FreePlan(
        start_s, end_s, (end_s - start_s) / (count - 1), count, bend, limb_bend, motion, sky
    )


# --------------------------------------------------------------------- evaluation


@dataclass
class _Values:
    """At some times: for each vector (rows) and target, the cosine f, its rate df and
    the angle (Kahan's formula); the limb's angular radius and rate (on an orbit); each
    target's angle σ to the momentum's direction (empty at rest)."""

    f: dict[str, NDArray[np.float64]]
    df: dict[str, NDArray[np.float64]]
    angle: dict[str, NDArray[np.float64]]
    limb: NDArray[np.float64] | None
    limb_rate: NDArray[np.float64] | None
    sigma: dict[str, NDArray[np.float64]] = field(default_factory=dict)
    ddf: dict[str, NDArray[np.float64]] = field(default_factory=dict)  # f


class _Evaluator:
    """The cosines, their rates and the angles of every body vector at any times of one
    segment: the exact attitude and ω of the solver, the interpolated surroundings."""

    def __init__(self, solver: EulerSolver, spec: PointingSpec, shared: SharedSurroundings):
        self.solver = solver
        self.shared = shared
        self.vectors = np.array([v.vector for v in spec.body_vectors], dtype=np.float64)
        self.targets = [t for t in TARGETS if t != "nadir" or spec.orbit is not None]
        momentum = np.asarray(solver.inertial_angular_momentum, dtype=np.float64)
        size = float(np.linalg.norm(momentum))
        self.axis = momentum / size if size > 0.0 and math.isfinite(size) else None
        self.calls = 0
        self.points = 0
        self.tensor = np.asarray(solver.inertia_tensor, dtype=np.float64)
        self.inverse = np.linalg.inv(self.tensor)

    def __call__(self, τ: NDArray[np.float64], angles: bool = False) -> _Values:
        """The values at τ; the angles (Kahan's formula) only with ``angles``."""
        τ = np.asarray(τ, dtype=np.float64)
        self.calls += 1
        self.points += τ.size
        q = self.solver.attitude_quaternion(τ)  # scalar first, body → inertial
        ω = self.solver.angular_velocity(τ)
        w, x, y, z = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
        # The rotation matrix, row by row (R v for many v without a (n, 3, 3) product).
        xx, yy, zz = x * x, y * y, z * z
        xy, xz, yz, wx, wy, wz = x * y, x * z, y * z, w * x, w * y, w * z
        rows = (
            (1.0 - 2.0 * (yy + zz), 2.0 * (xy - wz), 2.0 * (xz + wy)),
            (2.0 * (xy + wz), 1.0 - 2.0 * (xx + zz), 2.0 * (yz - wx)),
            (2.0 * (xz - wy), 2.0 * (yz + wx), 1.0 - 2.0 * (xx + yy)),
        )

        def rotate(v0, v1, v2):
            return [r[0] * v0 + r[1] * v1 + r[2] * v2 for r in rows]

        ω_in = rotate(ω[:, 0], ω[:, 1], ω[:, 2])
        # α = I⁻¹((Iω) × ω), Euler's equations in the body, then inertial.
        m = ω @ self.tensor.T
        α = np.cross(m, ω) @ self.inverse.T
        α_in = rotate(α[:, 0], α[:, 1], α[:, 2])
        sky = self.shared.targets(τ)
        f: dict[str, list] = {t: [] for t in self.targets}
        df: dict[str, list] = {t: [] for t in self.targets}
        angle: dict[str, list] = {t: [] for t in self.targets}
        ddf: dict[str, list] = {t: [] for t in self.targets}
        for b in self.vectors:
            d = rotate(b[0], b[1], b[2])
            rate = (
                ω_in[1] * d[2] - ω_in[2] * d[1],
                ω_in[2] * d[0] - ω_in[0] * d[2],
                ω_in[0] * d[1] - ω_in[1] * d[0],
            )
            # d̈ = α × d + ω × ḋ: a cosine bends by s·d̈ + 2 ṡ·ḋ (and s̈·d, left out:
            # below 1e-5 of the rest but for a body near rest, where f'' serves only
            # the incidence's integral and the extrema's Newton steps, not a bound).
            bend = (
                α_in[1] * d[2] - α_in[2] * d[1] + ω_in[1] * rate[2] - ω_in[2] * rate[1],
                α_in[2] * d[0] - α_in[0] * d[2] + ω_in[2] * rate[0] - ω_in[0] * rate[2],
                α_in[0] * d[1] - α_in[1] * d[0] + ω_in[0] * rate[1] - ω_in[1] * rate[0],
            )
            for target in self.targets:
                s = getattr(sky, target)
                s_rate = getattr(sky, f"{target}_rate")
                ddf[target].append(
                    (bend[0] * s[:, 0] + bend[1] * s[:, 1] + bend[2] * s[:, 2])
                    + 2.0 * (rate[0] * s_rate[:, 0] + rate[1] * s_rate[:, 1] + rate[2] * s_rate[:, 2])
                )
                f[target].append(d[0] * s[:, 0] + d[1] * s[:, 1] + d[2] * s[:, 2])
                df[target].append(
                    (d[0] * s_rate[:, 0] + d[1] * s_rate[:, 1] + d[2] * s_rate[:, 2])
                    + (rate[0] * s[:, 0] + rate[1] * s[:, 1] + rate[2] * s[:, 2])
                )
                if angles:
                    angle[target].append(unit_angle(np.stack(d, axis=1), s))
        sigma = {}
        if self.axis is not None:
            # arccos: near 0 and π it keeps ~1e-12 rad at σ = 1e-4, far below the
            # margin the envelope adds (_ENVELOPE_MARGIN).
            h0, h1, h2 = self.axis
            for target in self.targets:
                s = getattr(sky, target)
                along = s[:, 0] * h0 + s[:, 1] * h1 + s[:, 2] * h2
                sigma[target] = np.arccos(np.clip(along, -1.0, 1.0))
        return _Values(
            {t: np.array(v) for t, v in f.items()},
            {t: np.array(v) for t, v in df.items()},
            {t: np.array(v) for t, v in angle.items()} if angles else {},
            sky.limb,
            sky.limb_rate,
            sigma,
            {t: np.array(v) for t, v in ddf.items()},
        )


# ------------------------------------------------------------------ bounds in a cell


def _upper(g0, d0, g1, d1, h, M):
    """The greatest value a function with |g''| ≤ M can take on a cell [0, h] where it
    is g0, g1 with slopes d0, d1 at the ends: the maximum of the lower envelope of the
    two parabolas P0(x) = g0 + d0 x + Mx²/2 and P1(x) = g1 − d1(h − x) + M(h − x)²/2.
    P0 − P1 is linear and non-decreasing in x, so the envelope is P0 then P1, each
    convex: its maximum is at an end or where they meet."""
    slope = d0 - d1 + M * h
    offset = g0 - g1 + d1 * h - 0.5 * M * h * h
    with np.errstate(divide="ignore", invalid="ignore"):
        x = -offset / slope
    x = np.where(np.isfinite(x), np.clip(x, 0.0, h), 0.5 * h)
    meet = np.minimum(g0 + d0 * x + 0.5 * M * x * x, g1 - d1 * (h - x) + 0.5 * M * (h - x) ** 2)
    at0 = np.minimum(g0, g1 - d1 * h + 0.5 * M * h * h)
    at1 = np.minimum(g0 + d0 * h + 0.5 * M * h * h, g1)
    return np.maximum(np.maximum(at0, at1), meet)


def _bounds(g0, d0, g1, d1, h, M):
    """Lower and upper bounds of the function on each cell (see :func:`_upper`)."""
    return -_upper(-g0, -d0, -g1, -d1, h, M), _upper(g0, d0, g1, d1, h, M)


def _cubic(g0, d0, g1, d1, h):
    """The power coefficients in s = x/h ∈ [0, 1] of the cubic with the ends' values
    and slopes (cubic Hermite interpolation)."""
    a1 = h * d0
    a2 = 3.0 * (g1 - g0) - h * (2.0 * d0 + d1)
    a3 = 2.0 * (g0 - g1) + h * (d0 + d1)
    return g0, a1, a2, a3


def _cubic_at(c, s):
    return c[0] + s * (c[1] + s * (c[2] + s * c[3]))


def _cubic_peak(c, highest: NDArray[np.bool_]):
    """Where in (0, 1) the cubic is greatest (``highest``) or least, else 0.5."""
    a1, a2, a3 = c[1], c[2], c[3]
    with np.errstate(divide="ignore", invalid="ignore"):
        disc = np.sqrt(np.maximum(a2 * a2 - 3.0 * a1 * a3, 0.0))
        r1 = np.where(np.abs(a3) > 1e-300, (-a2 - disc) / (3.0 * a3), -a1 / (2.0 * a2))
        r2 = np.where(np.abs(a3) > 1e-300, (-a2 + disc) / (3.0 * a3), -a1 / (2.0 * a2))
    best = np.full(a1.shape, 0.5)
    score = np.full(a1.shape, -np.inf)
    sign = np.where(highest, 1.0, -1.0)
    for r in (r1, r2):
        ok = np.isfinite(r) & (r > 0.0) & (r < 1.0)
        value = np.where(ok, sign * _cubic_at(c, np.where(ok, r, 0.5)), -np.inf)
        better = value > score
        best = np.where(better, r, best)
        score = np.where(better, value, score)
    return best


def _cubic_root(c, g0, g1):
    """The cubic's root in [0, 1] where the ends differ in sign: Newton from the chord's."""
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(g0 != g1, g0 / (g0 - g1), 0.5)
        s = np.clip(np.where(np.isfinite(s), s, 0.5), 0.0, 1.0)
        for _ in range(4):
            slope = c[1] + s * (2.0 * c[2] + 3.0 * s * c[3])
            step = _cubic_at(c, s) / slope
            s = np.clip(np.where(np.isfinite(step), s - step, s), 0.0, 1.0)
    return s


def _envelope(plan: FreePlan, name: str, target: str, σ_a, σ_b, t_a, t_b):
    """Bounds (low, high) on the angle between body vector ``name``'s direction and
    ``target`` over each window [t_a, t_b], from the spherical triangle of the two and
    the momentum's direction Ĥ: |σ − β| ≤ angle ≤ min(σ + β, 2π − σ − β), with σ the
    target's angle to Ĥ (σ_a, σ_b at the ends, drifting at most at the target's rate)
    and β the vector's angle to the momentum, over the window from its periodic table
    (:class:`VectorMotion`).  (0, π) where there is no momentum."""
    tilt = plan.motion[name].tilt if name in plan.motion else None
    if tilt is None:
        return np.zeros(np.shape(t_a)), np.full(np.shape(t_a), math.pi)
    low, high = tilt.over(t_a, t_b)
    β_low = np.arccos(np.clip(high, -1.0, 1.0))
    β_high = np.arccos(np.clip(low, -1.0, 1.0))
    drift = plan.sky.get(f"{target}_1", math.inf) * 0.5 * (t_b - t_a)
    σ_low = np.minimum(σ_a, σ_b) - drift
    σ_high = np.maximum(σ_a, σ_b) + drift
    lower = np.maximum(np.maximum(σ_low - β_high, β_low - σ_high), 0.0)
    upper = np.minimum(np.minimum(σ_high + β_high, 2.0 * math.pi - σ_low - β_low), math.pi)
    lower = np.where(np.isfinite(lower), lower - _ENVELOPE_MARGIN, 0.0)
    upper = np.where(np.isfinite(upper), upper + _ENVELOPE_MARGIN, math.pi)
    return lower, upper


# ---------------------------------------------------------------------- the tracks


@dataclass(frozen=True)
class _Condition:
    """A condition of a vector: ``f[target] − c > 0`` (kind "cos"), or, for the limb,
    nadir angle < θ + ρ(t), i.e. f[nadir] − cos(θ + ρ) > 0 (kind "limb", c = θ)."""

    name: str
    vector: int
    target: str
    kind: str
    c: float


def conditions_of(spec: PointingSpec) -> list[_Condition]:
    """The conditions :mod:`attitude.pointing.search` names, per body vector."""
    out = []
    for j, v in enumerate(spec.body_vectors):
        out.append(_Condition(f"{v.name}.sun_visible", j, "sun", "cos", 0.0))
        for key, target, angle in (
            ("sun_exclusion", "sun", v.sun_exclusion_half_angle_rad),
            ("moon_exclusion", "moon", v.moon_exclusion_half_angle_rad),
            ("sun_in_view", "sun", v.sun_inclusion_half_angle_rad),
        ):
            if angle is not None:
                out.append(_Condition(f"{v.name}.{key}", j, target, "cos", math.cos(angle)))
        if v.earth_limb_exclusion_angle_rad is not None and spec.orbit is not None:
            out.append(
                _Condition(
                    f"{v.name}.earth_limb_exclusion", j, "nadir", "limb",
                    v.earth_limb_exclusion_angle_rad,
                )
            )
    return out


def _condition_values(values: _Values, conditions: list[_Condition]):
    """Each condition's function g, its rate, its target's angle σ to the momentum's
    direction (NaN at rest) and g'' (NaN for the limb's) at the values' times: (K, n)
    each."""
    g, dg, σ, ddg = [], [], [], []
    for c in conditions:
        f = values.f[c.target][c.vector]
        df = values.df[c.target][c.vector]
        σ.append(values.sigma.get(c.target, np.full(f.shape, np.nan)))
        cosine = c.kind == "cos" and c.target in values.ddf
        ddg.append(values.ddf[c.target][c.vector] if cosine else np.full(f.shape, np.nan))
        if c.kind == "cos":
            g.append(f - c.c)
            dg.append(df)
        else:
            assert values.limb is not None and values.limb_rate is not None
            edge = c.c + values.limb
            clipped = np.clip(edge, 0.0, math.pi)
            g.append(f - np.cos(clipped))
            dg.append(df + np.where(clipped == edge, np.sin(clipped), 0.0) * values.limb_rate)
    shape = (len(conditions), -1)
    return tuple(np.array(x).reshape(shape) for x in (g, dg, σ, ddg))


@dataclass
class FreeResult:
    """What :func:`search_free` found over its span: each condition's intervals (by the
    names of :mod:`attitude.pointing.search`), the extrema (the best of ``incumbents``
    and of the span, by problem name), the integral of the incidence of each vector,
    whether each vector saw no Sun at some time (``dark``), and the evaluations made."""

    intervals: dict[str, list[Interval]]
    extrema: dict[str, Extremum]
    incidence_integral: dict[str, float]
    dark: dict[str, bool]
    evaluations: int = 0


@dataclass
class _Cells:
    """Cells of the conditions (flat): condition index, ends, values and rates there,
    the target's angle to the momentum's direction and g'' there."""

    k: NDArray[np.intp]
    a: NDArray[np.float64]
    b: NDArray[np.float64]
    ga: NDArray[np.float64]
    gb: NDArray[np.float64]
    da: NDArray[np.float64]
    db: NDArray[np.float64]
    sa: NDArray[np.float64]
    sb: NDArray[np.float64]
    ea: NDArray[np.float64]
    eb: NDArray[np.float64]

    def take(self, which) -> _Cells:
        return _Cells(*(getattr(self, n)[which] for n in _CELL_FIELDS))

    @staticmethod
    def join(parts: list[_Cells]) -> _Cells:
        return _Cells(*(np.concatenate([getattr(p, n) for p in parts]) for n in _CELL_FIELDS))


_CELL_FIELDS = ("k", "a", "b", "ga", "gb", "da", "db", "sa", "sb", "ea", "eb")


def _settle(cells: _Cells, M: NDArray[np.float64], envelope):
    """Each cell's status: 0 settled without a crossing, 1 one crossing, 2 not proved.
    ``envelope(cells)``: bounds on each cell's angle to its threshold's target and that
    threshold as an angle (NaN where the envelope does not apply)."""
    h = cells.b - cells.a
    bend = M[cells.k]
    low, high = _bounds(cells.ga, cells.da, cells.gb, cells.db, h, bend)
    in_a, in_b = cells.ga > 0.0, cells.gb > 0.0
    settled = (~in_a & ~in_b & (high <= 0.0)) | (in_a & in_b & (low > 0.0))
    # The envelope, for the cells the bend bound leaves without a sign change.
    ask = np.flatnonzero(~settled & (in_a == in_b))
    if ask.size:
        angle_low, angle_high, threshold = envelope(cells.take(ask))
        with np.errstate(invalid="ignore"):
            settled[ask] |= ~in_a[ask] & (angle_low > threshold)
            settled[ask] |= in_a[ask] & (angle_high < threshold)
    slope_low = 0.5 * (cells.da + cells.db - bend * h)
    slope_high = 0.5 * (cells.da + cells.db + bend * h)
    crossing = (in_a != in_b) & ((slope_low > 0.0) | (slope_high < 0.0))
    tiny = h <= 4.0 * np.spacing(np.maximum(np.abs(cells.a), np.abs(cells.b)))
    status = np.full(h.size, 2, dtype=np.int8)
    status[settled | (tiny & (in_a == in_b))] = 0
    status[crossing | (tiny & (in_a != in_b))] = 1
    return status


def _cut(cells: _Cells) -> NDArray[np.float64]:
    """Where to cut unsettled cells: at the cubic's root when the ends differ in sign,
    else at its extremum towards the threshold (its peak for ends below it)."""
    h = cells.b - cells.a
    c = _cubic(cells.ga, cells.da, cells.gb, cells.db, h)
    change = (cells.ga > 0.0) != (cells.gb > 0.0)
    s = np.where(change, _cubic_root(c, cells.ga, cells.gb), _cubic_peak(c, cells.ga <= 0.0))
    return cells.a + np.clip(s, _CUT, 1.0 - _CUT) * h


def _partition(
    evaluate, conditions: list[_Condition], τ: NDArray[np.float64], values, M, envelope
) -> tuple[_Cells, NDArray[np.int8], int]:
    """Every condition's cells over the nodes τ (``values``: g, g', σ, g'' there), cut
    until each is settled (module notes): the final cells, their status (0 or 1) and
    the evaluations made."""
    K, n = values[0].shape
    k = np.repeat(np.arange(K), n - 1)
    ends = [x for v in values for x in (v[:, :-1].ravel(), v[:, 1:].ravel())]
    cells = _Cells(k, np.tile(τ[:-1], K), np.tile(τ[1:], K), *ends)
    done: list[_Cells] = []
    statuses: list[NDArray[np.int8]] = []
    evaluations = 0
    while cells.k.size:
        status = _settle(cells, M, envelope)
        final = status < 2
        done.append(cells.take(final))
        statuses.append(status[final])
        cells = cells.take(~final)
        if not cells.k.size:
            break
        cut = _cut(cells)
        times, inverse = np.unique(cut, return_inverse=True)
        at_cut = _condition_values(evaluate(times), conditions)
        evaluations += times.size
        g, dg, σ, ddg = (x[cells.k, inverse] for x in at_cut)
        left = _Cells(
            cells.k, cells.a, cut, cells.ga, g, cells.da, dg, cells.sa, σ, cells.ea, ddg
        )
        right = _Cells(
            cells.k, cut, cells.b, g, cells.gb, dg, cells.db, σ, cells.sb, ddg, cells.eb
        )
        cells = _Cells.join([left, right])
    final_cells = _Cells.join(done) if done else cells
    return final_cells, np.concatenate(statuses) if statuses else np.empty(0, np.int8), evaluations


def _quintic(y0, p0, q0, y1, p1, q1):
    """Power coefficients in s ∈ [0, 1] of the quintic with the ends' values y, first
    derivatives p and second derivatives q (in s: h f', h² f'')."""
    dy = y1 - y0
    return (
        y0,
        p0,
        0.5 * q0,
        10.0 * dy - 6.0 * p0 - 4.0 * p1 - 1.5 * q0 + 0.5 * q1,
        -15.0 * dy + 8.0 * p0 + 7.0 * p1 + 1.5 * q0 - q1,
        6.0 * dy - 3.0 * p0 - 3.0 * p1 - 0.5 * q0 + 0.5 * q1,
    )


def _polynomial_at(c, s):
    value = c[-1]
    for coefficient in reversed(c[:-1]):
        value = value * s + coefficient
    return value


# ------------------------------------------------------------------ the search


_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(4)
_QUANTITIES = ("sun_angle", "moon_angle", "cos_incidence", "nadir_angle", "earth_limb_angle")
# The quantities whose extrema are those of one cosine (the incidence's, outside the
# shadow), refined by Newton's method: at most this many steps, done below this (s).
_TARGET_OF = {"sun_angle": "sun", "moon_angle": "moon", "nadir_angle": "nadir", "cos_incidence": "sun"}
_NEWTON_STEPS = 6
_NEWTON_DONE_S = 1e-9


def search_free(
    plan: FreePlan,
    solver: EulerSolver,
    spec: PointingSpec,
    shared: SharedSurroundings,
    precision_s: float,
    extremum_precision_s: float,
    tolerance: float,
    problems: dict[str, Problem],
    incumbents: dict[str, Extremum | None],
    shadow: list[Interval],
    umbra: list[Interval],
    start_s: float,
    end_s: float,
) -> FreeResult:
    """Search the free segment of ``plan`` over [start_s, end_s] (within it): every
    condition's intervals, the extrema of ``problems`` (names ``"<vector>.<quantity>
    .low"``/``".high"``: the quantity, or its negative, to minimize; each problem's
    ``lipschitz`` prunes brackets; ``incumbents`` the best known), and each vector's
    integral of the incidence.  ``shadow`` and ``umbra``: the eclipses over the span
    (the lit fraction is 1 outside the shadow, 0 in umbra)."""
    evaluate = _Evaluator(solver, spec, shared)
    conditions = conditions_of(spec)
    names = [v.name for v in spec.body_vectors]
    M = np.array(
        [
            plan.bend[(names[c.vector], c.target)] + (plan.limb_bend if c.kind == "limb" else 0.0)
            for c in conditions
        ]
    )
    intervals: dict[str, list[Interval]] = {c.name: [] for c in conditions}
    best: dict[str, Extremum] = {}
    integral = dict.fromkeys(names, 0.0)
    dark = dict.fromkeys(names, False)
    shadow_ends = np.array([x for i in shadow for x in (i.start_s, i.end_s)], dtype=np.float64)
    umbra_ends = np.array([x for i in umbra for x in (i.start_s, i.end_s)], dtype=np.float64)
    step = plan.step_s
    count = max(math.ceil((end_s - start_s) / step), 1) + 1
    first = 0
    while first < count - 1:
        last = min(first + WINDOW_NODES, count - 1)
        w0 = start_s + (end_s - start_s) * first / (count - 1)
        w1 = end_s if last == count - 1 else start_s + (end_s - start_s) * last / (count - 1)
        τ = np.linspace(w0, w1, last - first + 1)
        inside = np.concatenate([shadow_ends, umbra_ends])
        inside = inside[(inside > w0) & (inside < w1)]
        if inside.size:
            τ = np.unique(np.concatenate([τ, inside]))
        window = _Window(evaluate, spec, shared, plan, conditions, M, τ, shadow, umbra)
        window.intervals(precision_s, intervals)
        window.extrema(problems, incumbents, best, tolerance, extremum_precision_s)
        for name, value in window.incidence().items():
            integral[name] += value
        for name, value in window.dark().items():
            dark[name] = dark[name] or value
        first = last
    return FreeResult(intervals, best, integral, dark, evaluate.points)


def _in_any(τ: NDArray[np.float64], intervals: list[Interval]) -> NDArray[np.bool_]:
    """Whether each time lies within one of the (sorted, disjoint) intervals."""
    if not intervals:
        return np.zeros(τ.shape, dtype=bool)
    starts = np.array([i.start_s for i in intervals])
    ends = np.array([i.end_s for i in intervals])
    k = np.searchsorted(starts, τ, side="right") - 1
    return (k >= 0) & (τ <= ends[np.maximum(k, 0)])


class _Window:
    """One window of nodes of a free segment, searched."""

    def __init__(self, evaluate, spec, shared, plan, conditions, M, τ, shadow, umbra) -> None:
        self.evaluate, self.spec, self.shared, self.plan = evaluate, spec, shared, plan
        self.conditions, self.M, self.τ = conditions, M, τ
        self.shadow, self.umbra = shadow, umbra
        self.limb_rate = shared.rate_bounds().get("limb_1", 0.0)
        self.values = evaluate(τ, angles=True)
        at_nodes = _condition_values(self.values, conditions)
        self.g = at_nodes[0]
        self.cells, self.status, _ = _partition(
            evaluate, conditions, τ, at_nodes, M, self._condition_envelope
        )
        # The refined time of each cell's crossing (NaN for a cell without one).
        self.cross = np.full(self.status.size, np.nan)
        self.found: dict[str, list[Interval]] = {}

    def _condition_envelope(self, cells: _Cells):
        """For :func:`_settle`: each cell's angle bounds to its condition's target and
        the condition's threshold angle (NaN for the limb's, which moves)."""
        low = np.zeros(cells.k.size)
        high = np.full(cells.k.size, math.pi)
        threshold = np.full(cells.k.size, np.nan)
        for index in np.unique(cells.k).tolist():
            condition = self.conditions[index]
            if condition.kind != "cos":
                continue
            mine = cells.k == index
            name = self.spec.body_vectors[condition.vector].name
            low[mine], high[mine] = _envelope(
                self.plan, name, condition.target,
                cells.sa[mine], cells.sb[mine], cells.a[mine], cells.b[mine],
            )
            threshold[mine] = math.acos(min(max(condition.c, -1.0), 1.0))
        return low, high, threshold

    # ---------------------------------------------------------------- intervals

    def intervals(self, precision_s: float, out: dict[str, list[Interval]]) -> None:
        """Refine the crossings and append each condition's intervals to ``out``."""
        from attitude.pointing.intervals import join

        crossing = self.status == 1
        cells = self.cells.take(crossing)
        times = self._crossings(cells, precision_s)
        inside_at_a = cells.ga > 0.0
        self.cross[crossing] = times
        w = np.array([self.τ[0], self.τ[-1]])
        for index, condition in enumerate(self.conditions):
            mine = np.flatnonzero(cells.k == index)
            order = mine[np.argsort(times[mine], kind="stable")]
            pieces = _assemble(
                w, np.array([self.g[index, 0] > 0.0]), times[order], ~inside_at_a[order]
            )
            self.found[condition.name] = pieces
            join(out[condition.name], pieces, float(self.τ[0]))

    def _crossings(self, cells: _Cells, precision_s: float) -> NDArray[np.float64]:
        """The crossing in each cell (one, where g' keeps its sign), to ``precision_s``.

        g at the root of the cubic through the ends, x, with its slope d there: on
        [x − δ, x + δ], δ = 2|g(x)|/|d|, g' stays within M δ of d, so if M δ < |d|/2 the
        crossing lies there, and within M δ²/|d| of the Newton step x − g(x)/d (Taylor's
        remainder over a slope at least |d|/2): reported when that is below
        ``precision_s``/2, one evaluation a crossing.  The others are refined by the
        probes and bisection of :func:`~attitude.pointing.intervals._refine`."""
        conditions = self.conditions
        h = cells.b - cells.a
        c = _cubic(cells.ga, cells.da, cells.gb, cells.db, h)
        x = cells.a + _cubic_root(c, cells.ga, cells.gb) * h
        if not x.size:
            return x
        g, dg, _, _ = _condition_values(self.evaluate(x), conditions)
        column = np.arange(x.size)
        g_x, d_x = g[cells.k, column], dg[cells.k, column]
        bend = self.M[cells.k]
        with np.errstate(divide="ignore", invalid="ignore"):
            δ = 2.0 * np.abs(g_x) / np.abs(d_x)
            newton = x - g_x / d_x
            error = bend * δ * δ / np.abs(d_x)
        good = (bend * δ < 0.5 * np.abs(d_x)) & (error < 0.5 * precision_s)
        good &= (newton >= cells.a) & (newton <= cells.b) & np.isfinite(newton)
        times = np.where(good, newton, np.nan)
        rest = np.flatnonzero(~good)
        if rest.size:
            sub = cells.take(rest)

            def f(τ: NDArray[np.float64], which: NDArray[np.intp]) -> NDArray[np.float64]:
                values = _condition_values(self.evaluate(τ), conditions)[0]
                return values[sub.k[which], np.arange(τ.size)]

            # The bracket keeps its side of x: the cell's ends, x itself.
            inside = sub.ga > 0.0
            beyond = (g_x[rest] > 0.0) != inside
            a = np.where(beyond, sub.a, x[rest])
            b = np.where(beyond, x[rest], sub.b)
            estimate = np.clip(np.where(np.isfinite(newton[rest]), newton[rest], x[rest]), a, b)
            times[rest] = _refine(f, a, b, inside, precision_s, estimate=estimate)
        return times

    # ------------------------------------------------------------------ extrema

    def _quantities(self, values: _Values, τ: NDArray[np.float64]) -> dict[str, NDArray]:
        """Each problem's function (to minimize) at τ."""
        out = {}
        fraction = self._fraction(τ)
        for j, v in enumerate(self.spec.body_vectors):
            for quantity, q in self._vector_quantities(values, j, fraction).items():
                out[f"{v.name}.{quantity}.low"] = q
                out[f"{v.name}.{quantity}.high"] = -q
        return out

    def _vector_quantities(self, values: _Values, j: int, fraction) -> dict[str, NDArray]:
        q = {
            "sun_angle": values.angle["sun"][j],
            "moon_angle": values.angle["moon"][j],
            "cos_incidence": np.maximum(values.f["sun"][j], 0.0) * fraction,
        }
        if "nadir" in values.angle:
            assert values.limb is not None
            q["nadir_angle"] = values.angle["nadir"][j]
            q["earth_limb_angle"] = values.angle["nadir"][j] - values.limb
        return q

    def _fraction(self, τ: NDArray[np.float64]) -> NDArray[np.float64]:
        """The lit fraction: 1 outside the shadow, 0 in umbra, the surroundings' else."""
        fraction = np.ones(τ.shape)
        partial = _in_any(τ, self.shadow) & ~_in_any(τ, self.umbra)
        fraction[_in_any(τ, self.umbra)] = 0.0
        if np.any(partial):
            fraction[partial] = self.shared.at(τ[partial]).sunlit_fraction
        return fraction

    def _cell_bounds(self, j: int, quantity: str, interesting=None) -> tuple[NDArray, NDArray]:
        """Bounds on a vector's quantity in each cell between nodes; the envelope tightens
        them where ``interesting(low, high)`` (of the bend bound's) says it matters."""
        τ, values = self.τ, self.values
        h = np.diff(τ)
        target = {"sun_angle": "sun", "moon_angle": "moon", "cos_incidence": "sun"}.get(
            quantity, "nadir"
        )
        name = self.spec.body_vectors[j].name
        f, df = values.f[target][j], values.df[target][j]
        bend = self.plan.bend[(name, target)]
        low, high = _bounds(f[:-1], df[:-1], f[1:], df[1:], h, bend)
        if quantity == "cos_incidence":
            σ = values.sigma.get(target)
            if σ is not None and interesting is not None:
                ask = np.flatnonzero(interesting(np.maximum(low, 0.0), np.maximum(high, 0.0)))
                env_low, env_high = _envelope(
                    self.plan, name, target, σ[:-1][ask], σ[1:][ask], τ[:-1][ask], τ[1:][ask]
                )
                low[ask] = np.maximum(low[ask], np.cos(env_high))
                high[ask] = np.minimum(high[ask], np.cos(env_low))
            fraction_low = np.where(self._cell_in(self.shadow), 0.0, 1.0)
            return np.maximum(low, 0.0) * fraction_low, np.maximum(high, 0.0)
        angle_low = np.arccos(np.clip(high, -1.0, 1.0))
        angle_high = np.arccos(np.clip(low, -1.0, 1.0))
        σ = values.sigma.get(target)
        if σ is not None and interesting is not None:
            # The envelope, for the cells the bend bound leaves in question.
            ask = np.flatnonzero(interesting(angle_low, angle_high))
            env_low, env_high = _envelope(
                self.plan, name, target, σ[:-1][ask], σ[1:][ask], τ[:-1][ask], τ[1:][ask]
            )
            angle_low[ask] = np.maximum(angle_low[ask], env_low)
            angle_high[ask] = np.minimum(angle_high[ask], env_high)
        if quantity == "earth_limb_angle":
            assert values.limb is not None
            drift = self.limb_rate * 0.5 * h
            limb_low = np.minimum(values.limb[:-1], values.limb[1:]) - drift
            limb_high = np.maximum(values.limb[:-1], values.limb[1:]) + drift
            return angle_low - limb_high, angle_high - limb_low
        return angle_low, angle_high

    def _cell_in(self, intervals: list[Interval]) -> NDArray[np.bool_]:
        """Whether each cell meets one of the intervals."""
        τ = self.τ
        if not intervals:
            return np.zeros(τ.size - 1, dtype=bool)
        starts = np.array([i.start_s for i in intervals])
        ends = np.array([i.end_s for i in intervals])
        k = np.searchsorted(starts, τ[1:], side="left") - 1  # last interval starting before b
        return (k >= 0) & (ends[np.maximum(k, 0)] > τ[:-1])

    def extrema(self, problems, incumbents, best, tolerance, precision_s) -> None:
        """The extrema of ``problems`` over the window, folded into ``best``."""
        τ = self.τ
        on_nodes = self._quantities(self.values, τ)
        self._node_problems = on_nodes
        for name, problem in problems.items():
            values = on_nodes[name]
            i = int(np.argmin(values))
            found = Extremum(float(τ[i]), float(values[i]))
            known = best.get(name) or incumbents.get(name)
            best[name] = found if known is None or found.value < known.value else known
        brackets = {}
        for j, v in enumerate(self.spec.body_vectors):
            for quantity in _QUANTITIES[: 3 if self.values.limb is None else 5]:
                keys = (f"{v.name}.{quantity}.low", f"{v.name}.{quantity}.high")
                if not any(key in problems for key in keys):
                    continue
                low_best = best[keys[0]].value if keys[0] in best else -np.inf
                high_best = -best[keys[1]].value if keys[1] in best else np.inf

                def interesting(lo, hi, lb=low_best, hb=high_best):
                    return (lo < lb - tolerance) | (hi > hb + tolerance)

                low, high = self._cell_bounds(j, quantity, interesting)
                for end, bound in (("low", low), ("high", -high)):
                    name = f"{v.name}.{quantity}.{end}"
                    if name not in problems:
                        continue
                    candidate = np.flatnonzero(bound < best[name].value - tolerance)
                    values = on_nodes[name]
                    brackets[name] = (
                        τ[candidate],
                        τ[candidate + 1],
                        values[candidate],
                        values[candidate + 1],
                    )

        def evaluate(t: NDArray[np.float64]) -> dict[str, NDArray[np.float64]]:
            return self._quantities(self.evaluate(t, angles=True), t)

        brackets = self._newton(brackets, problems, best, precision_s)
        found = least_in_brackets(evaluate, brackets, problems, best, tolerance, precision_s)
        best.update(found)

    def _newton(self, brackets, problems, best, precision_s: float):
        """Narrow the brackets of the smooth problems by Newton's method on the cosine's
        slope: the angles to the Sun, the Moon and nadir (the least angle where the
        cosine is greatest, the greatest where it is least) and the incidence outside
        the Earth's shadow (the cosine itself).  From the extremum of the cubic through
        the cell's ends, each step moves to x − f'(x)/f''(x) (f' and f'' exact), kept
        within the cell; every point evaluated counts for every problem.  A cell whose
        step shrinks below a nanosecond, or that reaches an end the slope leaves by, is
        done; one where f'' has the wrong sign, or still moving after the steps, goes
        on by golden-section search.  Returns the brackets left for it."""
        τ, values = self.τ, self.values
        rows = []  # (name, vector, target, sign: +1 where f is greatest), cell indices
        left = {}
        shadow = self._cell_in(self.shadow)
        for name, (a, _, _, _) in brackets.items():
            vector, quantity, end = name.rsplit(".", 2)
            target = _TARGET_OF.get(quantity)
            if target is None or target not in values.f or not a.size:
                left[name] = brackets[name]
                continue
            j = next(k for k, v in enumerate(self.spec.body_vectors) if v.name == vector)
            sign = 1.0 if (end == "low") != (quantity == "cos_incidence") else -1.0
            cells = np.searchsorted(τ, a)
            smooth = ~shadow[cells] if quantity == "cos_incidence" else np.ones(a.size, bool)
            rows.append((name, j, target, sign, cells[smooth]))
            rest = ~smooth
            left[name] = tuple(x[rest] for x in brackets[name])
        if not rows:
            return brackets
        name_of = np.concatenate([np.full(r[4].size, k) for k, r in enumerate(rows)])
        cells = np.concatenate([r[4] for r in rows])
        sign = np.concatenate([np.full(r[4].size, r[3]) for r in rows])
        a, b = τ[cells], τ[cells + 1]
        h = b - a
        f_of = [values.f[r[2]][r[1]] for r in rows]
        df_of = [values.df[r[2]][r[1]] for r in rows]
        ga = np.concatenate([f[r[4]] for f, r in zip(f_of, rows)])
        gb = np.concatenate([f[r[4] + 1] for f, r in zip(f_of, rows)])
        da = np.concatenate([d[r[4]] for d, r in zip(df_of, rows)])
        db = np.concatenate([d[r[4] + 1] for d, r in zip(df_of, rows)])
        c = _cubic(sign * ga, sign * da, sign * gb, sign * db, h)
        x = a + _cubic_peak(c, np.ones(a.size, dtype=bool)) * h
        active = np.ones(a.size, dtype=bool)
        for _ in range(_NEWTON_STEPS):
            which = np.flatnonzero(active)
            if not which.size:
                break
            times, inverse = np.unique(x[which], return_inverse=True)
            at = self.evaluate(times, angles=True)
            self._fold(self._quantities(at, times), times, problems, best)
            d1 = np.empty(which.size)
            d2 = np.empty(which.size)
            for k, r in enumerate(rows):
                mine = name_of[which] == k
                d1[mine] = at.df[r[2]][r[1]][inverse[mine]]
                d2[mine] = at.ddf[r[2]][r[1]][inverse[mine]]
            d1, d2 = sign[which] * d1, sign[which] * d2
            with np.errstate(divide="ignore", invalid="ignore"):
                step = -d1 / d2
            concave = d2 < 0.0
            new = np.clip(x[which] + step, a[which], b[which])
            done = concave & (np.abs(new - x[which]) <= _NEWTON_DONE_S)
            # At an end, a slope that leaves the cell: the end is the cell's best.
            done |= ((new == a[which]) & (d1 < 0.0)) | ((new == b[which]) & (d1 > 0.0))
            x[which] = np.where(concave, new, x[which])
            active[which[done]] = False
            active[which[~concave]] = False
            failed = which[~concave & ~done]
            for k in np.unique(name_of[failed]).tolist():
                mine = failed[name_of[failed] == k]
                name = rows[k][0]
                t0, t1 = a[mine], b[mine]
                more = (t0, t1, *self._at_nodes(name, cells[mine]))
                left[name] = tuple(np.concatenate([u, v]) for u, v in zip(left[name], more))
        # Still moving after the steps: golden-section search, from their cells.
        for k in np.unique(name_of[active]).tolist():
            mine = np.flatnonzero(active & (name_of == k))
            name = rows[k][0]
            more = (a[mine], b[mine], *self._at_nodes(name, cells[mine]))
            left[name] = tuple(np.concatenate([u, v]) for u, v in zip(left[name], more))
        return left

    def _at_nodes(self, name: str, cells: NDArray[np.intp]):
        """A problem's values at the ends of cells between nodes."""
        values = self._node_problems[name]
        return values[cells], values[cells + 1]

    def _fold(self, quantities, times, problems, best) -> None:
        """Fold the values of the problems at ``times`` into ``best``."""
        for name in problems:
            values = quantities[name]
            i = int(np.argmin(values))
            if values[i] < best[name].value:
                best[name] = Extremum(float(times[i]), float(values[i]))

    # ---------------------------------------------------------------- incidence

    def incidence(self) -> dict[str, float]:
        """Each vector's integral of max(f_sun, 0) × lit fraction over the window."""
        out = {}
        for index, condition in enumerate(self.conditions):
            if not condition.name.endswith(".sun_visible"):
                continue
            name = self.spec.body_vectors[condition.vector].name
            mine = self.cells.k == index
            cells = self.cells.take(mine)
            status = self.status[mine]
            a, b = cells.a.copy(), cells.b.copy()
            lit_a = cells.ga > 0.0
            keep = ((status == 0) & lit_a) | (status == 1)
            rows = np.flatnonzero(status == 1)
            cut = self.cross[mine][rows]
            entering = ~lit_a[rows]
            a[rows] = np.where(entering, cut, a[rows])
            b[rows] = np.where(entering, b[rows], cut)
            rows = np.flatnonzero(keep)
            h = cells.b[rows] - cells.a[rows]
            # The quintic through the ends' values, slopes and bends (the cubic where a
            # bend is missing): exact for it, 4 Gauss–Legendre points on the lit part.
            ea, eb = cells.ea[rows], cells.eb[rows]
            bent = np.isfinite(ea) & np.isfinite(eb)
            q0 = np.where(bent, ea, 0.0) * h * h
            q1 = np.where(bent, eb, 0.0) * h * h
            c = _quintic(cells.ga[rows], h * cells.da[rows], q0, cells.gb[rows], h * cells.db[rows], q1)
            c3 = _cubic(cells.ga[rows], cells.da[rows], cells.gb[rows], cells.db[rows], h)
            lo, hi = a[rows], b[rows]
            x = 0.5 * (hi + lo)[:, None] + 0.5 * (hi - lo)[:, None] * _GAUSS_X[None, :]
            s = (x - cells.a[rows][:, None]) / h[:, None]
            five = _polynomial_at(tuple(ci[:, None] for ci in c), s)
            three = _cubic_at(tuple(ci[:, None] for ci in c3), s)
            f = np.maximum(np.where(bent[:, None], five, three), 0.0)
            meets = _in_any(0.5 * (lo + hi), self.shadow) | _in_any(lo, self.shadow) | _in_any(hi, self.shadow)
            weight = np.ones_like(f)
            if np.any(meets):
                weight[meets] = self._fraction(x[meets].ravel()).reshape(-1, _GAUSS_X.size)
            out[name] = float(np.sum((f * weight) @ _GAUSS_W * 0.5 * (hi - lo)))
        return out

    def dark(self) -> dict[str, bool]:
        """Whether each vector saw no Sun at some time of the window."""
        out = {}
        span = (self.τ[0], self.τ[-1])
        in_umbra = any(i.end_s > span[0] and i.start_s < span[1] for i in self.umbra)
        for condition in self.conditions:
            if condition.name.endswith(".sun_visible"):
                name = self.spec.body_vectors[condition.vector].name
                pieces = self.found[condition.name]
                lit = len(pieces) == 1 and pieces[0].starts_before and pieces[0].ends_after
                out[name] = in_umbra or not lit
        return out
