"""The numba backend: the free flow of the elliptic cases, compiled, one state at a time.

``flow_one`` advances one state (moments, body momentum, unit quaternion) by dt, and
``flow_many`` a batch, state by state in a compiled loop.  They are a compiled copy of
the formulas of attitude.solver.closed_form for cases (i) and (ii) away from m = 1
(``Elliptic`` and ``step``), operation for operation on floats, with the elliptic
kernels of attitude.elliptic.compiled:

1. the moments sorted and the momentum permuted alike (``numpy_backend.SortedMoments``);
2. the exact case test in double-double with its error bound
   (``invariants._double_double``; Joldes, Muller, Popescu, ACM TOMS 44(2), 2017);
3. the preferred flips, the constants of ``closed_form.Elliptic`` (B13, B31, B2, K,
   λ, n, κ, C, ν, Π − K);
4. m and ψ at τ = 0 and τ = dt from the same formula ([Leroy] "Integrals"), then
   q(t0 + dt) = q(t0) ⊗ S⁻¹ ⊗ P(m(0))⁻¹ ⊗ Y(ψ(dt) − ψ(0)) ⊗ P(m(dt)) ⊗ S
   (``closed_form.step``).

Takes the elliptic states whose double-double case test is certain, with mc ≥ 2^-128
and moments and momentum components within 2^±60 (SI values of any spacecraft):
nearly every state of a real one, symmetric bodies included (case ii with n = 0).
Leaves, returned *unhandled* (``ok`` False), the separatrix and its |δ2| ~ 1e-13
neighbourhood (where the case or mc needs the exact integers), the sphere, bodies
whose rate underflows, rest, mc < 2^-128, magnitudes beyond 2^±60, and any result
that is not finite: attitude.solver.free_flow sends those to the float or numpy
backend (attitude.solver.backends.select), which cover every case exactly.  So this
module is a faster road to the same numbers, never a second definition of them: the
results agree with the numpy backend to a few ulps
(tests/test_compiled_flow_against_numpy_flow.py).

Why compiled: on a batch of 1000 spacecraft, the numpy flow cost 2.2 µs a state per
step, nearly all of it the fixed cost of a few hundred numpy calls over arrays of 1000,
and one state on Python floats 23 µs; compiled, 0.87 and 1.7 µs (docs/benchmarks.md,
"The free flow compiled").  The torque splitting calls the flow about ten times a step.
Importing this module imports numba and loads the compiled code (~0.6 s): only a
process that flows imports it (attitude.solver.free_flow imports it on first use).

[Leroy] P. Leroy, "On an Article by Celledoni et al." (2020), in Principia's
    documentation: https://github.com/mockingbirdnest/Principia/blob/master/documentation/Celledoni.pdf
"""

from __future__ import annotations

import math

import numpy as np

from attitude.base import double_double
from attitude.base.double_double import (
    dd_over_dd,
    dd_plus_dd,
    dd_times_dd,
    dd_times_float,
    two_prod,
    two_sum,
)
from attitude.base.jit import inline, jit
from attitude.elliptic.compiled import (
    AGM_LEVELS,
    agm,
    carlson_rf,
    carlson_rj,
    cel_pi_minus_k,
    complete_first_kind,
    reduced_sn_cn_dn,
)

__all__ = ["flow_many", "flow_one"]

inline(double_double.FUNCTIONS)


# As attitude.solver.invariants: the double-double error allowed per chain (64 u²).
_BOUND = 64.0 * 2.0**-106
# The moments and the non-zero momentum components that the compiled case test takes
# (SI values of any spacecraft): the double-double terms, products of two squared
# components, a difference of moments (≥ an ulp of I3) and a moment, then lie within
# 2^-300 and 2^300, with their errors far from underflow.
_SMALLEST = 2.0**-60
_LARGEST = 2.0**60
# As attitude.elliptic.functions.NEAR_ONE_MC: below, the kernels work from ln mc (left).
_NEAR_ONE_MC = 2.0**-128


# ----------------------------------------------------------------- the case test


@jit
def _term(m_hi, m_lo, d_hi, d_lo, other):
    """m_k² (I_k − I_j) I_l in double-double."""
    x0, x1 = dd_times_dd(m_hi, m_lo, d_hi, d_lo)
    return dd_times_float(x0, x1, other)


