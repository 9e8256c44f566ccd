"""What a converged fit says about itself: the covariance, the goodness of fit, and
whether the residuals look like the noise they should be.

- **Covariance** from the Jacobian J of the normalized residuals at the solution,
  (JᵀJ)⁻¹ through the singular value decomposition of J (no normal equations formed),
  times the reduced χ² when the noise was estimated from the residuals themselves.
  A singular value below 1e-10 of the largest marks a combination of the parameters
  that the data do not determine.
- **χ²** of the normalized residuals with N − p degrees of freedom, and the probability
  of a larger one under the stated noise (``scipy.stats.chi2``).
- **Normality**: D'Agostino and Pearson's omnibus test of the normalized residuals of
  each sensor (``scipy.stats.normaltest``: skewness and kurtosis), and their lag-one
  autocorrelation (white noise: 0 ± 1/√N), which a cycle slip or an unmodelled torque
  makes large.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import stats

__all__ = ["Goodness", "covariance", "goodness"]

# Singular values of the Jacobian below this fraction of the largest: not determined.
RANK_TOLERANCE = 1e-10


def covariance(jac: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(JᵀJ)⁻¹ from the SVD of J, and the singular values (largest first).  A zero
    singular value gets a variance of 1e300 along its direction: "not determined"."""
    _, s, Vt = np.linalg.svd(jac, full_matrices=False)
    with np.errstate(divide="ignore"):
        inverse = np.where(s > 0.0, 1.0 / (s * s), 1e300)
    return (Vt.T * inverse) @ Vt, s


@dataclass(frozen=True)
class Goodness:
    """χ², its degrees of freedom and tail probability; per sensor, the normality test
    (statistic, p-value; None below 20 residuals) and the lag-one autocorrelation."""

    chi2: float
    dof: int
    reduced_chi2: float
    p_value: float
    normality: dict[str, tuple[float, float] | None]
    autocorrelation: dict[str, float]

    def lines(self) -> list[str]:
        out = [
            f"chi2 = {self.chi2:.6g} for {self.dof} degrees of freedom: reduced chi2 "
            f"{self.reduced_chi2:.4g} (probability of a larger one {self.p_value:.3g})"
        ]
        for sensor, test in self.normality.items():
            rho = self.autocorrelation[sensor]
            text = (
                "too few for a normality test"
                if test is None
                else f"normality test statistic {test[0]:.3g}, p = {test[1]:.3g}"
            )
            out.append(f"{sensor} residuals: {text}; lag-one autocorrelation {rho:+.3f}")
        return out


def goodness(residuals: dict[str, NDArray[np.float64]], parameters: int) -> Goodness:
    """The statistics of normalized residuals given per sensor as (N, 3) arrays."""
    everything = np.concatenate([r.ravel() for r in residuals.values()])
    chi2 = float(np.sum(everything * everything))
    dof = max(everything.size - parameters, 1)
    normality: dict[str, tuple[float, float] | None] = {}
    autocorrelation: dict[str, float] = {}
    for sensor, r in residuals.items():
        flat = r.ravel()
        if flat.size >= 20:
            result = stats.normaltest(flat)
            normality[sensor] = (float(result.statistic), float(result.pvalue))
        else:
            normality[sensor] = None
        if r.shape[0] > 2:
            a, b = r[:-1], r[1:]
            denominator = math.sqrt(float(np.sum(a * a)) * float(np.sum(b * b)))
            autocorrelation[sensor] = float(np.sum(a * b)) / denominator if denominator else 0.0
        else:
            autocorrelation[sensor] = 0.0
    return Goodness(
        chi2, dof, chi2 / dof, float(stats.chi2.sf(chi2, dof)), normality, autocorrelation
    )
