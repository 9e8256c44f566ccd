"""Compiled (numba) elliptic kernels for one parameter and one argument at a time.

The exact free flow of one state (attitude.solver.numba_backend) needs, per step, the AGM of
its parameter, K, Bulirsch's sn, cn, dn at two arguments, F for the phase, Π − K and
Carlson's R_J twice.  In numpy on a batch of 1000 states, each of these costs a few
hundred numpy calls per flow, ~2 µs a state in all (docs/benchmarks.md); compiled,
they cost the arithmetic itself.  They are the same algorithms as attitude.elliptic.functions,
written for one float:

- ``agm``, ``bulirsch_sn_cn_dn``, ``reduced_sn_cn_dn``: Bulirsch's ``sncndn``
  (R. Bulirsch, "Numerical calculation of elliptic integrals and elliptic functions",
  Numer. Math. 7, 1965), with the Maclaurin series for tiny arguments and the quarter
  shift near ±K ([OLBC10] 22.10.1–3 and Table 22.4.3), as
  ``attitude.elliptic.functions.reduced_sn_cn_dn``;  K = π/(2 M(1, √mc)) from the same AGM
  ([OLBC10] 19.8.5), where attitude.elliptic.functions calls ``scipy.special.ellipkm1``.
- ``cel_pi_minus_k``: Bulirsch's ``cel`` (Numer. Math. 13, 1969) for Π(n|m) − K(m),
  as ``attitude.elliptic.functions._cel``.
- ``carlson_rf``, ``carlson_rj``: Carlson's duplication algorithms (B. C. Carlson,
  "Numerical computation of real or complex elliptic integrals", Numer. Algorithms 10,
  1995, doi:10.1007/BF02198293; [OLBC10] 19.36.1–2), where attitude.elliptic.functions calls
  ``scipy.special.elliprf`` and ``elliprj`` (which implement the same algorithms).

They agree with attitude.elliptic.functions to a few ulps;
tests/test_compiled_flow_against_numpy_flow.py
holds the free flow built on them against the numpy one, and the kernels against mpmath.

Every function is compiled by ``attitude.base.jit.jit`` (IEEE operations as written,
no fast-math; machine code cached).

[OLBC10] F. Olver et al., NIST Handbook of Mathematical Functions (the DLMF), 2010.
"""

from __future__ import annotations

import math

import numpy as np

from attitude.base import double_double
from attitude.base.double_double import two_prod
from attitude.base.jit import inline, jit

__all__ = [
    "AGM_LEVELS",
    "agm",
    "bulirsch_sn_cn_dn",
    "carlson_rf",
    "carlson_rj",
    "cel_pi_minus_k",
    "complete_first_kind",
    "reduced_sn_cn_dn",
]

# As attitude.elliptic.functions: Bulirsch's convergence threshold on the AGM (the method's
# accuracy is its square) and the series threshold of sn, cn, dn.
_AGM_TOLERANCE = 2.0**-27
_SERIES_THRESHOLD = 1.0e-4
# The AGM of 1 and √mc converges in 7 levels at mc = 2^-128 (the smallest the flow
# takes here); the caller's scratch arrays hold this many.
AGM_LEVELS = 40
# Carlson's duplication stops when every argument is within this relative distance of
# their mean: the neglected terms of the series are then below 2^-56 relative (degree 8
# in these distances for R_F, [OLBC10] 19.36.1; degree 6 for R_J, 19.36.2).
_RF_SPREAD = 2.0**-10
_RJ_SPREAD = 2.0**-10

inline(double_double.FUNCTIONS)  # two_prod, in complete_first_kind

# π/2 as a float and its rounding error (π/2 − HALF_PI = 6.1e-17, −0.35 ulp of K).
_HALF_PI = 0.5 * math.pi
_HALF_PI_LOW = 6.123233995736766e-17


