"""A law's angular velocity and acceleration from finite differences of its own
attitude, in extended precision: the reference of the tests of the laws' rates.

The attitude matrices R(t0 + k h), k = −4 … 4, are differenced with 9-point weights
solved in mpmath (order 8), in mpmath arithmetic (40 digits), so that the only errors
are the float64 rounding of the samples (≈ 5e-16 rad / h) and the truncation
(h/τ)⁸ for the law's time scale τ.  ω× = Ṙ Rᵀ and α× = R̈ Rᵀ + Ṙ Ṙᵀ, returned in body
axes (Rᵀ ω, Rᵀ α).
"""

import mpmath as mp
import numpy as np

HALF = 4
mp.mp.dps = 40


def _weights(derivative: int) -> list:
    """mpmath weights of the 9-point central difference for a derivative, step 1."""
    nodes = [mp.mpf(k) for k in range(-HALF, HALF + 1)]
    matrix = mp.matrix([[x**j for x in nodes] for j in range(len(nodes))])
    rhs = mp.matrix([mp.factorial(derivative) if j == derivative else 0 for j in range(len(nodes))])
    return list(mp.lu_solve(matrix, rhs))


W1, W2 = _weights(1), _weights(2)


def _vee(m) -> list:
    return [(m[2, 1] - m[1, 2]) / 2, (m[0, 2] - m[2, 0]) / 2, (m[1, 0] - m[0, 1]) / 2]


def reference_rates(bound, t0: float, step: float) -> tuple[np.ndarray, np.ndarray]:
    """ω and α (body axes) from the mpmath differences of the law's own attitude."""
    seconds = t0 + step * np.arange(-HALF, HALF + 1)
    matrices = [mp.matrix(m.tolist()) for m in bound.attitude(seconds).as_matrix()]
    h = mp.mpf(step)
    r0 = matrices[HALF]
    first = sum((w * m for w, m in zip(W1, matrices, strict=True)), mp.zeros(3, 3)) / h
    second = sum((w * m for w, m in zip(W2, matrices, strict=True)), mp.zeros(3, 3)) / h**2
    omega = mp.matrix(_vee(first * r0.T))
    alpha = mp.matrix(_vee(second * r0.T + first * first.T))
    body_omega = r0.T * omega
    body_alpha = r0.T * alpha
    return (
        np.array([float(x) for x in body_omega]),
        np.array([float(x) for x in body_alpha]),
    )
