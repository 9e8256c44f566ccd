"""A smooth function of the phase, tabulated once: piecewise Chebyshev interpolation.

``EulerSolver`` evaluates one state at many times.  The periodic part of the angle ψ
(attitude.solver.closed_form, ``Elliptic.periodic_angle``) costs one Carlson R_J per sample
when it is computed from its formula, half the cost of the attitude; it is a function
of the reduced phase r ∈ [−K, K] alone, analytic in a strip about the real axis, so a
table of polynomial pieces built once from the formula gives it for a few
multiplications a sample.

The interval is cut into P equal pieces, and on each the function is interpolated at
the d + 1 Chebyshev points of the first kind (Trefethen, *Approximation Theory and
Approximation Practice*, SIAM 2013, ch. 2–4: for a function analytic in a strip the
coefficients decay geometrically, faster the narrower the piece).  The number of
pieces is doubled until the last two Chebyshev coefficients of every piece are below
the rounding of the values themselves, so that the table adds nothing to the error of
the formula it replaces; the table is then checked against the formula between the
nodes.  Each piece is stored in the power basis of its local variable t ∈ [−1, 1] and
evaluated by Horner's rule, one coefficient of all samples gathered at a time.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.polynomial import chebyshev
from numpy.typing import NDArray

__all__ = ["PiecewiseChebyshev"]

# A function: values at an array of points, and the magnitude of the largest term of
# its formula there (its rounding is what the table must not exceed).
Function = Callable[[NDArray[np.float64]], tuple[NDArray[np.float64], float]]


class PiecewiseChebyshev:
    """``function`` on [lower, upper] as ``pieces`` polynomials of degree ``degree``.

    Build with ``fit``; call on an array of points in [lower, upper] (points a few
    ulps outside are evaluated on the end pieces).  ``rounding`` is the rounding scale
    of the function's formula (2^-52 times its largest term) and ``max_error`` the
    largest difference from the formula measured between the nodes.
    """

    def __init__(self, coefficients: NDArray[np.float64], lower: float, upper: float) -> None:
        # (degree + 1, pieces): row k holds the coefficient of t^k of each piece; kept
        # also as separate rows, gathered one at a time (``__call__``).
        self._coefficients = np.ascontiguousarray(coefficients)
        self._rows = [row.copy() for row in self._coefficients]
        self.degree = coefficients.shape[0] - 1
        self.pieces = coefficients.shape[1]
        self.lower = lower
        self.upper = upper
        self._scale = self.pieces / (upper - lower)
        self.rounding = 0.0
        self.max_error = 0.0

    @classmethod
    def fit(
        cls,
        function: Function,
        lower: float,
        upper: float,
        degree: int = 10,
        width: float = 0.5,
        max_pieces: int = 4096,
    ) -> PiecewiseChebyshev | None:
        """Interpolate ``function``, starting from pieces about ``width`` wide.

        Returns None if ``max_pieces`` pieces do not reach the function's own rounding
        (the caller then keeps the formula).
        """
        pieces = 1 << max(0, int(np.ceil(np.log2((upper - lower) / width))))
        nodes = chebyshev.chebpts1(degree + 1)
        to_chebyshev = np.linalg.inv(chebyshev.chebvander(nodes, degree))
        # Chebyshev coefficients → power coefficients of t (column k: T_k in powers).
        to_power = np.zeros((degree + 1, degree + 1))
        for k in range(degree + 1):
            to_power[: k + 1, k] = chebyshev.cheb2poly(np.eye(degree + 1)[k])
        while pieces <= max_pieces:
            width_k = (upper - lower) / pieces
            centres = lower + width_k * (np.arange(pieces) + 0.5)
            x = centres[:, None] + (0.5 * width_k) * nodes[None, :]
            values, largest = function(x.ravel())
            rounding = 2.0**-52 * max(largest, float(np.max(np.abs(values))), 1e-300)
            cheb = values.reshape(pieces, degree + 1) @ to_chebyshev.T  # (pieces, d + 1)
            tail = float(np.max(np.abs(cheb[:, -2:])))
            if tail <= 4.0 * rounding:
                table = cls(to_power @ cheb.T, lower, upper)
                table.rounding = rounding
                # Checked against the formula halfway between nodes, in every piece.
                between = (
                    centres[:, None] + (0.5 * width_k) * (0.5 * (nodes[1:] + nodes[:-1]))[None, :]
                )
                exact, _ = function(between.ravel())
                table.max_error = float(np.max(np.abs(table(between.ravel()) - exact)))
                if table.max_error <= 8.0 * rounding:
                    return table
            pieces *= 2
        return None

    def __call__(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """The interpolant at the points ``x`` (an array)."""
        position = (x - self.lower) * self._scale  # in [0, pieces], piece and fraction
        index = position.astype(np.intp)  # truncation: −0.x (a rounding below) → 0
        np.minimum(index, self.pieces - 1, out=index)  # x = upper: the last piece
        t = 2.0 * (position - index) - 1.0
        # Horner's rule, gathering one coefficient of every sample's piece at a time:
        # a (degree + 1, n) gather at once would hold 11 floats a sample.
        value = self._rows[self.degree].take(index, mode="clip")
        coefficient = position  # its buffer, no longer needed
        for k in range(self.degree - 1, -1, -1):
            value *= t
            value += self._rows[k].take(index, out=coefficient, mode="clip")
        return value