@jit
def agm(mc: float, a_seq: np.ndarray, b_seq: np.ndarray) -> tuple[int, float]:
    """The AGM of 1 and √mc for Bulirsch's recurrence: its levels (written into
    ``a_seq`` and ``b_seq``) and its final mean c = π/(2K); 0 < mc ≤ 1."""
    a = 1.0
    emc = mc
    for i in range(AGM_LEVELS):
        a_seq[i] = a
        emc = math.sqrt(emc)
        b_seq[i] = emc
        c = 0.5 * (a + emc)
        if abs(a - emc) <= _AGM_TOLERANCE * a:
            return i + 1, c
        emc = emc * a
        a = c
    return 0, math.nan  # not reached for mc ≥ 2^-1022


@jit
def complete_first_kind(c: float) -> float:
    """K = π/(2 M(1, √mc)) ([OLBC10] 19.8.5) from the final mean c of ``agm``.  π/2
    carried to twice the float precision: its rounding alone would bias K by −0.35 ulp,
    which a torqued run would accumulate over its flows."""
    q = _HALF_PI / c
    p, e = two_prod(q, c)  # q c = p + e exactly
    return q + (((_HALF_PI - p) - e) + _HALF_PI_LOW) / c  # the remainder, then its quotient


@jit
def bulirsch_sn_cn_dn(
    z: float, levels: int, c: float, a_seq: np.ndarray, b_seq: np.ndarray
) -> tuple[float, float, float]:
    """sn, cn, dn for 1e-4 ≤ |z| ≤ K/2: the descending Gauss transformation from one
    cotangent (``attitude.elliptic.functions._bulirsch``, operation for operation)."""
    x = z * c
    a = 1.0 / math.tan(x)
    c = c * a
    d = 1.0
    for i in range(levels - 1, -1, -1):
        a_i = a_seq[i]
        a_next = a * c
        c = c * d
        d = (b_seq[i] + a_next) / (a_i + a_next)
        a = c / a_i
    s = math.copysign(1.0 / math.sqrt(c * c + 1.0), x)
    return s, c * s, d


@jit
def reduced_sn_cn_dn(
    r: float, mc: float, K: float, levels: int, c: float, a_seq: np.ndarray, b_seq: np.ndarray
) -> tuple[float, float, float]:
    """sn, cn, dn of a reduced argument |r| ≤ K, 0 < mc ≤ 1, with the AGM of ``agm``
    (``attitude.elliptic.functions._reduced_sn_cn_dn_float``)."""
    far = abs(r) > 0.5 * K
    σ = math.copysign(1.0, r)
    z = r - σ * K if far else r
    if abs(z) < _SERIES_THRESHOLD:  # [OLBC10] 22.10.1–3, to z⁵
        m = 1.0 - mc
        z2 = z * z
        s = z * (1.0 - z2 * ((1.0 + m) / 6.0 - z2 * (1.0 + m * (14.0 + m)) / 120.0))
        co = 1.0 - z2 * (0.5 - z2 * (1.0 + 4.0 * m) / 24.0)
        d = 1.0 - m * z2 * (0.5 - z2 * (4.0 + m) / 24.0)
    else:
        s, co, d = bulirsch_sn_cn_dn(z, levels, c, a_seq, b_seq)
    if not far:
        return s, co, d
    sqrt_mc = math.sqrt(mc)  # [OLBC10] Table 22.4.3: the quarter shift z + σK
    return σ * co / d, -σ * sqrt_mc * s / d, sqrt_mc / d


@jit
def cel_pi_minus_k(kc: float, n: float) -> float:
    """Π(n|m) − K(m) = cel(kc, 1 − n, 0, n), kc = √mc > 0, n < 1: Bulirsch's ``cel``
    (``attitude.elliptic.functions._cel`` for one float)."""
    e = kc
    mean = 1.0
    p = math.sqrt(1.0 - n)
    a = 0.0
    b = n / p
    for _ in range(AGM_LEVELS):
        f = a
        a = a + b / p
        g = e / p
        b = 2.0 * (b + f * g)
        p = g + p
        g = mean
        mean = kc + mean
        if abs(g - kc) <= _AGM_TOLERANCE * g:
            return (0.5 * math.pi) * (a * mean + b) / (mean * (mean + p))
        kc = 2.0 * math.sqrt(e)
        e = kc * mean
    return math.nan  # not reached for kc ≥ 2^-64


