"""Sensitivities of the exact torque-free motion: its Jacobian with respect to the initial
attitude, the initial body momentum and the principal moments.

For an ``EulerSolver`` (principal moments along the body axes) and times t, returns the
derivatives of the body momentum m(t) and of the attitude Q(t) with respect to

- the initial attitude: Q0 → Q0 exp([δθ0]×), δθ0 in body axes at t0 (3 columns);
- the initial body momentum m0 (3 columns, N m s);
- the principal moments J along the body axes x, y, z (3 columns, kg m²),

the attitude's derivative as the body-axes rotation vector δθ(t) with
Q(t) → Q(t) exp([δθ(t)]×).  Rows (δθ(t), m(t)), columns (δθ0, m0, J): the first six
columns are the state-transition matrix of the motion, for linear covariance analysis
(``FlowSensitivities.covariance``), the last three its sensitivity to the inertia.

Method (derived in docs/estimation.md, "Sensitivities of the exact flow").  The closed
form of attitude.solver.closed_form (Celledoni, Fassò, Säfström and Zanna [CFSZ08] with
Leroy's corrections [Leroy]; docs/derivation.md) is differentiated analytically, in
forward mode: every constant of the formula (G, Δ1, Δ3, the amplitudes Bjh, λ, ν, mc,
n, C, κ) carries its gradient with respect to (m0, J) (``_Jet``), and the special
functions carry their analytic partial derivatives: the amplitude φ = am(u|m) with
∂φ/∂u = dn u and ∂φ/∂m = −dn u ∂F(φ|m)/∂m, F with ∂F/∂m = (1/6) sin³φ R_D(cos²φ, 1, Δ²)
(from ∂R_F/∂z = −R_D/6, [DLMF 19.18.1]), and Π − F with its partials in n and m in a
Carlson form written without the cancellations of [DLMF 19.4] (docs/estimation.md).
The quasi-periodicity F(φ + jπ) = F(φ) + 2jK and its like ([DLMF 19.2.10]) carry them to
every period.  The attitude's rotation vector follows from Q(t) = Q0 S⁻¹ P(0)⁻¹ Y(ψ(t) −
ψ(0)) P(t) S ([Leroy]): the variation of the minimal rotation P(m) and of the angle ψ.

Where the closed form has no derivative (the separatrix, Δ2 = 0 exactly, and states
within mc < 2⁻¹²⁸ of it, where the kernels work from ln mc) the variational equations
are integrated along the exact motion (scipy DOP853, rtol 1e-12).  An equilibrium (rest,
a spin exactly about a principal axis, the sphere, any state the solver calls steady)
has constant variational equations, solved exactly by a matrix exponential.

References
----------
[CFSZ08] E. Celledoni, F. Fassò, N. Säfström, A. Zanna, SIAM J. Sci. Comput. 30(4)
    (2008) 2084–2112, doi:10.1137/070704393.
[Leroy] P. Leroy, "On an Article by Celledoni et al." (2020), Principia's documentation.
[DLMF] F. W. J. Olver et al. (eds.), NIST Digital Library of Mathematical Functions,
    https://dlmf.nist.gov, §19.2, §19.18, §19.25 (elliptic integrals), §22.13, §22.16
    (Jacobi functions and amplitude).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import special
from scipy.linalg import expm
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.base.quantities import as_si_array
from attitude.elliptic.functions import (
    NEAR_ONE_MC,
    complete_first_kind,
    reduce_argument,
    reduced_sn_cn_dn,
)
from attitude.solver.euler_solver import EulerSolver

__all__ = ["FlowSensitivities", "flow_sensitivities", "skew"]

_P = 6  # the gradient's length: (m0, J), in body axes


def skew(v: ArrayLike) -> NDArray[np.float64]:
    """[v]×, the cross-product matrix of v (shape (..., 3) → (..., 3, 3))."""
    v = np.asarray(v, dtype=np.float64)
    out = np.zeros((*v.shape[:-1], 3, 3))
    out[..., 0, 1], out[..., 0, 2] = -v[..., 2], v[..., 1]
    out[..., 1, 0], out[..., 1, 2] = v[..., 2], -v[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -v[..., 1], v[..., 0]
    return out


# ----------------------------------------------------------------- forward-mode jets


def _e(value: Any) -> Any:
    """A value with a trailing axis, to scale a gradient."""
    return np.asarray(value)[..., None]


class _Jet:
    """A value (float, or array of samples) and its gradient with respect to (m0, J):
    ``d`` has the shape of the value plus a trailing axis of length 6."""

    __slots__ = ("d", "v")

    def __init__(self, v: Any, d: Any) -> None:
        self.v = v
        self.d = d

    def __add__(self, other: Any) -> _Jet:
        if isinstance(other, _Jet):
            return _Jet(self.v + other.v, self.d + other.d)
        return _Jet(self.v + other, self.d)

    __radd__ = __add__

    def __sub__(self, other: Any) -> _Jet:
        if isinstance(other, _Jet):
            return _Jet(self.v - other.v, self.d - other.d)
        return _Jet(self.v - other, self.d)

    def __rsub__(self, other: Any) -> _Jet:
        return _Jet(other - self.v, -self.d)

    def __neg__(self) -> _Jet:
        return _Jet(-self.v, -self.d)

    def __mul__(self, other: Any) -> _Jet:
        if isinstance(other, _Jet):
            return _Jet(self.v * other.v, self.d * _e(other.v) + other.d * _e(self.v))
        return _Jet(self.v * other, self.d * _e(other))

    __rmul__ = __mul__

    def __truediv__(self, other: Any) -> _Jet:
        if isinstance(other, _Jet):
            q = self.v / other.v
            return _Jet(q, (self.d - other.d * _e(q)) / _e(other.v))
        return _Jet(self.v / other, self.d / _e(other))

    def __rtruediv__(self, other: Any) -> _Jet:
        q = other / self.v
        return _Jet(q, -self.d * _e(q / self.v))


def _sqrt(x: _Jet) -> _Jet:
    root = np.sqrt(x.v)
    return _Jet(root, x.d / _e(2.0 * root))


def _chain(value: Any, *pairs: tuple[Any, _Jet]) -> _Jet:
    """The jet of f(x1, x2, ...) from its value and its partials ∂f/∂xk at the jets xk."""
    d = sum(_e(partial) * jet.d for partial, jet in pairs)
    return _Jet(value, d)


def _atan2(y: _Jet, x: _Jet) -> _Jet:
    r2 = x.v * x.v + y.v * y.v
    return _chain(np.arctan2(y.v, x.v), (x.v / r2, y), (-y.v / r2, x))


def _constant(value: float, gradient: NDArray[np.float64]) -> _Jet:
    return _Jet(float(value), np.asarray(gradient, dtype=np.float64))


# ----------------------------------------------------------------- the result


@dataclass(frozen=True)
class FlowSensitivities:
    """The exact motion at ``times`` and its derivatives (``flow_sensitivities``).

    ``jacobian[k]`` (6 × 9) holds ∂(δθ(t_k), m(t_k)) / ∂(δθ0, m0, J): rows the body-axes
    rotation vector of the attitude (Q → Q exp([δθ]×)) and the body momentum; columns
    the initial attitude (same convention, body axes at t0), the initial body momentum
    and the principal moments along the body axes x, y, z.  With ``attitude=False`` the
    attitude rows (and ``attitude``) are not computed and hold NaN.
    """

    times: NDArray[np.float64]  # (N,) s, the solver's time
    angular_momentum: NDArray[np.float64]  # (N, 3) body, N m s
    attitude: Rotation | None  # (N,) body → inertial
    jacobian: NDArray[np.float64]  # (N, 6, 9)
    method: str  # "closed form", "equilibrium" or "variational equations"

    @property
    def state_transition(self) -> NDArray[np.float64]:
        """(N, 6, 6): ∂(δθ(t), m(t)) / ∂(δθ0, m0), the state-transition matrix."""
        return self.jacobian[:, :, :6]

    @property
    def inertia_sensitivity(self) -> NDArray[np.float64]:
        """(N, 6, 3): ∂(δθ(t), m(t)) / ∂J, the principal moments along body x, y, z."""
        return self.jacobian[:, :, 6:]

    def covariance(self, initial: ArrayLike) -> NDArray[np.float64]:
        """(N, 6, 6): the covariance of (δθ(t), m(t)) from that of the initial state.

        ``initial`` is 6 × 6 (δθ0, m0) or 9 × 9 (δθ0, m0, J), in the units of the
        columns (rad, N m s, kg m²): linear propagation, Σ(t) = Φ(t) Σ0 Φ(t)ᵀ.
        """
        initial = np.asarray(initial, dtype=np.float64)
        if initial.shape not in ((6, 6), (9, 9)):
            raise InputError(
                f"initial covariance must be 6 x 6 (attitude, momentum) or 9 x 9 (with the "
                f"moments), got shape {initial.shape}"
            )
        phi = self.jacobian[:, :, : initial.shape[0]]
        return phi @ initial @ np.swapaxes(phi, 1, 2)


# ----------------------------------------------------------------- the entry point


def flow_sensitivities(
    solver: EulerSolver, t: ArrayLike, *, attitude: bool = True
) -> FlowSensitivities:
    """The motion of ``solver`` at times ``t`` (s) and its Jacobian (``FlowSensitivities``).

    ``solver`` must have its principal axes along the body axes (moments, not a full
    tensor: rotate the tensor's principal axes outside, as a fit of misaligned axes
    does).  ``attitude=False`` skips the attitude rows (cheaper: no elliptic integral of
    the third kind), for a fit to rates alone.
    """
    if not isinstance(solver, EulerSolver):
        raise InputError(f"solver must be an EulerSolver, got {type(solver).__name__}")
    tensor = solver.inertia_tensor
    if np.any(tensor != np.diag(np.diag(tensor))):
        raise InputError(
            "flow_sensitivities needs the principal axes along the body axes (moments "
            f"along x, y, z), got the tensor {tensor.tolist()}"
        )
    times = np.atleast_1d(as_si_array(t, "time", "t")).astype(np.float64, copy=False)
    if times.ndim != 1:
        raise InputError(f"t must be a scalar or a 1-D array, got shape {times.shape}")
    J = np.diag(tensor).copy()
    m0 = solver.initial_angular_momentum
    m = solver.angular_momentum(times)
    rotations = solver.attitude(times) if attitude else None
    jacobian = np.full((times.size, 6, 9), np.nan)
    τ = times - solver.t0
    zeros_off_axis = int(np.count_nonzero(m0 == 0.0))
    if solver.formula in ("rest", "steady") or zeros_off_axis >= 2:
        _equilibrium(J, m0, τ, jacobian)
        method = "equilibrium"
    elif solver.formula == "iii" or solver.mc < NEAR_ONE_MC:
        _variational(solver, J, times, jacobian)
        method = "variational equations"
    else:
        elliptic = _Elliptic(J, m0, solver.formula, solver.mc)
        jacobian[:, 3:, 3:] = elliptic.momentum_gradient(τ)
        jacobian[:, 3:, :3] = 0.0
        if rotations is not None:
            Φ = (solver.initial_attitude.inv() * rotations).as_matrix()
            jacobian[:, :3, 3:] = elliptic.attitude_gradient(τ, Φ)
            jacobian[:, :3, :3] = np.swapaxes(Φ, 1, 2)
        method = "closed form"
    if not attitude:
        jacobian[:, :3, :] = np.nan
    return FlowSensitivities(times, m, rotations, jacobian, method)


# ----------------------------------------------------------------- cases (i) and (ii)


class _Elliptic:
    """The closed form of cases (i) and (ii) with the gradients of its constants.

    Works in the preferred axes of [Leroy] (sorted I1 ≤ I2 ≤ I3, the component carrying
    dn made ≥ 0), where
      (i)  m = (B13 dn u, −B21 sn u, B31 cn u), λ = −λ3, preferred axis e1,
           ψ = (G/I3) τ + C (Π − F)(am u, n) − arctg(κ sc u);
      (ii) m = (B13 cn u, −B23 sn u, B31 dn u), λ = −λ1, preferred axis e3,
           ψ = (G/I1) τ + C (Π − F)(am u, n) + arctg(κ sc u),
    u = λτ − ν (docs/derivation.md §3, §7).  ``S`` maps body vectors to these axes.
    """

    def __init__(self, J: NDArray[np.float64], m0: NDArray[np.float64], formula: str, mc: float):
        order = sorted(range(3), key=lambda k: J[k])  # stable, as the solver's
        o0, o1, o2 = order
        odd = (o1 - o0) * (o2 - o0) * (o2 - o1) < 0
        signs = [1.0, -1.0 if odd else 1.0, 1.0]
        m_sorted = [signs[k] * m0[order[k]] for k in range(3)]
        case_ii = formula == "ii"
        if not case_ii and m_sorted[0] < 0.0:
            flips = (-1.0, -1.0, 1.0)
        elif case_ii and m_sorted[2] < 0.0:
            flips = (1.0, -1.0, -1.0)
        else:
            flips = (1.0, 1.0, 1.0)
        S = np.zeros((3, 3))
        for k in range(3):
            S[k, order[k]] = signs[k] * flips[k]
        self.S = S
        self.case_ii = case_ii
        self.axis = 2 if case_ii else 0  # the preferred axis a (carries dn), ≥ 0
        # Inputs as jets: the gradient of m_k (preferred) is row k of S in the m0
        # columns; that of I_k is the unit vector of the body axis order[k].  The
        # momentum is carried divided by a power of two near |m| (exact), so that its
        # squares neither underflow nor overflow: the rate λ and the ψ rate are scaled
        # back below, the rest of the formula is homogeneous of degree zero in m.
        eye = np.eye(_P)
        G_value = math.hypot(*m0)
        self.scale = 2.0 ** round(math.log2(G_value)) if G_value > 0.0 else 1.0
        m1, m2, m3 = (
            _constant(S[k] @ m0 / self.scale, np.concatenate([S[k] / self.scale, np.zeros(3)]))
            for k in range(3)
        )
        I1, I2, I3 = (_constant(J[order[k]], eye[3 + order[k]]) for k in range(3))
        self.m_pref0 = np.array([m1.v, m2.v, m3.v])
        self.I = (I1, I2, I3)
        I12, I13, I21, I23, I31, I32 = I1 - I2, I1 - I3, I2 - I1, I2 - I3, I3 - I1, I3 - I2
        G = _sqrt(m1 * m1 + m2 * m2 + m3 * m3)
        Δ1 = m2 * m2 * I21 / I2 + m3 * m3 * I31 / I3  # sums of same-sign terms (§1)
        Δ3 = m1 * m1 * I13 / I1 + m2 * m2 * I23 / I2
        Δ2 = m1 * m1 * I12 / I1 + m3 * m3 * I32 / I3
        # Δ2 is a difference: its value from the solver's exact mc (its gradient has no
        # cancellation), so that mc and what depends on it keep their digits.
        if case_ii:
            Δ2.v = mc * Δ1.v * I32.v / I31.v
            self.mc = Δ2 * I31 / (Δ1 * I32)
        else:
            Δ2.v = mc * Δ3.v * I21.v / I31.v
            self.mc = Δ2 * I31 / (Δ3 * I21)
        self.mc.v = mc
        B13 = _sqrt(I1 * Δ3 / I13)
        B31 = _sqrt(I3 * Δ1 / I31)
        product = I1 * I2 * I3
        if case_ii:
            B2 = _sqrt(I2 * Δ3 / I23)
            self.λ = -_sqrt(Δ1 * I32 / product)
            self.n = (I3 / I1) * (I21 / I23)  # I23 < 0 in case (ii)
            self.κ = _sqrt((I2 / I1) * (I31 / I32))
            self.C = (G / self.λ) * (I31 / (I1 * I3))
            self.ψ_rate = G / I1
            self.κ_sign = 1.0
            sin_ν, cos_ν = m2 / B2, m1 / B13
        else:
            B2 = _sqrt(I2 * Δ1 / I21)
            self.λ = -_sqrt(Δ3 * I12 / product)  # both ≤ 0
            self.n = (I1 / I3) * (I32 / I12)
            self.κ = _sqrt((I2 / I3) * (I31 / I21))
            self.C = (G / self.λ) * (I13 / (I1 * I3))
            self.ψ_rate = G / I3
            self.κ_sign = -1.0
            sin_ν, cos_ν = m2 / B2, m3 / B31
        self.λ = self.λ * self.scale
        self.ψ_rate = self.ψ_rate * self.scale
        self.G, self.B13, self.B31, self.B2 = G, B13, B31, B2
        self.K = float(complete_first_kind(mc))
        self.m = 1.0 - mc  # the parameter, as a float (only multiplies)
        self.dm = -self.mc.d  # its gradient
        # K_m = dK/dm = F_m(π/2) = R_D(0, 1, mc)/6; the complete Π − F and its partials.
        self.K_m = float(special.elliprd(0.0, 1.0, mc)) / 6.0
        # ν = F(φ0|m) with sin φ0 ∝ sin_ν, cos φ0 ∝ cos_ν (docs/derivation.md §4).
        φ0 = _atan2(sin_ν, cos_ν)
        j0 = float(np.rint(φ0.v / math.pi))
        s_r, c_r = math.sin(φ0.v - j0 * math.pi), math.cos(φ0.v - j0 * math.pi)
        Δ_r = math.sqrt(c_r * c_r + mc * s_r * s_r)
        F_r = s_r * float(special.elliprf(c_r * c_r, Δ_r * Δ_r, 1.0))
        ν_value = F_r + 2.0 * j0 * self.K
        F_m = _f_m(s_r, c_r, Δ_r) + 2.0 * j0 * self.K_m
        self.ν = _Jet(ν_value, φ0.d / Δ_r + _e(F_m) * self.dm)

    # -------------------------------------------------------------- per sample

    def _phase(self, τ: NDArray[np.float64]):
        """u = λτ − ν as a jet, its reduction u = 2jK + r, and sn, cn, dn of r."""
        u = _Jet(self.λ.v * τ - self.ν.v, _e(τ) * self.λ.d - self.ν.d)
        j, r = reduce_argument(u.v, self.K)
        sn_r, cn_r, dn_r = reduced_sn_cn_dn(r, self.mc.v, self.K)
        return u, j, r, sn_r, cn_r, dn_r

    def _amplitude(self, u: _Jet, j, sn_r, cn_r, dn_r):
        """φ = am(u|m) as a jet: ∂φ/∂u = dn, ∂φ/∂m = −dn F_m(φ); and sn, cn, dn of u."""
        parity = 1.0 - 2.0 * np.abs(j - 2.0 * np.rint(0.5 * j))
        sn, cn, dn = parity * sn_r, parity * cn_r, dn_r
        F_m = _f_m(sn_r, cn_r, dn_r) + 2.0 * j * self.K_m
        φ_d = _e(dn) * u.d + _e(-dn * F_m) * self.dm
        return φ_d, sn, cn, dn

    def _momentum(self, τ: NDArray[np.float64]):
        """The momentum in the preferred axes, divided by ``scale``, as three jets over
        the samples, with what the attitude needs of the phase."""
        u, j, r, sn_r, cn_r, dn_r = self._phase(τ)
        φ_d, sn, cn, dn = self._amplitude(u, j, sn_r, cn_r, dn_r)
        m = self.m
        sn_j = _Jet(sn, _e(cn) * φ_d)
        cn_j = _Jet(cn, _e(-sn) * φ_d)
        # dn = √(1 − m sn²): ∂/∂φ = −m sn cn/dn, ∂/∂m = −sn²/(2 dn).
        dn_j = _Jet(dn, _e(-m * sn * cn / dn) * φ_d + _e(-sn * sn / (2.0 * dn)) * self.dm)
        if self.case_ii:
            components = (self.B13 * cn_j, -(self.B2 * sn_j), self.B31 * dn_j)
        else:
            components = (self.B13 * dn_j, -(self.B2 * sn_j), self.B31 * cn_j)
        return components, (j, r, sn_r, cn_r, dn_r, sn, cn, dn, φ_d)

    def momentum_gradient(self, τ: NDArray[np.float64]) -> NDArray[np.float64]:
        """(N, 3, 6): ∂m_body(t)/∂(m0, J)."""
        components, _ = self._momentum(τ)
        d_pref = self.scale * np.stack([c.d for c in components], axis=1)  # (N, 3, 6)
        return np.einsum("ki,nkp->nip", self.S, d_pref)  # body = Sᵀ preferred

    def _angle(self, τ: NDArray[np.float64], phase) -> NDArray[np.float64]:
        """The gradient (N, 6) of ψ(τ) (up to a constant of the state)."""
        j, r, sn_r, cn_r, dn_r, sn, cn, _, φ_d = phase
        n, m, mc = self.n.v, self.m, self.mc.v
        c2, s2 = cn_r * cn_r, sn_r * sn_r
        P = c2 + (1.0 - n) * s2  # 1 − n sin²φ without cancellation
        # X = (Π − F)(φ, n|m) = n G_J with G_J = (1/3) s³ R_J(c², Δ², 1, P), reduced part
        # plus 2j times its complete value (n/3) R_J(0, mc, 1, 1 − n).
        G_J = sn_r * s2 * special.elliprj(c2, dn_r * dn_r, 1.0, P) / 3.0
        G_J_complete = float(special.elliprj(0.0, mc, 1.0, 1.0 - n)) / 3.0
        X = n * (G_J + 2.0 * j * G_J_complete)
        X_φ = n * s2 / (P * dn_r)
        R_D = special.elliprd(c2, dn_r * dn_r, 1.0)
        R_D_complete = float(special.elliprd(0.0, mc, 1.0))
        F_m = _f_m(sn_r, cn_r, dn_r)
        X_n = _pi_minus_f_n(n, m, r, sn_r * s2 * R_D, G_J, dn_r * sn_r * cn_r / P) + 2.0 * j * (
            _pi_minus_f_n(n, m, self.K, R_D_complete, G_J_complete, 0.0)
        )
        X_m = _pi_minus_f_m(n, m, F_m, G_J) + 2.0 * j * _pi_minus_f_m(n, m, self.K_m, G_J_complete)
        X_j = _Jet(X, _e(X_φ) * φ_d + _e(X_n) * self.n.d + _e(X_m) * self.dm)
        # T = arctg(κ tan φ), continued: ∂T/∂φ = κ/(cn² + κ² sn²), ∂T/∂κ = sn cn/(same).
        κ = self.κ.v
        den = cn * cn + κ * κ * sn * sn
        T_d = _e(κ / den) * φ_d + _e(sn * cn / den) * self.κ.d
        ψ = self.ψ_rate * τ + self.C * X_j
        return ψ.d + self.κ_sign * T_d

    def attitude_gradient(self, τ: NDArray[np.float64], Φ: NDArray[np.float64]) -> NDArray:
        """(N, 3, 6): ∂δθ_body(t)/∂(m0, J), with Φ(t) = Q0ᵀ Q(t) (N, 3, 3).

        δθ = a(t) + m̂(t) δψ − Φᵀ a(0) in body axes (docs/estimation.md), where a is the
        right variation of the minimal rotation P(m) taking m̂ onto the preferred axis
        e_a: a = δm̂ × m̂ + m̂ (m̂ × δm̂)·e_a / (1 + m̂_a), and δψ = δ(ψ(t) − ψ(0)).
        """
        τ_all = np.concatenate([[0.0], τ])
        components, phase = self._momentum(τ_all)
        m_val = np.stack([c.v for c in components], axis=1)  # (N+1, 3) preferred
        m_d = np.stack([c.d for c in components], axis=1)  # (N+1, 3, 6)
        ψ_d = self._angle(τ_all, phase)  # (N+1, 6)
        G = np.linalg.norm(m_val, axis=1)
        m_hat = m_val / G[:, None]
        # δm̂ = (δm − m̂ (m̂·δm)) / G
        radial = np.einsum("nk,nkp->np", m_hat, m_d)
        dm_hat = (m_d - m_hat[:, :, None] * radial[:, None, :]) / G[:, None, None]
        a_perp = np.cross(dm_hat, m_hat[:, :, None], axisa=1, axisb=1, axisc=1)
        ea = np.zeros(3)
        ea[self.axis] = 1.0
        twist = np.cross(m_hat[:, :, None], dm_hat, axisa=1, axisb=1, axisc=1)[:, self.axis, :]
        a = a_perp + m_hat[:, :, None] * (twist / (1.0 + m_hat[:, self.axis])[:, None])[:, None, :]
        a_body = np.einsum("ki,nkp->nip", self.S, a)  # (N+1, 3, 6)
        m_hat_body = m_hat @ self.S
        δψ = ψ_d[1:] - ψ_d[:1]
        result = a_body[1:] + m_hat_body[1:, :, None] * δψ[:, None, :]
        result -= np.einsum("nki,kp->nip", Φ, a_body[0])  # Φᵀ a(0)
        return result


def _f_m(s: Any, c: Any, Δ: Any) -> Any:
    """∂F(φ|m)/∂m for |φ| ≤ π/2 (sin φ = s, cos φ = c ≥ 0, Δ = √(1 − m s²)):
    (1/6) s³ R_D(c², 1, Δ²), from F = s R_F(c², Δ², 1) and ∂R_F/∂z = −R_D/6
    ([DLMF 19.25.5], [19.18.1]).  No cancellation anywhere, near m = 1 included."""
    return s * s * s * special.elliprd(c * c, 1.0, Δ * Δ) / 6.0


def _pi_minus_f_n(n: float, m: float, F: Any, s3_R_D: Any, G_J: Any, Δsc_over_P: Any) -> Any:
    """∂(Π − F)(φ, n|m)/∂n, |φ| ≤ π/2, from the Legendre form of ∂Π/∂n (Byrd and Friedman
    733.xx; docs/estimation.md) with Π − F = n G_J and E − F = −(m/3) s³ R_D(c², Δ², 1):

        [n F − (m/3) s³ R_D + (n² − m) G_J − n Δ s c / P] / (2 (m − n)(n − 1)).

    n ≤ 0 ≤ m here, so m − n = |m| + |n|: the numerator's rounding is not amplified.
    At n = m = 0 (a symmetric body) it is its limit G_J."""
    numerator = n * F - (m / 3.0) * s3_R_D + (n * n - m) * G_J - n * Δsc_over_P
    denominator = 2.0 * (m - n) * (n - 1.0)
    if denominator == 0.0:
        return G_J
    return numerator / denominator


def _pi_minus_f_m(n: float, m: float, F_m: Any, G_J: Any) -> Any:
    """∂(Π − F)(φ, n|m)/∂m = n (2 F_m − G_J) / (2 (m − n)), |φ| ≤ π/2 (docs/estimation.md);
    0 for n = 0, where Π = F whatever m."""
    if n == 0.0:
        return 0.0 * G_J
    return n * (2.0 * F_m - G_J) / (2.0 * (m - n))


# ----------------------------------------------------------------- equilibria


def _variational_matrix(J: NDArray[np.float64], m: NDArray[np.float64]) -> NDArray[np.float64]:
    """The 9 × 9 matrix of the variational equations at momentum m (body axes), on
    z = (δθ, δm, δJ): δṁ = δm × ω + m × δω, δω = δm/J − (m/J²) δJ, and the attitude's
    right variation δθ̇ = δω − ω × δθ (from Q̇ = Q [ω]×)."""
    ω = m / J
    M = np.zeros((9, 9))
    M[0:3, 0:3] = -skew(ω)
    M[0:3, 3:6] = np.diag(1.0 / J)
    M[0:3, 6:9] = -np.diag(m / (J * J))
    M[3:6, 3:6] = -skew(ω) + skew(m) @ np.diag(1.0 / J)
    M[3:6, 6:9] = -skew(m) @ np.diag(m / (J * J))
    return M


def _equilibrium(J, m0, τ, jacobian) -> None:
    """m fixed in the body (rest, a spin about a principal axis, the sphere): the
    variational equations have constant coefficients, z(τ) = exp(M τ) z(0)."""
    M = _variational_matrix(J, m0)
    jacobian[:] = expm(M[None, :, :] * τ[:, None, None])[:, :6, :]


def _variational(solver: EulerSolver, J, times, jacobian) -> None:
    """The variational equations integrated along the exact motion (DOP853, rtol 1e-12),
    forwards and backwards from t0: the separatrix and states within mc < 2⁻¹²⁸ of it."""
    from scipy.integrate import solve_ivp

    t0 = solver.t0

    def rhs(t, z):
        M = _variational_matrix(J, solver.angular_momentum(float(t)))
        return (M @ z.reshape(9, 9)).ravel()

    for side in (times >= t0, times < t0):
        if not np.any(side):
            continue
        targets = times[side]
        end = targets.max() if targets[0] >= t0 else targets.min()
        order = np.argsort(targets) if end >= t0 else np.argsort(-targets)
        if end == t0:
            jacobian[np.flatnonzero(side)] = np.eye(9)[:6]
            continue
        solution = solve_ivp(
            rhs,
            (t0, end),
            np.eye(9).ravel(),
            method="DOP853",
            t_eval=targets[order],
            rtol=1e-12,
            atol=1e-14,
        )
        if not solution.success:  # pragma: no cover
            raise InputError(f"the variational equations failed: {solution.message}")
        values = solution.y.T.reshape(-1, 9, 9)[:, :6, :]
        jacobian[np.flatnonzero(side)[order]] = values
