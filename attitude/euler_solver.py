"""The exact motion of a torque-free rigid body: ``EulerSolver``.

Closed-form solution of Euler's equations and of the attitude, after Celledoni,
Fassò, Säfström and Zanna [CFSZ07], with the corrections of Leroy [Leroy]
(``shared/references/leroy-notes-on-celledoni-exact-free-rigid-body.md``): the sign
of λ that fixes the precession direction, the separatrix with both free signs, the
cancellation-free Δj and mc, and the attitude through the "preferred axes" and ψ(t).
No numerical integration: evaluation at any time costs the same and does not drift.

Glossary (the symbols of [Leroy], kept as names in the code)
------------------------------------------------------------
I1 ≤ I2 ≤ I3   principal moments, sorted (the user's body axes are permuted to them)
Ijh            Ij − Ih
m = (m1,m2,m3) body angular momentum in the preferred principal axes
G              |m|, the norm of the angular momentum (conserved)
T              kinetic energy, 2T = Σ mj²/Ij (conserved)
Δj             G² − 2T Ij; we keep δj = Δj/G² (dimensionless), computed without
               cancellation as in [Leroy] "The quantity Δj", so that no square of a
               momentum can overflow or underflow.  Δ1 ≥ 0 ≥ Δ3; sign(Δ2) picks the case
Bjh            √(±Ij Δh / Ijh), amplitudes of the components of m
λ              the rate of the elliptic argument u = λ(t − t0) − ν
λ1, λ2, λ3     |λ| in cases (ii), (iii), (i)
ν              the phase: u(t0) = −ν
mc             1 − k², complementary parameter of the Jacobi functions ([Leroy]
               "The elliptic modulus"); k⁻² replaces k² in case (ii).  Below 2^-128
               (a state within ~1e-19 G of the separatrix) the kernels take ln mc,
               exact from the integers of _ExactΔ however small mc is: see _Parameter
K              K(mc), quarter period of the Jacobi functions in u
n              characteristic of the elliptic integral of the third kind Π(φ, n|m)
ψ              angle of the rotation about e1 (case i) or e3 (case ii) that completes
               the attitude: Q(t) = R ∘ Y(ψ(t)) ∘ P(t) ∘ S
S, P, Y, R     S: user body axes → preferred principal axes (a signed permutation,
               a proper rotation); P(t): maps m(t) onto G e1 or G e3; Y: rotation by ψ
               about that axis; R: constant, fixed by the initial attitude

Cases (exact sign test on Δ2 of the float inputs, no tolerance):
  (i)   Δ2 < 0: m circulates about the axis of least inertia, m1 = B13 dn > 0
  (ii)  Δ2 > 0: m circulates about the axis of greatest inertia, m3 = B31 dn > 0
  (iii) Δ2 = 0: the separatrix, m1 = B13 sech, m3 = B31 sech, m2 = G th
  steady and rest are the special cases whose formulas would be 0/0 or ∞·0: the
  sphere (I1 = I3), a rate λ that underflows (m within ~1e-160 G of an axis of a
  symmetric body), and G = 0.  Every other degenerate body (I1 = I2, I2 = I3, spin
  about any axis, the intermediate one included) goes through the general formulas.

References
----------
[CFSZ07] E. Celledoni, F. Fassò, N. Säfström, A. Zanna, "The exact computation of the
    free rigid body motion and its use in splitting methods", SIAM J. Sci. Comput. 30
    (2008) 2084–2112.
[Leroy] P. Leroy, "On an article by Celledoni et al.", 2020 (corrections used here).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from attitude.elliptic import (
    NEAR_ONE_MC,
    complete_first_kind,
    complete_first_kind_near_one,
    pi_minus_f,
    pi_minus_f_near_one,
    reduce_argument,
    reduced_sn_cn_dn,
    reduced_sn_cn_dn_near_one,
)
from attitude.errors import InputError
from attitude.inertia import principal_axes
from attitude.quantities import as_si_array, as_si_scalar, as_vector3
from attitude.quaternions import left_matrix, right_matrix

__all__ = ["EulerSolver"]

# Evaluations over many times run in slices of this many samples (see _in_chunks).
_CHUNK = 16384


def _rate(G: float, numerator: float, I1: float, I2: float, I3: float) -> float:
    """G √(numerator / (I1 I2 I3)), with the moments scaled by I3 so that their product
    cannot underflow or overflow (the λ of [Leroy]: numerator = Δ3 I12/G², Δ1 I32/G²,
    or −Δ1 Δ3 I2/G⁴)."""
    return (G / I3) * math.sqrt(numerator / I3 / ((I1 / I3) * (I2 / I3)))


class _Parameter:
    """The parameter m of the Jacobi functions of a state: mc = 1 − m, ln mc and K.

    For mc ≥ ``NEAR_ONE_MC`` the kernels take mc; below, where mc may be subnormal or
    below the float range while ln mc (from the exact integers) is always accurate,
    they take ln mc and use the expansions about m = 1 (see attitude/elliptic.py).
    """

    def __init__(self, mc: float, log_mc: float) -> None:
        self.mc = mc
        self.log_mc = log_mc
        self.near_one = mc < NEAR_ONE_MC
        if self.near_one:
            self.K = float(complete_first_kind_near_one(log_mc))
        else:
            self.K = float(complete_first_kind(mc))
        self.kc = math.exp(0.5 * log_mc)  # k' = √mc (0 when below the float range)

    def reduced_sn_cn_dn(self, r: NDArray[np.float64]):
        if self.near_one:
            return reduced_sn_cn_dn_near_one(r, self.log_mc, self.K)
        return reduced_sn_cn_dn(r, self.mc, self.K)

    def pi_minus_f(self, f: _Jacobi, n: float) -> NDArray[np.float64]:
        """Π(am u, n) − u."""
        if self.near_one:
            return pi_minus_f_near_one(f.j, f.r, f.sn_r, n, self.K)
        return pi_minus_f(f.j, f.sn_r, f.cn_r, f.dn_r, n, self.mc)

    def phase(
        self,
        G: float,
        sn: tuple[float, float],
        cn: tuple[float, float],
        dn: tuple[float, float],
    ) -> float:
        """ν, from sn ν, cn ν and dn ν each given as (component of m0, its amplitude B).

        [Leroy] "Phase and initial value": ν = F(am ν).  Away from m = 1 this is
        ``_elliptic_phase`` of (sn ν, cn ν).  Near m = 1 the components may differ by
        more than the float range (a state 1e-200 G from the intermediate axis with
        G = 1e124), so ν is found from their logarithms: sinh ν = sn/cn where
        dn ν ≥ √k' (|ν| ≤ K/2, sn = tanh, cn = sech), and otherwise, with the quarter
        shift ν = ±(K − z) of ``reduced_sn_cn_dn_near_one``, sinh z = |cn ν|/k'.
        cn ν < 0 means |ν| > K: then ν = ±2K − ν', with ν' the phase of −cn ν
        (cn(2K − x) = −cn x, sn and dn unchanged, [OLBC10] 22.4.3).
        """
        (m_s, B_s), (m_c, B_c), (m_d, B_d) = sn, cn, dn
        if not self.near_one:
            # sin φ : cos φ = m_s/B_s : m_c/B_c, scaled by B_s B_c/G² to stay O(1).
            s, c = _unit_vector_phase((m_s / G) * (B_c / G), (m_c / G) * (B_s / G))
            return _elliptic_phase(s, c, self.mc, self.K)
        σ = -1.0 if m_s < 0.0 else 1.0
        log_c = _log_abs(m_c) - math.log(B_c)
        if m_c != 0.0 and _log_abs(m_d) - math.log(B_d) >= 0.25 * self.log_mc:
            ν = σ * _asinh_of_exp(_log_abs(m_s) - math.log(B_s) - log_c)
        else:
            ν = σ * (self.K - _asinh_of_exp(log_c - 0.5 * self.log_mc))
        return σ * 2.0 * self.K - ν if m_c < 0.0 else ν


def _log_abs(x: float) -> float:
    return math.log(abs(x)) if x != 0.0 else -math.inf


def _asinh_of_exp(L: float) -> float:
    """asinh(e^L) without overflow: L + ln 2 + O(e^-2L) for large L."""
    if L > 20.0:
        return L + math.log(2.0)
    return math.asinh(math.exp(L))


class _Jacobi:
    """sn, cn, dn of u = 2jK + r, with those of the reduced r (|r| ≤ K) kept for Π."""

    def __init__(self, u: NDArray[np.float64], parameter: _Parameter) -> None:
        self.j, self.r = reduce_argument(u, parameter.K)
        self.sn_r, self.cn_r, self.dn_r = parameter.reduced_sn_cn_dn(self.r)
        sign = 1.0 - 2.0 * np.mod(self.j, 2.0)  # (−1)^j: sn, cn change sign every 2K
        self.sn = sign * self.sn_r
        self.cn = sign * self.cn_r
        self.dn = self.dn_r

    def arctan_of_scaled_sc(self, κ: float) -> NDArray[np.float64]:
        """arctg(κ sc(u)), continuous in u (κ > 0).

        With φ = am(u) = jπ + atan2(sn r, cn r), arctg(κ tan φ) is continued through
        φ + arctan((κ − 1) sn cn / (cn² + κ sn²)); the second term stays in
        (−π/2, π/2) because its denominator is positive.
        """
        s, c = self.sn_r, self.cn_r
        am = self.j * np.pi + np.arctan2(s, c)
        return am + np.arctan((κ - 1.0) * s * c / (c * c + κ * s * s))


def _unit_vector_phase(a: float, b: float) -> tuple[float, float]:
    """(sin φ, cos φ) of the angle φ whose sine and cosine are proportional to (a, b)."""
    h = math.hypot(a, b)
    if h == 0.0:
        return 0.0, 1.0
    return a / h, b / h


def _elliptic_phase(s: float, c: float, mc: float, K: float) -> float:
    """ν = F(φ|m) for sin φ = s, cos φ = c, φ in (−π, π] ([Leroy] "Phase and initial value").

    Carlson's form F = s R_F(c², 1 − m s², 1) holds for |φ| ≤ π/2; beyond,
    F(±π − φ') = ±2K − F(φ') ([OLBC10] 19.2.10).  Working from (s, c) rather than
    from φ = atan2 keeps ν accurate near φ = ±π/2, where dF/dφ = 1/dn is large
    close to the separatrix.
    """
    from scipy.special import elliprf

    c2 = c * c
    f = s * float(elliprf(c2, c2 + mc * s * s, 1.0))
    if c >= 0.0:
        return f
    return math.copysign(2.0 * K, s) - f


class _FormulaI:
    """Case (i), Δ2 < 0: [Leroy] "Case (i)" with σ = 1 (preferred axes make m1 > 0)."""

    name = "i"
    axis = 0  # P(t) maps m onto e1: m1 = B13 dn is the component that never vanishes

    @staticmethod
    def rate(G: float, I1: float, I2: float, I3: float, δ1: float, δ3: float) -> float:
        """λ3 = G √(δ3 I12 / (I1 I2 I3)), the magnitude of λ."""
        return _rate(G, δ3 * (I1 - I2), I1, I2, I3)

    def __init__(self, I1, I2, I3, m0, G, δ1, δ3, parameter) -> None:
        I12, I13, I21, I31, I32 = I1 - I2, I1 - I3, I2 - I1, I3 - I1, I3 - I2
        self.B13 = G * math.sqrt(I1 * δ3 / I13)
        self.B21 = G * math.sqrt(I2 * δ1 / I21)
        self.B31 = G * math.sqrt(I3 * δ1 / I31)
        self.parameter = parameter  # mc = Δ2 I31 / (Δ3 I21), from the exact Δj
        self.mc, self.K = parameter.mc, parameter.K
        self.λ = -self.rate(G, I1, I2, I3, δ1, δ3)  # the corrected sign: λ = −σ λ3
        # m0 = (B13 dn ν, B21 sn ν, B31 cn ν).
        self.ν = parameter.phase(G, (m0[1], self.B21), (m0[2], self.B31), (m0[0], self.B13))
        # ψ(t) = (G/I1) t + C Π(am u, n) − arctg(κ sc u)   [Leroy] "Integrals", case (i)
        self.C = (G / self.λ) * (I13 / I1 / I3)  # grouped to stay in the float range
        self.n = (I1 / I3) * (I32 / I12)
        self.κ = math.sqrt((I2 / I3) * (I31 / I21))
        # Π(am u, n) = u + (Π − F) since F(am u) = u, and C λ = G/I3 − G/I1, so the
        # secular part of ψ is (G/I3) t; the constant −C ν drops out of ψ(t) − ψ(t0).
        self.ψ_rate = G / I3

    def evaluate(self, τ: NDArray[np.float64], with_ψ: bool):
        u = self.λ * τ - self.ν
        f = _Jacobi(u, self.parameter)
        m = np.stack([self.B13 * f.dn, -self.B21 * f.sn, self.B31 * f.cn], axis=-1)
        if not with_ψ:
            return m, None
        Π_minus_F = self.parameter.pi_minus_f(f, self.n)
        ψ = self.ψ_rate * τ + self.C * Π_minus_F - f.arctan_of_scaled_sc(self.κ)
        return m, ψ

    @property
    def period(self) -> float:
        return 4.0 * self.K / abs(self.λ)


class _FormulaII:
    """Case (ii), Δ2 > 0: [Leroy] "Case (ii)" with σ = 1 (preferred axes make m3 > 0)."""

    name = "ii"
    axis = 2  # P(t) maps m onto e3: m3 = B31 dn never vanishes

    @staticmethod
    def rate(G: float, I1: float, I2: float, I3: float, δ1: float, δ3: float) -> float:
        """λ1 = G √(δ1 I32 / (I1 I2 I3)), the magnitude of λ."""
        return _rate(G, δ1 * (I3 - I2), I1, I2, I3)

    def __init__(self, I1, I2, I3, m0, G, δ1, δ3, parameter) -> None:
        I13, I21, I23, I31, I32 = I1 - I3, I2 - I1, I2 - I3, I3 - I1, I3 - I2
        self.B13 = G * math.sqrt(I1 * δ3 / I13)
        self.B23 = G * math.sqrt(I2 * δ3 / I23)
        self.B31 = G * math.sqrt(I3 * δ1 / I31)
        self.parameter = parameter  # mc = 1 − k⁻² = Δ2 I31 / (Δ1 I32), from the exact Δj
        self.mc, self.K = parameter.mc, parameter.K
        self.λ = -self.rate(G, I1, I2, I3, δ1, δ3)  # the corrected sign: λ = −σ λ1
        # m0 = (B13 cn ν, B23 sn ν, B31 dn ν).
        self.ν = parameter.phase(G, (m0[1], self.B23), (m0[0], self.B13), (m0[2], self.B31))
        # ψ(t) = (G/I3) t + C Π(am u, n) + arctg(κ sc u)   [Leroy] "Integrals", case (ii)
        self.C = (G / self.λ) * (I31 / I1 / I3)  # grouped to stay in the float range
        self.n = (I3 / I1) * (I21 / I23)
        self.κ = math.sqrt((I2 / I1) * (I31 / I32))
        # As in case (i): C λ = G/I1 − G/I3, so the secular part of ψ is (G/I1) t.
        self.ψ_rate = G / I1

    def evaluate(self, τ: NDArray[np.float64], with_ψ: bool):
        u = self.λ * τ - self.ν
        f = _Jacobi(u, self.parameter)
        m = np.stack([self.B13 * f.cn, -self.B23 * f.sn, self.B31 * f.dn], axis=-1)
        if not with_ψ:
            return m, None
        Π_minus_F = self.parameter.pi_minus_f(f, self.n)
        ψ = self.ψ_rate * τ + self.C * Π_minus_F + f.arctan_of_scaled_sc(self.κ)
        return m, ψ

    @property
    def period(self) -> float:
        return 4.0 * self.K / abs(self.λ)


class _FormulaIII:
    """Case (iii), Δ2 = 0, the separatrix: [Leroy] "Case (iii)", σ' = σ'' = 1."""

    name = "iii"
    mc = 0.0
    period = math.inf

    def __init__(self, I1, I2, I3, m0, G, δ1, δ3, parameter) -> None:
        I13, I31 = I1 - I3, I3 - I1
        self.G = G
        self.B13 = G * math.sqrt(I1 * δ3 / I13)
        self.B31 = G * math.sqrt(I3 * δ1 / I31)
        self.λ = _rate(G, -δ1 * δ3 * I2, I1, I2, I3)  # λ = σ'σ'' λ2 = G √(−δ1δ3/(I1 I3))
        # th(−ν) = m02/G and sech(−ν) = √(m01² + m03²)/G, so sinh(−ν) is their ratio:
        # no cancellation even when m02 is within an ulp of ±G.  A spin exactly about
        # e2 gives ν = ∓∞ and, through IEEE infinities, m(t) = (0, ±G, 0) at all t.
        with np.errstate(divide="ignore", over="ignore"):
            self.ν = -float(np.arcsinh(np.float64(m0[1]) / math.hypot(m0[0], m0[2])))
        # P(t) maps m onto e1 if B13 < B31, else onto e3 ([Leroy] "Case (iii)"), so that
        # the coefficient (B − G)/B' of the arc tangent has a non-zero denominator.
        self.axis = 0 if self.B13 < self.B31 else 2
        self.ψ_rate = G / I2

    def evaluate(self, τ: NDArray[np.float64], with_ψ: bool):
        u = self.λ * τ - self.ν
        with np.errstate(over="ignore"):
            sech = 1.0 / np.cosh(u)
        m = np.stack([self.B13 * sech, self.G * np.tanh(u), self.B31 * sech], axis=-1)
        if not with_ψ:
            return m, None
        th_half = np.tanh(0.5 * u)
        if self.axis == 0:
            ψ = self.ψ_rate * τ - 2.0 * np.arctan((self.B13 - self.G) / self.B31 * th_half)
        else:
            ψ = self.ψ_rate * τ + 2.0 * np.arctan((self.B31 - self.G) / self.B13 * th_half)
        return m, ψ


