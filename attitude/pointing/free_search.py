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

**Many searches at once** (:func:`search_free_many`: the loss-of-control envelope's
windows after each failure, each a run of pieces within one window of nodes): their nodes are put
end to end in one window, where no cell joins two pieces, so that each call of the
evaluator (the exact attitude of each piece, the surroundings, the cosines) serves all
of them.  Everything else is element by element (each cell's bounds, cuts, crossings
and Newton steps from its own values) or the search's own (its best extrema, the
cells of its own that decide whether the envelope tightens their bounds, its
intervals, its sums in the order it has alone, golden-section search on its own
cells), so each search's result is the one :func:`search_free` gives it alone, bit
for bit; a search costs a few evaluation calls whatever the number searched with it.

**The envelope.**  |f − B| ≤ A: a vector whose Sun cosine cannot change sign (|B| > A
throughout: a panel on the spin axis), or a cone the Sun cannot reach, is settled for
the whole segment without a node; see :func:`_settled_by_envelope`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from attitude.base.quaternions import rotation_rows
from attitude.pointing.extrema import Extremum, Problem, least_in_brackets
from attitude.pointing.intervals import Interval, _assemble, _refine, append_across, join
from attitude.pointing.shared_surroundings import SharedSurroundings
from attitude.pointing.spec import PointingSpec
from attitude.solver.euler_solver import EulerSolver

__all__ = [
    "FreePlan",
    "FreeResult",
    "VectorMotion",
    "fits_one_window",
    "free_plan",
    "free_plans",
    "search_free",
    "search_free_many",
    "vector_motion",
    "vector_motions",
]

# Nodes: the curvature bound's overshoot between nodes, M h²/8, at most this (a
# cosine), and at most this step (s).
_OVERSHOOT = 0.1
_LONGEST_STEP_S = 3600.0
# A window holds at most this many nodes (bounded memory).
WINDOW_NODES = 16_384
# vector_motion samples ω this many times a turn of the body over a period (or over
# the segment), and at least and at most these many times in all.
_SAMPLES_PER_TURN = 512
_MOTION_SAMPLES_LEAST = 256
_MOTION_SAMPLES = 16_384
# A cell is cut at the cubic's extremum or root, kept within this fraction of its ends.
_CUT = 0.1
TARGETS = ("sun", "moon", "nadir")
# The envelope's bounds are widened by this (rad): the rounding of the arc cosines
# it compares (~1e-12 rad near 0 and π) and of the directions it takes.
_ENVELOPE_MARGIN = 1e-9
# The envelope tightens an extremum's candidate cells when there are more than this.
_ENVELOPE_LEAST = 64


