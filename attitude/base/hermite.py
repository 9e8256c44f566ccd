"""Cubic Hermite interpolation on equally spaced nodes, without scipy.interpolate.

The piecewise cubic that matches values p and derivatives v at nodes t_k = t_0 + k h
(the interpolant of scipy's ``CubicHermiteSpline`` on such nodes): on [t_k, t_{k+1}],
with s = (t − t_k)/h,

    p(t) = h₀₀(s) p_k + h₁₀(s) h v_k + h₀₁(s) p_{k+1} + h₁₁(s) h v_{k+1},
    h₀₀ = (1 + 2s)(1 − s)²,  h₁₀ = s(1 − s)²,  h₀₁ = s²(3 − 2s),  h₁₁ = s²(s − 1).

Why our own: importing ``scipy.interpolate`` (which imports ``scipy.optimize``) costs
about 0.1 s of CPU, as much as the whole validity horizon's screen of a one-day run
(``attitude.trajectory.horizon``), which needs nothing else from it; the nodes being
equally spaced, finding a point's interval is one division.
``tests/test_hermite_against_scipy.py`` checks it against ``CubicHermiteSpline``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["UniformCubicHermite"]


class UniformCubicHermite:
    """The cubic Hermite interpolant of ``values`` and ``derivatives`` (shape (n, ...))
    at the n ≥ 2 nodes ``start + k spacing``; callable on times within them."""

    def __init__(
        self,
        start: float,
        spacing: float,
        values: NDArray[np.float64],
        derivatives: NDArray[np.float64],
    ) -> None:
        values = np.asarray(values, dtype=np.float64)
        derivatives = np.asarray(derivatives, dtype=np.float64)
        if values.shape != derivatives.shape or values.shape[0] < 2:
            raise ValueError(
                f"values {values.shape} and derivatives {derivatives.shape}: the same "
                "shape, at least two nodes"
            )
        if not spacing > 0.0:
            raise ValueError(f"spacing must be positive, got {spacing!r}")
        self.start, self.spacing = float(start), float(spacing)
        self.values, self.derivatives = values, derivatives * self.spacing
        self.stop = self.start + (values.shape[0] - 1) * self.spacing

    def __call__(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        """The interpolant at ``t`` (any shape; within [start, stop]): shape
        ``t.shape + values.shape[1:]``."""
        t = np.asarray(t, dtype=np.float64)
        position = (t - self.start) / self.spacing
        k = np.clip(np.floor(position).astype(np.intp), 0, self.values.shape[0] - 2)
        s = (position - k).reshape(t.shape + (1,) * (self.values.ndim - 1))
        one = 1.0 - s
        return (
            (1.0 + 2.0 * s) * one * one * self.values[k]
            + s * one * one * self.derivatives[k]
            + s * s * (3.0 - 2.0 * s) * self.values[k + 1]
            + s * s * (s - 1.0) * self.derivatives[k + 1]
        )
