"""The closed-form motion of a torque-free rigid body, one formula per case.

The formulas of Celledoni, Fassò, Säfström and Zanna [CFSZ08] as corrected by Leroy
[Leroy]: the momentum m(t) in Jacobi elliptic functions (or hyperbolic ones on the
separatrix) and the attitude through the angle ψ(t) of [Leroy] "Integrals", with an
elliptic integral of the third kind.  The project's own derivation, with every step
used here, is docs/derivation.md.

Every formula takes its constants and its times as floats or as numpy arrays that
broadcast together, and the namespace ``xp`` of their functions (numpy, or
``attitude.base.float_math.FLOAT`` for floats).  So one implementation serves one state at
many times (``EulerSolver``: float constants, an array of times), many states at one
time each (``attitude.solver.free_flow``: arrays of constants and of steps) and one state at
one time (floats throughout, ~100 times cheaper than numpy on arrays of one).

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

import math
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from attitude.base.float_math import FLOAT
from attitude.elliptic.functions import NEAR_ONE_MC, JacobiParameter, amplitude
from attitude.solver.invariants import Invariants, MomentConstants, invariants

__all__ = [
    "CaseFormula",
    "Elliptic",
    "Rest",
    "Separatrix",
    "SortedMoments",
    "Steady",
    "p_quaternion",
    "y_times_p",
]

_LN2 = math.log(2.0)


class CaseFormula(Protocol):
    """What the closed form of each case provides (constants per state).

    ``momentum(τ, xp)`` gives the components (a, b, c) of m in the P-frame at τ = t − t0,
    c ≥ 0; ``momentum_and_angle`` adds ψ(τ).  ``τ`` broadcasts with the constants.
    """

    name: str
    period: Any
    mc: Any  # the complementary parameter 1 − m (0 on the separatrix, NaN if none)

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
        j, r, sn_r, cn_r, dn_r = self.phase(τ, xp)
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


# The preferred flips (step 2 of the module docstring) and the relabelling into the
# P-frame (step 3), per case: P[k] = sign[k] · preferred[index[k]].
_FLIP_NONE, _FLIP_13, _FLIP_12, _FLIP_23 = (1, 1, 1), (-1, 1, -1), (-1, -1, 1), (1, -1, -1)
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


def norm(m1: Any, m2: Any, m3: Any, xp: Any) -> Any:
    """G = |m| without overflow or underflow of the squares, the same on floats and arrays
    (so that one state gives the same constants alone and in a batch)."""
    return xp.hypot(xp.hypot(m1, m2), m3)


class OneState:
    """The case formula of a single state and its frame, on Python floats.

    ``moments`` are principal moments along the principal axes (any order),
    ``momentum`` the momentum in those axes.  ``index``/``sign``: the signed permutation
    to the P-frame, P[k] = sign[k] · principal[index[k]] (a proper rotation).
    """

    formula: CaseFormula

    def __init__(self, moments: tuple[float, float, float], momentum: tuple[float, ...]) -> None:
        order = sorted(range(3), key=moments.__getitem__)  # stable, as numpy's
        o0, o1, o2 = order
        odd = (o1 - o0) * (o2 - o0) * (o2 - o1) < 0
        sorted_signs = (1.0, -1.0 if odd else 1.0, 1.0)
        I1, I2, I3 = moments[o0], moments[o1], moments[o2]
        m1, m2, m3 = momentum[o0], sorted_signs[1] * momentum[o1], momentum[o2]
        G = norm(m1, m2, m3, FLOAT)
        self.G, self.I = G, (I1, I2, I3)
        if G == 0.0:
            case, flips = "rest", _FLIP_NONE
        elif I1 == I3:
            case, flips = "steady", (_FLIP_23 if m3 < 0.0 else _FLIP_NONE)
        else:
            inv = invariants(I1, I2, I3, m1, m2, m3, FLOAT)
            if inv.sign == 0.0:
                case = "iii"
                flips = preferred_flips(m1 < 0.0, m3 < 0.0, FLOAT)
            else:
                case = "ii" if inv.sign > 0.0 else "i"
                flips = preferred_flips(case == "i" and m1 < 0.0, case == "ii" and m3 < 0.0, FLOAT)
        m1, m2, m3 = flips[0] * m1, flips[1] * m2, flips[2] * m3
        formula: CaseFormula
        if case in ("i", "ii"):
            formula = Elliptic(
                I1, I2, I3, m1, m2, m3, G, inv, case == "ii", inv.mc < NEAR_ONE_MC, FLOAT
            )
            if formula.λ == 0.0:  # underflows: see Steady
                case, more = "steady", (_FLIP_23 if m3 < 0.0 else _FLIP_NONE)
                flips = tuple(f * g for f, g in zip(flips, more, strict=True))
                m1, m2, m3 = (f * m for f, m in zip(more, (m1, m2, m3), strict=True))
        if case == "iii":
            formula = Separatrix(I1, I2, I3, m1, m2, m3, G, inv, FLOAT)
            if formula.onto_e1:
                case = "iii-e1"
        if case == "steady":
            formula = Steady(I1, I2, I3, m1, m2, m3, G, FLOAT)
        if case == "rest":
            formula = Rest()
        self.formula = formula
        self.preferred = (m1, m2, m3)
        # P[k] = r_sign[k] f[r_index[k]] s[r_index[k]] principal[order[r_index[k]]].
        (r0, r1, r2), (rs0, rs1, rs2) = RELABEL[case]
        self.index = (order[r0], order[r1], order[r2])
        self.sign = (
            rs0 * flips[r0] * sorted_signs[r0],
            rs1 * flips[r1] * sorted_signs[r1],
            rs2 * flips[r2] * sorted_signs[r2],
        )


class ManyStates:
    """The case formulas of a batch of states, grouped by case, on numpy arrays.

    ``moments`` (N, 3) and ``momentum`` (N, 3) as in ``OneState``.  ``groups`` lists
    (indices, formula) with one formula per case present (the elliptic cases split by
    the regime of their kernels, mc above or below ``NEAR_ONE_MC``); ``index`` and
    ``sign`` (N, 3) are the signed permutations to each state's P-frame.

    In the steps of the module docstring: sorted (``SortedMoments``, step 1), each
    state's case (``_cases``), the preferred flips (``_preferred_flips_per_case``,
    step 2), the formulas (``_group_formulas``: an elliptic rate that underflows makes
    the state steady) and the relabelling into the P-frame (``_relabel``, step 3).
    """

    def __init__(self, moments: np.ndarray, momentum: np.ndarray) -> None:
        sorted_moments = SortedMoments(moments)
        I1, I2, I3 = sorted_moments.I
        order, sorted_signs = sorted_moments.order, sorted_moments.sorted_signs
        m_sorted = momentum.take(sorted_moments.flat_order)  # its rows permuted alike
        m1, m2, m3 = m_sorted[:, 0], sorted_signs[:, 1] * m_sorted[:, 1], m_sorted[:, 2]
        m = np.stack([m1, m2, m3], axis=-1)
        G = norm(m1, m2, m3, np)
        self.G = G
        case, inv = _cases(I1, I2, I3, m1, m2, m3, G, sorted_moments.constants)
        flips = _preferred_flips_per_case(case, m1, m3)
        m = flips * m
        self.groups = _group_formulas((I1, I2, I3), m, G, inv, case, flips)
        self.index, self.sign = _relabel(case, order, flips, sorted_signs)


def _cases(I1: Any, I2: Any, I3: Any, m1: Any, m2: Any, m3: Any, G: Any, constants: Any):
    """Each state's case code (``_CODE``: rest for G = 0, steady for the sphere I1 = I3,
    else i, ii or iii by the sign of Δ2) and its invariants δ1, δ3, mc, log mc (zeros and
    NaNs where the case has none; ``sign`` left out).  ``constants``: a callable giving
    the moments' ``MomentConstants`` (``SortedMoments.constants``)."""
    N = G.shape[0]
    case = np.full(N, _CODE["rest"], dtype=np.int8)
    sphere = (G > 0.0) & (I1 == I3)
    general = (G > 0.0) & ~sphere
    case[sphere] = _CODE["steady"]
    if general.all():  # the usual batch: no gather
        inv = invariants(I1, I2, I3, m1, m2, m3, np, constants())
        case = np.where(
            inv.sign < 0.0, _CODE["i"], np.where(inv.sign > 0.0, _CODE["ii"], _CODE["iii"])
        ).astype(np.int8)
        return case, Invariants(None, inv.δ1, inv.δ3, inv.mc, inv.log_mc)
    g = np.flatnonzero(general)
    mc = np.full(N, np.nan)
    log_mc = np.full(N, np.nan)
    δ1 = np.zeros(N)
    δ3 = np.zeros(N)
    if g.size:
        inv = invariants(I1[g], I2[g], I3[g], m1[g], m2[g], m3[g], np)
        case[g] = np.where(
            inv.sign < 0.0, _CODE["i"], np.where(inv.sign > 0.0, _CODE["ii"], _CODE["iii"])
        )
        mc[g], log_mc[g], δ1[g], δ3[g] = inv.mc, inv.log_mc, inv.δ1, inv.δ3
    return case, Invariants(None, δ1, δ3, mc, log_mc)


