"""Least squares on the exact motion: robust, over a growing arc, from several starts,
and never stopping in a local minimum.

- **The residuals** are the measured minus the predicted body rates, and the rotation
  vector of (predicted)⁻¹ ⊗ measured attitude, each divided by its sensor's noise σ.
  scipy's ``least_squares`` (trust region reflective) minimizes them with a
  ``soft_l1`` loss (quadratic within 3 σ, linear beyond), so that an outlier pulls with
  a constant force instead of its square; the Jacobian is the model's, exact.
- **A growing arc.** Over an arc of many periods, a start whose period is off by a few
  per cent slips by whole cycles before the arc ends, and the cost has a minimum at
  each slip: that is where a plain Levenberg–Marquardt from a rough guess lands.  So
  the fit starts on about three periods of the motion, then extends the arc only as
  far as its own covariance predicts the motion to within a fraction of the signal
  (5 % of the rates, 0.1 rad of attitude), at most four times longer a stage, the way
  orbit determination bootstraps an arc.
- **Local minima are detected, not reported**: after each stage the residuals must
  match the noise (RMS of the normalized residuals at most ``RMS_LIMIT``); a start
  that fails is dropped and the next one tried.  The starts are the linear guess's
  ambiguities (attitude.estimation.linear_guess); if every start fails, the fit is
  refused with the best one's residuals.
- **Outliers**: at the end, samples with a normalized residual component beyond
  ``OUTLIER_SIGMA`` are flagged, and the last solve uses plain least squares on the
  others, whose Jacobian then gives the covariance (attitude.estimation.statistics).
- **Long arcs**: a stage is fitted on at most ``STAGE_SAMPLES`` samples, every k-th of
  its arc (a stage needs the motion's shape, and a million samples made each stage a
  minute); the last solve takes them all, beyond ``CHUNKED_ABOVE`` by Gauss–Newton on
  the R factor of the Jacobian accumulated stretch by stretch, so that the Jacobian of
  the whole arc (its sensitivities 2.4 GB for a million gyro samples) is never in
  memory at once.  ``progress`` hears of each stage, with the time left.
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.estimation.model import left_jacobian_inverse
from attitude.estimation.statistics import covariance

__all__ = [
    "OUTLIER_SIGMA",
    "RMS_LIMIT",
    "Data",
    "FitRefused",
    "Solution",
    "fit_from_starts",
]

# A fit whose normalized residuals have a larger RMS than this is not a fit: a local
# minimum, or a motion the model does not describe (χ²/dof = 4: residuals twice the noise).
RMS_LIMIT = 2.0
# A sample with a normalized residual component beyond this is an outlier.
OUTLIER_SIGMA = 5.0
# The robust loss is quadratic within this many σ.
ROBUST_SCALE = 3.0
# A stage of the growing arc is fitted on at most about this many samples (evenly
# thinned); the last solve, which gives the covariance, on all of them.
STAGE_SAMPLES = 20_000
# Beyond this many samples, the last solve is Gauss–Newton on the Jacobian's R factor
# accumulated over stretches of CHUNK_SAMPLES (its memory then stays bounded).
CHUNKED_ABOVE = 200_000
CHUNK_SAMPLES = 50_000
# How far the arc grows: predicted 1σ within these fractions of the signal.
RATE_FRACTION = 0.05
ATTITUDE_RAD = 0.1


class FitRefused(InputError):
    """The telemetry does not determine what was asked: the message says why."""


@dataclass
class Data:
    """The measurements, with their noise: gyro times (N,), rates (N, 3) and σ (3,);
    attitude times (M,), rotations (M,) and σ (rad).  Either kind may be None."""

    t_rates: NDArray[np.float64] | None
    rates: NDArray[np.float64] | None
    σ_rates: NDArray[np.float64] | None
    t_attitude: NDArray[np.float64] | None
    attitude: Rotation | None
    σ_attitude: float | None
    rate_inliers: NDArray[np.bool_] | None = None
    attitude_inliers: NDArray[np.bool_] | None = None

    def __post_init__(self) -> None:
        if self.t_rates is not None and self.rate_inliers is None:
            self.rate_inliers = np.ones(self.t_rates.size, dtype=bool)
        if self.t_attitude is not None and self.attitude_inliers is None:
            self.attitude_inliers = np.ones(self.t_attitude.size, dtype=bool)

    def until(self, t_end: float, inliers_only: bool = False) -> Data:
        """The samples at or before ``t_end`` (and, if asked, only the inliers)."""

        def pick(t, mask):
            if t is None:
                return None
            keep = t <= t_end
            return keep & mask if inliers_only else keep

        t_rates, rates = self.t_rates, self.rates
        t_attitude, attitude = self.t_attitude, self.attitude
        # Times and values are given together (both or neither).
        g = pick(t_rates, self.rate_inliers)
        a = pick(t_attitude, self.attitude_inliers)
        return Data(
            None if g is None or t_rates is None else t_rates[g],
            None if g is None or rates is None else rates[g],
            self.σ_rates,
            None if a is None or t_attitude is None else t_attitude[a],
            None if a is None or attitude is None else attitude[a],
            self.σ_attitude,
        )

    def thinned(self, limit: int) -> Data:
        """At most about ``limit`` samples: every k-th of each sensor, its last kept (the
        arc's end), the inliers' marks with them.  A stage of the growing arc needs the
        motion's shape, not every sample of a long arc: the last solve has them all."""
        if self.count <= limit:
            return self
        step = math.ceil(self.count / limit)

        def every(times):
            if times is None:
                return None
            keep = np.zeros(times.size, dtype=bool)
            keep[::step] = True
            keep[-1] = True
            return keep

        g, a = every(self.t_rates), every(self.t_attitude)
        return Data(
            None if g is None or self.t_rates is None else self.t_rates[g],
            None if g is None or self.rates is None else self.rates[g],
            self.σ_rates,
            None if a is None or self.t_attitude is None else self.t_attitude[a],
            None if a is None or self.attitude is None else self.attitude[a],
            self.σ_attitude,
            None if g is None or self.rate_inliers is None else self.rate_inliers[g],
            None if a is None or self.attitude_inliers is None else self.attitude_inliers[a],
        )

    @property
    def times(self) -> NDArray[np.float64]:
        parts = [t for t in (self.t_rates, self.t_attitude) if t is not None]
        return np.sort(np.concatenate(parts))

    @property
    def count(self) -> int:
        return sum(0 if t is None else t.size for t in (self.t_rates, self.t_attitude))


def residuals(model: Any, x: NDArray[np.float64], data: Data, jacobian: bool):
    """Normalized residuals (and their Jacobian): rates then attitudes, flattened."""
    rates, attitude = model.predict(x, data.t_rates, data.t_attitude, jacobian)
    parts, jparts = [], []
    if data.t_rates is not None and data.σ_rates is not None:
        parts.append(((data.rates - rates.ω) / data.σ_rates).ravel())
        if jacobian:
            jparts.append((-rates.dω / data.σ_rates[None, :, None]).reshape(-1, rates.dω.shape[2]))
    if data.t_attitude is not None:
        r = (attitude.attitude.inv() * data.attitude).as_rotvec()
        parts.append((r / data.σ_attitude).ravel())
        if jacobian:
            # r = log(exp(−δθ) exp(r)): ∂r/∂δθ = −J_l(r)⁻¹.
            dr = -np.einsum("nij,njp->nip", left_jacobian_inverse(r), attitude.dθ)
            jparts.append((dr / data.σ_attitude).reshape(-1, attitude.dθ.shape[2]))
    r = np.concatenate(parts)
    if not jacobian:
        return r
    return r, np.concatenate(jparts, axis=0)


@dataclass
class Solution:
    """A converged fit: the model (its references recentred), x, the data it was fitted
    to (with the outliers marked), its normalized residuals and Jacobian, and how it
    got there."""

    model: Any
    x: NDArray[np.float64]
    data: Data
    r: NDArray[np.float64]
    jac: NDArray[np.float64]  # or its R factor (the same JᵀJ) after a chunked last solve
    start: str
    stages: list[tuple[float, float]] = field(default_factory=list)  # (arc end, RMS)
    tried: list[str] = field(default_factory=list)  # the starts that failed, and why
    notes: list[str] = field(default_factory=list)

    @property
    def rms(self) -> float:
        return float(np.sqrt(np.mean(self.r * self.r)))


def _solve(model, x0, data: Data, robust: bool, max_nfev: int = 100):
    """Least squares from ``x0`` on ``data``.  Parameters the data do not touch (a zero
    column of the Jacobian: the moments' scale before the arc reaches the impulse that
    shows it, the attitude before the first fix) are held where they are."""
    _, J0 = residuals(model, x0, data, True)
    norms = np.linalg.norm(J0, axis=0)
    active = norms > 1e-12 * max(float(norms.max()), 1e-300)
    if not np.any(active):
        return x0

    def full(z):
        x = x0.copy()
        x[active] = z
        return x

    def fun(z):
        return residuals(model, full(z), data, False)

    first = x0[active].copy()

    def jac(z):
        if np.array_equal(z, first):  # least_squares starts where J0 was taken
            return J0[:, active]
        return residuals(model, full(z), data, True)[1][:, active]

    result = least_squares(
        fun,
        x0[active],
        jac,
        method="trf",
        loss="soft_l1" if robust else "linear",
        f_scale=ROBUST_SCALE,
        x_scale="jac",
        max_nfev=max_nfev,
    )
    return full(result.x)


def _rms(r: NDArray[np.float64]) -> float:
    return float(np.sqrt(np.mean(r * r))) if r.size else 0.0


def _inlier_rms(r: NDArray[np.float64]) -> float:
    """RMS over the components within ``OUTLIER_SIGMA`` (what the robust loss fits)."""
    keep = np.abs(r) <= OUTLIER_SIGMA
    return _rms(r[keep]) if np.any(keep) else _rms(r)


def _next_end(model, x, data: Data, arc: Data, t_end: float) -> tuple[float, float | None]:
    """How far the motion fitted on ``arc`` is predicted well enough to linearize about
    it: the arc end for the next stage (at most four times as long, at least a quarter
    longer, and reaching the next sample), and the predicted 1σ there if that sample
    lies beyond what the covariance predicts (a gap bridged)."""
    r, J = residuals(model, x, arc, True)
    cov = covariance(J)[0] * max(1.0, _rms(r) ** 2)
    times = data.times
    t_first, t_last = float(times[0]), float(times[-1])
    length = max(t_end - t_first, 1e-9)
    limit = min(t_last, t_first + 4.0 * length)
    probe = np.linspace(t_end, limit, 33)[1:]
    σ_rate, σ_attitude = _predicted_sigma(model, x, cov, data, probe)
    bad = (σ_rate > RATE_FRACTION) | (σ_attitude > ATTITUDE_RAD)
    end = limit if not np.any(bad) else float(probe[max(int(np.argmax(bad)) - 1, 0)])
    end = min(max(end, t_end + 0.25 * length), t_last)
    following = times[times > t_end]
    bridged = None
    if following.size and following[0] > end:  # a gap: the next sample is needed
        end = float(following[0])
        σ_r, σ_a = _predicted_sigma(model, x, cov, data, np.array([end]))
        bridged = float(max(σ_r[0] / RATE_FRACTION, σ_a[0] / ATTITUDE_RAD))
    return end, bridged


def _predicted_sigma(model, x, cov, data: Data, times: NDArray[np.float64]):
    """Predicted 1σ at ``times``: of the rates as a fraction of their size, and of the
    attitude in radians (zeros for a kind the data does not have)."""
    rates, attitude = model.predict(
        x,
        times if data.t_rates is not None else None,
        times if data.t_attitude is not None else None,
        True,
    )
    σ_rate = np.zeros(times.size)
    σ_attitude = np.zeros(times.size)
    if rates.ω is not None:
        size = np.maximum(np.linalg.norm(rates.ω, axis=1), 1e-300)
        σ_rate = np.sqrt(np.einsum("nip,pq,niq->n", rates.dω, cov, rates.dω)) / size
    if attitude.dθ is not None:
        σ_attitude = np.sqrt(np.einsum("nip,pq,niq->n", attitude.dθ, cov, attitude.dθ))
    return σ_rate, σ_attitude


class _Clock:
    """What the fit has done and how long the rest should take, for ``progress``: the
    stages' wall time so far, the arc's growth per stage, and the last solve's cost
    from the stages' cost per sample."""

    def __init__(self, progress: Callable[[str], None] | None, data: Data):
        self.say = progress or (lambda text: None)
        self.data = data
        self.times = data.times
        self.stages: list[tuple[float, float, int]] = []  # (arc end, wall s, samples)
        self.mark = time.perf_counter()

    def stage(self, t_end: float, samples: int, rms: float) -> None:
        now = time.perf_counter()
        self.stages.append((t_end, now - self.mark, samples))
        self.mark = now
        t_first, t_last = float(self.times[0]), float(self.times[-1])
        done = (t_end - t_first) / max(t_last - t_first, 1e-300)
        self.say(
            f"fit: arc to t = {t_end:.6g} s of {t_last:.6g} s ({100.0 * done:.0f} %) on "
            f"{samples} samples, residuals {rms:.3g} σ; {self.rest(t_end)}"
        )

    def rest(self, t_end: float) -> str:
        """'about N s more' from the stages so far (the growing arc's remaining stages
        at their mean cost, and the last solve at their cost per sample)."""
        walls = [w for _, w, _ in self.stages]
        per_sample = sum(walls) / max(sum(n for _, _, n in self.stages), 1)
        t_first, t_last = float(self.times[0]), float(self.times[-1])
        length = max(t_end - t_first, 1e-300)
        growth = 4.0
        if len(self.stages) > 1:
            lengths = [max(e - t_first, 1e-300) for e, _, _ in self.stages]
            growth = max(min((lengths[-1] / lengths[0]) ** (1.0 / (len(lengths) - 1)), 4.0), 1.25)
        remaining = math.ceil(math.log(max((t_last - t_first) / length, 1.0)) / math.log(growth))
        # The last solve: a few passes over every sample, each about half a stage's
        # cost per sample (measured on a million-sample arc).
        estimate = remaining * sum(walls) / len(walls) + 0.5 * per_sample * self.data.count
        return f"about {estimate:.2g} s more" if estimate >= 1.0 else "under a second more"

    def final(self) -> None:
        self.say(
            f"fit: the last solve on all {self.data.count} samples (outliers marked), then "
            f"the covariance; {self.rest(float(self.times[-1]))}"
        )


def _progressive(
    model, x, data: Data, first_end: float, label: str, clock: _Clock | None = None
) -> Solution | tuple[str, float]:
    """One start through the growing arcs; a Solution, or why it failed and the end of
    the arc on which it did."""
    times = data.times
    t_last = float(times[-1])
    t_end = min(max(first_end, float(times[min(times.size - 1, 19)])), t_last)
    stages: list[tuple[float, float]] = []
    bridges: list[str] = []
    while True:
        arc = data.until(t_end).thinned(STAGE_SAMPLES)
        try:
            x = _solve(model, x, arc, robust=True)
        except (ValueError, np.linalg.LinAlgError, InputError) as exc:
            return f"{label}: failed on the arc to t = {t_end:.6g} s ({exc})", t_end
        model, x = model.recentred(x)
        rms = _inlier_rms(residuals(model, x, arc, False))
        stages.append((t_end, rms))
        if clock is not None:
            clock.stage(t_end, arc.count, rms)
        if not math.isfinite(rms) or rms > RMS_LIMIT:
            return (
                f"{label}: a local minimum on the arc to t = {t_end:.6g} s (RMS of the "
                f"normalized residuals {rms:.3g}, more than {RMS_LIMIT:g})",
                t_end,
            )
        if t_end >= t_last:
            break
        t_end, bridged = _next_end(model, x, data, arc, t_end)
        if bridged is not None and bridged > 1.0:
            bridges.append(
                f"the arc was extended across a gap to t = {t_end:.6g} s, where the motion "
                f"fitted so far was predicted to {bridged:.3g} times the extension threshold "
                f"({RATE_FRACTION:g} of the rates, {ATTITUDE_RAD:g} rad)"
            )
    return Solution(
        model, x, data, np.empty(0), np.empty((0, x.size)), label, stages, notes=bridges
    )


def _final(solution: Solution) -> Solution:
    """Outliers marked, and plain least squares on the inliers: the covariance's fit."""
    model, x, data = solution.model, solution.x, solution.data
    r = residuals(model, x, data, False)
    offset = 0
    rate_inliers = attitude_inliers = None
    if data.t_rates is not None:
        block = np.abs(r[: 3 * data.t_rates.size].reshape(-1, 3))
        rate_inliers = np.all(block <= OUTLIER_SIGMA, axis=1)
        offset = 3 * data.t_rates.size
    if data.t_attitude is not None:
        block = np.abs(r[offset:].reshape(-1, 3))
        attitude_inliers = np.all(block <= OUTLIER_SIGMA, axis=1)
    data = replace(data, rate_inliers=rate_inliers, attitude_inliers=attitude_inliers)
    clean = data.until(np.inf, inliers_only=True)
    if clean.count > CHUNKED_ABOVE and getattr(model, "torques", None) is None:
        x, R = _chunked_gauss_newton(model, x, clean)
        model, x = model.recentred(x)
        return replace(
            solution, model=model, x=x, data=data, r=residuals(model, x, clean, False), jac=R
        )
    x = _solve(model, x, clean, robust=False)
    model, x = model.recentred(x)
    r, J = residuals(model, x, clean, True)
    return replace(solution, model=model, x=x, data=data, r=r, jac=J)


def _pieces(data: Data, size: int):
    """``data`` in consecutive stretches of about ``size`` samples (both sensors cut at
    the same times)."""
    times = data.times
    edges = [-np.inf, *times[size::size].tolist(), np.inf]
    for lo, hi in itertools.pairwise(edges):
        t_r, rates = _between(data.t_rates, data.rates, lo, hi)
        t_a, attitude = _between(data.t_attitude, data.attitude, lo, hi)
        if t_r is not None or t_a is not None:
            yield Data(t_r, rates, data.σ_rates, t_a, attitude, data.σ_attitude)


def _between(t, values, lo: float, hi: float):
    """The samples (times, values) in [lo, hi), or (None, None) if none."""
    if t is None or values is None:
        return None, None
    keep = (t >= lo) & (t < hi)
    return (t[keep], values[keep]) if np.any(keep) else (None, None)


def _chunked_gauss_newton(model, x, data: Data, iterations: int = 8):
    """Least squares on a long arc without its Jacobian in memory: Gauss–Newton steps
    from the growing arc's solution (already within a few σ of the optimum), each from
    the R factor of the Jacobian accumulated stretch by stretch (a QR of [R; J_k]: no
    normal equations formed), with a halved step if a step does not lower the cost.
    The solution and R at it: RᵀR = JᵀJ, all that the covariance needs."""

    def accumulate(x):
        R = np.zeros((0, x.size))
        z = np.zeros(0)
        cost = 0.0
        for piece in _pieces(data, CHUNK_SAMPLES):
            r, J = residuals(model, x, piece, True)
            cost += float(r @ r)
            Q, R = np.linalg.qr(np.vstack([R, J]))
            z = Q.T @ np.concatenate([z, r])
        return R, z, cost

    R, z, cost = accumulate(x)
    for _ in range(iterations):
        step = -np.linalg.lstsq(R, z, rcond=None)[0]  # R δ = −Qᵀr
        expected = float(z @ z) - float((z + R @ step) @ (z + R @ step))
        if expected <= 1e-10 * max(cost, 1.0):
            break
        for _ in range(8):
            trial = x + step
            R_trial, z_trial, cost_trial = accumulate(trial)
            if cost_trial <= cost:
                x, R, z, cost = trial, R_trial, z_trial, cost_trial
                break
            step = 0.5 * step
        else:
            break
    return x, R


def fit_from_starts(
    starts: list[tuple[Any, NDArray[np.float64], str, float]],
    data: Data,
    progress: Callable[[str], None] | None = None,
) -> Solution:
    """The first start (model, x, label, first arc end) to fit the whole arc with
    residuals at the noise, after the outliers are set aside; ``FitRefused`` if none.

    A start that falls into a local minimum on an arc is tried again from an arc a
    quarter as long (down to its first 20 samples), twice at most: a minimum that the
    growing arc walked into is usually a cycle slip that a shorter first arc avoids."""
    failures = []
    clock = _Clock(progress, data)
    times = data.times
    t_first = float(times[0])
    shortest = float(times[min(times.size - 1, 19)])
    for model, x, label, first_end in starts:
        end = first_end
        for attempt in range(3):
            outcome = _progressive(model, x, data, end, label, clock)
            if isinstance(outcome, Solution):
                break
            message, failed_at = outcome
            failures.append(message)
            end = t_first + 0.25 * (min(failed_at, end) - t_first)
            if attempt == 2 or min(failed_at, first_end) <= shortest:
                break
        if not isinstance(outcome, Solution):
            continue
        clock.final()
        final = _final(outcome)
        if final.rms > RMS_LIMIT:
            failures.append(f"{label}: residuals {final.rms:.3g} σ after the outliers")
            continue
        final.tried = failures
        return final
    raise FitRefused(
        "no fit: every start ends in a local minimum or a motion this model does not describe "
        "(unmodelled torques, a gyro bias, the wrong noise?); " + "; ".join(failures)
    )