class _Steady:
    """m fixed in the body: then m × ω = 0, so ω ∥ m and the body spins about m at |ω| = 2T/G.

    The sphere (I1 = I2 = I3), where every m is fixed; and a state so close to a
    principal axis of a symmetric body that the rate λ of cases (i)/(ii) underflows to
    zero (components ~1e-160 G or less): m then cannot move within any representable
    time, and the general formulas would give ∞·0.
    """

    name = "steady"
    axis = 2
    mc = math.nan
    period = math.inf

    def __init__(self, I1, I2, I3, m0, G, δ1, δ3, parameter) -> None:
        self.m0 = np.array(m0)
        x = self.m0 / G
        self.ψ_rate = G * float(np.sum(x * x / np.array([I1, I2, I3])))  # 2T/G

    def evaluate(self, τ: NDArray[np.float64], with_ψ: bool):
        m = np.broadcast_to(self.m0, (*τ.shape, 3)).copy()
        return m, (self.ψ_rate * τ if with_ψ else None)


class _Rest:
    """G = 0: nothing moves."""

    name = "rest"
    axis = None
    mc = math.nan
    period = math.inf

    def __init__(self, *args) -> None:
        pass

    def evaluate(self, τ: NDArray[np.float64], with_ψ: bool):
        return np.zeros((*τ.shape, 3)), (np.zeros(τ.shape) if with_ψ else None)