def _preferred_flips_per_case(case: np.ndarray, m1: np.ndarray, m3: np.ndarray) -> np.ndarray:
    """(N, 3) axis signs of step 2: the component carrying dn (m1 in case i, m3 in case
    ii), both sech components on the separatrix, and m3 of a steady state made ≥ 0."""
    flip1 = (m1 < 0.0) & ((case == _CODE["i"]) | (case == _CODE["iii"]))
    flip3 = (m3 < 0.0) & ((case == _CODE["ii"]) | (case == _CODE["iii"]))
    flip3 |= (m3 < 0.0) & (case == _CODE["steady"])
    return np.stack(preferred_flips(flip1, flip3, np), axis=-1)


def _group_formulas(
    moments: tuple[np.ndarray, np.ndarray, np.ndarray],
    m: np.ndarray,
    G: np.ndarray,
    inv: Invariants,
    case: np.ndarray,
    flips: np.ndarray,
) -> list[tuple[np.ndarray, CaseFormula]]:
    """(indices, formula) per case present, from the preferred components ``m`` (N, 3).

    An elliptic state whose rate λ underflows is steady (``_elliptic_groups``): its
    ``case``, ``flips`` and ``m`` are updated in place.  A separatrix state that P maps
    onto e1 gets the case code iii-e1 (its relabelling).
    """

    def constants(k):
        return _constants(k, moments, m, G, inv)

    with np.errstate(divide="ignore", invalid="ignore", over="ignore", under="ignore"):
        groups = _elliptic_groups(constants, inv.mc, case, flips, m)
        k = np.flatnonzero(case == _CODE["iii"])
        if k.size:
            formula = Separatrix(*constants(k), np)
            case[k[formula.onto_e1]] = _CODE["iii-e1"]
            groups.append((k, formula))
        k = np.flatnonzero(case == _CODE["steady"])
        if k.size:
            groups.append((k, Steady(*constants(k)[:7], np)))
        k = np.flatnonzero(case == _CODE["rest"])
        if k.size:
            groups.append((k, Rest()))
    return groups


