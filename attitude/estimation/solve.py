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
"""

from __future__ import annotations

import math
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
    jac: NDArray[np.float64]
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

    def jac(z):
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


def _progressive(
    model, x, data: Data, first_end: float, label: str
) -> Solution | tuple[str, float]:
    """One start through the growing arcs; a Solution, or why it failed and the end of
    the arc on which it did."""
    times = data.times
    t_last = float(times[-1])
    t_end = min(max(first_end, float(times[min(times.size - 1, 19)])), t_last)
    stages: list[tuple[float, float]] = []
    bridges: list[str] = []
    while True:
        arc = data.until(t_end)
        try:
            x = _solve(model, x, arc, robust=True)
        except (ValueError, np.linalg.LinAlgError, InputError) as exc:
            return f"{label}: failed on the arc to t = {t_end:.6g} s ({exc})", t_end
        model, x = model.recentred(x)
        rms = _inlier_rms(residuals(model, x, arc, False))
        stages.append((t_end, rms))
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
    x = _solve(model, x, clean, robust=False)
    model, x = model.recentred(x)
    r, J = residuals(model, x, clean, True)
    return replace(solution, model=model, x=x, data=data, r=r, jac=J)


def fit_from_starts(
    starts: list[tuple[Any, NDArray[np.float64], str, float]], data: Data
) -> Solution:
    """The first start (model, x, label, first arc end) to fit the whole arc with
    residuals at the noise, after the outliers are set aside; ``FitRefused`` if none.

    A start that falls into a local minimum on an arc is tried again from an arc a
    quarter as long (down to its first 20 samples), twice at most: a minimum that the
    growing arc walked into is usually a cycle slip that a shorter first arc avoids."""
    failures = []
    times = data.times
    t_first = float(times[0])
    shortest = float(times[min(times.size - 1, 19)])
    for model, x, label, first_end in starts:
        end = first_end
        for attempt in range(3):
            outcome = _progressive(model, x, data, end, label)
            if isinstance(outcome, Solution):
                break
            message, failed_at = outcome
            failures.append(message)
            end = t_first + 0.25 * (min(failed_at, end) - t_first)
            if attempt == 2 or min(failed_at, first_end) <= shortest:
                break
        if not isinstance(outcome, Solution):
            continue
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