@jit
def _case_test(I1, I2, I3, m1, m2, m3):
    """``attitude.solver.invariants._double_double`` for one state (sorted moments, I1 < I3):
    (sign of Δ2, δ1, δ3, mc, certain)."""
    # attitude.solver.invariants scales the moments and the momentum by powers of two so that
    # no term of the double-double underflows or overflows; within these bounds none
    # can, and scaling by a power of two changes no bit of the results (every
    # operation commutes with it), so the values are used as they are.  A state
    # outside them is left to the other backends.
    largest = max(abs(m1), abs(m2), abs(m3))
    valid = _SMALLEST <= I1 and I3 <= _LARGEST and largest <= _LARGEST
    for M in (m1, m2, m3):
        valid = valid and (M == 0.0 or abs(M) >= _SMALLEST)
    if not valid:
        return 0.0, 0.0, 0.0, 0.0, False
    I21 = two_sum(I2, -I1)  # exact differences
    I31 = two_sum(I3, -I1)
    I32 = two_sum(I3, -I2)
    s1, s2, s3 = two_prod(m1, m1), two_prod(m2, m2), two_prod(m3, m3)  # exact squares
    # The six terms m_k² I_kj I_l, as in attitude.solver.invariants._double_double.
    t0 = _term(s1[0], s1[1], I21[0], I21[1], I3)
    t1 = _term(s3[0], s3[1], I32[0], I32[1], I1)
    t2 = _term(s1[0], s1[1], I31[0], I31[1], I2)
    t3 = _term(s2[0], s2[1], I32[0], I32[1], I1)
    t4 = _term(s2[0], s2[1], I21[0], I21[1], I3)
    t5 = _term(s3[0], s3[1], I31[0], I31[1], I2)
    N2 = dd_plus_dd(t1[0], t1[1], -t0[0], -t0[1])  # I1 I3 Δ2
    P3 = dd_plus_dd(t2[0], t2[1], t3[0], t3[1])  # I1 I2 (−Δ3)
    N1 = dd_plus_dd(t4[0], t4[1], t5[0], t5[1])  # I2 I3 Δ1
    N2_error = _BOUND * (abs(t0[0]) + abs(t1[0]))
    sign_certain = abs(N2[0]) > 2.0 * N2_error
    G2a = dd_plus_dd(s1[0], s1[1], s2[0], s2[1])
    G2 = dd_plus_dd(G2a[0], G2a[1], s3[0], s3[1])
    case_i = N2[0] < 0.0
    sign = -1.0 if case_i else 1.0
    G2_23a = dd_times_float(G2[0], G2[1], I2)
    G2_23 = dd_times_float(G2_23a[0], G2_23a[1], I3)
    G2_12a = dd_times_float(G2[0], G2[1], I1)
    G2_12 = dd_times_float(G2_12a[0], G2_12a[1], I2)
    δ1 = dd_over_dd(N1[0], N1[1], G2_23[0], G2_23[1])[0]
    δ3 = -dd_over_dd(P3[0], P3[1], G2_12[0], G2_12[1])[0]
    # mc = |N2| I2 I31 / (I3 P3 I21) in case (i), |N2| I2 I31 / (I1 N1 I32) in case (ii).
    a0, a1 = dd_times_float(abs(N2[0]), math.copysign(1.0, N2[0]) * N2[1], I2)
    num = dd_times_dd(a0, a1, I31[0], I31[1])
    if case_i:
        b0, b1 = dd_times_float(P3[0], P3[1], I3)
        den = dd_times_dd(b0, b1, I21[0], I21[1])
    else:
        b0, b1 = dd_times_float(N1[0], N1[1], I1)
        den = dd_times_dd(b0, b1, I32[0], I32[1])
    mc, mc_low = dd_over_dd(num[0], num[1], den[0], den[1])
    error = mc * (N2_error / abs(N2[0]) + 4.0 * _BOUND)
    fraction, exponent = math.frexp(mc)
    spacing = math.ldexp(1.0, exponent - 53)  # the ulp of a normal mc
    below = 0.5 * spacing if fraction == 0.5 else spacing
    rounding_certain = (mc_low + error < 0.5 * spacing) and (mc_low - error > -0.5 * below)
    certain = sign_certain and rounding_certain and (mc >= 2.0**-900) and (mc <= 1.0)
    return sign, δ1, δ3, mc, certain