def _constants(k: np.ndarray, moments, m: np.ndarray, G: np.ndarray, inv: Invariants) -> tuple:
    """I1, I2, I3, m1, m2, m3, G and the invariants of the states ``k``, as the formulas
    take them (every state: the arrays themselves, no gather)."""
    I1, I2, I3 = moments
    if k.size == G.shape[0]:
        return (I1, I2, I3, m[:, 0], m[:, 1], m[:, 2], G, inv)
    inv_k = Invariants(None, inv.δ1[k], inv.δ3[k], inv.mc[k], inv.log_mc[k])
    return (I1[k], I2[k], I3[k], m[k, 0], m[k, 1], m[k, 2], G[k], inv_k)


def _elliptic_groups(
    constants: Any, mc: np.ndarray, case: np.ndarray, flips: np.ndarray, m: np.ndarray
) -> list[tuple[np.ndarray, CaseFormula]]:
    """The elliptic formulas, one per regime of the kernels (mc above or below
    ``NEAR_ONE_MC``).  A state whose rate λ underflows cannot move (``Steady``): it is
    made steady, its ``case``, ``flips`` and ``m`` updated in place with Steady's flip
    of m3, and the formula of the others made again."""
    groups: list[tuple[np.ndarray, CaseFormula]] = []
    elliptic = (case == _CODE["i"]) | (case == _CODE["ii"])
    for near_one in (False, True):
        k = np.flatnonzero(elliptic & ((mc < NEAR_ONE_MC) == near_one))
        if not k.size:
            continue
        formula = Elliptic(*constants(k), case[k] == _CODE["ii"], near_one, np)
        still = formula.λ != 0.0
        if not np.all(still):
            lost = k[~still]
            case[lost] = _CODE["steady"]
            sign3 = np.where(m[lost, 2] < 0.0, -1.0, 1.0)  # Steady's flip of m3
            more = np.stack([np.ones_like(sign3), sign3, sign3], axis=-1)
            flips[lost] *= more
            m[lost] *= more
            k = k[still]
            if k.size:
                formula = Elliptic(*constants(k), case[k] == _CODE["ii"], near_one, np)
        if k.size:
            groups.append((k, formula))
    return groups