@jit
def carlson_rf(x: float, y: float, z: float) -> float:
    """R_F(x, y, z) for x, y, z ≥ 0, at most one of them 0 ([OLBC10] 19.36.1)."""
    mean0 = (x + y + z) / 3.0
    # A_m − x_m = (A_0 − x_0)/4^m: the distances to the mean from the initial values.
    dx, dy = mean0 - x, mean0 - y
    spread = max(abs(dx), abs(dy), abs(mean0 - z))
    mean = mean0
    scale = 1.0  # 4^-m
    while scale * spread > _RF_SPREAD * abs(mean):
        sx, sy, sz = math.sqrt(x), math.sqrt(y), math.sqrt(z)
        λ = sx * sy + sy * sz + sz * sx
        x, y, z = 0.25 * (x + λ), 0.25 * (y + λ), 0.25 * (z + λ)
        mean = 0.25 * (mean + λ)
        scale *= 0.25
    X = dx * scale / mean
    Y = dy * scale / mean
    Z = -(X + Y)
    E2 = X * Y - Z * Z
    E3 = X * Y * Z
    series = (
        1.0
        - E2 / 10.0
        + E3 / 14.0
        + E2 * E2 / 24.0
        - 3.0 * E2 * E3 / 44.0
        - 5.0 * E2 * E2 * E2 / 208.0
        + 3.0 * E3 * E3 / 104.0
        + E2 * E2 * E3 / 16.0
    )
    return series / math.sqrt(mean)


@jit
def _rc_one_plus(e: float) -> float:
    """R_C(1, 1 + e) for e > −1: arctan(√e)/√e, or artanh(√−e)/√−e ([OLBC10] 19.2.18–19)."""
    if abs(e) < 2.0**-20:  # the series 1 − e/3 + e²/5 − e³/7 (next term below 2^-80)
        return 1.0 - e * (1.0 / 3.0 - e * (0.2 - e / 7.0))
    if e > 0.0:
        r = math.sqrt(e)
        return math.atan(r) / r
    r = math.sqrt(-e)
    return math.atanh(r) / r


@jit
def carlson_rj(x: float, y: float, z: float, p: float) -> float:
    """R_J(x, y, z, p) for x, y, z ≥ 0 (at most one 0) and p > 0: Carlson's duplication
    with the sum of R_C terms ([OLBC10] 19.36.2; Carlson 1995, Algorithm for R_J)."""
    mean0 = (x + y + z + 2.0 * p) / 5.0
    dx, dy, dz = mean0 - x, mean0 - y, mean0 - z  # as in carlson_rf
    spread = max(abs(dx), abs(dy), abs(dz), abs(mean0 - p))
    δ = (p - x) * (p - y) * (p - z)
    mean = mean0
    scale = 1.0  # 4^-m
    scale3 = 1.0  # 4^-3m
    total = 0.0
    while scale * spread > _RJ_SPREAD * abs(mean):
        sx, sy, sz, sp = math.sqrt(x), math.sqrt(y), math.sqrt(z), math.sqrt(p)
        λ = sx * sy + sy * sz + sz * sx
        d = (sp + sx) * (sp + sy) * (sp + sz)
        total += scale * _rc_one_plus(scale3 * δ / (d * d)) / d
        x, y, z, p = 0.25 * (x + λ), 0.25 * (y + λ), 0.25 * (z + λ), 0.25 * (p + λ)
        mean = 0.25 * (mean + λ)
        scale *= 0.25
        scale3 *= 1.0 / 64.0
    X = dx * scale / mean
    Y = dy * scale / mean
    Z = dz * scale / mean
    P = -0.5 * (X + Y + Z)
    XYZ = X * Y * Z
    E2 = X * Y + X * Z + Y * Z - 3.0 * P * P
    E3 = XYZ + 2.0 * E2 * P + 4.0 * P * P * P
    E4 = (2.0 * XYZ + E2 * P + 3.0 * P * P * P) * P
    E5 = XYZ * P * P
    series = (
        1.0
        - 3.0 * E2 / 14.0
        + E3 / 6.0
        + 9.0 * E2 * E2 / 88.0
        - 3.0 * E4 / 22.0
        - 9.0 * E2 * E3 / 52.0
        + 3.0 * E5 / 26.0
    )
    return scale * series / (mean * math.sqrt(mean)) + 6.0 * total