class _PeriodicRange:
    """The least and greatest of a sampled function over any time window: values at
    ``start_s + k·spacing`` (k < n), periodic with period n·spacing when ``periodic``,
    each within ``slack`` of the function between its neighbouring samples.  Range
    queries on a sparse table (each level the min and max of 2^level samples), so that a
    window costs two lookups whatever its length."""

    def __init__(self, values, start_s: float, spacing: float, periodic: bool, slack: float):
        self.start_s, self.spacing, self.periodic, self.slack = start_s, spacing, periodic, slack
        self.n = n = values.size
        levels = max(int(n).bit_length(), 1)
        # Row k: the min (max) of samples i .. i + 2^k − 1 (padded past the end).
        self.lows = np.empty((levels, n))
        self.highs = np.empty((levels, n))
        self.lows[0], self.highs[0] = values, values
        width = 1
        for k in range(1, levels):
            self.lows[k, : n - width] = np.minimum(
                self.lows[k - 1, : n - width], self.lows[k - 1, width:]
            )
            self.highs[k, : n - width] = np.maximum(
                self.highs[k - 1, : n - width], self.highs[k - 1, width:]
            )
            self.lows[k, n - width :] = self.lows[k - 1, n - width :]
            self.highs[k, n - width :] = self.highs[k - 1, n - width :]
            width *= 2
        self.whole = (float(values.min()) - slack, float(values.max()) + slack)

    def _query(self, i, j):
        """min and max of samples i..j (inclusive, 0 ≤ i ≤ j < n), vectorized: the two
        windows of the largest power of two that cover it."""
        level = np.floor(np.log2(np.maximum(j - i + 1, 1))).astype(np.intp)
        b = j - (np.left_shift(1, level)) + 1
        low = np.minimum(self.lows[level, i], self.lows[level, b])
        high = np.maximum(self.highs[level, i], self.highs[level, b])
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
    |d̈| = |α × b + ω × (ω × b)| of its inertial direction d = Q b, and b·m̂ (the cosine
    of its angle β to the momentum, body axes, periodic in the motion) at samples
    ``tilt_start_s + k tilt_spacing_s``, each within ``tilt_slack`` of it between its
    neighbours: the envelope of the module notes (None at rest), whose range table
    :meth:`tilt` builds when a search needs it (:meth:`release` drops it: a run with
    thousands of segments keeps only the samples)."""

    rate: float
    bend: float
    tilt_values: NDArray[np.float64] | None = field(default=None, compare=False, repr=False)
    tilt_start_s: float = 0.0
    tilt_spacing_s: float = 0.0
    tilt_periodic: bool = False
    tilt_slack: float = 0.0
    _table: dict = field(default_factory=dict, compare=False, repr=False)

    def tilt(self) -> _PeriodicRange | None:
        """The range table of b·m̂ over any window (None at rest)."""
        if self.tilt_values is None:
            return None
        if "table" not in self._table:
            self._table["table"] = _PeriodicRange(
                self.tilt_values,
                self.tilt_start_s,
                self.tilt_spacing_s,
                self.tilt_periodic,
                self.tilt_slack,
            )
        return self._table["table"]

    def release(self) -> None:
        self._table.clear()


def vector_motion(
    solver: EulerSolver,
    vectors: list[tuple[str, NDArray[np.float64]]],
    start_s: float,
    end_s: float,
) -> dict[str, VectorMotion]:
    """:class:`VectorMotion` of each (name, body vector) over [start_s, end_s].

    ω(t) is sampled (512 times a turn of the body, 256 to 16384 times in all) over
    one period of the body's motion (in which it takes all its values) or over the
    segment if that is shorter; α =
    I⁻¹(m × ω) (Euler's equations) at the same samples.  Within Δ/2 of a sample, |ω × b|
    is bounded by its Taylor expansion to second order there (α̇ = I⁻¹((m × ω) × ω + m ×
    α) exact at the sample) plus the third-order remainder, and |α × b + ω × (ω × b)| by
    its expansion to first order plus the second-order remainder.  Each result is also
    capped by its analytic bound (module notes).
    """
    return vector_motions([solver], vectors, [(start_s, end_s)])[0]


def vector_motions(
    solvers: list[EulerSolver],
    vectors: list[tuple[str, NDArray[np.float64]]],
    spans: list[tuple[float, float]],
) -> list[dict[str, VectorMotion]]:
    """:func:`vector_motion` of each solver over its span (``spans[i]``: start and
    end): each solver's ω at its own samples, then the arithmetic of all in one pass
    over their samples put end to end (element by element, each sample with its own
    solver's constants; each maximum over its solver's samples alone), so that each
    result is the one :func:`vector_motion` gives it alone, bit for bit."""
    out: list[dict[str, VectorMotion] | None] = [None] * len(solvers)
    live = []  # (index, start_s, scalars) of the solvers with a momentum
    ω_parts, tensors, inverses, gaps = [], [], [], []
    for i, (solver, (start_s, end_s)) in enumerate(zip(solvers, spans, strict=True)):
        moments = np.sort(np.asarray(solver.moments_of_inertia, dtype=np.float64))
        G = float(solver.angular_momentum_norm)
        least = float(moments[0])
        if G == 0.0:
            out[i] = {name: VectorMotion(0.0, 0.0) for name, _ in vectors}
            continue
        fastest = math.sqrt(max(2.0 * solver.kinetic_energy, 0.0) / least)
        spin_accel = (float(moments[2]) - least) / least * fastest * fastest / math.sqrt(3.0)
        period = solver.period
        periodic = math.isfinite(period) and period < end_s - start_s
        window = period if periodic else max(end_s - start_s, 0.0)
        # Hundreds of samples a turn of the body, within [256, 16384].
        turns = window * fastest / (2.0 * math.pi)
        samples = int(min(max(_SAMPLES_PER_TURN * turns, _MOTION_SAMPLES_LEAST), _MOTION_SAMPLES))
        t = start_s + window * np.arange(samples + 1.0) / samples
        tensor = np.asarray(solver.inertia_tensor, dtype=np.float64)
        inverse = np.asarray(np.linalg.inv(tensor), dtype=np.float64)
        spacing = window / samples
        gap = 0.5 * spacing
        # A bound on the third derivative of ω: each component of Euler's equations is
        # a product of two others with a coefficient at most Λ = (I3 − I1)/I1 (principal
        # axes), and every component is at most Ω, so by Leibniz's rule each component
        # of ω⁽ᵏ⁾ is at most k! Λᵏ Ω^(k+1), and |ω⁽³⁾| ≤ √3 · 6 Λ³ Ω⁴.
        Λ = (float(moments[2]) - least) / least
        third = math.sqrt(3.0) * 6.0 * Λ**3 * fastest**4
        # |ω⃛| + 2|ω̈||ω| + 2|ω̇|² ≤ (6√3 Λ³ + 4√3 Λ² + 6 Λ²) Ω⁴ by the same majorant.
        second = (6.0 * math.sqrt(3.0) * Λ**3 + (4.0 * math.sqrt(3.0) + 6.0) * Λ**2) * fastest**4
        ω_parts.append(solver.angular_velocity(t))
        tensors.append(tensor)
        inverses.append(inverse)
        gaps.append(gap)
        scalars = (fastest, spin_accel, periodic, window, spacing, gap, third, second)
        live.append((i, start_s, t.size, scalars))
    if not live:
        return out  # type: ignore[return-value]
    counts = [size for _, _, size, _ in live]
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.intp)
    # Each sample's solver's I and I⁻¹ ((3, 3, samples): matrix[i, j] a column) and Δ/2.
    tensor_of = np.repeat(np.stack(tensors, axis=-1), counts, axis=-1)
    inverse_of = np.repeat(np.stack(inverses, axis=-1), counts, axis=-1)
    gap_of = np.repeat(np.array(gaps), counts)
    # Columns (x, y, z) of the samples: ω, m = Iω, α = I⁻¹(m × ω), and ω̈ = α̇ =
    # I⁻¹((m × ω) × ω + m × α).
    ω = _columns(np.concatenate(ω_parts))
    m = _apply(tensor_of, ω)
    mω = _cross(m, ω)
    α = _apply(inverse_of, mω)
    α_rate = _apply(inverse_of, _add(_cross(mω, ω), _cross(m, α)))
    size = _norm(m)
    m_hat = (m[0] / size, m[1] / size, m[2] / size)
    drift = _cross(m_hat, ω)  # dm̂/dt in the body (ṁ = m × ω)
    found: list[dict[str, VectorMotion]] = [{} for _ in live]
    for name, b in vectors:
        ωb = _cross_vector(ω, b)
        αb = _cross_vector(α, b)
        # |ω × b| within Δ/2 of a sample: Taylor's expansion to second order there,
        # and the third-order remainder.
        taylor = (
            _norm(ωb) + _norm(αb) * gap_of + 0.5 * _norm(_cross_vector(α_rate, b)) * gap_of * gap_of
        )
        # |d̈| = |α × b + ω × (ω × b)| within Δ/2 of a sample: its value and exact rate
        # there (α̇ × b + α × (ω × b) + ω × (α × b)), and the second-order remainder.
        bend = _add(αb, _cross(ω, ωb))
        bend_rate = _add(_add(_cross_vector(α_rate, b), _cross(α, ωb)), _cross(ω, αb))
        tilt = m_hat[0] * b[0] + m_hat[1] * b[1] + m_hat[2] * b[2]
        # |d/dt (b·m̂)| = |b·(m̂ × ω)|, whose own rate is at most Ω² + A.
        tilt_rate = drift[0] * b[0] + drift[1] * b[1] + drift[2] * b[2]
        # Each solver's maxima over its own samples (a maximum is exact, in any order).
        taylor_max = np.maximum.reduceat(taylor, starts)
        bend_max = np.maximum.reduceat(_norm(bend) + _norm(bend_rate) * gap_of, starts)
        tilt_rate_max = np.maximum.reduceat(np.abs(tilt_rate), starts)
        for j, (_, start_s, count, scalars) in enumerate(live):
            fastest, spin_accel, periodic, window, spacing, gap, third, second = scalars
            rate = min(float(taylor_max[j]) + third * gap**3 / 6.0, fastest)
            bent = float(bend_max[j]) + 0.5 * second * gap * gap
            slack = (float(tilt_rate_max[j]) + (fastest * fastest + spin_accel) * gap) * gap
            values = None
            if window > 0.0:
                own = tilt[starts[j] : starts[j] + count]
                values = np.array(own[:-1] if periodic else own)
            found[j][name] = VectorMotion(
                rate,
                min(bent, spin_accel + fastest * rate),
                values,
                start_s,
                spacing,
                periodic,
                slack,
            )
    for j, (i, _, _, _) in enumerate(live):
        out[i] = found[j]
    return out  # type: ignore[return-value]


def _columns(v: NDArray[np.float64]):
    """The columns of (n, 3) vectors, contiguous."""
    return tuple(np.ascontiguousarray(v[:, k]) for k in range(3))


def _apply(matrix: NDArray[np.float64], v):
    """matrix · v for columns v."""
    return tuple(matrix[i, 0] * v[0] + matrix[i, 1] * v[1] + matrix[i, 2] * v[2] for i in range(3))


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _cross_vector(a, b: NDArray[np.float64]):
    """a × b for columns a and one vector b."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def _norm(a):
    return np.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


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
    return free_plans([solver], spec, shared, [(start_s, end_s)])[0]


def free_plans(
    solvers: list[EulerSolver],
    spec: PointingSpec,
    shared: SharedSurroundings,
    spans: list[tuple[float, float]],
) -> list[FreePlan | None]:
    """:func:`free_plan` of each solver over its span (``spans[i]``), the motions'
    bounds of all found together (:func:`vector_motions`): each the same, bit for bit,
    as alone."""
    vectors = [(v.name, v.vector) for v in spec.body_vectors]
    sky = shared.rate_bounds()
    motions = vector_motions(solvers, vectors, spans)
    return [
        _plan(motion, sky, vectors, start_s, end_s)
        for motion, (start_s, end_s) in zip(motions, spans, strict=True)
    ]


def _plan(motion, sky, vectors, start_s: float, end_s: float) -> FreePlan | None:
    """The :class:`FreePlan` from a segment's :class:`VectorMotion` of each vector and
    the sky's rate bounds."""
    targets = [t for t in TARGETS if f"{t}_1" in sky]
    bend = {}
    for name, _ in vectors:
        for target in targets:
            bend[(name, target)] = (
                sky[f"{target}_2"]
                + 2.0 * sky[f"{target}_1"] * motion[name].rate
                + motion[name].bend
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


@dataclass(frozen=True)
class FreePiece:
    """A torque-free segment's part of the searched span, [start_s, end_s], with its
    solver and :class:`FreePlan`; ``event_at_end``: an event ends it (and the next
    segment's state holds from end_s on)."""

    solver: EulerSolver
    plan: FreePlan
    start_s: float
    end_s: float
    event_at_end: bool = False


# --------------------------------------------------------------------- evaluation


@dataclass
class _Values:
    """At some times: for each vector (rows) and target, the cosine ``f``, its rate
    ``df`` and bend ``ddf`` (f'') and, when asked, the angle (Kahan's formula); the
    limb's angular radius and rate (on an orbit); each target's angle σ to the
    momentum's direction of the point's piece (NaN at rest)."""

    f: dict[str, NDArray[np.float64]]
    df: dict[str, NDArray[np.float64]]
    ddf: dict[str, NDArray[np.float64]]
    angle: dict[str, NDArray[np.float64]]
    sigma: dict[str, NDArray[np.float64]]
    limb: NDArray[np.float64] | None
    limb_rate: NDArray[np.float64] | None


class _Evaluator:
    """The cosines of every body vector with the targets, their rates and bends, at any
    times of the pieces: the exact attitude and ω of each piece's solver, the
    interpolated surroundings; one call for points of any pieces."""

    def __init__(self, pieces: list[FreePiece], spec: PointingSpec, shared: SharedSurroundings):
        self.pieces = pieces
        self.shared = shared
        self.vectors = np.array([v.vector for v in spec.body_vectors], dtype=np.float64)
        self.targets = [t for t in TARGETS if t != "nadir" or spec.orbit is not None]
        self.tensors = [np.asarray(p.solver.inertia_tensor, dtype=np.float64) for p in pieces]
        self.inverses = [np.linalg.inv(t) for t in self.tensors]
        self.inverses_stacked = np.array(self.inverses).reshape(-1, 3, 3)
        axes, momenta = [], []
        for piece in pieces:
            momentum = np.asarray(piece.solver.inertial_angular_momentum, dtype=np.float64)
            size = float(np.linalg.norm(momentum))
            momenta.append(momentum)
            axes.append(
                momentum / size if size > 0.0 and math.isfinite(size) else np.full(3, np.nan)
            )
        self.axes = np.array(axes).reshape(-1, 3)
        self.momenta = np.array(momenta).reshape(-1, 3)
        self.calls = 0
        self.points = 0

    def __call__(self, τ, piece, angles=False, targets=None, bends=None) -> _Values:
        """The values at times τ of pieces ``piece`` (indices): the cosines with
        ``targets`` (None: every target) and their rates; their bends with ``bends``
        (None: every one of them); the angles with ``angles`` (True: every one; a set:
        those).  Each is asked only where it is used: the cost is per target."""
        wanted = self.targets if targets is None else [t for t in self.targets if t in targets]
        bent = set(wanted) if bends is None else set(bends) & set(wanted)
        angled = set(wanted) if angles is True else set(angles or ()) & set(wanted)
        τ = np.asarray(τ, dtype=np.float64)
        piece = np.asarray(piece, dtype=np.intp)
        self.calls += 1
        self.points += τ.size
        n = τ.size
        q = np.empty((n, 4))
        if n and np.all(piece == piece[0]):
            groups = [(int(piece[0]), slice(None))]
        else:
            groups = [(int(k), piece == k) for k in np.unique(piece)]
        for k, mine in groups:
            q[mine] = self.pieces[k].solver.attitude_quaternion(τ[mine])
        rows = rotation_rows(q)  # R v for many v without an (n, 3, 3) product

        def rotate(v0, v1, v2):
            return [r[0] * v0 + r[1] * v1 + r[2] * v2 for r in rows]

        # The body momentum m = Qᵀ H (H the segment's inertial momentum, constant: the
        # solver's Q maps m onto it by construction), ω = I⁻¹ m and α = I⁻¹(m × ω)
        # (Euler's equations without torque): no second pass of the solver over τ.
        # Each point takes its piece's H and I⁻¹ (element by element: a point's values
        # do not depend on the others evaluated with it).
        if len(groups) == 1:
            h = self.momenta[groups[0][0]]
            inverse = self.inverses[groups[0][0]]
        else:
            h = self.momenta[piece].T
            inverse = np.moveaxis(self.inverses_stacked[piece], 0, -1)
        m = [rows[0][i] * h[0] + rows[1][i] * h[1] + rows[2][i] * h[2] for i in range(3)]
        ω = [inverse[i, 0] * m[0] + inverse[i, 1] * m[1] + inverse[i, 2] * m[2] for i in range(3)]
        mω = (m[1] * ω[2] - m[2] * ω[1], m[2] * ω[0] - m[0] * ω[2], m[0] * ω[1] - m[1] * ω[0])
        α = [
            inverse[i, 0] * mω[0] + inverse[i, 1] * mω[1] + inverse[i, 2] * mω[2] for i in range(3)
        ]
        # Inertial: ω_in = R ω.
        ω_in = [rows[i][0] * ω[0] + rows[i][1] * ω[1] + rows[i][2] * ω[2] for i in range(3)]
        α_in = [rows[i][0] * α[0] + rows[i][1] * α[1] + rows[i][2] * α[2] for i in range(3)]
        sky = self.shared.targets(τ, accelerations=bool(bent))
        f: dict[str, list] = {t: [] for t in wanted}
        df: dict[str, list] = {t: [] for t in wanted}
        ddf: dict[str, list] = {t: [] for t in wanted if t in bent}
        angle: dict[str, list] = {t: [] for t in wanted if t in angled}
        columns = {}
        for target in wanted:
            s = getattr(sky, target)
            sr = getattr(sky, f"{target}_rate")
            sa = getattr(sky, f"{target}_accel") if target in bent else s
            columns[target] = tuple(
                tuple(np.ascontiguousarray(v[:, i]) for i in range(3)) for v in (s, sr, sa)
            )
        for b in self.vectors:
            d = rotate(b[0], b[1], b[2])
            rate = (
                ω_in[1] * d[2] - ω_in[2] * d[1],
                ω_in[2] * d[0] - ω_in[0] * d[2],
                ω_in[0] * d[1] - ω_in[1] * d[0],
            )
            # d̈ = α × d + ω × ḋ: a cosine bends by s·d̈ + 2 ṡ·ḋ + s̈·d (f'' serves the
            # incidence's integral and the extrema's Newton steps, never a bound).
            if ddf:
                bend = (
                    α_in[1] * d[2] - α_in[2] * d[1] + ω_in[1] * rate[2] - ω_in[2] * rate[1],
                    α_in[2] * d[0] - α_in[0] * d[2] + ω_in[2] * rate[0] - ω_in[0] * rate[2],
                    α_in[0] * d[1] - α_in[1] * d[0] + ω_in[0] * rate[1] - ω_in[1] * rate[0],
                )
            for target in wanted:
                (s0, s1, s2), (r0, r1, r2), (a0, a1, a2) = columns[target]
                f[target].append(d[0] * s0 + d[1] * s1 + d[2] * s2)
                df[target].append(
                    (d[0] * r0 + d[1] * r1 + d[2] * r2)
                    + (rate[0] * s0 + rate[1] * s1 + rate[2] * s2)
                )
                if target in ddf:
                    ddf[target].append(
                        (bend[0] * s0 + bend[1] * s1 + bend[2] * s2)
                        + 2.0 * (rate[0] * r0 + rate[1] * r1 + rate[2] * r2)
                        + (d[0] * a0 + d[1] * a1 + d[2] * a2)
                    )
                if target in angle:
                    angle[target].append(_unit_angle_columns(d, columns[target][0]))
        # σ by arccos: ~1e-12 rad near 0 and π at σ = 1e-4, far below the margin the
        # envelope adds (_ENVELOPE_MARGIN).
        axis = self.axes[piece]
        sigma = {}
        for target in wanted:
            s0, s1, s2 = columns[target][0]
            along = s0 * axis[:, 0] + s1 * axis[:, 1] + s2 * axis[:, 2]
            sigma[target] = np.arccos(np.clip(along, -1.0, 1.0))

        def stacked(values: dict[str, list]) -> dict[str, NDArray[np.float64]]:
            return {t: np.array(v).reshape(len(self.vectors), -1) for t, v in values.items()}

        return _Values(
            stacked(f),
            stacked(df),
            stacked(ddf),
            stacked(angle),
            sigma,
            sky.limb,
            sky.limb_rate,
        )


def _unit_angle_columns(u, v) -> NDArray[np.float64]:
    """The angle between unit vectors given by columns, 2 atan2(|u − v|, |u + v|)
    (Kahan's formula, as :func:`attitude.pointing.surroundings.unit_angle`)."""
    d0, d1, d2 = u[0] - v[0], u[1] - v[1], u[2] - v[2]
    s0, s1, s2 = u[0] + v[0], u[1] + v[1], u[2] + v[2]
    return 2.0 * np.arctan2(
        np.sqrt(d0 * d0 + d1 * d1 + d2 * d2), np.sqrt(s0 * s0 + s1 * s1 + s2 * s2)
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
        value = np.where(ok, sign * _polynomial_at(c, np.where(ok, r, 0.5)), -np.inf)
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
            step = _polynomial_at(c, s) / slope
            s = np.clip(np.where(np.isfinite(step), s - step, s), 0.0, 1.0)
    return s


def _envelope(pieces: list[FreePiece], piece, name: str, target: str, σ_a, σ_b, t_a, t_b):
    """Bounds (low, high) on the angle between body vector ``name``'s direction and
    ``target`` over each window [t_a, t_b] of a piece (``piece``: indices), from the
    spherical triangle of the two and the momentum's direction Ĥ: |σ − β| ≤ angle ≤
    min(σ + β, 2π − σ − β), with σ the target's angle to Ĥ (σ_a, σ_b at the ends,
    drifting at most at the target's rate) and β the vector's angle to the momentum,
    over the window from the piece's periodic table (:class:`VectorMotion`).  (0, π)
    where there is no momentum."""
    low = np.zeros(np.shape(t_a))
    high = np.full(np.shape(t_a), math.pi)
    for k in np.unique(piece).tolist():
        plan = pieces[k].plan
        tilt = plan.motion[name].tilt() if name in plan.motion else None
        if tilt is None:
            continue
        mine = piece == k
        c_low, c_high = tilt.over(t_a[mine], t_b[mine])
        β_low = np.arccos(np.clip(c_high, -1.0, 1.0))
        β_high = np.arccos(np.clip(c_low, -1.0, 1.0))
        drift = plan.sky.get(f"{target}_1", math.inf) * 0.5 * (t_b[mine] - t_a[mine])
        σ_low = np.minimum(σ_a[mine], σ_b[mine]) - drift
        σ_high = np.maximum(σ_a[mine], σ_b[mine]) + drift
        lower = np.maximum(np.maximum(σ_low - β_high, β_low - σ_high), 0.0)
        upper = np.minimum(np.minimum(σ_high + β_high, 2.0 * math.pi - σ_low - β_low), math.pi)
        low[mine] = np.where(np.isfinite(lower), np.maximum(lower - _ENVELOPE_MARGIN, 0.0), 0.0)
        high[mine] = np.where(np.isfinite(upper), upper + _ENVELOPE_MARGIN, math.pi)
    return low, high


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
                    f"{v.name}.earth_limb_exclusion",
                    j,
                    "nadir",
                    "limb",
                    v.earth_limb_exclusion_angle_rad,
                )
            )
    return out


def _condition_values(values: _Values, conditions: list[_Condition]):
    """Each condition's function g, its rate, its target's angle σ to the momentum's
    direction and g'' (NaN for the limb's) at the values' times: (K, n) each."""
    g, dg, σ, ddg = [], [], [], []
    for c in conditions:
        f = values.f[c.target][c.vector]
        df = values.df[c.target][c.vector]
        σ.append(values.sigma[c.target])
        if c.kind == "cos":
            g.append(f - c.c)
            dg.append(df)
            bends = values.ddf.get(c.target)
            ddg.append(np.full(f.shape, np.nan) if bends is None else bends[c.vector])
        else:
            assert values.limb is not None and values.limb_rate is not None
            edge = c.c + values.limb
            clipped = np.clip(edge, 0.0, math.pi)
            g.append(f - np.cos(clipped))
            dg.append(df + np.where(clipped == edge, np.sin(clipped), 0.0) * values.limb_rate)
            ddg.append(np.full(f.shape, np.nan))
    shape = (len(conditions), -1)
    return tuple(np.array(x).reshape(shape) for x in (g, dg, σ, ddg))


_CELL_FIELDS = ("k", "p", "a", "b", "ga", "gb", "da", "db", "sa", "sb", "ea", "eb")


@dataclass
class _Cells:
    """Cells of the conditions (flat): condition index, piece, ends, values and rates
    there, the target's angle to the momentum's direction and g'' there."""

    k: NDArray[np.intp]
    p: NDArray[np.intp]
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


def _settle(cells: _Cells, M: NDArray[np.float64], envelope):
    """Each cell's status: 0 settled without a crossing, 1 one crossing, 2 not proved.
    ``M`` (conditions, pieces): the bounds on |g''|; ``envelope(cells)``: bounds on
    each cell's angle to its condition's target and the threshold as an angle (NaN
    where the envelope does not apply)."""
    h = cells.b - cells.a
    bend = M[cells.k, cells.p]
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


def _partition(evaluate, conditions, cells: _Cells, M, envelope) -> tuple[_Cells, NDArray[np.int8]]:
    """Every condition's ``cells``, cut until each is settled (module notes): the final
    cells and their status (0 or 1)."""
    done: list[_Cells] = []
    statuses: list[NDArray[np.int8]] = []
    while cells.k.size:
        status = _settle(cells, M, envelope)
        final = status < 2
        done.append(cells.take(final))
        statuses.append(status[final])
        cells = cells.take(~final)
        if not cells.k.size:
            break
        cut = _cut(cells)
        keys = np.stack([cut, cells.p.astype(np.float64)])
        unique, inverse = np.unique(keys, axis=1, return_inverse=True)
        inverse = inverse.ravel()
        at_cut = _condition_values(evaluate(unique[0], unique[1].astype(np.intp)), conditions)
        g, dg, σ, ddg = (x[cells.k, inverse] for x in at_cut)
        left = _Cells(
            cells.k, cells.p, cells.a, cut, cells.ga, g, cells.da, dg, cells.sa, σ, cells.ea, ddg
        )
        right = _Cells(
            cells.k, cells.p, cut, cells.b, g, cells.gb, dg, cells.db, σ, cells.sb, ddg, cells.eb
        )
        cells = _Cells.join([left, right])
    final_cells = _Cells.join(done) if done else cells
    return final_cells, np.concatenate(statuses) if statuses else np.empty(0, np.int8)


# ------------------------------------------------------------------ the search


_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(4)
_QUANTITIES = ("sun_angle", "moon_angle", "cos_incidence", "nadir_angle", "earth_limb_angle")
# Extrema found by Newton's method on a cosine's slope: the quantity's target (the
# incidence's outside the shadow, the limb's with the limb's own rate); at most this
# many steps, done below this step (s).
_TARGET_OF = {
    "sun_angle": "sun",
    "moon_angle": "moon",
    "nadir_angle": "nadir",
    "cos_incidence": "sun",
    "earth_limb_angle": "nadir",
}
_NEWTON_STEPS = 6
_NEWTON_DONE_S = 1e-9
_ANGLES = ("angle", "limb")
# The lit fraction's slope and bend by central differences this far apart (s): it
# changes over the seconds of a penumbra.
_FRACTION_STEP_S = 1e-2
# A piece that ends at an event ends its nodes this long before it (s): the
# trajectory puts times within SAME_INSTANT_S of an event at the event's state.
_BEFORE_EVENT_S = 2e-9


@dataclass
class FreeResult:
    """What :func:`search_free` found over its span: each condition's intervals (by the
    names of :mod:`attitude.pointing.search`), the extrema (the best of ``incumbents``
    and of the span, by problem name), the integral of the incidence of each vector,
    whether each vector saw no Sun at some time (``dark``), and the points evaluated."""

    intervals: dict[str, list[Interval]]
    extrema: dict[str, Extremum]
    incidence_integral: dict[str, float]
    dark: dict[str, bool]
    evaluations: int = 0


def _nodes(pieces: list[FreePiece]) -> tuple[NDArray[np.float64], NDArray[np.intp]]:
    """The nodes of every piece, in order, and each node's piece: every ``plan.step_s``
    over [start_s, end_s], the last of a piece that an event ends just before it (the
    trajectory gives the event's state from SAME_INSTANT_S before it on)."""
    times, owner = [], []
    for k, piece in enumerate(pieces):
        count = max(math.ceil((piece.end_s - piece.start_s) / piece.plan.step_s), 1) + 1
        τ = np.linspace(piece.start_s, piece.end_s, count)
        if piece.event_at_end:
            τ[-1] = max(piece.end_s - _BEFORE_EVENT_S, τ[-2] if count > 2 else piece.start_s)
        times.append(τ)
        owner.append(np.full(count, k, dtype=np.intp))
    return np.concatenate(times), np.concatenate(owner)


def _eclipse_ends(shadow: list[Interval], umbra: list[Interval]) -> NDArray[np.float64]:
    return np.array([x for i in [*shadow, *umbra] for x in (i.start_s, i.end_s)], dtype=np.float64)


def _with_ends(τ, owner, ends):
    """The nodes τ (of pieces ``owner``) with the eclipses' ``ends`` inside them added:
    the lit fraction has kinks there."""
    inside = ends[(ends > τ[0]) & (ends < τ[-1])]
    if inside.size:
        piece_of = owner[np.clip(np.searchsorted(τ, inside, side="right") - 1, 0, τ.size - 1)]
        order = np.lexsort((np.concatenate([τ, inside]), np.concatenate([owner, piece_of])))
        τ = np.concatenate([τ, inside])[order]
        owner = np.concatenate([owner, piece_of])[order]
    return τ, owner


def _bend_bounds(pieces: list[FreePiece], conditions: list[_Condition], names: list[str]):
    """The bound on |g''| of each condition on each piece: (conditions, pieces)."""
    return np.array(
        [
            [
                p.plan.bend[(names[c.vector], c.target)]
                + (p.plan.limb_bend if c.kind == "limb" else 0.0)
                for p in pieces
            ]
            for c in conditions
        ]
    ).reshape(len(conditions), len(pieces))


def search_free(
    pieces: list[FreePiece],
    spec: PointingSpec,
    shared: SharedSurroundings,
    precision_s: float,
    extremum_precision_s: float,
    tolerance: float,
    problems: dict[str, Problem],
    incumbents: dict[str, Extremum | None],
    shadow: list[Interval],
    umbra: list[Interval],
) -> FreeResult:
    """Search the consecutive torque-free ``pieces`` together: every condition's
    intervals, the extrema of ``problems`` (names ``"<vector>.<quantity>.low"``/
    ``".high"``: the quantity, or its negative, to minimize; each problem's
    ``lipschitz`` prunes golden-section brackets; ``incumbents`` the best known), and
    each vector's integral of the incidence.  ``shadow``/``umbra``: the eclipses over
    the span (the lit fraction is 1 outside the shadow, 0 in umbra).  The nodes are
    searched in windows of at most :data:`WINDOW_NODES`."""
    evaluate = _Evaluator(pieces, spec, shared)
    conditions = conditions_of(spec)
    names = [v.name for v in spec.body_vectors]
    M = _bend_bounds(pieces, conditions, names)
    out: dict[str, list[Interval]] = {c.name: [] for c in conditions}
    best: dict[str, Extremum] = {}
    integral = dict.fromkeys(names, 0.0)
    dark = dict.fromkeys(names, False)
    ends = _eclipse_ends(shadow, umbra)
    τ_all, owner_all = _nodes(pieces)
    alone = np.zeros(len(pieces), dtype=np.intp)  # every piece is of the one search
    first = 0
    while first < τ_all.size - 1:
        last = min(first + WINDOW_NODES, τ_all.size - 1)
        τ, owner = _with_ends(τ_all[first : last + 1], owner_all[first : last + 1], ends)
        window = _Window(
            evaluate, spec, shared, pieces, conditions, M, τ, owner, alone, [shadow], [umbra]
        )
        # The last window's intervals reach the pieces' end (its node may be before it).
        end_s = pieces[-1].end_s if last == τ_all.size - 1 else None
        found = window.search(
            precision_s, [problems], [incumbents], [best], tolerance, extremum_precision_s, [end_s]
        )[0]
        for name, pieces_found in found.items():
            if first == 0:
                join(out[name], pieces_found, float(τ[0]))
            else:
                append_across(out[name], pieces_found, float(τ[0]))
        for name, value in window.incidence()[0].items():
            integral[name] += value
        for name, value in window.dark()[0].items():
            dark[name] = dark[name] or value
        for k in range(int(owner[0]), int(owner[-1]) + (1 if last == τ_all.size - 1 else 0)):
            for motion in pieces[k].plan.motion.values():
                motion.release()  # the pieces behind: their tables are not needed again
        first = last
    return FreeResult(out, best, integral, dark, evaluate.points)


def fits_one_window(pieces: list[FreePiece]) -> bool:
    """Whether :func:`search_free` searches ``pieces`` in one window (what
    :func:`search_free_many` takes)."""
    return sum(max(math.ceil((p.end_s - p.start_s) / p.plan.step_s), 1) + 1 for p in pieces) <= (
        WINDOW_NODES + 1
    )


def search_free_many(
    runs: list[list[FreePiece]],
    spec: PointingSpec,
    shared: SharedSurroundings,
    precision_s: float,
    extremum_precision_s: float,
    tolerance: float,
    problems: list[dict[str, Problem]],
    incumbents: list[dict[str, Extremum | None]],
    shadows: list[list[Interval]],
    umbras: list[list[Interval]],
) -> list[FreeResult]:
    """:func:`search_free` of many independent searches at once (the envelope's
    windows after each failure): ``runs[g]`` the consecutive pieces of search g, each
    within one window (:func:`fits_one_window`), with its ``problems[g]`` (the same
    names for all, each its own rate bounds), its ``incumbents[g]`` and its eclipses
    ``shadows[g]``, ``umbras[g]``.  Their nodes form one window in which no cell joins
    two pieces; each call of the evaluator serves every search, and every quantity of a
    search is computed element by element from its own points, with its own decisions
    (its extrema, its counts), so that each result is the one :func:`search_free` gives
    for that search alone, bit for bit."""
    pieces = [p for run in runs for p in run]
    evaluate = _Evaluator(pieces, spec, shared)
    conditions = conditions_of(spec)
    names = [v.name for v in spec.body_vectors]
    M = _bend_bounds(pieces, conditions, names)
    group_of = np.concatenate(
        [np.full(len(run), g, dtype=np.intp) for g, run in enumerate(runs)]
    ).astype(np.intp)
    times, owners, offset = [], [], 0
    for run, shadow, umbra in zip(runs, shadows, umbras, strict=True):
        if not fits_one_window(run):
            raise ValueError("search_free_many takes searches of one window each")
        τ, owner = _nodes(run)
        τ, owner = _with_ends(τ, owner + offset, _eclipse_ends(shadow, umbra))
        times.append(τ)
        owners.append(owner)
        offset += len(run)
    τ_all, owner_all = np.concatenate(times), np.concatenate(owners)
    window = _Window(
        evaluate, spec, shared, pieces, conditions, M, τ_all, owner_all, group_of, shadows, umbras
    )
    best: list[dict[str, Extremum]] = [{} for _ in runs]
    found = window.search(
        precision_s,
        problems,
        incumbents,
        best,
        tolerance,
        extremum_precision_s,
        [run[-1].end_s for run in runs],
    )
    incidence, dark = window.incidence(), window.dark()
    results = []
    for g in range(len(runs)):
        start_s = float(times[g][0])
        out: dict[str, list[Interval]] = {c.name: [] for c in conditions}
        for name, pieces_found in found[g].items():
            join(out[name], pieces_found, start_s)
        integral = {name: 0.0 + incidence[g].get(name, 0.0) for name in names}
        darks = {name: False or dark[g].get(name, False) for name in names}
        results.append(FreeResult(out, best[g], integral, darks, int(times[g].size)))
    for run in runs:
        for piece in run:
            for motion in piece.plan.motion.values():
                motion.release()
    return results


def _in_any(τ: NDArray[np.float64], intervals: list[Interval]) -> NDArray[np.bool_]:
    """Whether each time lies within one of the (sorted, disjoint) intervals."""
    if not intervals:
        return np.zeros(τ.shape, dtype=bool)
    starts = np.array([i.start_s for i in intervals])
    ends = np.array([i.end_s for i in intervals])
    k = np.searchsorted(starts, τ, side="right") - 1
    return (k >= 0) & (τ <= ends[np.maximum(k, 0)])


def _by_group(group: NDArray[np.intp], count: int):
    """(g, indices) of each search g that ``group`` (each element's search) holds, the
    indices in their order: one search's elements in the order it has alone."""
    if count == 1:
        return [(0, np.arange(group.size))] if group.size else []
    order = np.argsort(group, kind="stable")
    cuts = np.searchsorted(group[order], np.arange(count + 1))
    return [(g, order[cuts[g] : cuts[g + 1]]) for g in range(count) if cuts[g + 1] > cuts[g]]


def _in_any_of(
    τ: NDArray[np.float64], group: NDArray[np.intp], lists: list[list[Interval]]
) -> NDArray[np.bool_]:
    """:func:`_in_any` of each time in the intervals of its search (``group``)."""
    if len(lists) == 1:
        return _in_any(τ, lists[0])
    out = np.zeros(τ.shape, dtype=bool)
    for g, which in _by_group(group, len(lists)):
        if lists[g]:
            out[which] = _in_any(τ[which], lists[g])
    return out


class _Window:
    """One window of nodes (τ, each of a piece: ``owner``), searched: the nodes of one
    search, or of many independent ones (:func:`search_free_many`; ``group``: each
    piece's search, whose nodes are contiguous, with its eclipses ``shadows[g]`` and
    ``umbras[g]``), each search's extrema, intervals and sums its own."""

    def __init__(
        self, evaluate, spec, shared, pieces, conditions, M, τ, owner, group, shadows, umbras
    ):
        self.evaluate, self.spec, self.shared, self.pieces = evaluate, spec, shared, pieces
        self.fraction_rate = pieces[0].plan.sky.get("fraction_1", math.inf)
        self.conditions, self.M, self.τ, self.owner = conditions, M, τ, owner
        self.shadows, self.umbras = shadows, umbras
        self.groups = len(shadows)
        self.piece_group = group
        self.node_group = group[owner]
        cuts = np.searchsorted(self.node_group, np.arange(self.groups + 1))
        # Each search's nodes: τ[first[g] : first[g + 1]].
        self.first = cuts
        self.any_shadow = any(bool(s) for s in shadows)
        self.limb_rate = shared.rate_bounds().get("limb_1", 0.0)
        # Which targets the conditions look at (the cuts and crossings ask only those),
        # and the Sun's bend for the incidence's integral.
        self.condition_targets = {c.target for c in conditions}
        self.values = evaluate(τ, owner, angles=True, bends={"sun"})
        at_nodes = _condition_values(self.values, conditions)
        self.g = at_nodes[0]
        # Cells join neighbouring nodes of one piece.
        self.cell = np.flatnonzero(owner[1:] == owner[:-1])
        self.cell_group = self.node_group[self.cell]
        K = len(conditions)
        i = self.cell
        k = np.repeat(np.arange(K), i.size)
        pairs = [x for v in at_nodes for x in (v[:, i].ravel(), v[:, i + 1].ravel())]
        cells = _Cells(k, np.tile(owner[i], K), np.tile(τ[i], K), np.tile(τ[i + 1], K), *pairs)
        targets = self.condition_targets

        def at_cuts(t, piece):
            return evaluate(t, piece, targets=targets, bends={"sun"} & targets)

        self.cells, self.status = _partition(
            at_cuts, conditions, cells, M, self._condition_envelope
        )
        # The refined time of each cell's crossing (NaN for a cell without one).
        self.cross = np.full(self.status.size, np.nan)
        self._cosines: dict = {}
        self._envelopes: dict = {}
        self.found: list[dict[str, list[Interval]]] = [{} for _ in shadows]

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
                self.pieces,
                cells.p[mine],
                name,
                condition.target,
                cells.sa[mine],
                cells.sb[mine],
                cells.a[mine],
                cells.b[mine],
            )
            threshold[mine] = math.acos(min(max(condition.c, -1.0), 1.0))
        return low, high, threshold

    # ---------------------------------------------------------------- intervals

    def search(
        self, precision_s, problems, incumbents, best, tolerance, extremum_precision_s, end_s=None
    ):
        """Every condition's intervals over the window, for each search g (returned; to
        ``end_s[g]`` if given, else to its last node) and the extrema of
        ``problems[g]`` (folded into ``best[g]``, from ``incumbents[g]``).  The
        crossings' estimates and the extrema's first Newton points are evaluated in one
        call."""
        crossing = self.status == 1
        cells = self.cells.take(crossing)
        h = cells.b - cells.a
        c = _cubic(cells.ga, cells.da, cells.gb, cells.db, h)
        x = cells.a + _cubic_root(c, cells.ga, cells.gb) * h
        problems_of, problems = problems, problems[0]  # each search's, and their names
        newton = self._extrema_start(problems, incumbents, best, tolerance)
        points = np.concatenate([x, newton.x])
        owners = np.concatenate([cells.p, newton.piece])
        stepped = newton.targets()
        at = None
        if points.size:
            at = self.evaluate(
                points,
                owners,
                angles=stepped,
                targets=self.condition_targets | stepped,
                bends=stepped,
            )
        times = self._crossings(cells, x, at, precision_s)
        self.cross[crossing] = times
        self._extrema_finish(newton, at, x.size, problems_of, best, tolerance, extremum_precision_s)
        ends = [
            self.τ[self.first[g + 1] - 1] if e is None else e
            for g, e in enumerate(end_s or [None] * self.groups)
        ]
        return self._intervals(cells, times, ends)

    def _intervals(self, cells: _Cells, times, end_s: list[float]):
        """Each search's conditions' intervals over the window from its crossings'
        ``times`` (a crossing at each event where the condition's value jumps across 0),
        to its ``end_s``."""
        entering = cells.ga <= 0.0
        # Events inside the window: a search's pieces' last nodes and the next ones' first.
        τ, owner, node_group = self.τ, self.owner, self.node_group
        boundary = np.flatnonzero((owner[1:] != owner[:-1]) & (node_group[1:] == node_group[:-1]))
        out: list[dict[str, list[Interval]]] = [{} for _ in range(self.groups)]
        cell_group = self.piece_group[cells.p]
        for index, condition in enumerate(self.conditions):
            mine = np.flatnonzero(cells.k == index)
            g_all = self.g[index]
            jumps_all = boundary[(g_all[boundary] > 0.0) != (g_all[boundary + 1] > 0.0)]
            jump_group = node_group[jumps_all]
            for group in range(self.groups):
                if self.groups == 1:
                    own, jumps = mine, jumps_all
                else:
                    own = mine[cell_group[mine] == group]
                    jumps = jumps_all[jump_group == group]
                first = self.first[group]
                w = np.array([τ[first], end_s[group]])
                at = np.concatenate([times[own], τ[jumps + 1]])
                enters = np.concatenate([entering[own], g_all[jumps + 1] > 0.0])
                order = np.argsort(at, kind="stable")
                pieces = _assemble(w, np.array([g_all[first] > 0.0]), at[order], enters[order])
                self.found[group][condition.name] = pieces
                out[group][condition.name] = pieces
        return out

    def _crossings(self, cells: _Cells, x, at, precision_s: float) -> NDArray[np.float64]:
        """The crossing in each cell (one, where g' keeps its sign), to ``precision_s``,
        from g at the root x of the cubic through the ends (``at``: the values there,
        its first x.size points).

        With d the slope at x: on [x − δ, x + δ], δ = 2|g(x)|/|d|, g' stays within M δ
        of d, so if M δ < |d|/2 the crossing lies there, and within M δ²/|d| of the
        Newton step x − g(x)/d (Taylor's remainder over a slope at least |d|/2):
        reported when that is below ``precision_s``/2, one evaluation a crossing.  The
        others are refined by the probes and bisection of
        :func:`~attitude.pointing.intervals._refine`."""
        conditions = self.conditions
        if not x.size:
            return x
        g, dg, _, _ = _condition_values(at, conditions)
        column = np.arange(x.size)
        g_x, d_x = g[cells.k, column], dg[cells.k, column]
        bend = self.M[cells.k, cells.p]
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
                at = self.evaluate(τ, sub.p[which], targets=self.condition_targets, bends=())
                values = _condition_values(at, conditions)[0]
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

    def _quantities(
        self, values: _Values, τ: NDArray[np.float64], fraction=None, group=None
    ) -> dict[str, NDArray]:
        """Each problem's function (to minimize) at τ (the lit fraction there, if known;
        ``group``: each time's search)."""
        out = {}
        if fraction is None:
            fraction = self._fraction(τ, group)
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

    def _fraction(self, τ: NDArray[np.float64], group=None) -> NDArray[np.float64]:
        """The lit fraction at τ (``group``: each time's search; None: the window's one
        search): 1 outside the shadow, 0 in umbra, the surroundings' else."""
        fraction = np.ones(τ.shape)
        if not self.any_shadow:
            return fraction
        if group is None:
            assert self.groups == 1
            group = np.zeros(τ.shape, dtype=np.intp)
        in_umbra = _in_any_of(τ, group, self.umbras)
        partial = _in_any_of(τ, group, self.shadows) & ~in_umbra
        fraction[in_umbra] = 0.0
        if np.any(partial):
            fraction[partial] = self.shared.at(τ[partial]).sunlit_fraction
        return fraction

    def _cell_in(self, lists: list[list[Interval]]) -> NDArray[np.bool_]:
        """Whether each cell (between nodes) meets one of its search's intervals
        (``lists[g]``)."""
        out = np.zeros(self.cell.size, dtype=bool)
        for g, which in _by_group(self.cell_group, self.groups):
            intervals = lists[g]
            if not intervals:
                continue
            a, b = self.τ[self.cell[which]], self.τ[self.cell[which] + 1]
            starts = np.array([i.start_s for i in intervals])
            ends = np.array([i.end_s for i in intervals])
            k = np.searchsorted(starts, b, side="left") - 1  # the last one starting before b
            out[which] = (k >= 0) & (ends[np.maximum(k, 0)] > a)
        return out

    def _cosine_bounds(self, target: str):
        """Bounds (low, high), (vectors, cells), on every vector's cosine with ``target``
        in each cell between nodes, from the bend bound (computed once a window)."""
        if target not in self._cosines:
            values, i = self.values, self.cell
            h = self.τ[i + 1] - self.τ[i]
            piece = self.owner[i]
            bend = np.array(
                [
                    [p.plan.bend[(v.name, target)] for p in self.pieces]
                    for v in self.spec.body_vectors
                ]
            )[:, piece]
            f, df = values.f[target], values.df[target]
            self._cosines[target] = _bounds(f[:, i], df[:, i], f[:, i + 1], df[:, i + 1], h, bend)
        return self._cosines[target]

    def _envelope_at(self, j: int, target: str, ask: NDArray[np.intp]):
        """The envelope's angle bounds (:func:`_envelope`) of vector j with ``target`` in
        the cells ``ask`` (computed once a cell)."""
        key = (j, target)
        if key not in self._envelopes:
            size = self.cell.size
            self._envelopes[key] = (np.zeros(size, bool), np.zeros(size), np.full(size, math.pi))
        known, low, high = self._envelopes[key]
        missing = ask[~known[ask]]
        if missing.size:
            i = self.cell[missing]
            σ = self.values.sigma[target]
            low[missing], high[missing] = _envelope(
                self.pieces,
                self.owner[i],
                self.spec.body_vectors[j].name,
                target,
                σ[i],
                σ[i + 1],
                self.τ[i],
                self.τ[i + 1],
            )
            known[missing] = True
        return low[ask], high[ask]

    def _cell_bounds(self, j: int, quantity: str, interesting=None) -> tuple[NDArray, NDArray]:
        """Bounds on a vector's quantity in each cell between nodes; the envelope tightens
        them where ``interesting(low, high)`` (of the bend bound's) says it matters."""
        τ, values, i = self.τ, self.values, self.cell
        h = τ[i + 1] - τ[i]
        target = _TARGET_OF[quantity]
        cos_low, cos_high = self._cosine_bounds(target)
        low, high = cos_low[j].copy(), cos_high[j].copy()

        def tighten(lo, hi, as_cosine: bool, ask_where):
            if ask_where is None:
                return lo, hi
            ask = np.flatnonzero(ask_where(lo, hi))
            if self.groups > 1:  # each search's own count
                counts = np.bincount(self.cell_group[ask], minlength=self.groups)
                ask = ask[counts[self.cell_group[ask]] > _ENVELOPE_LEAST]
                if not ask.size:
                    return lo, hi
            elif ask.size <= _ENVELOPE_LEAST:
                return lo, hi  # a few cells: Newton's steps cost less than the envelope
            env_low, env_high = self._envelope_at(j, target, ask)
            if as_cosine:
                lo[ask] = np.maximum(lo[ask], np.cos(env_high))
                hi[ask] = np.minimum(hi[ask], np.cos(env_low))
            else:
                lo[ask] = np.maximum(lo[ask], env_low)
                hi[ask] = np.minimum(hi[ask], env_high)
            return lo, hi

        if quantity == "cos_incidence":
            low, high = tighten(np.maximum(low, 0.0), np.maximum(high, 0.0), True, interesting)
            low, high = np.maximum(low, 0.0), np.maximum(high, 0.0)
            if not self.any_shadow:
                return low, high
            # The lit fraction: 1 outside the shadow, 0 in umbra, and in the penumbra
            # at most the ends' greater plus its rate over half the cell.
            outside = ~self._cell_in(self.shadows)
            fraction = self._node_fraction
            most = np.maximum(fraction[i], fraction[i + 1]) + self.fraction_rate * 0.5 * h
            return np.where(outside, low, 0.0), np.where(
                outside, high, high * np.minimum(most, 1.0)
            )
        angle_low = np.arccos(np.clip(high, -1.0, 1.0))
        angle_high = np.arccos(np.clip(low, -1.0, 1.0))
        if quantity != "earth_limb_angle":
            return tighten(angle_low, angle_high, False, interesting)
        assert values.limb is not None
        drift = self.limb_rate * 0.5 * h
        limb_low = np.minimum(values.limb[i], values.limb[i + 1]) - drift
        limb_high = np.maximum(values.limb[i], values.limb[i + 1]) + drift
        ask_where = None
        if interesting is not None:

            def ask_where(lo, hi):
                return interesting(lo - limb_high, hi - limb_low)

        angle_low, angle_high = tighten(angle_low, angle_high, False, ask_where)
        return angle_low - limb_high, angle_high - limb_low

    def _cell_within(self, intervals: list[Interval]) -> NDArray[np.bool_]:
        """Whether each cell lies wholly within one of the intervals."""
        a, b = self.τ[self.cell], self.τ[self.cell + 1]
        if not intervals:
            return np.zeros(a.size, dtype=bool)
        starts = np.array([i.start_s for i in intervals])
        ends = np.array([i.end_s for i in intervals])
        k = np.searchsorted(starts, a, side="right") - 1
        return (k >= 0) & (ends[np.maximum(k, 0)] >= b)

    def _extrema_start(self, problems, incumbents, best, tolerance) -> _Newton:
        """The extrema's start: the nodes' values folded into ``best``, the cells whose
        bounds could beat them (by ``tolerance``), and Newton's first points in them
        (where the quantity is smooth; the rest go to golden-section search)."""
        τ = self.τ
        self._node_fraction = self._fraction(τ, self.node_group)
        on_nodes = self._quantities(self.values, τ, self._node_fraction)
        self._node_problems = on_nodes
        for mine, theirs in zip(best, incumbents, strict=True):
            for name in problems:
                known = mine.get(name) or theirs.get(name)
                if known is not None:
                    mine[name] = known
        for g in range(self.groups):
            nodes = slice(int(self.first[g]), int(self.first[g + 1]))
            self._fold({n: on_nodes[n][nodes] for n in problems}, τ[nodes], problems, best[g])
        cells = self.cell_group

        def each(name: str, missing: float):
            # Each cell's search's best value of a problem.
            if self.groups == 1:
                return best[0][name].value if name in best[0] else missing
            return np.array([b[name].value if name in b else missing for b in best])[cells]

        candidates: dict[str, NDArray[np.intp]] = {}
        for j, v in enumerate(self.spec.body_vectors):
            for quantity in _QUANTITIES[: 3 if self.values.limb is None else 5]:
                keys = (f"{v.name}.{quantity}.low", f"{v.name}.{quantity}.high")
                if not any(key in problems for key in keys):
                    continue
                low_best = each(keys[0], -np.inf)
                high_best = -each(keys[1], -np.inf)

                def interesting(lo, hi, lb=low_best, hb=high_best):
                    return (lo < lb - tolerance) | (hi > hb + tolerance)

                low, high = self._cell_bounds(j, quantity, interesting)
                for name, bound in ((keys[0], low), (keys[1], -high)):
                    if name in problems:
                        candidates[name] = np.flatnonzero(bound < each(name, np.nan) - tolerance)
        return _Newton.start(self, candidates)

    def _extrema_finish(self, newton, at, offset, problems, best, tolerance, precision_s):
        """Newton's steps from the first points' values (``at``, from ``offset``), then
        golden-section search for what is left."""
        τ, on_nodes = self.τ, self._node_problems
        left = newton.run(self, at, offset, problems[0], best, tolerance)
        # Golden-section search, each search's cells alone (few are left to it).
        for g in range(self.groups):
            nodes = slice(int(self.first[g]), int(self.first[g + 1]))

            def evaluate(t: NDArray[np.float64], piece: NDArray[np.intp], g=g):
                group = np.full(t.shape, g, dtype=np.intp)
                return self._quantities(self.evaluate(t, piece, angles=True), t, group=group)

            brackets: dict[str, tuple[NDArray[np.float64], ...]] = {}
            for name, cells in left.items():
                if self.groups > 1:
                    cells = cells[self.cell_group[cells] == g]
                i = self.cell[cells]
                values = on_nodes[name]
                brackets[name] = (τ[i], τ[i + 1], values[i], values[i + 1])
            if any(b[0].size for b in brackets.values()):
                found = least_in_brackets(
                    _PiecewiseCall(evaluate, τ[nodes], self.owner[nodes]),
                    brackets,
                    problems[g],
                    best[g],
                    tolerance,
                    precision_s,
                )
                best[g].update(found)

    def _fold(self, quantities, times, problems, best) -> None:
        """Fold the values of the problems at ``times`` into ``best``."""
        for name in problems:
            values = quantities[name]
            i = int(np.argmin(values))
            if name not in best or values[i] < best[name].value:
                best[name] = Extremum(float(times[i]), float(values[i]))

    # ---------------------------------------------------------------- incidence

    def incidence(self) -> list[dict[str, float]]:
        """Each search's integral of max(f_sun, 0) × lit fraction over the window, for
        each vector, on the quintic through each cell's ends (their values, slopes and
        bends) of the Sun's visibility: in closed form, h (f0 + f1)/2 + h² (f0' −
        f1')/10 + h³ (f0'' + f1'')/120, on a cell lit throughout and outside the
        shadow; by 4 Gauss–Legendre points (exact for a quintic) on the lit part of a
        cell cut by a crossing, or with the lit fraction where the cell meets the
        shadow."""
        index_of = {
            k: c.vector for k, c in enumerate(self.conditions) if c.name.endswith(".sun_visible")
        }
        mine = np.isin(self.cells.k, list(index_of))
        cells = self.cells.take(mine)
        status = self.status[mine]
        cross = self.cross[mine]
        vector = np.array([index_of[k] for k in cells.k.tolist()], dtype=np.intp)
        lit_a = cells.ga > 0.0
        keep = ((status == 0) & lit_a) | (status == 1)
        cells, status, cross, vector = cells.take(keep), status[keep], cross[keep], vector[keep]
        h = cells.b - cells.a
        a, b = cells.a.copy(), cells.b.copy()
        cut = status == 1
        entering = cells.ga <= 0.0
        a[cut] = np.where(entering[cut], cross[cut], a[cut])
        b[cut] = np.where(entering[cut], b[cut], cross[cut])
        group = self.piece_group[cells.p]
        meets = np.zeros(h.size, dtype=bool)
        if self.any_shadow:
            shadows = self.shadows
            meets = (
                _in_any_of(0.5 * (a + b), group, shadows)
                | _in_any_of(a, group, shadows)
                | _in_any_of(b, group, shadows)
            )
        whole = ~cut & ~meets
        total = np.zeros(h.size)
        hw = h[whole]
        total[whole] = (
            0.5 * hw * (cells.ga[whole] + cells.gb[whole])
            + hw * hw * (cells.da[whole] - cells.db[whole]) / 10.0
            + hw**3 * (cells.ea[whole] + cells.eb[whole]) / 120.0
        )
        rows = np.flatnonzero(~whole)
        if rows.size:
            hr = h[rows]
            c = _quintic(
                cells.ga[rows],
                hr * cells.da[rows],
                hr * hr * cells.ea[rows],
                cells.gb[rows],
                hr * cells.db[rows],
                hr * hr * cells.eb[rows],
            )
            lo, hi = a[rows], b[rows]
            x = 0.5 * (hi + lo)[:, None] + 0.5 * (hi - lo)[:, None] * _GAUSS_X[None, :]
            s = (x - cells.a[rows][:, None]) / hr[:, None]
            f = np.maximum(_polynomial_at(tuple(ci[:, None] for ci in c), s), 0.0)
            weight = np.ones_like(f)
            shaded = meets[rows]
            if np.any(shaded):
                points = np.repeat(group[rows][shaded], _GAUSS_X.size)
                weight[shaded] = self._fraction(x[shaded].ravel(), points).reshape(
                    -1, _GAUSS_X.size
                )
            # The Gauss sum written out: each cell's sum in one order, whatever the
            # cells summed with it (a matrix product's order may depend on their count).
            fw = f * weight
            w = _GAUSS_W
            total[rows] = (
                (fw[:, 0] * w[0] + fw[:, 1] * w[1] + fw[:, 2] * w[2] + fw[:, 3] * w[3])
                * 0.5
                * (hi - lo)
            )
        # np.bincount adds each bin's weights in their order: a search's cells in the
        # order it has alone.
        V = len(self.spec.body_vectors)
        sums = np.bincount(group * V + vector, weights=total, minlength=self.groups * V)
        names = [(j, self.spec.body_vectors[j].name) for j in sorted(set(index_of.values()))]
        return [{name: float(sums[g * V + j]) for j, name in names} for g in range(self.groups)]

    def dark(self) -> list[dict[str, bool]]:
        """Whether each search's each vector saw no Sun at some time of the window."""
        outs = []
        for g in range(self.groups):
            out = {}
            span = (self.τ[self.first[g]], self.τ[self.first[g + 1] - 1])
            in_umbra = any(i.end_s > span[0] and i.start_s < span[1] for i in self.umbras[g])
            for condition in self.conditions:
                if condition.name.endswith(".sun_visible"):
                    name = self.spec.body_vectors[condition.vector].name
                    pieces = self.found[g][condition.name]
                    lit = len(pieces) == 1 and pieces[0].starts_before and pieces[0].ends_after
                    out[name] = in_umbra or not lit
            outs.append(out)
        return outs


