"""Taylor jets: a quantity with its first time derivatives, carried through arithmetic.

A :class:`Jet` holds the Taylor coefficients of a function of time about an epoch,
``f(t + τ) = c₀ + c₁ τ + c₂ τ² + … + c_N τ^N``, with ``c_k = f⁽ᵏ⁾(t)/k!``: an array
of shape ``(N + 1, *shape)``, where ``shape`` is that of the value (``(n,)`` for n
scalars, ``(n, 3)`` for n vectors, ``(n, 3, 3)`` for n matrices).  Sums, products,
cross and dot products, matrix products, reciprocals, square roots, sines and cosines
of jets are the jets of the results: the product rule (Leibniz) and the chain rule are
applied to the coefficients, so a formula written once gives its value and its exact
derivatives up to order N (forward-mode automatic differentiation in truncated power
series: A. Griewank and A. Walther, *Evaluating Derivatives*, 2nd ed., SIAM, 2008,
chapter 13, the propagation of Taylor coefficients).  No finite difference is involved: the
derivatives carry only the rounding of their own arithmetic.

Taylor coefficients rather than derivatives are stored because products are then plain
convolutions, ``(ab)_k = Σ_{i≤k} a_i b_{k−i}``, with no binomial factors;
:meth:`Jet.derivatives` converts back (``f⁽ᵏ⁾ = k! c_k``).  Orders up to 3 are what the
attitude laws use (the orbit's jerk enters the law's angular acceleration).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "Jet",
    "cross",
    "dot",
    "matmul",
    "matvec",
    "norm",
    "normalized",
    "reciprocal",
    "sin_cos",
    "sqrt",
]


class Jet:
    """Taylor coefficients ``c[k] = f⁽ᵏ⁾/k!`` of a quantity, ``k = 0 … order``.

    ``coefficients``: array of shape ``(order + 1, *shape)``.  Arithmetic with a plain
    array (or number) treats it as a constant.  Operands of different orders give a
    result of the lower order.
    """

    __slots__ = ("c",)

    def __init__(self, coefficients: ArrayLike) -> None:
        self.c = np.asarray(coefficients, dtype=np.float64)
        if self.c.ndim < 1:
            raise ValueError("a jet needs an axis of coefficients")

    # ------------------------------------------------------------------ making jets

    @classmethod
    def from_derivatives(cls, derivatives: ArrayLike) -> Jet:
        """The jet of a stack ``[f, f', f″, …]`` (axis 0: the order of the derivative)."""
        d = np.asarray(derivatives, dtype=np.float64)
        factorials = np.array([math.factorial(k) for k in range(d.shape[0])], dtype=np.float64)
        return cls(d / factorials.reshape((-1,) + (1,) * (d.ndim - 1)))

    @classmethod
    def constant(cls, value: ArrayLike, order: int) -> Jet:
        """A quantity that does not change: its derivatives are zero."""
        v = np.asarray(value, dtype=np.float64)
        c = np.zeros((order + 1, *v.shape))
        c[0] = v
        return cls(c)

    @classmethod
    def linear(cls, value: ArrayLike, rate: ArrayLike, order: int) -> Jet:
        """``value + rate τ``: a quantity changing at a constant rate."""
        v = np.asarray(value, dtype=np.float64)
        c = np.zeros((order + 1, *np.broadcast_shapes(v.shape, np.shape(rate))))
        c[0] = v
        if order >= 1:
            c[1] = rate
        return cls(c)

    # ------------------------------------------------------------------ reading jets

    @property
    def order(self) -> int:
        return self.c.shape[0] - 1

    @property
    def value(self) -> NDArray[np.float64]:
        return self.c[0]

    @property
    def shape(self) -> tuple[int, ...]:
        return self.c.shape[1:]

    def derivatives(self) -> NDArray[np.float64]:
        """The stack ``[f, f', f″, …]`` (``k! c_k``), shape ``(order + 1, *shape)``."""
        factorials = np.array([math.factorial(k) for k in range(self.order + 1)])
        return self.c * factorials.reshape((-1,) + (1,) * (self.c.ndim - 1))

    def derivative(self) -> Jet:
        """The jet of f', one order lower: ``c'_k = (k + 1) c_{k+1}``."""
        k = np.arange(1, self.order + 1, dtype=np.float64)
        return Jet(self.c[1:] * k.reshape((-1,) + (1,) * (self.c.ndim - 1)))

    def truncated(self, order: int) -> Jet:
        """The same quantity, keeping derivatives up to ``order`` only."""
        if order > self.order:
            raise ValueError(f"a jet of order {self.order} cannot give order {order}")
        return Jet(self.c[: order + 1])

    def __getitem__(self, index: Any) -> Jet:
        """Index the value's axes (not the coefficients'): ``jet[..., 0]`` is the x
        component of a vector jet."""
        if not isinstance(index, tuple):
            index = (index,)
        return Jet(self.c[(slice(None), *index)])

    def column(self) -> Jet:
        """A trailing axis of length 1, so that n scalars broadcast over n vectors."""
        return Jet(self.c[..., None])

    def __repr__(self) -> str:
        return f"Jet(order={self.order}, shape={self.shape})"

    # ------------------------------------------------------------------ arithmetic

    def _coefficients_of(self, other: Any) -> NDArray[np.float64]:
        if isinstance(other, Jet):
            return other.c
        value = np.asarray(other, dtype=np.float64)
        c = np.zeros((self.order + 1, *np.broadcast_shapes(value.shape, self.shape)))
        c[0] = value
        return c

    def __add__(self, other: Any) -> Jet:
        a, b = _common(self.c, self._coefficients_of(other))
        return Jet(a + b)

    __radd__ = __add__

    def __sub__(self, other: Any) -> Jet:
        a, b = _common(self.c, self._coefficients_of(other))
        return Jet(a - b)

    def __rsub__(self, other: Any) -> Jet:
        a, b = _common(self.c, self._coefficients_of(other))
        return Jet(b - a)

    def __neg__(self) -> Jet:
        return Jet(-self.c)

    def __mul__(self, other: Any) -> Jet:
        """Elementwise product (numpy broadcasting over the value axes)."""
        if not isinstance(other, Jet):
            value = np.asarray(other, dtype=np.float64)
            return Jet(self.c * value)
        return Jet(_convolve(self.c, other.c, np.multiply))

    __rmul__ = __mul__

    def __truediv__(self, other: Any) -> Jet:
        if not isinstance(other, Jet):
            return Jet(self.c / np.asarray(other, dtype=np.float64))
        return self * reciprocal(other)


def _common(a: NDArray[np.float64], b: NDArray[np.float64]):
    """Two coefficient arrays cut to the lower order."""
    order = min(a.shape[0], b.shape[0])
    return a[:order], b[:order]


def _convolve(a: NDArray[np.float64], b: NDArray[np.float64], product) -> NDArray[np.float64]:
    """``(a ⋆ b)_k = Σ_{i ≤ k} product(a_i, b_{k−i})``: the coefficients of a product."""
    a, b = _common(a, b)
    terms = [sum(product(a[i], b[k - i]) for i in range(k + 1)) for k in range(a.shape[0])]
    return np.stack(np.broadcast_arrays(*terms))


def dot(a: Jet, b: Jet) -> Jet:
    """The dot product of vector jets (last axis)."""
    return Jet(_convolve(a.c, b.c, lambda x, y: np.sum(x * y, axis=-1)))


def cross(a: Jet, b: Jet) -> Jet:
    """The cross product of vector jets (last axis, length 3)."""
    return Jet(_convolve(a.c, b.c, np.cross))


def matvec(m: Jet | NDArray[np.float64], v: Jet) -> Jet:
    """Matrices (…, 3, 3) times vectors (…, 3); either may be a constant array."""
    if not isinstance(m, Jet):
        return Jet(np.einsum("...ij,...j->...i", np.asarray(m, dtype=np.float64), v.c))
    return Jet(_convolve(m.c, v.c, lambda x, y: np.einsum("...ij,...j->...i", x, y)))


def matmul(a: Jet, b: Jet | NDArray[np.float64]) -> Jet:
    """Matrix products of jets (…, 3, 3); ``b`` may be a constant array."""
    if not isinstance(b, Jet):
        return Jet(a.c @ np.asarray(b, dtype=np.float64))
    return Jet(_convolve(a.c, b.c, np.matmul))


def reciprocal(s: Jet) -> Jet:
    """1/s: r₀ = 1/s₀, r_k = −(Σ_{i=1..k} s_i r_{k−i}) / s₀."""
    c = np.empty_like(s.c)
    inverse = 1.0 / s.c[0]
    c[0] = inverse
    for k in range(1, s.order + 1):
        c[k] = -sum(s.c[i] * c[k - i] for i in range(1, k + 1)) * inverse
    return Jet(c)


def sqrt(s: Jet) -> Jet:
    """√s: q₀ = √s₀, q_k = (s_k − Σ_{i=1..k−1} q_i q_{k−i}) / (2 q₀)."""
    c = np.empty_like(s.c)
    c[0] = np.sqrt(s.c[0])
    half_inverse = 0.5 / c[0]
    for k in range(1, s.order + 1):
        c[k] = (s.c[k] - sum(c[i] * c[k - i] for i in range(1, k))) * half_inverse
    return Jet(c)


def sin_cos(u: Jet) -> tuple[Jet, Jet]:
    """sin u and cos u: from (sin u)' = cos u · u' and (cos u)' = −sin u · u',
    s_k = (1/k) Σ_{i=1..k} i u_i c_{k−i} and c_k = −(1/k) Σ_{i=1..k} i u_i s_{k−i}."""
    s = np.empty_like(u.c)
    c = np.empty_like(u.c)
    s[0], c[0] = np.sin(u.c[0]), np.cos(u.c[0])
    for k in range(1, u.order + 1):
        s[k] = sum(i * u.c[i] * c[k - i] for i in range(1, k + 1)) / k
        c[k] = -sum(i * u.c[i] * s[k - i] for i in range(1, k + 1)) / k
    return Jet(s), Jet(c)


def norm(v: Jet) -> Jet:
    """|v| of vector jets."""
    return sqrt(dot(v, v))


def normalized(v: Jet) -> Jet:
    """v/|v|: the unit vector and its derivatives.  A zero vector gives inf or NaN:
    callers check the norm first where it can vanish."""
    return v * reciprocal(norm(v)).column()