def _as_rotation(attitude: Any) -> Rotation:
    if attitude is None:
        return Rotation.identity()
    if not isinstance(attitude, Rotation):
        raise InputError(
            "attitude must be a scipy.spatial.transform.Rotation (body -> inertial), "
            f"got {type(attitude).__name__}: {attitude!r}"
        )
    if not attitude.single:
        raise InputError(f"attitude must be a single rotation, got a stack of {len(attitude)}")
    q = attitude.as_quat(scalar_first=True)
    if not np.all(np.isfinite(q)):
        raise InputError(f"attitude must be finite, got quaternion {q.tolist()}")
    return attitude


def _as_integers(*values: float) -> list[int]:
    """The floats ``values`` times one common power of two, as exact integers."""
    ratios = [float(v).as_integer_ratio() for v in values]
    scale = max(q for _, q in ratios)  # every q is a power of two and divides scale
    return [p * (scale // q) for p, q in ratios]


class _ExactΔ:
    """Δ1, Δ2, Δ3 of the float inputs, exactly, and the ratios taken from them.

    Floats are dyadic rationals: with I_k = J_k 2^a and m_k = M_k 2^b for integers J,
    M, the quantity of [Leroy] "The quantity Δj", Δj = Σ_k m_k² (I_k − I_j)/I_k, is
    Δj = 2^{2b} D_j / P with P = J1 J2 J3 and the integer
        D_j = Σ_{k≠j} M_k² (J_k − J_j) P/J_k,
    and G² = 2^{2b} S with S = Σ M_k².  So δj = Δj/G² = D_j/(P S), and the
    complementary parameter, a ratio of Δ's, is a ratio of integers: Python divides
    each with a single rounding.  Why: near the separatrix Δ2 is a difference of
    nearly equal terms (in floats it keeps only |δ2|/eps of its digits, a relative
    error of 1e-2 at |Δ2|/G² = 1e-14, which moves the flip period by 1e-8); near a
    principal axis δ1 or δ3 underflow in floats while mc, a ratio of two tiny
    numbers, is of order one.  The sign of D2 is the exact case test.
    """

    def __init__(self, I1: float, I2: float, I3: float, m1: float, m2: float, m3: float):
        J = _as_integers(I1, I2, I3)
        M = _as_integers(m1, m2, m3)
        P = J[0] * J[1] * J[2]
        squares = [Mk * Mk for Mk in M]
        self.J = J
        self.D = [
            sum(squares[k] * (J[k] - J[j]) * (P // J[k]) for k in range(3) if k != j)
            for j in range(3)
        ]
        self.PS = P * sum(squares)

    @property
    def sign_Δ2(self) -> int:
        return (self.D[1] > 0) - (self.D[1] < 0)

    def δ(self, j: int) -> float:
        """δj = Δj/G², correctly rounded (j = 1, 2, 3)."""
        return self.D[j - 1] / self.PS

    def mc(self, case: str) -> float:
        """mc = Δ2 I31/(Δ3 I21) in case (i), Δ2 I31/(Δ1 I32) in case (ii) ([Leroy]
        "The elliptic modulus"), correctly rounded, in [0, 1]."""
        numerator, denominator = self._mc_ratio(case)
        return numerator / denominator

    def log_mc(self, case: str) -> float:
        """ln mc, accurate however small mc is (Python's log takes integers of any size)."""
        numerator, denominator = self._mc_ratio(case)
        return math.log(numerator) - math.log(denominator)

    def _mc_ratio(self, case: str) -> tuple[int, int]:
        J1, J2, J3 = self.J
        D1, D2, D3 = self.D
        if case == "i":
            return -D2 * (J3 - J1), -D3 * (J2 - J1)
        return D2 * (J3 - J1), D1 * (J3 - J2)


def _preferred_axes(moments: NDArray[np.float64]) -> tuple[NDArray[np.intp], NDArray[np.float64]]:
    """Sorting permutation of the moments and the axis signs that make it proper.

    The principal coordinates are x_p[k] = signs[k] · x_body[order[k]]; for an odd
    permutation the middle axis is reversed so that the map is a rotation.
    """
    order = np.argsort(moments, kind="stable")
    matrix = np.zeros((3, 3))
    matrix[np.arange(3), order] = 1.0
    signs = np.ones(3)
    if np.linalg.det(matrix) < 0.0:
        signs[1] = -1.0
    return order, signs


class EulerSolver:
    """Exact torque-free motion of a rigid body from its state at ``t0``.

    Parameters
    ----------
    inertia
        The three principal moments of inertia along the body x, y, z axes, in any
        order, or the symmetric 3×3 inertia tensor in body axes, kg m² (or a
        ``Quantity``).  A tensor is diagonalized and every result is still given in
        the body axes.
    angular_momentum
        Body-frame angular momentum at ``t0``, N m s (kg m²/s).
    attitude
        ``scipy.spatial.transform.Rotation`` taking body coordinates to inertial
        coordinates at ``t0``; identity when None.
    t0
        Epoch of the initial state, seconds (the solver's own time origin).

    The attitude at t is ``Q(t) = R ∘ Y(ψ(t)) ∘ P(t) ∘ S`` (see the module glossary),
    built so that ``Q(t0)`` is the given attitude and nothing is singular anywhere
    on the sphere of momenta.  All evaluations accept a scalar or an array of times
    (seconds, before or after ``t0``) and are vectorized.
    """

    def __init__(
        self,
        inertia: ArrayLike,
        angular_momentum: ArrayLike,
        attitude: Rotation | None = None,
        t0: float = 0.0,
    ) -> None:
        axes = principal_axes(inertia)
        m_body = as_vector3(angular_momentum, "angular_momentum", "angular_momentum")
        self._initial_attitude = _as_rotation(attitude)
        self._t0 = as_si_scalar(t0, "time", "t0")
        self._axes = axes
        self._initial_angular_momentum = m_body

        # Body → principal (the identity unless a full tensor was given), then sorted.
        m_principal = m_body if axes.is_diagonal else axes.body_to_principal.apply(m_body)
        order, signs = _preferred_axes(axes.moments)
        I1, I2, I3 = (float(v) for v in axes.moments[order])  # Python floats: no warnings
        self._I_preferred = np.array([I1, I2, I3])
        m = signs * m_principal[order]
        G = math.hypot(*m)  # math.hypot scales: no overflow or underflow of the squares
        self._G = G
        parameter = None
        if not math.isfinite(G / I1):
            raise InputError(
                f"angular_momentum {m_body.tolist()} with moments {axes.moments.tolist()}: the "
                f"angular velocity |m|/I1 = {G / I1:g} rad/s is beyond the float range"
            )
        if G == 0.0:
            δ1 = δ3 = 0.0
            formula = _Rest
        else:
            exact = _ExactΔ(I1, I2, I3, *m)
            δ1, δ3 = exact.δ(1), exact.δ(3)
            if I1 == I3:
                formula = _Steady  # the sphere
            elif exact.sign_Δ2 < 0:
                formula, case = _FormulaI, "i"
            elif exact.sign_Δ2 > 0:
                formula, case = _FormulaII, "ii"
            else:
                formula = _FormulaIII
            if formula in (_FormulaI, _FormulaII):
                parameter = _Parameter(exact.mc(case), exact.log_mc(case))
                if formula.rate(G, I1, I2, I3, δ1, δ3) == 0.0:
                    formula = _Steady  # λ underflows: see _Steady
        # 2T = Σ mj²/Ij = G² (x1²/I1 + x2²/I2 + x3²/I3); Python floats: an energy
        # beyond the float range is inf, without a numpy warning.
        x = m / G if G > 0.0 else m
        self._kinetic_energy = 0.5 * G * (G * float(np.sum(x * x / np.array([I1, I2, I3]))))

        # Preferred axes ([Leroy] "An alternative quaternionic solution"): reverse axes
        # (by a rotation of π) so that the components carrying dn or sech are ≥ 0.
        flip1 = formula in (_FormulaI, _FormulaIII) and m[0] < 0.0
        flip3 = formula in (_FormulaII, _FormulaIII, _Steady) and m[2] < 0.0
        flips = np.ones(3)
        if flip1 and flip3:
            flips[[0, 2]] = -1.0
        elif flip1:
            flips[[0, 1]] = -1.0
        elif flip3:
            flips[[1, 2]] = -1.0
        signs = signs * flips
        m = flips * m
        self._formula = formula(I1, I2, I3, m, G, δ1, δ3, parameter)

        # S: user body → preferred principal axes: a signed permutation with det +1
        # after the body → principal rotation.  Row vectors go back to the body as
        # m_preferred @ S (exact when S is a signed permutation).
        S_matrix = np.zeros((3, 3))
        S_matrix[np.arange(3), order] = signs
        if not axes.is_diagonal:
            S_matrix = S_matrix @ axes.body_to_principal.as_matrix()
        self._S_matrix = np.ascontiguousarray(S_matrix)
        S = Rotation.from_matrix(S_matrix).as_quat(scalar_first=True)
        # R = Q0 ∘ S⁻¹ ∘ P(t0)⁻¹ so that Q(t0) = Q0, with ψ measured from ψ(t0).
        m_t0, ψ_t0 = self._formula.evaluate(np.zeros(1), with_ψ=True)
        self._ψ_t0 = float(ψ_t0[0])
        Q0 = self._initial_attitude.as_quat(scalar_first=True)
        if self._formula.axis is None:
            P0 = np.array([1.0, 0.0, 0.0, 0.0])
        else:
            P0 = self._p_quaternion(m_t0)[0]
        S_inv = S * np.array([1.0, -1.0, -1.0, -1.0])
        P0_inv = P0 * np.array([1.0, -1.0, -1.0, -1.0])
        R = left_matrix(Q0) @ left_matrix(S_inv) @ P0_inv
        # q(t) = R ⊗ (Y ⊗ P)(t) ⊗ S = L(R) Rr(S) (Y ⊗ P)(t): one constant 4×4 matrix.
        # Kept transposed, with its columns reordered so that the product comes out
        # scalar last, the layout Rotation.from_quat takes without a copy.
        M = left_matrix(R) @ right_matrix(S)
        self._M_T_scalar_last = np.ascontiguousarray(M[[1, 2, 3, 0]].T)
        self._inertial_angular_momentum = self._initial_attitude.apply(m_body)

    @classmethod
    def from_angular_velocity(
        cls,
        inertia: ArrayLike,
        angular_velocity: ArrayLike,
        attitude: Rotation | None = None,
        t0: float = 0.0,
    ) -> EulerSolver:
        """Build the solver from the body angular velocity at ``t0`` (rad/s)."""
        tensor = principal_axes(inertia).tensor
        ω = as_vector3(angular_velocity, "angular_velocity", "angular_velocity")
        return cls(inertia, tensor @ ω, attitude, t0)

    # ----------------------------------------------------------------- evaluation

    def _τ(self, t: Any) -> NDArray[np.float64]:
        return as_si_array(t, "time", "t") - self._t0

    def _evaluate(self, chunk, t: Any, width: int, τ: NDArray[np.float64] | None = None):
        """``chunk`` over the times ``t`` in slices, refusing a time too far from t0.

        Far enough from t0 (|t − t0| beyond ~1.8e308 divided by the motion's fastest
        angular rate) an angle λ(t − t0) or ψ(t) leaves the float range and the
        result would be NaN: that time gets an InputError that names it instead.
        """
        if τ is None:
            τ = self._τ(t)
        with np.errstate(over="ignore", invalid="ignore"):
            out = self._in_chunks(chunk, τ, width)
        if not np.isfinite(out).all():
            bad = np.flatnonzero(~np.isfinite(out).reshape(-1, width).all(axis=-1))[0]
            t_bad = np.ravel(as_si_array(t, "time", "t"))[bad] if np.ndim(t) else t
            rate = max(abs(getattr(self._formula, "λ", 0.0)), self._G / self._I_preferred[0])
            raise InputError(
                f"t = {float(t_bad)!r} s is too far from t0 = {self._t0!r} s for this motion: "
                f"its angles, at rates up to {rate:.3g} rad/s, times t - t0 exceed the float "
                "range (1.8e308)"
            )
        return out

    def _to_body(self, v_preferred: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.dot(v_preferred, self._S_matrix)

    def _p_quaternion(self, m: NDArray[np.float64]) -> NDArray[np.float64]:
        """P(t) as scalar-first quaternions: the rotation taking m onto G e1 or G e3.

        [Leroy] "Case (i)" (onto e1) and "Case (ii)" (onto e3) of "Integrals":
        p0 = √((1 + ma/G)/2) and the other components over √(2G(G + ma)) = 2G p0,
        where ma ≥ 0 is the preferred component, so that G + ma ≥ G never vanishes.
        """
        G = self._G
        m1, m2, m3 = m[..., 0], m[..., 1], m[..., 2]
        zero = np.zeros_like(m1)
        if self._formula.axis == 0:
            p0 = np.sqrt(0.5 * (1.0 + m1 / G))
            return np.stack([p0, zero, m3 / (2.0 * G * p0), -m2 / (2.0 * G * p0)], axis=-1)
        p0 = np.sqrt(0.5 * (1.0 + m3 / G))
        return np.stack([p0, m2 / (2.0 * G * p0), -m1 / (2.0 * G * p0), zero], axis=-1)

    def _momentum_chunk(self, τ: NDArray[np.float64]) -> NDArray[np.float64]:
        m, _ = self._formula.evaluate(τ, with_ψ=False)
        return self._to_body(m)

    def _velocity_chunk(self, τ: NDArray[np.float64]) -> NDArray[np.float64]:
        m, _ = self._formula.evaluate(τ, with_ψ=False)
        return self._to_body(m / self._I_preferred)

    def _quaternion_chunk(self, τ: NDArray[np.float64]) -> NDArray[np.float64]:
        """Attitude quaternions at τ = t − t0, scalar LAST (x, y, z, w), body → inertial."""
        m, ψ = self._formula.evaluate(τ, with_ψ=True)
        half = 0.5 * (ψ - self._ψ_t0)
        cy, sy = np.cos(half), np.sin(half)
        p = self._p_quaternion(m)
        p0, p1, p2, p3 = p[..., 0], p[..., 1], p[..., 2], p[..., 3]
        # Y ⊗ P with Y = (cos ψ/2, sin ψ/2 e_axis); P has no component along e_axis.
        if self._formula.axis == 0:
            yp = np.stack([cy * p0, sy * p0, cy * p2 - sy * p3, cy * p3 + sy * p2], axis=-1)
        else:
            yp = np.stack([cy * p0, cy * p1 - sy * p2, cy * p2 + sy * p1, sy * p0], axis=-1)
        return np.dot(yp, self._M_T_scalar_last)

    @staticmethod
    def _in_chunks(function, τ: NDArray[np.float64], width: int) -> NDArray[np.float64]:
        """Apply ``function`` to τ in slices of ``_CHUNK`` elements.

        A slice's temporaries stay in the processor's cache; over a million samples
        this is about 1.7 times faster than one pass over the whole array.
        """
        flat = τ.ravel()
        if flat.size <= _CHUNK:
            return function(flat).reshape((*τ.shape, width))
        out = np.empty((flat.size, width))
        for start in range(0, flat.size, _CHUNK):
            out[start : start + _CHUNK] = function(flat[start : start + _CHUNK])
        return out.reshape((*τ.shape, width))

    def angular_momentum(self, t: ArrayLike) -> NDArray[np.float64]:
        """Body-frame angular momentum at ``t`` (N m s), shape ``np.shape(t) + (3,)``."""
        return self._evaluate(self._momentum_chunk, t, 3)

    def angular_velocity(self, t: ArrayLike) -> NDArray[np.float64]:
        """Body-frame angular velocity at ``t`` (rad/s), shape ``np.shape(t) + (3,)``."""
        return self._evaluate(self._velocity_chunk, t, 3)

    def attitude(self, t: ArrayLike) -> Rotation:
        """Rotation taking body coordinates to inertial coordinates at ``t``.

        One ``Rotation`` for a scalar ``t``, a stack for a 1-D array.
        """
        τ = self._τ(t)
        if τ.ndim > 1:
            raise InputError(
                f"t must be a scalar or a 1-D array for attitude(), got shape {τ.shape}"
            )
        return Rotation.from_quat(self._quaternions_scalar_last(t, τ))

    def attitude_quaternion(self, t: ArrayLike, scalar_first: bool = True) -> NDArray[np.float64]:
        """The attitude at ``t`` as unit quaternions, body → inertial, shape ``np.shape(t) + (4,)``.

        Scalar first (w, x, y, z) by default.  The same rotation as ``attitude(t)``,
        without building a ``Rotation``: for writing files and for callers that
        assemble many segments.
        """
        q = self._quaternions_scalar_last(t, self._τ(t))
        q /= np.linalg.norm(q, axis=-1, keepdims=True)
        return q[..., [3, 0, 1, 2]] if scalar_first else q

    def _quaternions_scalar_last(self, t: Any, τ: NDArray[np.float64]) -> NDArray[np.float64]:
        if self._formula.axis is None:  # at rest
            return np.broadcast_to(self._initial_attitude.as_quat(), (*τ.shape, 4)).copy()
        return self._evaluate(self._quaternion_chunk, t, 4, τ)

    def spin_axis_cone(self) -> tuple[NDArray[np.float64], float, float] | None:
        """The body axis about which m circulates, and the cone it describes about m.

        In case (i) m circulates about the axis of least inertia (m1 = B13 dn u), in
        case (ii) about the axis of greatest inertia (m3 = B31 dn u).  Returns that
        axis as a unit vector in body coordinates, and the least and greatest angle
        (rad) between it and the angular momentum: arccos(B/G) at dn = 1 and
        arccos(B √mc/G) at dn = √mc, reached alternately every period/2 (the
        nutation).  None on the separatrix, for a sphere and at rest.
        """
        f = self._formula
        if f.name not in ("i", "ii"):
            return None
        B = f.B13 if f.name == "i" else f.B31
        axis = self._to_body(np.eye(3)[f.axis])
        G = self._G
        return axis, math.acos(min(1.0, B / G)), math.acos(min(1.0, B * f.parameter.kc / G))

    def _flip_phases(self, t_start: Any, t_end: Any) -> tuple[float, float] | None:
        """The phases u at t_start and t_end (ascending), or None if the body never flips.

        A flip is a sign change of the momentum component along the intermediate
        principal axis while the body turns over: m2 ∝ sn(u) vanishes at u = 2jK in
        cases (i) and (ii), every period/2; on the separatrix there is one, at u = 0.
        The body turns over only if the intermediate axis swings from near +m to
        near −m: we count flips when the amplitude of m2 exceeds G/√2 (that axis
        comes within 45° of the angular momentum).  Below, m2 changes sign too, but
        as part of a nutation about the spin axis, not as a flip.  None also for a
        body without a distinct intermediate axis (I1 = I2 or I2 = I3).
        """
        t_start = as_si_scalar(t_start, "time", "t_start")
        t_end = as_si_scalar(t_end, "time", "t_end")
        f = self._formula
        I1, I2, I3 = self._I_preferred
        if not (I1 < I2 < I3) or f.name not in ("i", "ii", "iii") or f.λ == 0.0:
            return None
        if not math.isfinite(f.ν):  # a steady spin about the intermediate axis
            return None
        if f.name != "iii" and (f.B21 if f.name == "i" else f.B23) <= self._G * math.sqrt(0.5):
            return None
        phases = []
        for name, t in (("t_start", t_start), ("t_end", t_end)):
            u = f.λ * (t - self._t0) - f.ν
            if not math.isfinite(u):
                raise InputError(
                    f"{name} = {t!r} s is too far from t0 = {self._t0!r} s: the phase of the "
                    f"motion, {f.λ:.3g} rad/s times {name} - t0, exceeds the float range"
                )
            phases.append(u)
        u_a, u_b = sorted(phases)
        return u_a, u_b

    def flip_count(self, t_start: float, t_end: float) -> int:
        """The number of flips in [t_start, t_end], in closed form (no array is built).

        The count of j with 2jK in [u(t_start), u(t_end)] (``flip_times`` says what a
        flip is): floor(u_b/2K) − ceil(u_a/2K) + 1, exact for the float phases u;
        0 or 1 on the separatrix.  A flip within rounding of t_start or t_end (a few
        ulps of λ(t − t0)) may be counted on either side.
        """
        phases = self._flip_phases(t_start, t_end)
        if phases is None:
            return 0
        u_a, u_b = phases
        f = self._formula
        if f.name == "iii":
            return int(u_a <= 0.0 <= u_b)
        return max(0, math.floor(u_b / (2.0 * f.K)) - math.ceil(u_a / (2.0 * f.K)) + 1)

    def flip_times(
        self, t_start: float, t_end: float, limit: int = 10_000_000
    ) -> NDArray[np.float64]:
        """Times in [t_start, t_end] at which the body flips (the Джанибеков effect).

        The exact times t = t0 + (2jK + ν)/λ, every period/2, at which the momentum
        component along the intermediate axis changes sign while the body turns over
        (see ``_flip_phases``); on the separatrix there is one, at u = 0.  Empty if
        the body never turns over.

        A span with more than ``limit`` flips (80 MB of float64 at the default) is
        refused with an InputError naming the count: ``flip_count`` gives the count
        alone, at no cost, for any span.
        """
        count = self.flip_count(t_start, t_end)
        if count > limit:
            count_text = str(count) if count < 10**12 else f"{float(count):.4g}"
            raise InputError(
                f"flip_times({t_start!r}, {t_end!r}): the body flips {count_text} times in "
                f"this span ({count * 8 / 2**30:.3g} GiB of float64), beyond limit={limit}; "
                "ask for a shorter span, or flip_count() for the number alone"
            )
        if count == 0:
            return np.empty(0)
        u_a, _ = self._flip_phases(t_start, t_end)
        f = self._formula
        if f.name == "iii":
            zeros_u = np.array([0.0])
        else:
            zeros_u = 2.0 * f.K * (float(math.ceil(u_a / (2.0 * f.K))) + np.arange(count))
        return np.sort(self._t0 + (zeros_u + f.ν) / f.λ)

    # ----------------------------------------------------------------- properties

    @property
    def period(self) -> float:
        """Period of the body-frame motion m(t), seconds: 4K/|λ|.

        ``math.inf`` on the separatrix, for a sphere and at rest.  For a steady spin
        about axis 1 or 3 (m constant) it is the period of the nearby motions.
        """
        return float(self._formula.period)

    @property
    def formula(self) -> str:
        """Which closed form applies: 'i', 'ii', 'iii' (separatrix), 'steady' (the sphere,
        or m fixed to within float range) or 'rest'."""
        return self._formula.name

    @property
    def mc(self) -> float:
        """Complementary parameter 1 − m of the Jacobi functions (0 on the separatrix)."""
        return float(self._formula.mc)

    @property
    def t0(self) -> float:
        """Epoch of the initial state, seconds."""
        return self._t0

    @property
    def moments_of_inertia(self) -> NDArray[np.float64]:
        """Principal moments, kg m²: as given, or ascending for a tensor."""
        return self._axes.moments.copy()

    @property
    def inertia_tensor(self) -> NDArray[np.float64]:
        """The inertia tensor in body axes, kg m²."""
        return self._axes.tensor.copy()

    @property
    def initial_angular_momentum(self) -> NDArray[np.float64]:
        """Body-frame angular momentum at ``t0``, N m s."""
        return self._initial_angular_momentum.copy()

    @property
    def initial_attitude(self) -> Rotation:
        """Attitude (body → inertial) at ``t0``."""
        return self._initial_attitude

    @property
    def angular_momentum_norm(self) -> float:
        """G = |m|, N m s (conserved)."""
        return self._G

    @property
    def kinetic_energy(self) -> float:
        """T = ½ Σ mj²/Ij, J (conserved)."""
        return self._kinetic_energy

    @property
    def inertial_angular_momentum(self) -> NDArray[np.float64]:
        """The angular momentum in inertial axes, N m s (conserved)."""
        return self._inertial_angular_momentum.copy()

    def __repr__(self) -> str:
        return (
            f"EulerSolver(inertia={self._axes.moments.tolist()}, "
            f"angular_momentum={self._initial_angular_momentum.tolist()}, t0={self._t0}, "
            f"formula={self.formula!r}, period={self.period:.6g} s)"
        )