# ----------------------------------------------------------------- the flow


@jit
def _momentum_and_angle(τ, formula, a_seq, b_seq):
    """m in the P-frame and ψ at τ: ``closed_form.Elliptic._evaluate``, with the
    constants of ``formula`` (see ``_flow``) and the AGM levels in ``a_seq``, ``b_seq``."""
    λ, ν, K, mc, levels, c_agm, A_s, A_c, A_d, n, C, κ, κ_sign, ψ_rate, Π_minus_K = formula
    u = λ * τ - ν
    j = np.rint(u / (2.0 * K))
    r = u if j == 0.0 else u - j * (2.0 * K)
    sn_r, cn_r, dn_r = reduced_sn_cn_dn(r, mc, K, levels, c_agm, a_seq, b_seq)
    parity = 1.0 - 2.0 * abs(j - 2.0 * np.rint(0.5 * j))  # (−1)^j
    c2, s2 = cn_r * cn_r, sn_r * sn_r
    if n == 0.0:  # symmetric: Π = F
        Π_minus_F = 2.0 * j * Π_minus_K
    else:
        r_j = carlson_rj(c2, dn_r * dn_r, 1.0, c2 + (1.0 - n) * s2)
        Π_minus_F = (n / 3.0) * sn_r * s2 * r_j + 2.0 * j * Π_minus_K
    # arctg(κ sc u), continuous in u: am(u) + arctan((κ − 1) sn cn / (cn² + κ sn²)).
    arctan_sc = j * math.pi + math.atan2(sn_r, cn_r)
    arctan_sc += math.atan((κ - 1.0) * sn_r * cn_r / (c2 + κ * s2))
    ψ = ψ_rate * τ + C * Π_minus_F + κ_sign * arctan_sc
    return A_s * parity * sn_r, A_c * parity * cn_r, A_d * dn_r, ψ


@jit
def _p_quaternion(a, b, c, G):
    """P = (p0, p1, p2, 0), taking m = (a, b, c) onto G e3: ``closed_form.p_quaternion``."""
    p0 = math.sqrt(0.5 * (1.0 + c / G))
    half_over_p0 = 0.5 / p0
    return p0, (b / G) * half_over_p0, -(a / G) * half_over_p0


@jit
def _place(i0, i1, x0, x1, x2):
    """(y0, y1, y2) with y[i0] = x0, y[i1] = x1 and the third one x2 (i0 ≠ i1)."""
    y0 = x0 if i0 == 0 else (x1 if i1 == 0 else x2)
    y1 = x0 if i0 == 1 else (x1 if i1 == 1 else x2)
    y2 = x0 if i0 == 2 else (x1 if i1 == 2 else x2)
    return y0, y1, y2


@jit
def flow_one(
    I_a: float,
    I_b: float,
    I_c: float,
    m_a: float,
    m_b: float,
    m_c: float,
    qw: float,
    qx: float,
    qy: float,
    qz: float,
    dt: float,
) -> tuple[bool, float, float, float, float, float, float, float]:
    """One state (moments and momentum along the principal axes in any order, a unit
    quaternion scalar first) after dt: (ok, m_a, m_b, m_c, qw, qx, qy, qz).  ``ok``
    False: not handled here (module docstring), the other values meaningless."""
    a_seq = np.empty(AGM_LEVELS)
    b_seq = np.empty(AGM_LEVELS)
    return _flow(I_a, I_b, I_c, m_a, m_b, m_c, qw, qx, qy, qz, dt, a_seq, b_seq)


