"""A global start for sparse fixes: the inertia ratios and the phase searched from the
fixes themselves, and every family of solutions that fits reported.

Radar or ground-based fixes a day apart, each with the body rates (and, mostly, the
attitude) at its time, are too sparse for the linear first guess (no derivative of the
rates), and between two of them the body turns hundreds of times: a start whose period
is off by a thousandth slips by a turn, and the least squares has a minimum at each
number of turns.  Several of them may fit the fixes within the noise: the fixes then
do not decide, and each is a *family* of solutions.  The search:

1. **Momentum and energy** (the conservation laws of the torque-free motion: no phase
   in them).  For moments J = (1, e^ρ2, e^ρ3) along the body axes (in units of the
   first), each fix k gives 2T_k = ω_k · J ω_k and, with its attitude, the inertial
   momentum H_k = Q_k J ω_k (without one, |J ω_k|); all must be equal.  Their weighted
   means profiled out, the scatter χ²_c(ρ) (each term over its noise, propagated from
   the rates' and the attitude's σ) is computed on a grid over ρ ∈ [−ln 20, ln 20]²
   (the triangle inequality kept), and each of its minima refined by least squares:
   ρ_c and its covariance C_c.  Momentum and energy that the fixes do not conserve
   within their noise (a torque, a wrong σ) are refused here.
2. **The turns between the first two fixes.**  The ratios as far from ρ_c as a family
   could lie and still fit (the square root of the ``FAMILY_P`` quantile of the fit's
   χ², in σ of C_c) are searched on a grid fine enough that the predictions at the fixes
   move by at most ``GRID_PHASE_RAD`` between neighbours (the spacing from the exact
   flow's sensitivities at ρ_c), each point started from the first fix (its rate and
   attitude), all points at once (``EulerSolverBatch``).  Each local minimum of the
   grid is settled by Levenberg–Marquardt in every parameter of the motion (all points
   at once, ``_settled``), then polished by least squares on the exact motion with its
   Jacobian; the solutions within the noise are the families of the two fixes.
3. **Fix by fix**, as the growing arc of attitude.estimation.solve takes samples: each
   family is carried to the next fix.  If it predicts it to within a fraction of a
   turn, it is kept when the fix lies within the noise of the prediction (and
   refitted), dropped otherwise; if not, it is split again about itself (step 2 with
   its own covariance).  A fix at an irregular interval removes most families (their
   numbers of turns no longer agree); fixes at the same time each day remove none.
4. **Families**: every solution left whose χ² is within the noise (a probability of a
   larger one of at least ``FAMILY_P``), told from the others by its rate and ratios
   (more than 3 σ apart), best χ² first, each with its own covariance; the fit says
   when there are several (``attitude.estimation.fit``).  More than ``MAX_FAMILIES``
   (or ``MAX_HYPOTHESES`` followed on the way, or a grid of more than ``MAX_GRID``
   points) is refused: the fixes cannot decide the turns between them, and closer or
   more fixes, or a guess, are needed.

The grid's spacing was checked against one of 0.15 rad on seven noise realisations of
three daily fixes (the same families).  Known impulses and burns break the
conservation laws and are not searched through: sparse fixes across them need a guess.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import stats
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.environment.timescales import SAME_INSTANT_S
from attitude.estimation.solve import Data, FitRefused, Solution, _final, residuals
from attitude.estimation.statistics import covariance
from attitude.solver.batch import EulerSolverBatch

__all__ = ["FAMILY_P", "MAX_FAMILIES", "MAX_GRID", "Invariants", "families", "invariants"]

# The moments searched: within this factor of each other (ρ within ±ln 20).
RATIO_RANGE = 20.0
# The conservation grid's spacing in ρ.
COARSE_STEP = 0.03
# The phase grid: neighbours' predictions at most this far apart (rad, or rates as a
# fraction of their size).
GRID_PHASE_RAD = 0.3
MAX_GRID = 40_000
# Families followed from fix to fix at most (beyond: the fixes cannot decide).
MAX_HYPOTHESES = 500
# A family fits within the noise: its χ² has at least this probability of a larger one.
FAMILY_P = 1e-3
MAX_FAMILIES = 20
# Momentum and energy conserved within the noise: χ²_c below its 1 − this quantile.
CONSERVATION_P = 1e-4


@dataclass(frozen=True)
class Fixes:
    """The fixes as the conservation laws take them: rates at their times (K, 3) with
    σ (3,), and the attitude at the same times (a Rotation, or None where a fix has
    none: ``paired``)."""

    t: NDArray[np.float64]
    ω: NDArray[np.float64]
    σ_ω: NDArray[np.float64]
    Q: Rotation | None
    paired: NDArray[np.bool_]
    σ_θ: float


@dataclass(frozen=True)
class Invariants:
    """A minimum of the conservation scatter: ρ_c, its covariance, χ²_c and its dof."""

    ρ: NDArray[np.float64]
    covariance: NDArray[np.float64]
    chi2: float
    dof: int


def fixes_of(data: Data) -> Fixes:
    """The rate samples, with the attitude at the same instant where there is one."""
    if data.t_rates is None or data.rates is None or data.σ_rates is None:
        raise InputError(
            "sparse attitude fixes without rates: the rates at the fixes (radar, a gyro "
            "reading) or a guess are needed to start the fit"
        )
    t = data.t_rates
    paired = np.zeros(t.size, dtype=bool)
    Q = None
    if data.t_attitude is not None and data.attitude is not None:
        nearest = np.clip(np.searchsorted(data.t_attitude, t), 0, data.t_attitude.size - 1)
        for shift in (0, -1):
            k = np.clip(nearest + shift, 0, data.t_attitude.size - 1)
            near = np.abs(data.t_attitude[k] - t) <= SAME_INSTANT_S
            nearest = np.where(near & ~paired, k, nearest)
            paired |= near
        Q = data.attitude[nearest]
    σ_θ = float(data.σ_attitude) if data.σ_attitude is not None else 0.0
    return Fixes(t, data.rates, np.asarray(data.σ_rates, dtype=float), Q, paired, σ_θ)


# ----------------------------------------------------------------- 1. momentum and energy


def _moments(ρ: NDArray[np.float64]) -> NDArray[np.float64]:
    """J = (1, e^ρ2, e^ρ3) for each row of ρ (G, 2)."""
    return np.exp(np.concatenate([np.zeros((ρ.shape[0], 1)), ρ], axis=1))


def _scatter(fixes: Fixes, ρ: NDArray[np.float64]) -> NDArray[np.float64]:
    """The normalized deviations of each fix's invariants from their weighted means,
    (G, count) for ρ (G, 2): 2T, and H (three components) or |H| per fix."""
    J = _moments(ρ)[:, None, :]  # (G, 1, 3)
    ω, σ = fixes.ω[None, :, :], fixes.σ_ω
    Jω = J * ω  # (G, K, 3)
    energy = np.sum(Jω * ω, axis=2)
    σ_energy = 2.0 * np.sqrt(np.sum((Jω * σ) ** 2, axis=2))
    parts = [_deviations(energy, σ_energy)]
    size = np.linalg.norm(Jω, axis=2)
    lone = ~fixes.paired
    if np.any(lone):  # |H| alone: dH = J dω projected on H
        σ_size = np.sqrt(np.sum((J * Jω * σ) ** 2, axis=2)) / np.maximum(size, 1e-300)
        parts.append(_deviations(size[:, lone], σ_size[:, lone]))
    if fixes.Q is not None and np.any(fixes.paired):
        pairs = np.flatnonzero(fixes.paired)
        R = fixes.Q[pairs].as_matrix()  # (P, 3, 3)
        H = np.einsum("kij,gkj->gki", R, Jω[:, pairs])
        # Isotropic noise per component: the rates' through J, the attitude's across H.
        σ_H = np.sqrt(
            np.mean((J * σ) ** 2, axis=2) + (fixes.σ_θ * size[:, pairs]) ** 2 * (2.0 / 3.0)
        )
        for axis in range(3):
            parts.append(_deviations(H[:, :, axis], σ_H))
    return np.concatenate(parts, axis=1)


def _deviations(values: NDArray[np.float64], σ: NDArray[np.float64]) -> NDArray[np.float64]:
    """(values − their weighted mean) / σ, each row (G, K) on its own."""
    w = 1.0 / np.maximum(σ, 1e-300) ** 2
    mean = np.sum(values * w, axis=1, keepdims=True) / np.sum(w, axis=1, keepdims=True)
    return (values - mean) / np.maximum(σ, 1e-300)


def _physical(ρ: NDArray[np.float64]) -> NDArray[np.bool_]:
    """The triangle inequality J_i ≤ J_j + J_k of a real body, for each row of ρ."""
    J = _moments(ρ)
    return np.all(2.0 * J <= J.sum(axis=1, keepdims=True) * (1.0 + 1e-9), axis=1)


def invariants(fixes: Fixes, source: str) -> list[Invariants]:
    """The minima of the conservation scatter (module docstring, step 1), best first."""
    limit = math.log(RATIO_RANGE)
    axis = np.arange(-limit, limit + COARSE_STEP / 2, COARSE_STEP)
    grid = np.stack(np.meshgrid(axis, axis, indexing="ij"), axis=-1).reshape(-1, 2)
    chi2 = np.full(grid.shape[0], np.inf)
    keep = _physical(grid)
    chi2[keep] = np.sum(_scatter(fixes, grid[keep]) ** 2, axis=1)
    count = _scatter(fixes, grid[:1]).shape[1]
    # Each fix's invariants have one mean among them; 2 ratios are fitted.
    groups = 1 + (1 if np.any(~fixes.paired) else 0) + (3 if np.any(fixes.paired) else 0)
    dof = count - groups - 2
    if dof < 1:
        raise FitRefused(
            f"{fixes.t.size} fix(es): too few for their momentum and energy to show the "
            "inertia ratios; more fixes (with their rates and attitude), or a guess",
            file=source,
        )
    surface = chi2.reshape(axis.size, axis.size)
    minima = _local_minima(surface)
    best = float(np.min(surface.ravel()[minima])) if minima.size else math.inf
    found: list[Invariants] = []
    for index in minima[np.argsort(surface.ravel()[minima])][:12]:
        if surface.ravel()[index] > best + 100.0:
            break
        refined = _refine(fixes, grid[index], dof)
        if refined is not None and not any(
            _mahalanobis(refined.ρ - other.ρ, other.covariance) < 1.0 for other in found
        ):
            found.append(refined)
    found.sort(key=lambda item: item.chi2)
    if not found or stats.chi2.sf(found[0].chi2, dof) < CONSERVATION_P:
        shown = f"{found[0].chi2:.4g}" if found else "inf"
        raise FitRefused(
            f"the fixes' momentum and energy are not conserved within their noise "
            f"(chi2 {shown} for {dof} degrees of freedom at the best inertia ratios): a "
            "torque between the fixes, or a noise given too small?",
            file=source,
        )
    return [f for f in found if stats.chi2.sf(f.chi2, dof) >= CONSERVATION_P]


def _local_minima(surface: NDArray[np.float64]) -> NDArray[np.intp]:
    """Flat indices of the finite points not above any of their 8 neighbours."""
    padded = np.pad(surface, 1, constant_values=np.inf)
    centre = padded[1:-1, 1:-1]
    lowest = np.isfinite(centre)
    for di, dj in itertools.product((-1, 0, 1), repeat=2):
        if di or dj:
            neighbour = padded[1 + di : padded.shape[0] - 1 + di, 1 + dj : padded.shape[1] - 1 + dj]
            lowest &= centre <= neighbour
    return np.flatnonzero(lowest)


def _refine(fixes: Fixes, ρ0: NDArray[np.float64], dof: int) -> Invariants | None:
    def fun(ρ):
        return _scatter(fixes, ρ[None, :])[0]

    result = least_squares(fun, ρ0, method="lm", x_scale=1.0)
    if not np.all(np.isfinite(result.x)) or not _physical(result.x[None, :])[0]:
        return None
    D = np.asarray(result.jac, dtype=np.float64)
    covariance: NDArray[np.float64]
    try:
        covariance = np.asarray(np.linalg.inv(D.T @ D), dtype=np.float64)
    except np.linalg.LinAlgError:
        covariance = np.full((2, 2), np.inf)
    return Invariants(np.asarray(result.x, dtype=np.float64), covariance, 2.0 * result.cost, dof)


def _mahalanobis(δ: NDArray[np.float64], covariance: NDArray[np.float64]) -> float:
    try:
        return float(np.sqrt(max(float(δ @ np.linalg.solve(covariance, δ)), 0.0)))
    except np.linalg.LinAlgError:
        return math.inf


# ----------------------------------------------------------------- 2. the phase


def _region_grid(model, x, data: Data, centre, covariance, reach: float, source: str):
    """The ratios searched about ``centre`` (ρ, with ``covariance``): a grid whose
    neighbours' predictions at the times of ``data`` differ by at most
    ``GRID_PHASE_RAD`` (the spacing from the exact flow's sensitivities at ``x``),
    over ``reach`` σ of the covariance.  (G, 2) points, the grid's shape and the
    metric SᵀS of the predictions' changes."""
    ρ_block = model.layout.block("ρ")
    rates, attitude = model.predict(x, data.t_rates, data.t_attitude, True)
    rows = []
    if rates.dω is not None and rates.ω is not None:
        size = np.maximum(np.linalg.norm(rates.ω, axis=1), 1e-300)
        rows.append((rates.dω[:, :, ρ_block] / size[:, None, None]).reshape(-1, 2))
    if attitude.dθ is not None:
        rows.append(attitude.dθ[:, :, ρ_block].reshape(-1, 2))
    S = np.concatenate(rows)
    λ, E = np.linalg.eigh(S.T @ S)
    spacing = GRID_PHASE_RAD / np.sqrt(np.maximum(λ, 1e-300))
    spread = np.einsum("ji,jk,ki->i", E, covariance, E)
    extent = np.minimum(reach * np.sqrt(np.maximum(spread, 0.0)), math.log(RATIO_RANGE))
    counts = 2 * np.ceil(extent / spacing).astype(np.int64) + 1  # odd: the centre is in
    total = float(np.prod(counts.astype(float)))
    if not math.isfinite(total) or total > MAX_GRID:
        turns = float(np.prod(np.maximum(extent * np.sqrt(λ) / math.pi, 1.0)))
        raise FitRefused(
            "the fixes cannot decide the number of turns between them: their momentum and "
            f"energy leave the inertia ratios free over about {turns:.3g} families of "
            f"solutions, more than the {MAX_FAMILIES} reported; closer or more fixes, or a "
            "guess",
            file=source,
        )
    axes = [
        np.linspace(-e, e, int(c)) if c > 1 else np.zeros(1)
        for e, c in zip(extent, counts, strict=True)
    ]
    a, b = np.meshgrid(*axes, indexing="ij")
    points = centre[None, :] + np.stack([a.ravel(), b.ravel()], axis=1) @ E.T
    return points, tuple(int(c) for c in counts), S.T @ S


def _grid_residuals(points, data: Data, ω0, Q0) -> NDArray[np.float64]:
    """The normalized residuals (G, R) of the motion of each grid point (ratios ρ
    (G, 2); the rate ``ω0`` (3,) or (G, 3) and the attitude ``Q0`` (one, a stack of G,
    or None) at t = 0), all points at once (``EulerSolverBatch``); rows of inf for the
    points that are no real body."""
    J = _moments(points)
    keep = _physical(points)
    ω0 = np.broadcast_to(ω0, (points.shape[0], 3))[keep]
    if Q0 is not None and not Q0.single:
        Q0 = Q0[np.flatnonzero(keep)]
    parts = []
    J = J[keep]
    if J.shape[0] == 3:  # (3, 3) reads as one tensor: a fourth state, dropped after
        J, ω0 = np.vstack([J, J[:1]]), np.vstack([ω0, ω0[:1]])
        if Q0 is not None and not Q0.single:
            Q0 = Rotation.concatenate([Q0, Q0[:1]])
    batch = EulerSolverBatch.from_angular_velocity(J, ω0, Q0, 0.0)
    if data.t_rates is not None and data.rates is not None and data.σ_rates is not None:
        ω = batch.angular_velocity(data.t_rates)[: int(keep.sum())]  # (G, K, 3)
        parts.append(((ω - data.rates[None]) / data.σ_rates).reshape(ω.shape[0], -1))
    if data.t_attitude is not None and data.attitude is not None and data.σ_attitude:
        q = batch.attitude_quaternion(data.t_attitude, scalar_first=True)[: int(keep.sum())]
        predicted = Rotation.from_quat(q.reshape(-1, 4), scalar_first=True)
        measured = Rotation.concatenate([data.attitude] * int(keep.sum()))
        r = (predicted.inv() * measured).as_rotvec() / data.σ_attitude
        parts.append(r.reshape(q.shape[0], -1))
    out = np.full((points.shape[0], sum(p.shape[1] for p in parts)), np.inf)
    out[keep] = np.concatenate(parts, axis=1)
    return out


def _settled(points, data: Data, ω0, Q_ref, unit: float, iterations: int = 30):
    """Each grid point moved to the nearest minimum of the residuals in every parameter
    of the motion: the ratios, the rate at t = 0 and (with attitude fixes) the attitude
    at t = 0 as a rotation vector about ``Q_ref``; Levenberg–Marquardt steps with the
    Jacobian by forward differences, all points at once (those still moving).  The
    ratios (G, 2), the rates (G, 3), the attitudes (a Rotation of G, or None) and the
    residuals' χ² (G,)."""
    count = points.shape[0]
    width = 5 + (3 if Q_ref is not None else 0)
    z = np.zeros((count, width))
    z[:, :2], z[:, 2:5] = points, ω0 / unit

    def attitude(z):
        return None if Q_ref is None else Q_ref * Rotation.from_rotvec(z[:, 5:8])

    def evaluate(z):
        return _grid_residuals(z[:, :2], data, z[:, 2:5] * unit, attitude(z))

    h = 1e-7
    damping = np.full(count, 1.0)  # cautious first steps: the residuals wrap at π
    r = evaluate(z)
    cost = np.sum(r * r, axis=1)
    moving = np.isfinite(cost)
    for _ in range(iterations):
        rows = np.flatnonzero(moving)
        if rows.size == 0:
            break
        zr, rr = z[rows], r[rows]
        D = np.stack([(evaluate(zr + h * e) - rr) / h for e in np.eye(width)], axis=2)
        D[~np.isfinite(D)] = 0.0
        A = np.einsum("gri,grj->gij", D, D)
        diagonal = np.maximum(np.einsum("gii->gi", A), 1e-12)
        A += damping[rows, None, None] * (np.eye(width)[None] * diagonal[:, None, :])
        step = np.linalg.solve(A, -np.einsum("gri,gr->gi", D, rr)[..., None])[..., 0]
        r_trial = evaluate(zr + step)
        cost_trial = np.sum(r_trial * r_trial, axis=1)
        better = np.isfinite(cost_trial) & (cost_trial < cost[rows])
        settled = better & (cost[rows] - cost_trial <= 1e-6 * cost[rows] + 1e-9)
        good = rows[better]
        z[good], r[good] = zr[better] + step[better], r_trial[better]
        cost[good] = cost_trial[better]
        damping[rows] = np.where(better, damping[rows] * 0.2, damping[rows] * 10.0)
        moving[rows[settled]] = False
        moving &= damping < 1e8
    return z[:, :2], z[:, 2:5] * unit, attitude(z), cost


def _expand(model, x, data: Data, centre, covariance, reach: float, source: str) -> list[Solution]:
    """The solutions on ``data`` started from the minima of the residuals over a grid of
    ratios about ``centre`` (the other parameters of ``x`` held): the grid's local
    minima, each settled to its own (``_settled``), one start per minimum."""
    points, shape, metric = _region_grid(model, x, data, centre, covariance, reach, source)
    Q0 = model.initial_attitude(x) if model.layout.attitude else None
    ω0 = model.rate(x)
    r = _grid_residuals(points, data, ω0, Q0)
    costs = np.sum(r * r, axis=1)
    inside = _mahalanobis_rows(points - centre, covariance) <= reach
    costs[~inside] = np.inf
    minima = _local_minima(costs.reshape(shape))
    minima = minima[np.isfinite(costs[minima])]
    if minima.size == 0:
        return []
    settled, rates, attitudes, final = _settled(points[minima], data, ω0, Q0, model.rate_unit)
    starts: list[int] = []
    for index in np.argsort(final):  # one start per minimum: the best of those near it
        if not math.isfinite(final[index]):
            continue
        point = settled[index]
        near = (
            float(np.sqrt((point - settled[k]) @ metric @ (point - settled[k])))
            + float(np.linalg.norm(rates[index] - rates[k]) / np.linalg.norm(rates[k]))
            for k in starts
        )
        if all(distance > 1e-3 for distance in near):  # settled to the same point: one start
            starts.append(int(index))
    out: list[Solution] = []
    L = model.layout
    for index in starts:
        start = x.copy()
        start[L.block("ρ")] = settled[index]
        start[L.block("w")] = rates[index] / model.rate_unit
        if attitudes is not None:  # Q0 = Q_ref exp([θ]×), about the model's reference
            start[L.block("θ")] = (model.Q_ref.inv() * attitudes[int(index)]).as_rotvec()
        solution = _local(model, start, data)
        if solution is not None and not any(_same(solution, other) for other in out):
            out.append(solution)
    return out


def _mahalanobis_rows(
    δ: NDArray[np.float64], covariance: NDArray[np.float64]
) -> NDArray[np.float64]:
    try:
        inverse = np.linalg.inv(covariance)
    except np.linalg.LinAlgError:
        return np.zeros(δ.shape[0])
    return np.sqrt(np.maximum(np.einsum("gi,ij,gj->g", δ, inverse, δ), 0.0))


# ----------------------------------------------------------------- 3. the families


def families(model, data: Data, source: str, progress=None) -> tuple[list[Solution], str]:
    """Every family of solutions that fits the sparse fixes within the noise, best
    first, and a line describing the search (module docstring).

    The fixes are taken in time order, as the growing arc of attitude.estimation.solve
    takes samples: the families of the first two fixes from a grid about the ratios of
    the conservation laws, then each family carried to the next fix, kept if it
    predicts it within the noise, and split into the families about it again where its
    prediction there is too uncertain to decide the turns between."""
    say = progress or (lambda text: None)
    fixes = fixes_of(data)
    L = model.layout
    if getattr(model, "impulses", ()) or getattr(model, "burns", ()) or L.scale:
        raise FitRefused(
            "sparse fixes across known impulses or burns: their momentum and energy are "
            "not conserved, and the global start does not search through them; give a guess",
            file=source,
        )
    found = invariants(fixes, source)
    ω_first = fixes.ω[0]
    Q_first = fixes.Q[0] if fixes.Q is not None and fixes.paired[0] else None
    if float(fixes.t[0]) != float(data.times[0]) or (L.attitude and Q_first is None):
        raise FitRefused(
            "the first sample is not a fix with both the rates and the attitude: the global "
            "start takes the phase from one",
            file=source,
        )
    times = np.unique(data.times)
    # How far from the conservation laws' ratios a family can lie and still fit: its
    # χ² holds their Mahalanobis distance squared, and may reach its FAMILY_P quantile.
    reach = math.sqrt(stats.chi2.isf(FAMILY_P, max(3 * data.count - L.size, 1)))
    hypotheses: list[Solution] = []
    for invariant in found:
        J_c = _moments(invariant.ρ[None, :])[0]
        model_c, x_c = model.start(J_c, Rotation.identity(), ω_first, Q_first)
        first = data.until(float(times[min(1, times.size - 1)]))
        say(
            f"global start: the inertia ratios 1 : {J_c[1]:.5g} : {J_c[2]:.5g} from the "
            "fixes' momentum and energy; the turns between the first two fixes searched"
        )
        candidates = _expand(model_c, x_c, first, invariant.ρ, invariant.covariance, reach, source)
        for solution in candidates:
            if not any(_same(solution, other) for other in hypotheses):
                hypotheses.append(solution)
    for t in times[2:]:
        upto = data.until(float(t))
        carried: list[Solution] = []
        for solution in hypotheses:
            for child in _carry(solution, upto, reach, source):
                if not any(_same(child, other) for other in carried):
                    carried.append(child)
        hypotheses = carried
        if len(hypotheses) > MAX_HYPOTHESES:
            raise FitRefused(
                f"the fixes cannot decide the number of turns between them: {len(hypotheses)} "
                f"families of solutions fit the fixes up to t = {t:.6g} s, more than "
                f"{MAX_HYPOTHESES} followed; closer or more fixes, or a guess",
                file=source,
            )
        say(f"global start: {_families(len(hypotheses))} fit the fixes to t = {t:.6g} s")
    finals = [s for s in (_finished(h) for h in hypotheses) if s is not None]
    if not finals:
        raise FitRefused(
            "no fit: no family of solutions from the global search (the inertia ratios "
            "about those the fixes' momentum and energy give, every number of turns "
            "between the fixes) fits the fixes within the noise (unmodelled torques, the "
            "wrong noise?)",
            file=source,
        )
    if len(finals) > MAX_FAMILIES:
        raise FitRefused(
            f"the fixes cannot decide the number of turns between them: {len(finals)} "
            f"families of solutions fit within the noise, more than the {MAX_FAMILIES} "
            "reported; closer or more fixes, or a guess",
            file=source,
        )
    finals.sort(key=lambda s: float(s.r @ s.r))
    text = (
        f"global start from {times.size} fixes (too sparse for the linear guess): the "
        "inertia ratios from their momentum and energy, the turns between them searched "
        f"fix by fix: {len(finals)} famil{'y' if len(finals) == 1 else 'ies'} of solutions "
        "within the noise"
    )
    return finals, text


def _carry(solution: Solution, data: Data, reach: float, source: str) -> list[Solution]:
    """A family of the earlier fixes on ``data`` (one more fix): refitted if it predicts
    the new fix to within a fraction of a turn, else split about it (``_expand``)."""
    model, x = solution.model, solution.x
    cov, _ = covariance(solution.jac)
    t_new = float(data.times[-1])
    rates, attitude = model.predict(
        x,
        np.array([t_new]) if data.t_rates is not None else None,
        np.array([t_new]) if data.t_attitude is not None else None,
        True,
    )
    spread = 0.0
    if rates.dω is not None and rates.ω is not None:
        size = max(float(np.linalg.norm(rates.ω[0])), 1e-300)
        spread = max(
            spread,
            float(np.sqrt(np.max(np.linalg.eigvalsh(rates.dω[0] @ cov @ rates.dω[0].T)))) / size,
        )
    if attitude.dθ is not None:
        spread = max(
            spread,
            float(np.sqrt(np.max(np.linalg.eigvalsh(attitude.dθ[0] @ cov @ attitude.dθ[0].T)))),
        )
    if spread <= 0.5 * GRID_PHASE_RAD:
        # Predicted to within a fraction of a turn: kept only if the new fix lies
        # within the noise of the prediction (no least squares for the others).
        r_new, J_new = residuals(model, x, _at(data, t_new), True)
        spread_new = np.eye(r_new.size) + J_new @ cov @ J_new.T  # noise + prediction
        distance = float(r_new @ np.linalg.solve(spread_new, r_new))
        if stats.chi2.sf(distance, r_new.size) < FAMILY_P:
            return []
        refitted = _local(model, x, data)
        return [] if refitted is None else [refitted]
    ρ_block = model.layout.block("ρ")
    return _expand(model, x, data, x[ρ_block], cov[ρ_block, ρ_block], reach, source)


def _families(count: int) -> str:
    return f"{count} famil{'y' if count == 1 else 'ies'} of solutions"


def _at(data: Data, t: float) -> Data:
    """The samples of ``data`` at the time ``t`` alone."""

    def pick(times, values):
        if times is None or values is None:
            return None, None
        keep = times == t
        return times[keep], values[keep]

    t_r, rates = pick(data.t_rates, data.rates)
    t_a, attitude = pick(data.t_attitude, data.attitude)
    if t_r is not None and t_r.size == 0:
        t_r = rates = None
    if t_a is not None and t_a.size == 0:
        t_a = attitude = None
    return Data(t_r, rates, data.σ_rates, t_a, attitude, data.σ_attitude)


def _local(model, x, data: Data) -> Solution | None:
    """Least squares from one start on ``data``; the solution if it fits within the
    noise (its χ² has a probability ``FAMILY_P`` or more of a larger one)."""
    try:
        # In the step from the start (zero at first): trf's first trust region is then
        # one σ of the residuals (x_scale="jac"), where from x itself it would span
        # turns of the motion, and a first step would land in another family's basin.
        def values(δ):
            return residuals(model, x + δ, data, False)

        def derivatives(δ):
            return residuals(model, x + δ, data, True)[1]

        result = least_squares(
            values, np.zeros(x.size), derivatives, method="trf", x_scale="jac", max_nfev=40
        )
        model, x = model.recentred(x + result.x)
        r, jac = residuals(model, x, data, True)
    except (ValueError, np.linalg.LinAlgError, InputError):
        return None
    if not np.all(np.isfinite(r)) or not _within_noise(r, x.size):
        return None
    return Solution(model, x, data, r, jac, "global start")


def _within_noise(r: NDArray[np.float64], parameters: int) -> bool:
    dof = r.size - parameters
    χ2 = float(r @ r)
    return χ2 <= r.size * 1e-12 if dof < 1 else bool(stats.chi2.sf(χ2, dof) >= FAMILY_P)


def _finished(solution: Solution) -> Solution | None:
    """The last solve (attitude.estimation.solve: outliers marked, plain least squares
    on the others), kept if still within the noise."""
    try:
        final = _final(solution)
    except (ValueError, np.linalg.LinAlgError, InputError):
        return None
    return final if _within_noise(final.r, final.x.size) else None


def _same(a: Solution, b: Solution) -> bool:
    """The same family: the body rate and the inertia ratios within 3 σ of each other
    (families differ by whole turns between the fixes: far more)."""
    cov, _ = covariance(b.jac)
    L = b.model.layout
    block = np.r_[L.block("w"), L.block("ρ")]
    δ = np.concatenate(
        [
            (a.model.rate(a.x) - b.model.rate(b.x)) / b.model.rate_unit,
            np.log(a.model.moments(a.x)[1:] / a.model.moments(a.x)[0])
            - np.log(b.model.moments(b.x)[1:] / b.model.moments(b.x)[0]),
        ]
    )
    return _mahalanobis(δ, cov[np.ix_(block, block)]) < 3.0