class _PiecewiseCall:
    """``evaluate(t, piece)`` as golden-section search calls it, ``evaluate(t)``: each
    point on the piece whose nodes surround it (no cell spans two pieces)."""

    def __init__(self, evaluate, τ: NDArray[np.float64], owner: NDArray[np.intp]) -> None:
        self.evaluate, self.τ, self.owner = evaluate, τ, owner

    def __call__(self, t: NDArray[np.float64]) -> dict[str, NDArray[np.float64]]:
        k = np.clip(np.searchsorted(self.τ, t, side="right") - 1, 0, self.τ.size - 1)
        return self.evaluate(t, self.owner[k])


class _Newton:
    """Newton's method on the slope of a cosine, for the candidate cells of the smooth
    extremum problems: the angles to the Sun, the Moon and nadir (the least angle where
    the cosine is greatest, the greatest where it is least), the incidence outside the
    Earth's shadow (the cosine itself) and the limb angle (nadir's cosine, its slope
    shifted by the limb's rate: d/dt (α − ρ) = 0 ⇔ f' + ρ̇ sin α = 0).  From the
    extremum of the cubic through the cell's ends, each step moves to x − s/f'' (s that
    slope, f'' the exact bend), kept within the cell; every point evaluated counts for
    every problem.  A cell is done when its next step could improve its quantity by
    less than the tolerance (½|f''| step², over sin α for an angle), when it
    sits at an end that the slope leaves by, or where the function is convex at the
    cubic's peak: the cell then holds no peak, and its best is the end the slope climbs
    to (a node, counted).  In the shadow the incidence is the cosine times the lit
    fraction F, whose slope and bend come from F by central differences.  A cell still
    moving after :data:`_NEWTON_STEPS` is left to golden-section search."""

    def __init__(self) -> None:
        self.rows: list = []
        self.left: dict[str, NDArray[np.intp]] = {}
        self.x = np.empty(0)
        self.piece = np.empty(0, dtype=np.intp)
        # Per cell stepped: its row, cell index, sign, ends.
        self.which_row = np.empty(0, dtype=np.intp)
        self.cells = np.empty(0, dtype=np.intp)
        self.sign = np.empty(0)
        self.a = np.empty(0)
        self.b = np.empty(0)

    @classmethod
    def start(cls, window: _Window, candidates: dict[str, NDArray[np.intp]]) -> _Newton:
        """The rows (problem, vector, target, sign, kind, cells) and the first points."""
        self = cls()
        values, τ = window.values, window.τ
        index = {v.name: j for j, v in enumerate(window.spec.body_vectors)}
        shadow = window._cell_in(window.shadows)
        for name, cells in candidates.items():
            vector, quantity, end = name.rsplit(".", 2)
            target = _TARGET_OF[quantity]
            self.left[name] = cells[:0]
            if target not in values.f:
                self.left[name] = cells
                continue
            # +1 where the quantity is extreme where the cosine is greatest.
            sign = 1.0 if (end == "low") != (quantity == "cos_incidence") else -1.0
            kind = {"earth_limb_angle": "limb", "cos_incidence": "cosine"}.get(quantity, "angle")
            if kind == "cosine":
                # In the shadow the incidence is the cosine times the lit fraction.
                shaded = shadow[cells]
                for part, part_kind in ((cells[~shaded], kind), (cells[shaded], "shaded")):
                    if part.size:
                        self.rows.append((name, index[vector], target, sign, part_kind, part))
                continue
            self.rows.append((name, index[vector], target, sign, kind, cells))
        if not self.rows:
            return self
        self.which_row = np.concatenate([np.full(r[5].size, k) for k, r in enumerate(self.rows)])
        self.cells = np.concatenate([r[5] for r in self.rows])
        self.sign = np.concatenate([np.full(r[5].size, r[3]) for r in self.rows])
        i = window.cell[self.cells]
        self.a, self.b, self.piece = τ[i], τ[i + 1], window.owner[i]
        h = self.b - self.a
        ga, gb, da, db = (np.empty(self.cells.size) for _ in range(4))
        for k, r in enumerate(self.rows):
            mine = self.which_row == k
            f, df = values.f[r[2]][r[1]], values.df[r[2]][r[1]]
            j = i[mine]
            ga[mine], gb[mine], da[mine], db[mine] = f[j], f[j + 1], df[j], df[j + 1]
        s = self.sign
        c = _cubic(s * ga, s * da, s * gb, s * db, h)
        self.x = self.a + _cubic_peak(c, np.ones(self.a.size, dtype=np.bool_)) * h
        return self

    def _fold(self, window: _Window, at: _Values, times, which, points, best) -> None:
        """Fold each row's quantity at its own points (``which``: the rows' cells being
        stepped, ``points``: their indices into ``at``) into each search's ``best[g]``."""
        for k in np.unique(self.which_row[which]).tolist():
            name, j, target, _, kind, _ = self.rows[k]
            mine = self.which_row[which] == k
            there = points[mine]
            group = window.cell_group[self.cells[which[mine]]]
            if kind == "cosine":
                q = np.maximum(at.f[target][j][there], 0.0)  # outside the shadow: lit
            elif kind == "shaded":
                q = np.maximum(at.f[target][j][there], 0.0) * window._fraction(times[there], group)
            else:
                q = at.angle[target][j][there]
                if kind == "limb":
                    assert at.limb is not None
                    q = q - at.limb[there]
            if name.endswith(".high"):
                q = -q
            for g, own in _by_group(group, window.groups):
                i = int(np.argmin(q[own]))
                if q[own][i] < best[g][name].value:
                    best[g][name] = Extremum(float(times[there][own][i]), float(q[own][i]))

    def targets(self) -> set[str]:
        """The targets of the rows (what their steps evaluate)."""
        return {r[2] for r in self.rows}

    def run(self, window: _Window, at, offset: int, problems, best, tolerance):
        """The steps, the first from ``at`` (the values at ``self.x``, from
        ``offset``); returns the cells left to golden-section search, per problem."""
        if not self.rows:
            return self.left
        active = np.ones(self.x.size, dtype=bool)
        for count in range(_NEWTON_STEPS):
            which = np.flatnonzero(active)
            if not which.size:
                break
            if count == 0:
                points = offset + which
                times = np.concatenate([np.full(offset, np.nan), self.x])
            else:
                keys = np.stack([self.x[which], self.piece[which].astype(np.float64)])
                unique, inverse = np.unique(keys, axis=1, return_inverse=True)
                targets = {self.rows[k][2] for k in np.unique(self.which_row[which]).tolist()}
                at = window.evaluate(
                    unique[0],
                    unique[1].astype(np.intp),
                    angles=targets,
                    targets=targets,
                    bends=targets,
                )
                points, times = inverse.ravel(), unique[0]
            self._fold(window, at, times, which, points, best)
            slope, bend, size = (np.empty(which.size) for _ in range(3))
            for k, r in enumerate(self.rows):
                mine = self.which_row[which] == k
                if not np.any(mine):
                    continue
                there = points[mine]
                slope[mine] = at.df[r[2]][r[1]][there]
                bend[mine] = at.ddf[r[2]][r[1]][there]
                size[mine] = np.sin(at.angle[r[2]][r[1]][there]) if r[4] in _ANGLES else 1.0
                if r[4] == "limb":  # the slope of α − ρ, times −sin α
                    assert at.limb_rate is not None
                    slope[mine] += at.limb_rate[there] * size[mine]
                if r[4] == "shaded":  # (f F)' and (f F)'' with F the lit fraction
                    f = at.f[r[2]][r[1]][there]
                    t = times[there]
                    group = window.cell_group[self.cells[which[mine]]]
                    F = window._fraction(t, group)
                    ahead = window._fraction(t + _FRACTION_STEP_S, group)
                    behind = window._fraction(t - _FRACTION_STEP_S, group)
                    F1 = (ahead - behind) / (2.0 * _FRACTION_STEP_S)
                    F2 = (ahead - 2.0 * F + behind) / _FRACTION_STEP_S**2
                    bend[mine] = bend[mine] * F + 2.0 * slope[mine] * F1 + f * F2
                    slope[mine] = slope[mine] * F + f * F1
            slope, bend = self.sign[which] * slope, self.sign[which] * bend
            with np.errstate(divide="ignore", invalid="ignore"):
                step = -slope / bend
                gain = 0.5 * np.abs(bend) * step * step / np.maximum(size, 1e-300)
            concave = bend < 0.0
            x = self.x[which]
            a, b = self.a[which], self.b[which]
            new = np.clip(x + step, a, b)
            done = concave & ((np.abs(new - x) <= _NEWTON_DONE_S) | (gain < tolerance))
            # At an end, a slope that leaves the cell: the end is the cell's best.
            done |= ((x == a) & (slope < 0.0)) | ((x == b) & (slope > 0.0))
            # Convex where the cubic put its peak: the cell holds no peak of its own,
            # its best is the end the slope climbs to (a node, already counted).
            flat = ~concave & ~done
            done |= flat
            self.x[which] = np.where(concave, new, np.where(slope > 0.0, b, a))
            active[which[done]] = False
        failed = active
        for k, r in enumerate(self.rows):
            more = self.cells[(self.which_row == k) & failed]
            self.left[r[0]] = np.concatenate([self.left.get(r[0], more[:0]), more])
        return self.left
