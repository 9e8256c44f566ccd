"""Jacobi elliptic functions and elliptic integrals, parametrized by mc = 1 − m.

Everything here takes the *complementary parameter* ``mc = 1 − m`` ([OLBC10] §19.1,
§22.2) instead of the parameter ``m``: near the separatrix of the free rigid body
``m`` is within 1e-14 of 1, and a float ``m`` has already lost the digits that
matter there.  The solver computes ``mc`` from the physics without cancellation
(Leroy, "The elliptic modulus") and hands it to these kernels unchanged.

How small mc may be.  The general kernels below depend on mc through K (through
ln mc as mc → 0: K = ln(4/√mc) + O(mc ln mc), [OLBC10] 19.12.1) and through the AGM of
1 and √mc; both keep full accuracy for any float mc, down to the subnormals (checked
against mpmath at mc from 1e-100 to 1e-320: a few ulps, plus eps·|u|·|f'| for large
|u|).  What fails first is mc itself: a subnormal float carries fewer than 53
significant bits (1e-320 has 11), and K moves by half the relative error of mc, so a
subnormal mc that is a rounded physical ratio gives K, hence the period, to only a
few digits; and a ratio below 5e-324 rounds to zero, the separatrix, whose motion is
not periodic at all.  So below ``NEAR_ONE_MC`` (2^-128 ≈ 2.9e-39) the kernels take
ln mc instead, which the solver computes from its exact integers for any mc however
small, and use the expansions about m = 1: there the neglected terms are O(√mc)
relative, below 2^-66 (derivation in ``reduced_sn_cn_dn_near_one`` and
``pi_minus_f_near_one``).

Arrays and floats.  Every function takes numpy arrays (vectorized over arguments and
parameters).  ``JacobiParameter``, the interface the solver uses, also takes Python
floats, for a single state: the same formulas run through ``attitude.base.float_math``, and
the one kernel that branches per element (sn, cn, dn) has a float dispatcher over the
same pieces.

Why our own kernels: ``scipy.special.ellipj`` takes ``m`` and, for ``m ≥ 1 − 1e-9``,
switches to an approximation that is only valid in the first quarter period (values
of 1e47 and NaN further out; scipy issue #8480), and its error grows with ``u``
because it does not reduce the argument.  The Carlson symmetric integrals and the
complete integral K are taken from scipy, which computes them well.

References
----------
[OLBC10] F. Olver et al., *NIST Handbook of Mathematical Functions*, 2010
    (the DLMF), chapters 19 (elliptic integrals) and 22 (Jacobi functions).
[Bul65] R. Bulirsch, "Numerical calculation of elliptic integrals and elliptic
    functions", Numerische Mathematik 7 (1965) 78–90, procedure ``sncndn``.
[Bul69] R. Bulirsch, "Numerical calculation of elliptic integrals and elliptic
    functions. III", Numerische Mathematik 13 (1969) 305–315,
    doi:10.1007/BF02165405, procedure ``cel``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import special
from scipy.special import cython_special

from attitude.base.float_math import FLOAT

__all__ = [
    "NEAR_ONE_MC",
    "JacobiParameter",
    "complete_first_kind",
    "complete_first_kind_near_one",
    "elliptic_f",
    "elliptic_pi",
    "elliptic_pi_complete",
    "jacobi_amplitude",
    "jacobi_sn_cn_dn",
    "pi_minus_f",
    "pi_minus_f_near_one",
    "reduce_argument",
    "reduced_sn_cn_dn",
    "reduced_sn_cn_dn_near_one",
]

# Bulirsch's convergence threshold on the arithmetic-geometric mean: the method's
# accuracy is the square of it, so 2**-27 gives full double precision.
_AGM_TOLERANCE = 2.0**-27
# Below this |u| the Taylor series to u⁵ is exact to rounding (the next term is
# O(u⁶) ≈ 1e-24), and it avoids the overflow of Bulirsch's cot recurrence at tiny u.
_SERIES_THRESHOLD = 1.0e-4
# Below this complementary parameter the kernels work from ln mc and the expansions
# about m = 1, whose neglected terms are O(√mc) = O(2^-64) relative (module docstring).
NEAR_ONE_MC = 2.0**-128
_LN4 = math.log(4.0)


def _as_mc(mc: ArrayLike) -> NDArray[np.float64]:
    mc = np.asarray(mc, dtype=np.float64)
    if not np.all((mc >= 0.0) & (mc <= 1.0)):
        bad = mc[~((mc >= 0.0) & (mc <= 1.0))].ravel()[0]
        raise ValueError(
            f"complementary parameter mc must lie in [0, 1] (m = 1 - mc in [0, 1]), got mc={bad!r}"
        )
    return mc


def complete_first_kind(mc: ArrayLike) -> NDArray[np.float64]:
    """K(m), the complete elliptic integral of the first kind, from mc = 1 − m.

    [OLBC10] 19.2.8.  Uses ``scipy.special.ellipkm1``, which takes mc directly and
    is accurate as mc → 0 (where K ≈ ln(4/√mc)).  K is infinite for mc = 0.
    """
    mc = _as_mc(mc)
    return special.ellipkm1(mc)


def reduce_argument(u: ArrayLike, K: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Split ``u = 2 j K + r`` with integer ``j`` (as float) and ``|r| ≤ K``.

    The Jacobi functions have period 4K, and sn, cn change sign over 2K while dn does
    not ([OLBC10] 22.4.3); the amplitude grows by π over 2K ([OLBC10] 22.16.2).  For
    K = ∞ (mc = 0) nothing is periodic and ``j = 0``, ``r = u``.
    """
    u = np.asarray(u, dtype=np.float64)
    K = np.asarray(K, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        j = np.where(np.isfinite(K), np.rint(u / (2.0 * K)), 0.0)
        r = np.where(j == 0.0, u, u - j * (2.0 * K))
    return j, r


# ----------------------------------------------------------------- sn, cn, dn: the pieces
# Each piece is elementwise arithmetic and functions of the namespace ``xp`` (numpy, or
# attitude.base.float_math.FLOAT), shared by the array and the float dispatchers below.


def _maclaurin(x: Any, mc: Any) -> tuple[Any, Any, Any]:
    """sn, cn, dn to x⁵ for |x| < 1e-4 ([OLBC10] 22.10.1–3)."""
    m = 1.0 - mc
    x2 = x * x
    sn = x * (1.0 - x2 * ((1.0 + m) / 6.0 - x2 * (1.0 + m * (14.0 + m)) / 120.0))
    cn = 1.0 - x2 * (0.5 - x2 * (1.0 + 4.0 * m) / 24.0)
    dn = 1.0 - m * x2 * (0.5 - x2 * (4.0 + m) / 24.0)
    return sn, cn, dn


def _agm(mc: Any, xp: Any) -> tuple[list, list, Any, Any]:
    """The AGM of 1 and √mc that drives ``_bulirsch``: the means a_i, the geometric
    means b_i, the final mean c, and the number of levels.

    With an array ``mc`` each element keeps its own: the loop runs until every element
    has converged, and ``levels`` (an integer array) and ``c`` are each element's at its
    own convergence, so that ``_bulirsch`` gives it the same bits as alone (for one
    float, ``levels`` is None).
    """
    a = 1.0
    emc = mc
    a_seq, b_seq = [], []
    if xp is FLOAT or np.ndim(mc) == 0:
        sqrt = xp.sqrt
        for _ in range(40):
            a_seq.append(a)
            emc = sqrt(emc)
            b_seq.append(emc)
            c = 0.5 * (a + emc)
            if abs(a - emc) <= _AGM_TOLERANCE * a:
                return a_seq, b_seq, c, None
            emc = emc * a
            a = c
        raise ArithmeticError("AGM did not converge")  # pragma: no cover  (10 steps at 1e-300)
    levels = np.zeros(np.shape(mc), dtype=np.intp)
    c_final = np.zeros(np.shape(mc))
    pending = np.ones(np.shape(mc), dtype=bool)
    for _ in range(40):
        a_seq.append(a)
        emc = np.sqrt(emc)
        b_seq.append(emc)
        c = 0.5 * (a + emc)
        levels += pending  # each element counts the levels it runs, its last included
        now = pending & (abs(a - emc) <= _AGM_TOLERANCE * a)
        if now.any():
            np.copyto(c_final, c, where=now)  # masked copies: no gather, no scatter
            pending &= ~now
            if not pending.any():
                return a_seq, b_seq, c_final, levels
        emc = emc * a
        a = c
    raise ArithmeticError("AGM did not converge")  # pragma: no cover


def _bulirsch(z: Any, mc: Any, xp: Any, agm: tuple | None = None) -> tuple[Any, Any, Any]:
    """sn, cn, dn for 1e-4 ≤ |z| ≤ K/2 and mc > 0: Bulirsch's ``sncndn`` [Bul65].

    The descending Gauss transformation driven by the AGM of 1 and √mc (``_agm``, or
    ``agm`` if the caller keeps it: it depends on mc only): one cotangent, then a
    rational recurrence.  (Bulirsch starts from cos x / sin x; 1/tan x is the same
    number to rounding, and numpy's tangent is vectorized, five times cheaper than
    its sine and cosine.)  Pass a scalar ``mc`` when all elements share it: the
    AGM is then computed once.  With an array ``mc``, each element runs through its
    own levels only (the others are held by a ``where``).
    """
    a_seq, b_seq, c, levels = _agm(mc, xp) if agm is None else agm
    x = z * c  # |x| ≤ π/4, since c K = π/2
    a: Any = 1.0 / xp.tan(x)  # cot x: one tangent (numpy's is vectorized; sin, cos are not)
    c = c * a
    d: Any = 1.0
    shared = len(a_seq) if levels is None else int(levels.min())  # levels every element has
    for i in range(len(a_seq) - 1, -1, -1):
        a_i, b_i = a_seq[i], b_seq[i]
        a_next = a * c
        c_next = c * d
        d_next = (b_i + a_next) / (a_i + a_next)
        a_next = c_next / a_i
        if i < shared:
            a, c, d = a_next, c_next, d_next
        else:
            own = i < levels
            a, c, d = np.where(own, a_next, a), np.where(own, c_next, c), np.where(own, d_next, d)
    s = xp.copysign(1.0 / xp.sqrt(c * c + 1.0), x)  # sin x has the sign of x
    return s, c * s, d


def _quarter_shift(σ: Any, mc: Any, s: Any, c: Any, d: Any, xp: Any) -> tuple[Any, Any, Any]:
    """sn, cn, dn of z + σK from those of z ([OLBC10] Table 22.4.3, σ = ±1):
    sn = σ cd z, cn = −σ √mc sd z, dn = √mc nd z."""
    sqrt_mc = xp.sqrt(mc)
    return σ * c / d, -σ * sqrt_mc * s / d, sqrt_mc / d


def _sn_cn_dn_core(
    z: NDArray[np.float64], mc: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """sn, cn, dn for |z| ≤ K/2 (same shapes for z and mc): Bulirsch, series or hyperbolic."""
    sn = np.empty(z.shape)
    cn = np.empty(z.shape)
    dn = np.empty(z.shape)
    hyperbolic = mc == 0.0
    small = (np.abs(z) < _SERIES_THRESHOLD) & ~hyperbolic
    general = ~(hyperbolic | small)

    if np.any(hyperbolic):
        x = z[hyperbolic]
        sn[hyperbolic] = np.tanh(x)
        cn[hyperbolic] = dn[hyperbolic] = 1.0 / np.cosh(x)

    if np.any(small):
        sn[small], cn[small], dn[small] = _maclaurin(z[small], mc[small])

    if np.any(general):
        # The AGM depends on mc only: computed once when mc is a scalar (the solver's
        # case), elementwise otherwise.
        mc_g = mc[general]
        if np.all(mc_g == mc_g.flat[0]):
            mc_g = mc_g.flat[0]
        sn[general], cn[general], dn[general] = _bulirsch(z[general], mc_g, np)
    return sn, cn, dn


def reduced_sn_cn_dn(
    r: ArrayLike, mc: ArrayLike, K: ArrayLike | None = None
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """sn, cn, dn of a reduced argument ``|r| ≤ K`` (so cn ≥ 0), for 0 ≤ mc ≤ 1.

    Bulirsch's ``sncndn`` [Bul65] (descending Gauss transformation driven by the
    AGM of 1 and √mc), vectorized: one sine and one cosine per element, then a
    rational recurrence.  For mc = 0 the functions are tanh, sech, sech
    ([OLBC10] 22.5.8); for tiny |r| the Maclaurin series ([OLBC10] 22.10.1–3).

    Near ±K, where cn and dn are both small (dn(K) = √mc), the recurrence only has
    absolute accuracy.  So for K/2 < |r| ≤ K we evaluate at z = r ∓ K and shift by a
    quarter period ([OLBC10] Table 22.4.3: sn(z + K) = cd z, cn(z + K) = −√mc sd z,
    dn(z + K) = √mc nd z), which keeps all three to full relative accuracy.
    ``K`` may be passed when the caller already has it.
    """
    r = np.asarray(r, dtype=np.float64)
    mc = _as_mc(mc)
    if K is None:
        K = complete_first_kind(mc)
    r, mc, K = np.broadcast_arrays(r, mc, np.asarray(K, dtype=np.float64))
    far = np.abs(r) > 0.5 * K
    z = np.where(far, r - np.copysign(K, r), r)
    s, c, d = _sn_cn_dn_core(z, mc)
    if not np.any(far):
        return s, c, d
    shifted = _quarter_shift(np.copysign(1.0, r), mc, s, c, d, np)
    return np.where(far, shifted[0], s), np.where(far, shifted[1], c), np.where(far, shifted[2], d)


def _reduced_sn_cn_dn_positive_mc(
    r: NDArray[np.float64], mc: Any, K: Any, agm: tuple | None = None
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """``reduced_sn_cn_dn`` for 0 < mc ≤ 1 (one float, or an array like ``r``): the
    same pieces as ``_sn_cn_dn_core`` and ``_quarter_shift``, on the whole array.

    Bulirsch's recurrence runs over every element (its AGM once for a float mc, or
    until every element has converged); the few elements with |z| below the series
    threshold (where the cot recurrence would overflow) are then recomputed by the
    series, and the quarter shift is a ``where``.  No boolean gather of the whole
    array: each piece is a pass over contiguous memory.
    """
    far = np.abs(r) > 0.5 * K
    σ = np.copysign(1.0, r)
    z = np.where(far, r - σ * K, r)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        s, c, d = _bulirsch(z, mc, np, agm)
    small = np.flatnonzero(np.abs(z) < _SERIES_THRESHOLD)
    if small.size:  # s, c, d are new arrays: their flat views write through
        mc_small = mc if np.ndim(mc) == 0 else np.broadcast_to(mc, z.shape).reshape(-1)[small]
        values = _maclaurin(z.reshape(-1)[small], mc_small)
        for out, value in zip((s, c, d), values, strict=True):
            out.reshape(-1)[small] = value
    shifted = _quarter_shift(σ, mc, s, c, d, np)
    return np.where(far, shifted[0], s), np.where(far, shifted[1], c), np.where(far, shifted[2], d)


def _reduced_sn_cn_dn_float(
    r: float, mc: float, K: float, agm: tuple | None = None
) -> tuple[float, float, float]:
    """``reduced_sn_cn_dn`` for one float (0 < mc ≤ 1): the same pieces, chosen by ``if``."""
    far = abs(r) > 0.5 * K
    σ = math.copysign(1.0, r)
    z = r - σ * K if far else r
    if abs(z) < _SERIES_THRESHOLD:
        s, c, d = _maclaurin(z, mc)
    else:
        s, c, d = _bulirsch(z, mc, FLOAT, agm)
    return _quarter_shift(σ, mc, s, c, d, FLOAT) if far else (s, c, d)


def jacobi_sn_cn_dn(
    u: ArrayLike, mc: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Jacobi elliptic functions sn(u|m), cn(u|m), dn(u|m) for any real u, from mc = 1 − m.

    The argument is first reduced by the half period 2K ([OLBC10] 22.4.3:
    sn(u + 2K) = −sn u, cn(u + 2K) = −cn u, dn(u + 2K) = dn u), so the error does not
    grow with |u| beyond the rounding of u itself.
    """
    mc = _as_mc(mc)
    j, _r, sn, cn, dn = _jacobi_reduced(u, mc, complete_first_kind(mc))
    sign = _parity_sign(j, np)
    return sign * sn, sign * cn, dn


def _jacobi_reduced(u: ArrayLike, mc: NDArray[np.float64], K: NDArray[np.float64]):
    j, r = reduce_argument(u, K)
    return (j, r, *reduced_sn_cn_dn(r, mc, K))


def _parity_sign(j: Any, xp: Any) -> Any:
    """(−1)^j for an integer-valued float j: sn and cn change sign every 2K."""
    if xp is FLOAT:
        return -1.0 if j % 2.0 else 1.0
    return 1.0 - 2.0 * xp.abs(j - 2.0 * xp.rint(0.5 * j))


def amplitude(j: Any, sn_r: Any, cn_r: Any, xp: Any = np) -> Any:
    """am(u) = jπ + atan2(sn r, cn r) for u = 2jK + r, |r| ≤ K ([OLBC10] 22.16.2).

    On |r| ≤ K, where cn ≥ 0, atan2 lies in [−π/2, π/2] with no branch jump, so the
    amplitude is continuous and increasing in u.
    """
    return j * xp.pi + xp.arctan2(sn_r, cn_r)


def jacobi_amplitude(u: ArrayLike, mc: ArrayLike) -> NDArray[np.float64]:
    """The Jacobi amplitude am(u|m), continuous and increasing in u, from mc = 1 − m.

    See ``amplitude``.  For mc = 0 it is the Gudermannian gd(u) ([OLBC10] 22.16.4
    with 4.23.40).
    """
    mc = _as_mc(mc)
    j, _r, sn, cn, _dn = _jacobi_reduced(u, mc, complete_first_kind(mc))
    return amplitude(j, sn, cn)


# ----------------------------------------------------------------- F and Π


def _split_angle(phi: ArrayLike) -> tuple[NDArray[np.float64], ...]:
    """φ = jπ + φr with |φr| ≤ π/2; returns j, sin φr, cos φr (cos φr ≥ 0)."""
    phi = np.asarray(phi, dtype=np.float64)
    j = np.rint(phi / np.pi)
    phir = phi - j * np.pi
    return j, np.sin(phir), np.cos(phir)


def _f_of_sin_cos(s: Any, c: Any, mc: Any, xp: Any = np) -> Any:
    """F(φ|m) for |φ| ≤ π/2 from s = sin φ and c = cos φ ≥ 0: [OLBC10] 19.25.5,
    F = s R_F(c², c² + mc s², 1) (``c² + mc s²`` is 1 − m s² without cancellation)."""
    c2 = c * c
    return s * _special(xp).elliprf(c2, c2 + mc * s * s, 1.0)


def _special(xp: Any) -> Any:
    """scipy's special functions for arrays (ufuncs), or for floats their Cython
    versions (``scipy.special.cython_special``: the same code and bits, a float in and
    out, without the ufunc's dispatch, a third of its cost on one float)."""
    return cython_special if xp is FLOAT else special


def elliptic_f(phi: ArrayLike, mc: ArrayLike) -> NDArray[np.float64]:
    """Incomplete elliptic integral of the first kind F(φ|m) for any real φ, from mc.

    Carlson form on |φ| ≤ π/2 (``_f_of_sin_cos``) and the quasi-periodicity
    F(φ + jπ) = F(φ) + 2jK ([OLBC10] 19.2.10).
    """
    mc = _as_mc(mc)
    j, s, c = _split_angle(phi)
    with np.errstate(invalid="ignore"):
        f = _f_of_sin_cos(s, c, mc)
        return np.where(j == 0.0, f, f + 2.0 * j * complete_first_kind(mc))


def pi_minus_f(j: Any, sn: Any, cn: Any, dn: Any, n: Any, mc: Any) -> Any:
    """Π(φ, n|m) − F(φ|m) at the amplitude φ = jπ + φr, given sin φr, cos φr ≥ 0, Δ(φr).

    From [OLBC10] 19.25.14 (Carlson form of Π, valid for |φr| ≤ π/2):
        Π(φr, n) = s R_F(c², Δ², 1) + (n/3) s³ R_J(c², Δ², 1, 1 − n s²),
    and the quasi-periodicity Π(φr + jπ, n) = Π(φr, n) + 2j Π(n), with the complete
    Π(n) = K + (n/3) R_J(0, mc, 1, 1 − n) ([OLBC10] 19.25.2).  The F parts cancel, so
    what remains needs only R_J.

    This is the useful form on a Jacobi amplitude: if φ = am(u), then F(φ) = u exactly
    and Π(am u, n) = u + pi_minus_f(...), with sn, cn, dn of the reduced argument.
    Requires n < 1 (no singularity on the path; the solver's n are all ≤ 0).
    ``1 − n s²`` is written ``c² + (1 − n) s²`` so that it has no cancellation.
    Takes arrays or, all together, floats.
    """
    c2 = cn * cn
    s2 = sn * sn
    incomplete = sn * s2 * special.elliprj(c2, dn * dn, 1.0, c2 + (1.0 - n) * s2)
    if np.all(j == 0.0):
        return (n / 3.0) * incomplete
    complete = special.elliprj(0.0, mc, 1.0, 1.0 - n)
    return (n / 3.0) * (incomplete + 2.0 * j * complete)


def _check_n(n: ArrayLike) -> NDArray[np.float64]:
    n = np.asarray(n, dtype=np.float64)
    if not np.all(n < 1.0):
        bad = n[~(n < 1.0)].ravel()[0]
        raise ValueError(f"characteristic n must be < 1 (hyperbolic case), got n={bad!r}")
    return n


def elliptic_pi(phi: ArrayLike, n: ArrayLike, mc: ArrayLike) -> NDArray[np.float64]:
    """Incomplete elliptic integral of the third kind Π(φ, n|m) for any real φ, n < 1.

    Π(φ, n|m) = ∫₀^φ dθ / ((1 − n sin²θ) √(1 − m sin²θ))  ([OLBC10] 19.2.7; the
    convention of [BF54] and of Leroy's notes).  Computed as F(φ) + (Π − F) with
    [OLBC10] 19.25.5, 19.25.14 and the quasi-periodicity 19.2.10.
    """
    n = _check_n(n)
    mc = _as_mc(mc)
    j, s, c = _split_angle(phi)
    dn = np.sqrt(c * c + mc * s * s)
    return elliptic_f(phi, mc) + pi_minus_f(j, s, c, dn, n, mc)


def elliptic_pi_complete(n: ArrayLike, mc: ArrayLike) -> NDArray[np.float64]:
    """Complete elliptic integral of the third kind Π(n|m), n < 1, from mc ([OLBC10] 19.25.2)."""
    n = _check_n(n)
    mc = _as_mc(mc)
    return special.elliprf(0.0, mc, 1.0) + (n / 3.0) * special.elliprj(0.0, mc, 1.0, 1.0 - n)


def _cel(kc: Any, p: Any, a: Any, b: Any, xp: Any = np) -> Any:
    """Bulirsch's general complete elliptic integral, vectorized ([Bul69] ``cel``):

        cel(kc, p, a, b) = ∫₀^{π/2} (a cos²θ + b sin²θ) dθ
                           / ((cos²θ + p sin²θ) √(cos²θ + kc² sin²θ)),   kc > 0, p > 0.

    With kc² = mc, p = 1 − n, a = 0 and b = n it is Π(n|m) − K(m) ([OLBC10] 19.2.7 with
    n sin²θ/(1 − n sin²θ) = 1/(1 − n sin²θ) − 1), the same number as
    (n/3) R_J(0, mc, 1, 1 − n) ([OLBC10] 19.25.2) for a third of the cost: a Gauss
    (AGM) transformation of the integrand, quadratically convergent; the iteration
    stops when the arithmetic and geometric means agree to 2^-27, that is the
    integral to ~2^-54.  Each element of an array takes its value at its own
    convergence, so that a state gives the same bits alone (floats) and in a batch.
    """
    sqrt = xp.sqrt
    e = kc
    mean: Any = 1.0
    p = sqrt(p)
    a = a + 0.0 * kc
    b = b / p
    final: list[Any] | None = None
    pending: Any = None
    for _ in range(40):
        f = a
        a = a + b / p
        g = e / p
        b = 2.0 * (b + f * g)
        p = g + p
        g = mean
        mean = kc + mean
        converged = abs(g - kc) <= _AGM_TOLERANCE * g
        if xp is FLOAT:
            if converged:
                return (0.5 * math.pi) * (a * mean + b) / (mean * (mean + p))
        else:
            # Each element's a, b, mean, p at its own convergence, as for one state
            # alone; the result is formed from them once, at the end.
            if final is None:
                shape = np.shape(converged)
                final = [np.empty(shape) for _ in range(4)]
                pending = np.ones(shape, bool)
            now = converged & pending
            if now.any():
                for kept, value in zip(final, (a, b, mean, p), strict=True):
                    np.copyto(kept, value, where=now)
                pending &= ~now
                if not pending.any():
                    a, b, mean, p = final
                    return (0.5 * math.pi) * (a * mean + b) / (mean * (mean + p))
        kc = 2.0 * sqrt(e)
        e = kc * mean
    raise ArithmeticError("cel did not converge")  # pragma: no cover  (8 steps at 2^-128)


# ----------------------------------------------------------------- m within 2^-128 of 1


def complete_first_kind_near_one(log_mc: Any) -> Any:
    """K from ln mc, for mc < ``NEAR_ONE_MC``: K = ln 4 − ½ ln mc.

    [OLBC10] 19.12.1: K = ln(4/k') + O(k'² ln k') with k' = √mc; the neglected term is
    below 2^-128·100 there.  ``log_mc = −∞`` (the separatrix) gives K = ∞.
    """
    return _LN4 - 0.5 * log_mc


def reduced_sn_cn_dn_near_one(r: Any, log_mc: Any, K: Any, xp: Any = np) -> tuple[Any, Any, Any]:
    """sn, cn, dn of a reduced argument ``|r| ≤ K`` for mc < ``NEAR_ONE_MC``, from ln mc.

    With k' = √mc and K = ln(4/k') (``complete_first_kind_near_one``):

    - |r| ≤ K/2: sn = tanh r, cn = dn = sech r.  [OLBC10] 22.10.8–10 give the first
      corrections, (k'²/4)(sinh r cosh r − r) times sech² r, −tanh r sech r and
      +tanh r sech r: relative to the leading terms they are below k'²/4 for sn and
      (k'²/4) sinh² r ≤ (k'²/4) e^K/4 = k'/4 for cn and dn.
    - K/2 < |r| ≤ K: the quarter-period shift z = r ∓ K, |z| < K/2 ([OLBC10] Table
      22.4.3): sn = ±cd z, cn = ∓k' sd z, dn = k' nd z, whose leading terms are ±1,
      ∓k' sinh z and k' cosh z, with the same O(k') relative corrections.

    So every value is exact to a relative 2^-66 when mc < 2^-128.  The products
    k' sinh z and k' cosh z are formed as exponentials of ln k' ± |z|, so that a k'
    below the float range (mc < 5e-324 has no float, ln mc always has one) still
    gives the components that are representable; those below ~1e-308 round to 0.
    ``log_mc = −∞`` (K = ∞) gives the separatrix functions tanh, sech, sech.
    Arrays (``xp = numpy``) or floats (``xp = FLOAT``).
    """
    far = abs(r) > 0.5 * K
    σ = xp.copysign(1.0, r)
    z = xp.where(far, r - σ * K, r)
    a = abs(z)
    e = xp.exp(-a)
    sech = 2.0 * e / (1.0 + e * e)  # no overflow of cosh for large |z|
    log_kc = 0.5 * log_mc
    grow = xp.exp(log_kc + a)  # k' e^|z| (≤ 2 √k' since |z| ≤ K/2)
    decay = xp.exp(log_kc - a)  # k' e^-|z|
    k_sinh = xp.copysign(0.5 * (grow - decay), z)  # k' sinh z
    k_cosh = 0.5 * (grow + decay)  # k' cosh z
    sn = xp.where(far, σ, xp.tanh(z))
    cn = xp.where(far, -σ * k_sinh, sech)
    dn = xp.where(far, k_cosh, sech)
    return sn, cn, dn


def pi_minus_f_near_one(j: Any, r: Any, sn: Any, n: Any, K: Any, xp: Any = np) -> Any:
    """Π(am u, n|m) − u for u = 2jK + r, |r| ≤ K, n < 0 and mc < ``NEAR_ONE_MC``.

    ``sn`` is sn r.  Derivation (the project's own; [OLBC10] 19.2.7 for Π): with
    s = sin θ, c = cos θ and Δ = √(c² + mc s²),

        Π(φ, n) − F(φ) = ∫₀^φ n s² dθ / ((1 − n s²) Δ)
                       = n/(1 − n) · [F(φ) − ∫₀^φ c² dθ / ((1 − n s²) Δ)],

    since n s²/(1 − n s²) = n/(1 − n) − n c²/((1 − n)(1 − n s²)).  For |φ| ≤ π/2,
    c²/Δ differs from |c| by at most mc/Δ, whose integral is mc F(φ) ≤ mc K; and
    ∫₀^φ c dθ/(1 − n s²) = A(sin φ) with A(x) = arctan(√−n x)/√−n.  On a Jacobi
    amplitude F(am r) = r, so Π(am r) − r = n/(1 − n) (r − A(sn r)) + O(mc K), and by
    the quasi-periodicity ([OLBC10] 19.2.10 for F and Π) each half period adds the
    complete value n/(1 − n) (K − A(1)).  The error is below mc K ≈ 2^-121.
    """
    A_sn, A_1 = _arctan_integral(sn, n, xp), _arctan_integral(1.0, n, xp)
    return (n / (1.0 - n)) * ((r - A_sn) + 2.0 * j * (K - A_1))


def _arctan_integral(x: Any, n: Any, xp: Any) -> Any:
    """A(x) = ∫₀^x ds/(1 − n s²) = arctan(√−n x)/√−n for n ≤ 0 (x in the limit n → 0)."""
    a = xp.sqrt(-n)
    positive = a > 0.0
    a_safe = xp.where(positive, a, 1.0)
    return xp.where(positive, xp.arctan(a_safe * x) / a_safe, x)


# ----------------------------------------------------------------- the solver's interface


class JacobiParameter:
    """The parameter m = 1 − mc of the Jacobi functions of one state or of a batch.

    Held as mc and ln mc, with K.  For mc ≥ ``NEAR_ONE_MC`` the kernels take mc;
    below, where mc may be subnormal or below the float range while ln mc (which the
    solver computes from exact integers) is always accurate, they take ln mc and the
    expansions about m = 1.  One regime per instance: a batch that mixes them is
    split by the caller.  ``mc`` and ``log_mc`` are floats (one state; ``xp = FLOAT``
    builds K as a float) or arrays of a batch.  Each method takes the namespace of its
    arguments: floats (``FLOAT``) or arrays (numpy) that broadcast with the parameter.
    """

    def __init__(self, mc: Any, log_mc: Any, near_one: bool, xp: Any = np) -> None:
        self.mc = mc
        self.log_mc = log_mc
        self.near_one = near_one
        self.K: Any
        if near_one:
            self.K = complete_first_kind_near_one(log_mc)
        elif xp is FLOAT:
            self.K = cython_special.ellipkm1(mc)
        else:
            self.K = special.ellipkm1(mc)
        self.kc = xp.exp(0.5 * log_mc)  # k' = √mc (0 below the float range)
        # The AGM of Bulirsch's recurrence, once for a single state (it depends on mc).
        self._agm = _agm(mc, FLOAT) if xp is FLOAT and not near_one and mc > 0.0 else None

    def jacobi(self, u: Any, xp: Any) -> tuple[Any, Any, Any, Any, Any]:
        """j, r, sn r, cn r, dn r for u = 2jK + r, |r| ≤ K."""
        K = self.K
        j: Any
        if xp is FLOAT:
            j = float(round(u / (2.0 * K)))
            r = u - j * (2.0 * K)
            if self.near_one:
                return (j, r, *reduced_sn_cn_dn_near_one(r, self.log_mc, K, FLOAT))
            return (j, r, *_reduced_sn_cn_dn_float(r, self.mc, K, self._agm))
        if np.ndim(K) == 0 and math.isfinite(K):  # one state: reduce_argument, unmasked
            j = np.rint(u / (2.0 * K))
            r = u - j * (2.0 * K)
        else:
            j, r = reduce_argument(u, K)
        if self.near_one:
            return (j, r, *reduced_sn_cn_dn_near_one(r, self.log_mc, K))
        if np.ndim(self.mc) == 0:  # one state at many times
            return (j, r, *_reduced_sn_cn_dn_positive_mc(r, float(self.mc), float(K), self._agm))
        return (j, r, *_reduced_sn_cn_dn_positive_mc(r, self.mc, K))  # a batch, mc ≥ 2^-128

    @staticmethod
    def full(j: Any, sn_r: Any, cn_r: Any, dn_r: Any, xp: Any) -> tuple[Any, Any, Any]:
        """sn u, cn u, dn u from those of r: (−1)^j sn r, (−1)^j cn r, dn r."""
        sign = _parity_sign(j, xp)
        return sign * sn_r, sign * cn_r, dn_r

    def complete_pi_minus_k(self, n: Any, xp: Any) -> Any:
        """Π(n|m) − K(m): what Π(am u, n) − u gains over each half period 2K.

        (n/3) R_J(0, mc, 1, 1 − n) ([OLBC10] 19.25.2), evaluated as Bulirsch's ``cel``
        (``_cel``), or n/(1 − n) (K − A(1)) near m = 1 (``pi_minus_f_near_one``).  A
        constant of the state: computed once.
        """
        if self.near_one:
            return (n / (1.0 - n)) * (self.K - _arctan_integral(1.0, n, xp))
        # Bulirsch's cel: the same integral as (n/3) R_J(0, mc, 1, 1 − n), to an ulp
        # where scipy's R_J is off by several (and it costs a third as much).
        return _cel(xp.sqrt(self.mc), 1.0 - n, 0.0, n, xp)

    def pi_minus_f(
        self, j: Any, r: Any, sn: Any, cn: Any, dn: Any, n: Any, complete: Any, xp: Any
    ) -> Any:
        """Π(am u, n) − u for u = 2jK + r, from the reduced functions and
        ``complete = complete_pi_minus_k(n)``: ``pi_minus_f`` or its near-one form."""
        if self.near_one:
            incomplete = (n / (1.0 - n)) * (r - _arctan_integral(sn, n, xp))
        elif (xp is FLOAT or np.ndim(n) == 0) and n == 0.0:  # symmetric: Π = F, no R_J
            incomplete = 0.0 * r
        else:
            c2, s2 = cn * cn, sn * sn
            r_j = _special(xp).elliprj(c2, dn * dn, 1.0, c2 + (1.0 - n) * s2)
            incomplete = (n / 3.0) * sn * s2 * r_j
        return incomplete + 2.0 * j * complete

    def f_of_sin_cos(self, s: Any, c: Any, xp: Any) -> Any:
        """F(φ|m) for sin φ = s, cos φ = c, φ ∈ (−π, π] (mc ≥ ``NEAR_ONE_MC``).

        ``_f_of_sin_cos`` for c ≥ 0, and F(±π − φ') = ±2K − F(φ') ([OLBC10] 19.2.10)
        beyond.  Working from (s, c) rather than from φ = atan2 keeps F accurate near
        φ = ±π/2, where dF/dφ = 1/dn is large close to the separatrix.
        """
        f = _f_of_sin_cos(s, abs(c), self.mc, xp)
        return xp.where(c >= 0.0, f, xp.copysign(2.0 * self.K, s) - f)
