"""The orbit's position and velocity with their time derivatives, as jets.

The laws' rates need the derivatives of the directions they follow, hence of the
spacecraft's position up to the jerk (nadir, a ground site) and of its velocity up to
its second derivative (the velocity, the orbit normal).  Two ways, by source:

- **Analytic**: a source with a ``derivatives_tt(jd1, jd2, order)`` method
  (:class:`attitude.environment.keplerian.KeplerianOrbit`) gives them exactly; the
  velocity is then the position's derivative.
- **Finite differences** for the others (SGP4, OEM): central differences on 9 epochs
  t + k h, k = −4 … 4 (weights exact rationals, :func:`stencil_weights`: order 8 for
  the first and second derivatives, 6 for the third), of the position *and*, apart,
  of the velocity the source gives.  SGP4's velocity is not the derivative of its
  position (by up to metres per second on eccentric orbits, :mod:`attitude.environment.orbit`):
  a law built on the source's velocity (the orbit normal, LVLH) has as its rate the
  derivative of that velocity, so each is differenced on its own.  The step is
  h = |r|/|v| / 100 (9.3 s in LEO, 140 s in GEO): the truncation error is then ~1e-16
  of the derivative, and what limits the accuracy is the rounding of the epochs
  themselves (half a day from its reference an epoch is known to 5e-12 s, in which a
  LEO spacecraft moves 4e-8 m) divided by h^k.  Measured against the exact derivatives
  of Keplerian orbits seen only through their positions
  (``tests/test_law_rates_against_mpmath.py``): ṙ to 2e-12 (LEO) and 2e-11 (e = 0.7)
  of its size, r̈ to 8e-10 and 7e-9, the jerk to 7e-8 and 7e-6.  A law's rate moves by
  |δṙ|/|r| < 3e-14 rad/s, its angular acceleration by < 1e-15 rad/s².

Near the ends of a span the source may not cover (an OEM file), the stencil is shifted
inside ``[first, last]`` (one-sided differences of the same order: measured as
accurate as the central ones, within a factor 2), and shortened to fit a span shorter
than 8 steps, down to 1 s steps.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import numpy as np
from numpy.typing import NDArray

from attitude.base.jets import Jet
from attitude.environment.timescales import SECONDS_PER_DAY

__all__ = ["OrbitDerivatives", "orbit_derivatives", "stencil_weights"]

_HALF_WIDTH = 4  # the stencil's epochs are t + k h, k = −4 … 4 (shifted near the ends)
_STEP_FRACTION = 0.01  # h = |r|/|v| / 100
_STEP_LIMITS_S = (0.05, 600.0)


@dataclass(frozen=True)
class OrbitDerivatives:
    """The spacecraft's position jet (order 3: r, ṙ, r̈, jerk; m and s) and velocity jet
    (order 2: v, v̇, v̈) at some epochs, GCRS, and how they were obtained
    (``"analytic"`` or ``"finite differences"``)."""

    position: Jet
    velocity: Jet
    method: str


@functools.cache
def stencil_weights(shift: int) -> NDArray[np.float64]:
    """Weights (4, 9) of the derivatives 0–3 on the epochs t + (k + shift) h,
    k = −4 … 4, for a step h = 1: row d gives f⁽ᵈ⁾(t) ≈ Σ_k w_dk f(t + (k + shift) h)
    / h^d.  Solved exactly in rationals (the Vandermonde system Σ_k w_k x_k^j = d! δ_jd),
    then rounded once."""
    nodes = [Fraction(k + shift) for k in range(-_HALF_WIDTH, _HALF_WIDTH + 1)]
    size = len(nodes)
    rows = []
    for d in range(4):
        # Solve V w = b with V_jk = x_k^j, b_j = d! δ_jd, by Gauss–Jordan in Fractions.
        matrix = [
            [x**j for x in nodes] + [Fraction(math.factorial(d) if j == d else 0)]
            for j in range(size)
        ]
        for col in range(size):
            pivot = next(r for r in range(col, size) if matrix[r][col] != 0)
            matrix[col], matrix[pivot] = matrix[pivot], matrix[col]
            lead = matrix[col][col]
            matrix[col] = [value / lead for value in matrix[col]]
            for r in range(size):
                if r != col and matrix[r][col] != 0:
                    factor = matrix[r][col]
                    matrix[r] = [
                        a - factor * b for a, b in zip(matrix[r], matrix[col], strict=True)
                    ]
        rows.append([float(matrix[k][size]) for k in range(size)])
    return np.array(rows)


def orbit_derivatives(
    orbit: Any,
    jd1: NDArray[np.float64],
    jd2: NDArray[np.float64],
    bounds_jd2: tuple[float, float] | None = None,
) -> OrbitDerivatives:
    """The position and velocity jets of ``orbit`` at the TT Julian dates jd1 + jd2
    (flat arrays, one jd1 per epoch).  ``bounds_jd2``: the span (jd2 values with the
    same jd1) the stencil must stay in, for a source that covers only it (see the
    module notes)."""
    jd1 = np.asarray(jd1, dtype=np.float64)
    jd2 = np.asarray(jd2, dtype=np.float64)
    analytic = getattr(orbit, "derivatives_tt", None)
    if analytic is not None:
        position = Jet.from_derivatives(analytic(jd1, jd2, 3))
        return OrbitDerivatives(position, position.derivative(), "analytic")
    r, v = orbit.state_tt(jd1, jd2)
    h = _STEP_FRACTION * np.linalg.norm(r, axis=-1) / np.maximum(np.linalg.norm(v, axis=-1), 1e-300)
    h = np.clip(h, *_STEP_LIMITS_S)
    shift = np.zeros(jd2.shape, dtype=np.int64)
    if bounds_jd2 is not None:
        first, last = bounds_jd2
        span_s = (last - first) * SECONDS_PER_DAY
        # Fit the stencil in the span, but not with steps below 1 s (whose differences
        # the epochs' rounding would spoil): a shorter span is left at both ends.
        h = np.minimum(h, max(span_s / (2 * _HALF_WIDTH), 1.0))
        before_s = (jd2 - first) * SECONDS_PER_DAY  # room before and after each epoch
        after_s = (last - jd2) * SECONDS_PER_DAY
        with np.errstate(divide="ignore", invalid="ignore"):
            need_up = np.ceil(_HALF_WIDTH - before_s / h)
            need_down = np.ceil(_HALF_WIDTH - after_s / h)
        shift = np.where(need_up > 0, need_up, np.where(need_down > 0, -need_down, 0)).astype(
            np.int64
        )
        shift = np.clip(shift, -_HALF_WIDTH, _HALF_WIDTH)
    k = np.arange(-_HALF_WIDTH, _HALF_WIDTH + 1)
    offsets_s = (k[None, :] + shift[:, None]) * h[:, None]  # (n, 9)
    n = jd2.size
    rs, vs = orbit.state_tt(
        np.repeat(jd1, k.size), (jd2[:, None] + offsets_s / SECONDS_PER_DAY).ravel()
    )
    rs = rs.reshape(n, k.size, 3)
    vs = vs.reshape(n, k.size, 3)
    table = np.stack([stencil_weights(s) for s in range(-_HALF_WIDTH, _HALF_WIDTH + 1)])
    weights = table[shift + _HALF_WIDTH]  # (n, 4, 9)
    scale = h[None, :, None] ** np.arange(4)[:, None, None]  # h^d, (4, n, 1)
    r_d = np.einsum("ndk,nkj->dnj", weights, rs) / scale
    v_d = np.einsum("ndk,nkj->dnj", weights[:, :3], vs) / scale[:3]
    # The value at t itself is the source's, not the stencil's (which is exact there
    # only when the stencil holds t, i.e. always; kept explicit for shifted stencils).
    r_d[0], v_d[0] = r, v
    return OrbitDerivatives(
        Jet.from_derivatives(r_d), Jet.from_derivatives(v_d), "finite differences"
    )