@jit
def _flow(I_a, I_b, I_c, m_a, m_b, m_c, qw, qx, qy, qz, dt, a_seq, b_seq):
    """``flow_one`` with scratch arrays of ``AGM_LEVELS`` floats for the AGM."""
    nothing = (False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    # 1. Sorted, stably, by three compare-exchanges; the middle axis reversed for an
    #    odd permutation (numpy_backend.SortedMoments).
    I1, I2, I3 = I_a, I_b, I_c
    o0, o1, o2 = 0, 1, 2
    odd = False
    if I1 > I2:
        I1, I2, o0, o1, odd = I2, I1, o1, o0, not odd
    if I2 > I3:
        I2, I3, o1, o2, odd = I3, I2, o2, o1, not odd
    if I1 > I2:
        I1, I2, o0, o1, odd = I2, I1, o1, o0, not odd
    momentum = (m_a, m_b, m_c)
    middle_sign = -1.0 if odd else 1.0
    m1, m2, m3 = momentum[o0], middle_sign * momentum[o1], momentum[o2]
    G = math.hypot(math.hypot(m1, m2), m3)
    if not (G > 0.0 and I1 < I3 and I1 > 0.0):
        return nothing
    # 2. The exact case test.
    sign, δ1, δ3, mc, certain = _case_test(I1, I2, I3, m1, m2, m3)
    if not certain or sign == 0.0 or not mc >= _NEAR_ONE_MC:
        return nothing
    case_ii = sign > 0.0
    # 3. The preferred flips (closed_form.preferred_flips) and the constants.
    flip1 = (not case_ii) and m1 < 0.0
    flip3 = case_ii and m3 < 0.0
    f1 = -1.0 if flip1 else 1.0
    f3 = -1.0 if flip3 else 1.0
    f2 = -1.0 if flip1 != flip3 else 1.0
    m1, m2, m3 = f1 * m1, f2 * m2, f3 * m3
    I12, I13, I21, I23, I31, I32 = I1 - I2, I1 - I3, I2 - I1, I2 - I3, I3 - I1, I3 - I2
    B13 = G * math.sqrt(I1 * δ3 / I13)
    B31 = G * math.sqrt(I3 * δ1 / I31)
    if case_ii:
        B2 = G * math.sqrt(I2 * δ3 / (I23 if I23 != 0.0 else 1.0))
        A_c, A_d = -B13, B31
        numerator = δ1 * I32
        n = (I3 / I1) * (I21 / (I23 if I23 != 0.0 else 1.0))
        κ = math.sqrt((I2 / I1) * (I31 / I32))
        κ_sign = 1.0
        C_factor = I31 / I1 / I3
        ψ_rate = G / I1
    else:
        B2 = G * math.sqrt(I2 * δ1 / (I21 if I21 != 0.0 else 1.0))
        A_c, A_d = B31, B13
        numerator = δ3 * I12
        n = (I1 / I3) * (I32 / (I12 if I12 != 0.0 else 1.0))
        κ = math.sqrt((I2 / I3) * (I31 / I21))
        κ_sign = -1.0
        C_factor = I13 / I1 / I3
        ψ_rate = G / I3
    A_s = -B2
    levels, c_agm = agm(mc, a_seq, b_seq)
    K = complete_first_kind(c_agm)
    λ = -(G / I3) * math.sqrt(numerator / I3 / ((I1 / I3) * (I2 / I3)))  # closed_form.rate
    if λ == 0.0:
        return nothing  # Steady (closed_form): left to the other backends
    C = (G / λ) * C_factor
    # ν ([Leroy] "Phase and initial value", closed_form.Elliptic._phase away from m = 1).
    # sn ν = a/|A_s| and cn ν = b/A_c, with (a, b) = (m2, −m1) in case ii, (m2, m3) in i.
    pa, pb = (m2, -m1) if case_ii else (m2, m3)
    cn_num = -pb if A_c < 0.0 else pb
    s = (pa / G) * (abs(A_c) / G)
    co = (cn_num / G) * (-A_s / G)
    h = math.hypot(s, co)
    sin_φ, cos_φ = (s / h, co / h) if h > 0.0 else (0.0, 1.0)
    c2 = cos_φ * cos_φ
    f = sin_φ * carlson_rf(c2, c2 + mc * sin_φ * sin_φ, 1.0)  # F(φ|m), [OLBC10] 19.25.5
    ν = f if cos_φ >= 0.0 else math.copysign(2.0 * K, sin_φ) - f
    Π_minus_K = cel_pi_minus_k(math.sqrt(mc), n)
    # 4. Both ends from the same formula (closed_form.step).
    formula = (λ, ν, K, mc, levels, c_agm, A_s, A_c, A_d, n, C, κ, κ_sign, ψ_rate, Π_minus_K)
    a0, b0, c0, ψ0 = _momentum_and_angle(0.0, formula, a_seq, b_seq)
    a1, b1, c1, ψ1 = _momentum_and_angle(dt, formula, a_seq, b_seq)
    p00, p01, p02 = _p_quaternion(a0, b0, c0, G)
    p10, p11, p12 = _p_quaternion(a1, b1, c1, G)
    # Y(ψ) ⊗ P(m(dt)) from t = tan ψ/4 (closed_form.y_times_p).
    t = math.tan(0.25 * (ψ1 - ψ0))
    t2 = t * t
    w = 1.0 / (1.0 + t2)
    cy, sy = (1.0 - t2) * w, (t + t) * w
    y0, y1, y2, y3 = cy * p10, cy * p11 - sy * p12, cy * p12 + sy * p11, sy * p10
    # P(m(0))⁻¹ ⊗ (Y ⊗ P): (p00, −p01, −p02, 0) ⊗ (y0, y1, y2, y3).
    z0 = p00 * y0 + p01 * y1 + p02 * y2
    z1 = p00 * y1 - p01 * y0 - p02 * y3
    z2 = p00 * y2 + p01 * y3 - p02 * y0
    z3 = p00 * y3 - p01 * y2 + p02 * y1
    # Back to the body: x_body[index[k]] = sign[k] x_frame[k], with the relabelling of
    # closed_form.RELABEL ((1, 2, 0), (1, 1, 1)) in case i, ((1, 0, 2), (1, −1, 1)) in ii.
    flips = (f1, f2, f3)
    sorted_signs = (1.0, middle_sign, 1.0)
    order = (o0, o1, o2)
    r0, r1, r2 = (1, 0, 2) if case_ii else (1, 2, 0)
    s0 = flips[r0] * sorted_signs[r0]
    s1 = (-1.0 if case_ii else 1.0) * flips[r1] * sorted_signs[r1]
    s2 = flips[r2] * sorted_signs[r2]
    i0, i1 = order[r0], order[r1]
    mx, my, mz = _place(i0, i1, s0 * a1, s1 * b1, s2 * c1)
    vx, vy, vz = _place(i0, i1, s0 * z1, s1 * z2, s2 * z3)
    # q ⊗ (z0, v).
    w_ = qw * z0 - qx * vx - qy * vy - qz * vz
    x_ = qw * vx + qx * z0 + qy * vz - qz * vy
    y_ = qw * vy - qx * vz + qy * z0 + qz * vx
    z_ = qw * vz + qx * vy - qy * vx + qz * z0
    norm = math.sqrt(w_ * w_ + x_ * x_ + y_ * y_ + z_ * z_)
    out = (True, mx, my, mz, w_ / norm, x_ / norm, y_ / norm, z_ / norm)
    finite = True
    for value in (mx, my, mz, w_ / norm, x_ / norm, y_ / norm, z_ / norm):
        finite = finite and math.isfinite(value)
    return out if finite else nothing


@jit
def flow_many(
    moments: np.ndarray,
    momentum: np.ndarray,
    quaternion: np.ndarray,
    dt: np.ndarray,
    m_out: np.ndarray,
    q_out: np.ndarray,
    ok: np.ndarray,
) -> None:
    """``flow_one`` over a batch: arrays (N, 3), (N, 3), (N, 4) and (N,) in, (N, 3),
    (N, 4) and the flags ``ok`` (N,) written."""
    a_seq = np.empty(AGM_LEVELS)
    b_seq = np.empty(AGM_LEVELS)
    for k in range(moments.shape[0]):
        handled, m1, m2, m3, qw, qx, qy, qz = _flow(
            moments[k, 0], moments[k, 1], moments[k, 2],
            momentum[k, 0], momentum[k, 1], momentum[k, 2],
            quaternion[k, 0], quaternion[k, 1], quaternion[k, 2], quaternion[k, 3],
            dt[k], a_seq, b_seq,
        )  # fmt: skip
        ok[k] = handled
        m_out[k, 0], m_out[k, 1], m_out[k, 2] = m1, m2, m3
        q_out[k, 0], q_out[k, 1], q_out[k, 2], q_out[k, 3] = qw, qx, qy, qz
