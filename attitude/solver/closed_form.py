"""The closed-form motion of a torque-free rigid body, one formula per case.

The formulas of Celledoni, Fassò, Säfström and Zanna [CFSZ08] as corrected by Leroy
[Leroy]: the momentum m(t) in Jacobi elliptic functions (or hyperbolic ones on the
separatrix) and the attitude through the angle ψ(t) of [Leroy] "Integrals", with an
elliptic integral of the third kind.  The project's own derivation, with every step
used here, is docs/derivation.md.

This module is the formula set: what is computed, once.  Each case's constants and
formulas (``Elliptic``, ``Separatrix``, ``Steady``, ``Rest``: the ``CaseFormula``
protocol), the frames (S, P, Y), one state's attitude q(t) = M (Y ⊗ P)(t)
(``Motion``) and the step of the flow (``step``).  Every formula takes its constants
and its times as floats or as numpy arrays that broadcast together, and the namespace
``xp`` of their functions (numpy, or ``attitude.base.float_math.FLOAT`` for floats).
The backends evaluate it, each in a module of its own (attitude.solver.backends: which
states each takes and leaves, and the one rule that picks them): ``float_backend`` on
Python floats, ``numpy_backend`` on arrays, ``table_backend`` on arrays with ψ's
periodic part from a table, and ``numba_backend``, a compiled copy of the elliptic
cases.

Frames.  A state's principal axes (moments in any order) are mapped onto the frame of
its formula by a signed permutation with determinant +1, in three steps:
  1. sorted so that I1 ≤ I2 ≤ I3, the middle axis reversed for an odd permutation;
  2. the *preferred* flips of [Leroy] "An alternative quaternionic solution": two
     axes reversed together (a rotation by π) so that the component carrying dn (or
     sech) is ≥ 0; the free signs σ, σ', σ'' of [Leroy] are then all +1;
  3. relabelled (a rotation by a multiple of 90°) so that this component is the
     third: the *P-frame*, in which P(t) maps m onto G e3 and Y(ψ) turns about e3 in
     every case.  A rotation about e3 commutes with Y and conjugates P into itself, so
     ψ is [Leroy]'s in each case: case (i) maps onto e1 in [Leroy], here (m2, m3, m1);
     case (ii) onto e3, here (m2, −m1, m3) so that both elliptic cases read
     (A_s sn u, A_c cn u, A_d dn u); the separatrix onto e3, or onto e1 when B13 < B31,
     here (m3, −m2, m1), so that both read (A_1 sech u, A_2 th u, A_3 sech u).

Glossary (the symbols of [Leroy], kept as names)
------------------------------------------------
I1 ≤ I2 ≤ I3   principal moments, sorted; Ijh = Ij − Ih
m1, m2, m3     body momentum in the preferred (sorted, flipped) axes
G, T           |m| and the kinetic energy, 2T = Σ mj²/Ij (both conserved)
Δj, δj         Δj = G² − 2T Ij; the code keeps δj = Δj/G² (attitude.solver.invariants)
Bjh            √(±Ij Δh/Ijh), amplitudes of the components of m
λ, ν           u = λτ − ν is the argument of the Jacobi functions, τ = t − t0
mc, K          mc = 1 − k² (k⁻² in case ii), K = K(mc) (attitude.elliptic.functions)
n, C, κ        characteristic of Π, and the coefficients of Π and of arctg(κ sc u) in ψ
ψ              the angle of Y about e3: Q(t) = R ∘ Y(ψ(t) − ψ(t0)) ∘ P(t) ∘ S

References
----------
[CFSZ08] E. Celledoni, F. Fassò, N. Säfström, A. Zanna, "The exact computation of the
    free rigid body motion and its use in splitting methods", SIAM J. Sci. Comput. 30(4)
    (2008) 2084–2112, doi:10.1137/070704393.
[Leroy] P. Leroy, "On an Article by Celledoni et al." (2020), corrections and
    implementation notes, in Principia's documentation:
    https://github.com/mockingbirdnest/Principia/blob/master/documentation/Celledoni.pdf
[OLBC10] F. Olver et al., NIST Handbook of Mathematical Functions (the DLMF), 2010.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from attitude.base.float_math import FLOAT
from attitude.elliptic.functions import JacobiParameter, amplitude
from attitude.solver.invariants import Invariants

__all__ = [
    "FLIP_23",
    "FLIP_NONE",
    "RELABEL",
    "CaseFormula",
    "Elliptic",
    "Motion",
    "NotRepresentable",
    "Rest",
    "Separatrix",
    "Steady",
    "hamilton",
    "norm",
    "p_quaternion",
    "permutation_quaternion",
    "preferred_flips",
    "step",
    "y_times_p",
]

_LN2 = math.log(2.0)


class NotRepresentable(ArithmeticError):
    """A result beyond the float range: the angles λτ or ψ(τ) of a time too far from t0
    (or of a step too long).  ``index``: the first such time (or state) of an array.
    The front ends turn it into an InputError that names the time."""

    def __init__(self, index: int = 0) -> None:
        super().__init__(index)
        self.index = index


class CaseFormula(Protocol):
    """What the closed form of each case provides (constants per state).

    ``momentum(τ, xp)`` gives the components (a, b, c) of m in the P-frame at τ = t − t0,
    c ≥ 0; ``momentum_and_angle`` adds ψ(τ).  ``τ`` broadcasts with the constants.
    """

    @property
    def name(self) -> str: ...

    @property
    def period(self) -> Any: ...

    @property
    def mc(self) -> Any:  # the complementary parameter 1 − m (0 on the separatrix, NaN if none)
        ...

    def momentum(self, τ: Any, xp: Any) -> tuple[Any, Any, Any]: ...

    def momentum_and_angle(self, τ: Any, xp: Any) -> tuple[Any, Any, Any, Any]: ...


def rate(G: Any, numerator: Any, I1: Any, I2: Any, I3: Any, xp: Any) -> Any:
    """G √(numerator / (I1 I2 I3)), with the moments scaled by I3 so that their product
    cannot underflow or overflow: [Leroy]'s λ3 (numerator δ3 I12), λ1 (δ1 I32) and
    λ2 (−δ1 δ3 I2), with δj = Δj/G²."""
    return (G / I3) * xp.sqrt(numerator / I3 / ((I1 / I3) * (I2 / I3)))


def _asinh_of_exp(L: Any, xp: Any) -> Any:
    """asinh(e^L) without overflow: L + ln 2 + O(e^-2L) for L > 20."""
    return xp.where(L > 20.0, L + _LN2, xp.arcsinh(xp.exp(xp.minimum(L, 20.0))))


def _log_abs(x: Any, xp: Any) -> Any:
    return xp.log(abs(x))


class Elliptic:
    """Cases (i), Δ2 < 0, and (ii), Δ2 > 0: [Leroy] "Case (i)", "Case (ii)", σ = 1.

    In the P-frame m = (A_s sn u, A_c cn u, A_d dn u), u = λτ − ν:
      (i)  (m2, m3, m1) = (−B21 sn, B31 cn, B13 dn), λ = −λ3,
           ψ = (G/I3) τ + C (Π(am u, n) − u) − arctg(κ sc u)
      (ii) (m2, −m1, m3) = (−B23 sn, −B13 cn, B31 dn), λ = −λ1,
           ψ = (G/I1) τ + C (Π(am u, n) − u) + arctg(κ sc u)
    with the constants of [Leroy] "Integrals" (the n and the sign of λ corrected there).
    Π(am u, n) = u + (Π − F) since F(am u) = u; and C λ = G/I3 − G/I1 in case (i),
    G/I1 − G/I3 in case (ii), so the secular parts of ψ fold into its linear term and
    the constant −C ν drops out of ψ(t) − ψ(t0).  ``case_ii`` is a bool per state.
    """

    def __init__(
        self,
        I1: Any,
        I2: Any,
        I3: Any,
        m1: Any,
        m2: Any,
        m3: Any,
        G: Any,
        invariants: Invariants,
        case_ii: Any,
        near_one: bool,
        xp: Any,
    ) -> None:
        w = xp.where
        δ1, δ3 = invariants.δ1, invariants.δ3
        I12, I13, I21, I23, I31, I32 = I1 - I2, I1 - I3, I2 - I1, I2 - I3, I3 - I1, I3 - I2
        self.case_ii = case_ii
        B13 = G * xp.sqrt(I1 * δ3 / I13)
        B31 = G * xp.sqrt(I3 * δ1 / I31)
        # B21 (case i) and B23 (case ii), and the quotients that would be 0/0 in the
        # other case (I21 = 0 or I23 = 0 only happens in the other case).
        I21_or_23 = w(case_ii, I23, I21)
        δ1_or_3 = w(case_ii, δ3, δ1)
        B2 = G * xp.sqrt(I2 * δ1_or_3 / w(I21_or_23 != 0.0, I21_or_23, 1.0))
        self.A_s = -B2
        self.A_c = w(case_ii, -B13, B31)
        self.A_d = w(case_ii, B31, B13)
        self.parameter = JacobiParameter(invariants.mc, invariants.log_mc, near_one, xp)
        self.mc, self.K = invariants.mc, self.parameter.K
        self.λ = -rate(G, w(case_ii, δ1 * I32, δ3 * I12), I1, I2, I3, xp)
        I_12_or_23 = w(case_ii, I23, I12)
        self.n = w(case_ii, I3 / I1, I1 / I3) * (
            w(case_ii, I21, I32) / w(I_12_or_23 != 0.0, I_12_or_23, 1.0)
        )
        self.κ = xp.sqrt(w(case_ii, I2 / I1, I2 / I3) * (I31 / w(case_ii, I32, I21)))
        self.κ_sign = w(case_ii, 1.0, -1.0)
        # Grouped to stay in the float range; λ = 0 (underflow) makes the state Steady.
        self.C = (G / w(self.λ != 0.0, self.λ, 1.0)) * (w(case_ii, I31, I13) / I1 / I3)
        self.ψ_rate = w(case_ii, G / I1, G / I3)
        self.ν = self._phase(m1, m2, m3, G, xp)
        self.Π_minus_K = self.parameter.complete_pi_minus_k(self.n, xp)

    @property
    def period(self) -> Any:
        """4K/|λ|, the period of m(t)."""
        return 4.0 * self.K / abs(self.λ)

    @property
    def name(self) -> str:
        """'i' or 'ii' for one state; 'elliptic' for a batch (see ``case_ii``)."""
        if np.ndim(self.case_ii):
            return "elliptic"
        return "ii" if self.case_ii else "i"

    def _phase(self, m1: Any, m2: Any, m3: Any, G: Any, xp: Any) -> Any:
        """ν, from sn ν = −a/A_s, cn ν = b/A_c, dn ν = c/A_d at τ = 0.

        [Leroy] "Phase and initial value": ν = F(am ν).  Away from m = 1 through
        ``JacobiParameter.f_of_sin_cos`` of (sn ν, cn ν), scaled by B's product over G²
        to stay O(1).  Near m = 1 the components may differ by more than the float range
        (a state 1e-200 G from the intermediate axis with G = 1e124), so ν is found
        from their logarithms: sinh ν = sn/cn where dn ν ≥ √k' (|ν| ≤ K/2, sn = tanh,
        cn = sech), and otherwise, with the quarter shift ν = ±(K − z) of
        ``reduced_sn_cn_dn_near_one``, sinh z = |cn ν|/k'.  cn ν < 0 means |ν| > K:
        then ν = ±2K − ν', ν' the phase of −cn ν (cn(2K − x) = −cn x, sn and dn
        unchanged, [OLBC10] 22.4.3).
        """
        w = xp.where
        a, b, c = w(self.case_ii, m2, m2), w(self.case_ii, -m1, m3), w(self.case_ii, m3, m1)
        sn_num, sn_den = a, -self.A_s  # sn ν = a/|A_s| (A_s < 0)
        cn_num, cn_den = w(self.A_c < 0.0, -b, b), abs(self.A_c)
        dn_num, dn_den = c, self.A_d
        if not self.parameter.near_one:
            s = (sn_num / G) * (cn_den / G)
            co = (cn_num / G) * (sn_den / G)
            h = xp.hypot(s, co)
            h_safe = w(h > 0.0, h, 1.0)
            sin_φ, cos_φ = w(h > 0.0, s / h_safe, 0.0), w(h > 0.0, co / h_safe, 1.0)
            return self.parameter.f_of_sin_cos(sin_φ, cos_φ, xp)
        log_mc, K = self.parameter.log_mc, self.K
        σ = w(sn_num < 0.0, -1.0, 1.0)
        log_c = _log_abs(cn_num, xp) - xp.log(cn_den)
        near_half = (cn_num != 0.0) & (_log_abs(dn_num, xp) - xp.log(dn_den) >= 0.25 * log_mc)
        ν_near = σ * _asinh_of_exp(_log_abs(sn_num, xp) - xp.log(sn_den) - log_c, xp)
        ν_far = σ * (K - _asinh_of_exp(log_c - 0.5 * log_mc, xp))
        ν = w(near_half, ν_near, ν_far)
        return w(cn_num < 0.0, σ * 2.0 * K - ν, ν)

    def momentum(self, τ: Any, xp: Any) -> tuple[Any, Any, Any]:
        a, b, c, _ = self._evaluate(τ, xp, with_ψ=False)
        return a, b, c

    def momentum_and_angle(self, τ: Any, xp: Any) -> tuple[Any, Any, Any, Any]:
        return self._evaluate(τ, xp, with_ψ=True)

    def _evaluate(self, τ: Any, xp: Any, with_ψ: bool):
        j, r, sn_r, cn_r, dn_r = self.parameter.jacobi(self.λ * τ - self.ν, xp)  # phase()
        a, b, c = self.momentum_of_phase(j, sn_r, cn_r, dn_r, xp)
        if not with_ψ:
            return a, b, c, None
        return a, b, c, self._angle(τ, j, r, sn_r, cn_r, dn_r, xp)

    def _angle(self, τ: Any, j: Any, r: Any, sn_r: Any, cn_r: Any, dn_r: Any, xp: Any) -> Any:
        """ψ at τ, from the reduced phase u = λτ − ν = 2jK + r and its sn, cn, dn."""
        Π_minus_F = self.parameter.pi_minus_f(j, r, sn_r, cn_r, dn_r, self.n, self.Π_minus_K, xp)
        return (
            self.ψ_rate * τ
            + self.C * Π_minus_F
            + self.κ_sign * _arctan_of_scaled_sc(j, sn_r, cn_r, self.κ, xp)
        )

    def phase(self, τ: Any, xp: Any) -> tuple[Any, Any, Any, Any, Any]:
        """j, r, sn r, cn r, dn r for the phase u = λτ − ν = 2jK + r, |r| ≤ K."""
        return self.parameter.jacobi(self.λ * τ - self.ν, xp)

    def momentum_of_phase(self, j: Any, sn_r: Any, cn_r: Any, dn_r: Any, xp: Any):
        """m in the P-frame, (A_s sn u, A_c cn u, A_d dn u), from ``phase``."""
        sn, cn, dn = JacobiParameter.full(j, sn_r, cn_r, dn_r, xp)
        return self.A_s * sn, self.A_c * cn, self.A_d * dn

    def angle_rates(self) -> tuple[float, float]:
        """s_u and Ω: ψ(τ) = Ω τ − s_u ν + ``periodic_angle``(r), for one state.

        Over each half period 2K of u, Π(am u, n) − u gains its complete value and the
        arc tangent π (``pi_minus_f``, ``_arctan_of_scaled_sc``): ψ grows on average
        by s_u = (2 C (Π(n) − K) + κ_sign π)/(2K) per unit of u, and so, with
        u = λτ − ν, at the rate Ω = G/I_a + s_u λ in time.
        """
        s_u = (2.0 * self.C * self.Π_minus_K + self.κ_sign * math.pi) / (2.0 * self.K)
        return s_u, self.ψ_rate + s_u * self.λ

    def periodic_angle(self, r: NDArray[np.float64]) -> tuple[NDArray[np.float64], float]:
        """The periodic part of ψ at the reduced phase r, |r| ≤ K, for one state.

        per(r) = C (Π − F)(am r, n) + κ_sign arctg(κ sc r) − s_u r (``angle_rates``):
        odd, 2K-periodic (per(±K) = 0) and analytic, so that ψ(τ) = Ω τ − s_u ν +
        per(r(τ)).  Also returns the magnitude of the largest of its terms, whose
        rounding is the error of this formula (what a table of it must not exceed).
        """
        s_u, _ = self.angle_rates()
        j, r, sn_r, cn_r, dn_r = self.parameter.jacobi(r, np)  # j = 0 on |r| ≤ K
        terms = (
            self.C * self.parameter.pi_minus_f(j, r, sn_r, cn_r, dn_r, self.n, 0.0, np),
            self.κ_sign * _arctan_of_scaled_sc(j, sn_r, cn_r, self.κ, np),
            -s_u * r,
        )
        largest = max(float(np.max(np.abs(term))) for term in terms)
        return terms[0] + terms[1] + terms[2], largest


def _arctan_of_scaled_sc(j: Any, s: Any, c: Any, κ: Any, xp: Any) -> Any:
    """arctg(κ sc u), continuous in u (κ > 0), from sn r = s and cn r = c ≥ 0.

    With φ = am(u) (``attitude.elliptic.functions.amplitude``), arctg(κ tan φ) is continued
    through φ + arctan((κ − 1) sn cn / (cn² + κ sn²)); the second term stays in
    (−π/2, π/2) because its denominator is positive.
    """
    return amplitude(j, s, c, xp) + xp.arctan((κ - 1.0) * s * c / (c * c + κ * s * s))


class Separatrix:
    """Case (iii), Δ2 = 0: [Leroy] "Case (iii)" with σ' = σ'' = 1.

    m = (B13 sech u, G th u, B31 sech u), u = λ2 τ − ν, ν = −argth(m2/G).  In the
    P-frame (A_1 sech u, A_2 th u, A_3 sech u): (B13, G, B31) when P maps onto e3,
    (B31, −G, B13) when it maps onto e1, which [Leroy] does when B13 < B31 so that the
    coefficient of the arc tangent, (B − G)/B', has a non-zero denominator:
    ψ = (G/I2) τ ± 2 arctg((A_3 − G)/A_1 th(u/2)).
    """

    name = "iii"
    mc = 0.0
    period = math.inf

    def __init__(self, I1, I2, I3, m1, m2, m3, G, invariants: Invariants, xp: Any) -> None:
        w = xp.where
        δ1, δ3 = invariants.δ1, invariants.δ3
        B13 = G * xp.sqrt(I1 * δ3 / (I1 - I3))
        B31 = G * xp.sqrt(I3 * δ1 / (I3 - I1))
        self.λ = rate(G, -δ1 * δ3 * I2, I1, I2, I3, xp)
        # th(−ν) = m2/G and sech(−ν) = √(m1² + m3²)/G, so sinh(−ν) is their ratio: no
        # cancellation when m2 is within an ulp of ±G.  A spin exactly about e2 gives
        # ν = ∓∞ and, through IEEE infinities, m(t) = (0, ±G, 0) at all t.
        h = xp.hypot(m1, m3)
        h_safe = w(h > 0.0, h, 1.0)
        self.ν = w(h > 0.0, -xp.arcsinh(m2 / h_safe), -xp.copysign(xp.inf, m2))
        onto_e1 = B13 < B31
        self.A_1 = w(onto_e1, B31, B13)
        self.A_2 = w(onto_e1, -G, G)
        self.A_3 = w(onto_e1, B13, B31)
        self.onto_e1 = onto_e1
        self.arctan_sign = w(onto_e1, -1.0, 1.0)
        self.arctan_ratio = (self.A_3 - G) / self.A_1
        self.ψ_rate = G / I2

    def momentum(self, τ: Any, xp: Any) -> tuple[Any, Any, Any]:
        u = self.λ * τ - self.ν
        e = xp.exp(-abs(u))
        sech = 2.0 * e / (1.0 + e * e)  # no overflow of cosh
        return self.A_1 * sech, self.A_2 * xp.tanh(u), self.A_3 * sech

    def momentum_and_angle(self, τ: Any, xp: Any) -> tuple[Any, Any, Any, Any]:
        a, b, c = self.momentum(τ, xp)
        u = self.λ * τ - self.ν
        ψ = self.ψ_rate * τ + 2.0 * self.arctan_sign * xp.arctan(
            self.arctan_ratio * xp.tanh(0.5 * u)
        )
        return a, b, c, ψ


class Steady:
    """m fixed in the body: m × ω = 0, so ω ∥ m and the body spins about m at 2T/G.

    The sphere (I1 = I3), where every m is fixed; and a state so close to a principal
    axis of a symmetric body that the rate λ of cases (i)/(ii) underflows to zero
    (components ~1e-160 G or less): m then cannot move within any representable time,
    and the general formulas would give ∞·0.  The P-frame is the preferred frame, with
    m3 ≥ 0.
    """

    name = "steady"
    mc = math.nan
    period = math.inf

    def __init__(self, I1, I2, I3, m1, m2, m3, G, xp: Any) -> None:
        self.a, self.b, self.c = m1, m2, m3
        x1, x2, x3 = m1 / G, m2 / G, m3 / G
        self.ψ_rate = G * (x1 * x1 / I1 + x2 * x2 / I2 + x3 * x3 / I3)  # 2T/G

    def momentum(self, τ: Any, xp: Any) -> tuple[Any, Any, Any]:
        zero = 0.0 * τ
        return self.a + zero, self.b + zero, self.c + zero

    def momentum_and_angle(self, τ: Any, xp: Any) -> tuple[Any, Any, Any, Any]:
        return (*self.momentum(τ, xp), self.ψ_rate * τ)


class Rest:
    """G = 0: nothing moves (no P, no ψ: the attitude stays the initial one)."""

    name = "rest"
    mc = math.nan
    period = math.inf

    def momentum(self, τ: Any, xp: Any) -> tuple[Any, Any, Any]:
        zero = 0.0 * τ
        return zero, zero, zero

    def momentum_and_angle(self, τ: Any, xp: Any) -> tuple[Any, Any, Any, Any]:
        zero = 0.0 * τ
        return zero, zero, zero, zero


# ----------------------------------------------------------------- P(t) and Y(ψ)


def p_quaternion(a: Any, b: Any, c: Any, G: Any, xp: Any) -> tuple[Any, Any, Any]:
    """P as a quaternion (p0, p1, p2, 0): the rotation taking m = (a, b, c) onto G e3.

    [Leroy] "Case (ii)" of "Integrals": p0 = √((1 + c/G)/2) and the other components
    over √(2G(G + c)) = 2G p0.  c ≥ 0 in the P-frame, so G + c ≥ G never vanishes.
    """
    p0 = xp.sqrt(0.5 * (1.0 + c / G))
    half_over_p0 = 0.5 / p0  # p0 ≥ √½; and m/G first, for a G near underflow
    return p0, (b / G) * half_over_p0, -(a / G) * half_over_p0


def y_times_p(half_ψ: Any, p0: Any, p1: Any, p2: Any, xp: Any) -> tuple[Any, Any, Any, Any]:
    """Y(ψ) ⊗ P, scalar first, with Y = (cos ψ/2, 0, 0, sin ψ/2) and P = (p0, p1, p2, 0).

    cos and sin of ψ/2 from t = tan ψ/4: (1 − t²)/(1 + t²) and 2t/(1 + t²), to an
    ulp or two of each component, from one tangent (vectorized in numpy, where its sine
    and cosine are not).  Near ψ/4 = ±π/2, t is large but finite for any float.
    """
    t = xp.tan(0.5 * half_ψ)
    t2 = t * t
    w = 1.0 / (1.0 + t2)
    cy, sy = (1.0 - t2) * w, (t + t) * w
    return cy * p0, cy * p1 - sy * p2, cy * p2 + sy * p1, sy * p0


# ----------------------------------------------------------------- frames and case choice


# No flip, and the turn by π about e1 that makes m3 ≥ 0 (a steady state's flip).
FLIP_NONE, FLIP_23 = (1.0, 1.0, 1.0), (1.0, -1.0, -1.0)
# The relabelling into the P-frame (step 3 of the module docstring), after the preferred
# flips (step 2), per case: P[k] = sign[k] · preferred[index[k]].
RELABEL: dict[str, tuple[tuple[int, int, int], tuple[int, int, int]]] = {
    "i": ((1, 2, 0), (1, 1, 1)),
    "ii": ((1, 0, 2), (1, -1, 1)),
    "iii": ((0, 1, 2), (1, 1, 1)),
    "iii-e1": ((2, 1, 0), (1, -1, 1)),
    "steady": ((0, 1, 2), (1, 1, 1)),
    "rest": ((0, 1, 2), (1, 1, 1)),
}


def preferred_flips(flip1: Any, flip3: Any, xp: Any) -> tuple[Any, Any, Any]:
    """The axis signs that reverse m1 (flip1), m3 (flip3) or both, as a rotation by π.

    Both: axes 1 and 3; m1 alone: axes 1 and 2; m3 alone: axes 2 and 3.
    """
    w = xp.where
    f1 = w(flip1, -1.0, 1.0)
    f3 = w(flip3, -1.0, 1.0)
    f2 = w(flip1 != flip3, -1.0, 1.0)
    return f1, f2, f3


@functools.lru_cache(maxsize=64)
def permutation_quaternion(
    index: tuple[int, int, int], sign: tuple[float, float, float]
) -> tuple[float, float, float, float]:
    """The quaternion (scalar first) of the signed permutation S[k, index[k]] = sign[k]
    with determinant +1: one of 24 rotations, each converted once by scipy."""
    matrix = np.zeros((3, 3))
    matrix[np.arange(3), index] = sign
    w, x, y, z = Rotation.from_matrix(matrix).as_quat(scalar_first=True).tolist()
    return w, x, y, z


def norm(m1: Any, m2: Any, m3: Any, xp: Any) -> Any:
    """G = |m| without overflow or underflow of the squares, the same on floats and arrays
    (so that one state gives the same constants alone and in a batch)."""
    return xp.hypot(xp.hypot(m1, m2), m3)


def hamilton(p: tuple, q: tuple) -> tuple[Any, Any, Any, Any]:
    """p ⊗ q, scalar first (floats or arrays)."""
    pw, px, py, pz = p
    qw, qx, qy, qz = q
    return (
        pw * qw - px * qx - py * qy - pz * qz,
        pw * qx + px * qw + py * qz - pz * qy,
        pw * qy - px * qz + py * qw + pz * qx,
        pw * qz + px * qy - py * qx + pz * qw,
    )


# ----------------------------------------------------------------- one state's attitude


@dataclass
class Motion:
    """One state's motion: its case formula and the constants that turn the formula's
    m(τ) and ψ(τ) into body vectors and attitudes, τ = t − t0.

    The attitude is q(t) = r ⊗ Y(ψ(τ) − ψ(0)) ⊗ P(m(τ)) ⊗ s ([Leroy] "An alternative
    quaternionic solution", with R = Q0 ∘ S⁻¹ ∘ P(m(0))⁻¹ so that q(t0) = Q0), that is
    ``M`` (Y ⊗ P)(τ) with the constant 4×4 matrix M = L(r) R(s) (docs/derivation.md
    §10; ``M_rows``, its rows as floats).  S is the signed permutation
    P[k] = sign[k] · principal[index[k]] onto the formula's frame, after the rotation
    ``body_to_principal`` of a tensor (None for principal body axes); a vector of the
    formula's frame goes back to the body as v_frame @ S (``S_columns``: the non-zero
    entries (i, S_ik) of each column k of S).  Built by ``float_backend.motion``; the
    backends evaluate it.  What only arrays need (``S_matrix``, ``I_frame``, ``M``) is
    made at first use, and ``table`` is the table backend's.
    """

    formula: CaseFormula
    G: float
    t0: float
    moments: tuple[float, float, float]  # I1 ≤ I2 ≤ I3
    preferred: tuple[float, float, float]  # m at t0 in the preferred (sorted, flipped) axes
    index: tuple[int, int, int]
    sign: tuple[float, float, float]
    body_to_principal: NDArray[np.float64] | None
    S_columns: tuple[tuple[tuple[int, float], ...], ...]
    I_frame_floats: tuple[float, float, float]  # the moments along the frame's axes
    M_rows: tuple[tuple[float, float, float, float], ...]
    ψ_t0: float
    q0: tuple[float, float, float, float]  # the attitude at t0, scalar first
    table: Any = None

    @functools.cached_property
    def S_matrix(self) -> NDArray[np.float64]:
        """S as a 3×3 matrix (body → the formula's frame)."""
        S = np.zeros((3, 3))
        S[np.arange(3), self.index] = self.sign
        if self.body_to_principal is not None:
            S = np.ascontiguousarray(S @ self.body_to_principal)
        return S

    @functools.cached_property
    def I_frame(self) -> NDArray[np.float64]:
        """The moments along the axes of the formula's frame, as an array."""
        return np.array(self.I_frame_floats)

    @functools.cached_property
    def M(self) -> NDArray[np.float64]:
        """M as a 4×4 array."""
        return np.array(self.M_rows)

    @property
    def fastest_rate(self) -> float:
        """The largest angular rate of the motion, |λ| or |ω| ≤ G/I1 (rad/s)."""
        return max(abs(getattr(self.formula, "λ", 0.0)), self.G / self.moments[0])


# ----------------------------------------------------------------- a step of the flow


def step(formula: CaseFormula, G: Any, τ: Any, xp: Any) -> tuple[tuple[Any, Any, Any], tuple]:
    """m(τ) in the formula's frame and P(m(0))⁻¹ ⊗ Y(ψ(τ) − ψ(0)) ⊗ P(m(τ)): the flow's
    step, q(t0 + τ) = q(t0) ⊗ S⁻¹ ⊗ (this) ⊗ S (attitude.solver.free_flow)."""
    # Both ends from the same formula (not m(0) from the state), so that their rounding
    # errors, a shift of the phase ν, are the same and cancel in the step: a zero step
    # is the identity, and ψ(τ) − ψ(0) is as accurate as τ is short.
    if xp is FLOAT:
        a0, b0, c0, ψ0 = formula.momentum_and_angle(0.0, xp)
        a1, b1, c1, ψ1 = formula.momentum_and_angle(τ, xp)
    else:  # both times in one pass over the states: (2, n) against constants (n,)
        (a0, a1), (b0, b1), (c0, c1), (ψ0, ψ1) = formula.momentum_and_angle(
            np.stack([np.zeros_like(τ), τ]), xp
        )
    p0 = p_quaternion(a0, b0, c0, G, xp)
    p1 = p_quaternion(a1, b1, c1, G, xp)
    yp = y_times_p(0.5 * (ψ1 - ψ0), *p1, xp)
    return (a1, b1, c1), hamilton((p0[0], -p0[1], -p0[2], 0.0 * p0[0]), yp)
