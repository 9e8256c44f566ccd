"""Δ1, Δ2, Δ3 and mc of float inputs: the exact case test, for one state or a batch.

[Leroy] "The quantity Δj" writes Δj = G² − 2T Ij without cancellation as
Δj = Σ_{k≠j} m_k² (I_k − I_j)/I_k; the sign of Δ2 picks the case ([Leroy] "Solution of
Euler's equation") and mc is a ratio of Δ's ([Leroy] "The elliptic modulus").  Near the
separatrix Δ2 is a difference of nearly equal terms: in floats it keeps only |δ2|/eps
of its digits (δj = Δj/G²), a relative error of 1e-2 at |δ2| = 1e-14, which moves the
flip period by 1e-8.  So the case is decided on the exact value for the float inputs,
and mc is its correctly rounded value:

1. For a batch, in double-double arithmetic (a float plus its rounding error:
   attitude.base.double_double, elementwise over numpy arrays), with a proved error
   bound: the products m_k² and the differences
   I_k − I_j are exact, each product of double-doubles errs by at most 7u² and each sum
   by 3u² relative (u = 2^-53; Joldes, Muller and Popescu, "Tight and rigorous error
   bounds for basic building blocks of double-word arithmetic", ACM Trans. Math. Softw.
   44(2), 2017, doi:10.1145/3121432, Algorithms 6, 7 and 10; we allow 64u²).  The sign of
   Δ2 is certain when |Δ2| exceeds its bound, and mc's rounding when the bound does not
   straddle a rounding boundary.
2. The states for which either is uncertain, and a single state (where Python's
   integers cost less than the double-double), go to the exact path, ``_ExactΔ``: floats
   are dyadic rationals, so Δj is a ratio of Python integers.  These are the states
   within |δ2| ~ 1e-13 of the separatrix (the relative error of Δ2 is ~64u²/|δ2|, which
   must stay below a fraction of an ulp of mc; for the sign alone it is ~1e-29), the
   separatrix itself, and magnitudes that would underflow the double-double terms.

δ1 and δ3 are sums of terms of one sign: in double-double they come out faithfully
rounded (within an ulp, nearly always the correctly rounded value).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from attitude.base import double_double as dd
from attitude.base.float_math import FLOAT

__all__ = ["Invariants", "MomentConstants", "invariants"]

_U2 = 2.0**-106  # u², u = 2^-53 the unit roundoff
_BOUND = 64.0 * _U2  # relative error allowed for each double-double chain (see above)
# Scaled by powers of two so that I3 and max|m_k| lie in [0.5, 1), the double-double
# terms (products of four such numbers and a difference of moments) and their errors stay
# normal floats when every non-zero |m_k| and I1 are at least 2^-150.
_SMALLEST_SCALED = 2.0**-150


@dataclass
class Invariants:
    """The exact case test and the ratios of Δ's, per state (floats, or arrays of a batch).

    ``sign`` is the sign of Δ2 (−1 case i, +1 case ii, 0 the separatrix) as a float;
    δ1 = Δ1/G² ≥ 0 and δ3 = Δ3/G² ≤ 0; ``mc`` is Δ2 I31/(Δ3 I21) in case (i) and
    Δ2 I31/(Δ1 I32) in case (ii), correctly rounded, and ``log_mc`` its logarithm,
    accurate however small mc is (0 and −∞ on the separatrix).
    """

    sign: Any
    δ1: Any
    δ3: Any
    mc: Any
    log_mc: Any


# ----------------------------------------------------------------- the invariants


def _presplit(b: Any) -> tuple[Any, Any, Any]:
    """b with its Veltkamp halves (``double_double.split``): the operand of the
    ``*_presplit`` operations, kept when b is a factor of many products (the moments of
    a batch)."""
    return (b, *dd.split(b))


# The double-double operations on pairs (hi, lo), as the batch below holds them.
def _times_float(x: tuple, b: tuple) -> tuple[Any, Any]:
    return dd.dd_times_float_presplit(x[0], x[1], *b)


def _times_dd(x: tuple, y: tuple, y_split: tuple) -> tuple[Any, Any]:
    return dd.dd_times_dd_presplit(x[0], x[1], y[0], y[1], y_split[1], y_split[2])


def _plus(x: tuple, y: tuple) -> tuple[Any, Any]:
    return dd.dd_plus_dd(x[0], x[1], y[0], y[1])


def _over(x: tuple, y: tuple) -> tuple[Any, Any]:
    return dd.dd_over_dd(x[0], x[1], y[0], y[1])


class MomentConstants:
    """What the double-double test needs of the sorted moments alone, for a batch.

    The moments scaled by a power of two, their exact differences and the Veltkamp
    halves of every moment factor of ``_double_double``, each computed once for the
    batch rather than in every product that takes it (the same operations, so the same
    bits).
    """

    def __init__(self, I1: Any, I2: Any, I3: Any) -> None:
        with np.errstate(over="ignore", under="ignore", invalid="ignore"):
            moments = np.ldexp(np.stack([I1, I2, I3]), -np.frexp(I3)[1])
            self.valid = moments[0] >= _SMALLEST_SCALED
            I_diff = dd.two_sum(moments[[1, 2, 2]], -moments[[0, 0, 1]])  # I21, I31, I32, exact
            # The six terms of Δ's (see _double_double): the difference and the third
            # moment of each.
            d, other = [0, 2, 1, 2, 0, 1], [2, 0, 1, 0, 2, 1]
            self.t_diff = (I_diff[0][d], I_diff[1][d])
            self.t_diff_split = _presplit(self.t_diff[0])
            self.t_other = _presplit(moments[other])
            self.G2_factors = (_presplit(moments[[1, 0]]), _presplit(moments[[2, 1]]))
            self.I2 = _presplit(moments[1])
            self.I31 = (I_diff[0][1], I_diff[1][1])
            self.I31_split = _presplit(I_diff[0][1])
            # Case (i) and case (ii) factors of mc's denominator: I3 and I21, I1 and I32.
            self.I_other = (_presplit(moments[2]), _presplit(moments[0]))
            self.I_d = ((I_diff[0][0], I_diff[1][0]), (I_diff[0][2], I_diff[1][2]))
            self.I_d_split = (_presplit(I_diff[0][0]), _presplit(I_diff[0][2]))


def _select(case_i: Any, when_i: tuple, when_ii: tuple) -> tuple:
    return tuple(np.where(case_i, a, b) for a, b in zip(when_i, when_ii, strict=True))


def _double_double(m1: Any, m2: Any, m3: Any, c: MomentConstants):
    """Δ's in double-double, with the certainty of the sign of Δ2 and of mc's rounding.

    Returns (sign, δ1, δ3, mc, log_mc, certain); where ``certain`` is False the other
    values are to be replaced by the exact path.  Arrays of a batch: the like terms are
    stacked, so that each double-double operation is one numpy call over all of them;
    ``c`` holds what depends on the moments alone.
    """
    # Exact scaling by powers of two (Δ's ratios are scale-free); the moments' in ``c``.
    m = np.stack([m1, m2, m3])
    m = np.ldexp(m, -np.frexp(np.max(np.abs(m), axis=0))[1])
    representable = (m == 0.0) | (np.abs(m) >= _SMALLEST_SCALED)
    valid = representable.all(axis=0) & c.valid

    sq = dd.two_prod_presplit(m, *_presplit(m))  # m_k², exact (m split once)
    # The six terms m_k² I_kj I_l: m1² I21 I3 and m3² I32 I1 (Δ2), m1² I31 I2 and
    # m2² I32 I1 (−Δ3), m2² I21 I3 and m3² I31 I2 (Δ1), all scaled.
    k = [0, 2, 0, 1, 1, 2]
    t = _times_float(_times_dd((sq[0][k], sq[1][k]), c.t_diff, c.t_diff_split), c.t_other)
    # I1 I3 Δ2 = t3 − t1, I1 I2 (−Δ3) and I2 I3 Δ1: sums of two terms (of one sign for
    # the last two).
    sums = _plus(
        (t[0][[1, 2, 4]], t[1][[1, 2, 4]]),
        (t[0][[0, 3, 5]] * [[-1.0], [1.0], [1.0]], t[1][[0, 3, 5]] * [[-1.0], [1.0], [1.0]]),
    )
    N2, P3, N1 = (sums[0][0], sums[1][0]), (sums[0][1], sums[1][1]), (sums[0][2], sums[1][2])
    N2_error = _BOUND * (np.abs(t[0][0]) + np.abs(t[0][1]))
    sign_certain = np.abs(N2[0]) > 2.0 * N2_error
    G2 = _plus(_plus((sq[0][0], sq[1][0]), (sq[0][1], sq[1][1])), (sq[0][2], sq[1][2]))
    case_i = N2[0] < 0.0
    sign = np.where(case_i, -1.0, 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        # δ1 = Δ1/G² = N1/(I2 I3 G²), δ3 = −P3/(I1 I2 G²): faithful, nearly always the
        # correctly rounded values of the exact path (a few ulps off would be amplified
        # next to the separatrix, where the batch must agree with one state alone).
        G2_I = _times_float(
            _times_float((np.stack([G2[0], G2[0]]), np.stack([G2[1], G2[1]])), c.G2_factors[0]),
            c.G2_factors[1],
        )
        δ = _over((np.stack([N1[0], P3[0]]), np.stack([N1[1], P3[1]])), G2_I)[0]
        δ1, δ3 = δ[0], -δ[1]
    # mc = |N2| I2 I31 / (I3 P3 I21) in case (i), |N2| I2 I31 / (I1 N1 I32) in case (ii).
    N2_abs = (np.abs(N2[0]), np.copysign(1.0, N2[0]) * N2[1])
    numerator = _times_dd(_times_float(N2_abs, c.I2), c.I31, c.I31_split)
    D = (np.where(case_i, P3[0], N1[0]), np.where(case_i, P3[1], N1[1]))
    I_other = _select(case_i, *c.I_other)
    I_d = _select(case_i, *c.I_d)
    I_d_split = _select(case_i, *c.I_d_split)
    denominator = _times_dd(_times_float(D, I_other), I_d, I_d_split)
    with np.errstate(divide="ignore", invalid="ignore"):
        mc, mc_low = _over(numerator, denominator)
        # Relative error: that of N2 plus the chains' (four products, a sum, a quotient).
        error = mc * (N2_error / np.abs(N2[0]) + 4.0 * _BOUND)
        spacing = np.spacing(mc)
        below = np.where(np.frexp(mc)[0] == 0.5, 0.5 * spacing, spacing)
        rounding_certain = (mc_low + error < 0.5 * spacing) & (mc_low - error > -0.5 * below)
        certain = valid & sign_certain & rounding_certain & (mc >= 2.0**-900) & (mc <= 1.0)
        log_mc = np.log(mc) + mc_low / mc
    return sign, δ1, δ3, mc, log_mc, certain


def invariants(
    I1: Any,
    I2: Any,
    I3: Any,
    m1: Any,
    m2: Any,
    m3: Any,
    xp: Any = np,
    constants: MomentConstants | None = None,
) -> Invariants:
    """The invariants of states with sorted moments I1 ≤ I2 ≤ I3 (I1 < I3) and m ≠ 0.

    Floats with ``xp = FLOAT``, 1-D arrays of a batch with ``xp = numpy``; ``constants``:
    ``MomentConstants(I1, I2, I3)`` if the caller has it (built here otherwise).
    """
    if xp is FLOAT:
        # On one state in Python, the integers (~8 µs) cost less than the
        # double-double (~18 µs), and they are exact.
        return _ExactΔ(I1, I2, I3, m1, m2, m3).invariants()
    if constants is None:
        constants = MomentConstants(I1, I2, I3)
    with np.errstate(over="ignore", under="ignore", invalid="ignore", divide="ignore"):
        sign, δ1, δ3, mc, log_mc, certain = _double_double(m1, m2, m3, constants)
    for k in np.flatnonzero(~certain):
        exact = _ExactΔ(I1[k], I2[k], I3[k], m1[k], m2[k], m3[k]).invariants()
        sign[k], δ1[k], δ3[k], mc[k], log_mc[k] = (
            exact.sign,
            exact.δ1,
            exact.δ3,
            exact.mc,
            exact.log_mc,
        )
    return Invariants(sign, δ1, δ3, mc, log_mc)


def _as_integers(a: float, b: float, c: float) -> tuple[int, int, int]:
    """The floats a, b, c times one common power of two, as exact integers."""
    (pa, qa), (pb, qb), (pc, qc) = a.as_integer_ratio(), b.as_integer_ratio(), c.as_integer_ratio()
    bits = max(qa, qb, qc).bit_length()  # every q is a power of two
    return (
        pa << (bits - qa.bit_length()),
        pb << (bits - qb.bit_length()),
        pc << (bits - qc.bit_length()),
    )


# A spacecraft stepped by the torqued solver keeps its moments from flow to flow: their
# integers are computed once (the cache is keyed on the float values, so exact).
_moment_integers = functools.lru_cache(maxsize=256)(_as_integers)


class _ExactΔ:
    """Δ1, Δ2, Δ3 of the float inputs, exactly, and the ratios taken from them.

    With I_k = J_k 2^a and m_k = M_k 2^b for integers J, M, Leroy's
    Δj = Σ_k m_k² (I_k − I_j)/I_k is Δj = 2^{2b} D_j / P with P = J1 J2 J3 and the integer
        D_j = Σ_{k≠j} M_k² (J_k − J_j) P/J_k,
    and G² = 2^{2b} S with S = Σ M_k².  So δj = Δj/G² = D_j/(P S), and mc, a ratio of
    Δ's, is a ratio of integers: Python divides each with a single rounding, and takes
    the logarithm of integers of any size (mc may be far below the float range).
    """

    def __init__(self, I1: float, I2: float, I3: float, m1: float, m2: float, m3: float):
        J1, J2, J3 = _moment_integers(I1, I2, I3)
        M1, M2, M3 = _as_integers(m1, m2, m3)
        S1, S2, S3 = M1 * M1, M2 * M2, M3 * M3
        J12, J13, J23 = J1 * J2, J1 * J3, J2 * J3  # P/J3, P/J2, P/J1
        self.J = (J1, J2, J3)
        self.D = (
            S2 * (J2 - J1) * J13 + S3 * (J3 - J1) * J12,
            S1 * (J1 - J2) * J23 + S3 * (J3 - J2) * J12,
            S1 * (J1 - J3) * J23 + S2 * (J2 - J3) * J13,
        )
        self.PS = J12 * J3 * (S1 + S2 + S3)

    def invariants(self) -> Invariants:
        D1, D2, D3 = self.D
        sign = float((D2 > 0) - (D2 < 0))
        δ1, δ3 = D1 / self.PS, D3 / self.PS
        if D2 == 0:
            return Invariants(sign, δ1, δ3, 0.0, -math.inf)
        J1, J2, J3 = self.J
        if D2 < 0:
            numerator, denominator = -D2 * (J3 - J1), -D3 * (J2 - J1)
        else:
            numerator, denominator = D2 * (J3 - J1), D1 * (J3 - J2)
        mc = numerator / denominator
        if mc >= 2.0**-1022:  # a normal float: its own logarithm is the accurate one
            return Invariants(sign, δ1, δ3, mc, math.log(mc))
        # Below the normal range: the logarithms of the integers (any size) keep ln mc.
        return Invariants(sign, δ1, δ3, mc, math.log(numerator) - math.log(denominator))