def _relabel(
    case: np.ndarray, order: np.ndarray, flips: np.ndarray, sorted_signs: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Step 3: the signed permutations (N, 3) to each state's P-frame,
    P[k] = r_sign[k] f[r_index[k]] s[r_index[k]] principal[order[r_index[k]]]."""
    # Flat indices into the rows (N, 3): one gather each, cheaper than take_along_axis.
    flat = _RELABEL_INDEX[case] + 3 * np.arange(case.shape[0])[:, None]
    index = order.take(flat)
    sign = _RELABEL_SIGN[case] * flips.take(flat) * sorted_signs.take(flat)
    return index, sign


class SortedMoments:
    """The moments of a batch sorted, step 1 of the module docstring, with what the case
    test needs of them alone (``constants``, made only if a state needs the test).

    ``I``: the sorted moments as columns (I1, I2, I3); ``order`` (N, 3): the stable
    permutation that sorts each row; ``sorted_signs`` (N, 3): the middle axis reversed
    for an odd permutation.  A sorting network of three compare-exchanges over columns
    (bubble sort, stable), several times cheaper than ``argsort`` along rows of three.
    """

    def __init__(self, moments: np.ndarray) -> None:
        Is = [moments[:, 0], moments[:, 1], moments[:, 2]]
        N = moments.shape[0]
        index = [np.zeros(N, np.intp), np.ones(N, np.intp), np.full(N, 2, np.intp)]
        odd = np.zeros(N, dtype=bool)
        for a, b in ((0, 1), (1, 2), (0, 1)):
            swap = Is[a] > Is[b]
            for column in (Is, index):
                column[a], column[b] = (
                    np.where(swap, column[b], column[a]),
                    np.where(swap, column[a], column[b]),
                )
            odd ^= swap
        self.I = tuple(Is)
        self.order = np.stack(index, axis=-1)
        self.flat_order = self.order + 3 * np.arange(N)[:, None]  # into a flat (N, 3) array
        self.sorted_signs = np.ones((N, 3))
        self.sorted_signs[:, 1] = np.where(odd, -1.0, 1.0)
        self._constants: MomentConstants | None = None

    def constants(self) -> MomentConstants:
        """The double-double constants of the sorted moments (made on first use)."""
        if self._constants is None:
            self._constants = MomentConstants(*self.I)
        return self._constants


# The relabelling of each case as arrays indexed by a small integer code, for batches.
_CODE = {name: code for code, name in enumerate(RELABEL)}
_RELABEL_INDEX = np.array([RELABEL[name][0] for name in RELABEL])
_RELABEL_SIGN = np.array([RELABEL[name][1] for name in RELABEL], dtype=float)
