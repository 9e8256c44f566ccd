"""Known burns in the fitted motion: constant torques over intervals, crossed by
integrating the motion together with its sensitivities.

A burn (``attitude.Burn``: a torque Γ constant in the body axes or in the inertial
axes, over [start, start + duration)) makes the motion leave the closed form: a
body-fixed torque on a triaxial body has no closed-form solution.  The fit's motion
(attitude.estimation.model) is therefore the exact torque-free solver between the
burns, and across each burn the equations of motion in the principal axes,

    ṁ = m × ω + g,   q̇ = ½ q ⊗ (0, ω),   ω = m / J,
    g = Aᵀ Γ (body burn, A the principal → body axes)  or  Rᵀ(q) Γ (inertial burn),

integrated by DOP853 (rtol 1e-10 on the state, ``RTOL``) together with the derivative
S = ∂(δθ, m)/∂x of the state with respect to the fit's parameters (the variational
equations of attitude.solver.sensitivities with the torque's own terms):

    δω  = δm / J − (m / J²) δJ,
    δθ̇  = δω − ω × δθ,
    δṁ  = δm × ω + m × δω + δg,   δg = g_b × δα' (body; δα' = J_r(α) δα)  or
                                   g × δθ (inertial: Rᵀ Γ seen from the perturbed attitude).

The Jacobian is then exact to the integration's tolerance (no finite differences), and
crossing a 60 s burn costs milliseconds: the fit under burns is in the time class of the
torque-free fit.  The integrator's error control is on the state alone (the
sensitivities only steer the least squares and give the covariance, to far better than
their own statistical error).

Overlapping burns add: the time line is cut at every start and stop, and the torques
on over each piece are summed (body and inertial apart), as
``attitude.torques.models.ConstantTorqueSchedule`` does.  A burn is on over
[start, stop), the rule of ``ConstantTorque``.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError

__all__ = ["RTOL", "BurnFlow", "KnownBurn", "burn_flow", "known_burns", "torque_pieces"]

# The integrator's relative tolerance on the state across a burn: 1e-10 of the rate is
# far below any gyro's noise, and of the attitude far below any star tracker's.
RTOL = 1e-10


@dataclass(frozen=True)
class KnownBurn:
    """A known constant torque over [start, stop) (s from the telemetry's t = 0), N m,
    in body axes (``frame="body"``) or ICRF axes (``"inertial"``)."""

    start: float
    stop: float
    torque: NDArray[np.float64]
    frame: str = "body"


def known_burns(burns: Any, epoch: Any) -> tuple[KnownBurn, ...]:
    """``attitude.Burn`` s (epoch a ``Time`` or ISO text, or TT seconds after
    ``epoch``, the telemetry's first sample) as ``KnownBurn`` s in seconds from t = 0."""
    from attitude.base.quantities import as_si_scalar
    from attitude.environment.timescales import as_time, tt_seconds

    out = []
    for k, burn in enumerate(burns or ()):
        start = burn.epoch
        if hasattr(start, "jd1") or isinstance(start, str):
            if epoch is None:
                raise InputError(
                    f"a burn's epoch ({start}) needs telemetry times as epochs too",
                    key=f"torques.burns[{k}].epoch",
                )
            at = as_time(start, epoch.scale, f"torques.burns[{k}].epoch")
            start_s = float(tt_seconds(at, epoch))
        else:
            start_s = as_si_scalar(start, "time", f"torques.burns[{k}].epoch")
        torque = np.asarray(burn.torque, dtype=np.float64)
        out.append(KnownBurn(start_s, start_s + float(burn.duration), torque, burn.frame))
    return tuple(out)


def torque_pieces(
    burns: tuple[KnownBurn, ...],
) -> list[tuple[float, float, NDArray[np.float64], NDArray[np.float64]]]:
    """The time line from t = 0 cut at every burn's start and stop: (a, b, Γ_body,
    Γ_inertial) for each piece [a, b) with a torque on (the sums of the burns on)."""
    edges = sorted({max(e, 0.0) for b in burns for e in (b.start, b.stop) if b.stop > 0.0})
    pieces = []
    for a, b in itertools.pairwise(edges):
        on = [burn for burn in burns if burn.start <= a < burn.stop]
        body = [x.torque for x in on if x.frame == "body"]
        inertial = [x.torque for x in on if x.frame != "body"]
        Γ_b = np.array([math.fsum(c) for c in zip(*body, strict=True)]) if body else np.zeros(3)
        Γ_i = (
            np.array([math.fsum(c) for c in zip(*inertial, strict=True)])
            if inertial
            else np.zeros(3)
        )
        if np.any(Γ_b != 0.0) or np.any(Γ_i != 0.0):
            pieces.append((a, b, Γ_b, Γ_i))
    return pieces


@dataclass
class BurnFlow:
    """The motion across one piece of a burn: momentum (N, 3) and attitude (principal
    → ICRF) at the times asked, with ∂(δθ, m)/∂x (N, 6, n) when asked; and the same at
    the piece's end."""

    m: NDArray[np.float64]
    attitude: Rotation
    jacobian: NDArray[np.float64] | None
    m_end: NDArray[np.float64]
    attitude_end: Rotation
    jacobian_end: NDArray[np.float64] | None


def _rhs(J: NDArray[np.float64], g_b, g_i, G_α, dJ, n: int, jacobian: bool):
    """The right-hand side on y = (q (4, scalar first), m (3), S (6 × n) row-major).

    The variational equations are linear in S: Ṡ = M(t) S + F(t), with
    M = [[−[ω]×, diag(1/J)], [[g_i]×, −[ω]× + [m]× diag(1/J)]] ([g_i]× only for an
    inertial torque, g_i = Rᵀ Γ) and F = [[−(m/J²) dJ], [−[m]× (m/J²) dJ + G_α]]."""
    J1, J2, J3 = J
    gbx, gby, gbz = g_b
    gix, giy, giz = g_i
    inertial = bool(np.any(g_i != 0.0))
    inverse = np.diag(1.0 / J)
    M = np.zeros((6, 6))
    F = np.empty((6, n))

    def rhs(_t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        w, x, y_, z = y[0], y[1], y[2], y[3]
        m1, m2, m3 = y[4], y[5], y[6]
        o1, o2, o3 = m1 / J1, m2 / J2, m3 / J3
        out = np.empty_like(y)
        out[0] = 0.5 * (-x * o1 - y_ * o2 - z * o3)
        out[1] = 0.5 * (w * o1 + y_ * o3 - z * o2)
        out[2] = 0.5 * (w * o2 + z * o1 - x * o3)
        out[3] = 0.5 * (w * o3 + x * o2 - y_ * o1)
        if inertial:  # Rᵀ(q) Γ_i: v − 2w (u × v) + 2 u × (u × v), u = (x, y, z)
            cx, cy, cz = y_ * giz - z * giy, z * gix - x * giz, x * giy - y_ * gix
            h1 = gix - 2.0 * w * cx + 2.0 * (y_ * cz - z * cy)
            h2 = giy - 2.0 * w * cy + 2.0 * (z * cx - x * cz)
            h3 = giz - 2.0 * w * cz + 2.0 * (x * cy - y_ * cx)
        else:
            h1 = h2 = h3 = 0.0
        out[4] = m2 * o3 - m3 * o2 + gbx + h1
        out[5] = m3 * o1 - m1 * o3 + gby + h2
        out[6] = m1 * o2 - m2 * o1 + gbz + h3
        if jacobian:
            W = _skew(o1, o2, o3)
            Km = _skew(m1, m2, m3)
            M[0:3, 0:3] = -W
            M[0:3, 3:6] = inverse
            M[3:6, 3:6] = Km @ inverse - W
            if inertial:
                M[3:6, 0:3] = _skew(h1, h2, h3)
            δω_J = np.array([m1 / (J1 * J1), m2 / (J2 * J2), m3 / (J3 * J3)])[:, None] * dJ
            F[0:3] = -δω_J
            F[3:6] = G_α - Km @ δω_J
            out[7:] = (M @ y[7:].reshape(6, n) + F).ravel()
        return out

    return rhs


def _skew(a: float, b: float, c: float) -> NDArray[np.float64]:
    """[v]× for v = (a, b, c)."""
    return np.array([[0.0, -c, b], [c, 0.0, -a], [-b, a, 0.0]])


def burn_flow(
    J: NDArray[np.float64],
    m0: NDArray[np.float64],
    Q0: Rotation,
    S0: NDArray[np.float64] | None,
    dJ: NDArray[np.float64] | None,
    t0: float,
    t1: float,
    times: NDArray[np.float64],
    g_body: NDArray[np.float64],
    g_inertial: NDArray[np.float64],
    G_α: NDArray[np.float64] | None,
) -> BurnFlow:
    """The motion from (m0, Q0) at ``t0`` (principal axes; Q0 principal → ICRF) to ``t1``
    under the body torque ``g_body`` (principal axes) and the inertial torque
    ``g_inertial`` (ICRF), sampled at ``times`` (within [t0, t1]).  With ``S0`` (6 × n,
    ∂(δθ, m)/∂x at t0), ``dJ`` (3 × n, ∂J/∂x) and ``G_α`` (3 × n, ∂g_body/∂x: the axes'
    parameters), the sensitivities too (module docstring)."""
    jacobian = S0 is not None
    n = S0.shape[1] if S0 is not None else 0
    q0 = Q0.as_quat(scalar_first=True)
    y0 = np.concatenate([q0, m0, S0.ravel() if S0 is not None else []])
    span = max(t1 - t0, 0.0)
    size = max(
        float(np.linalg.norm(m0)),
        (float(np.linalg.norm(g_body)) + float(np.linalg.norm(g_inertial))) * span,
        1e-300,
    )
    # The sensitivities do not steer the step, only the state does (an infinite
    # tolerance); solve_ivp's error is an RMS over every component, hence the state's
    # tolerance scaled by √(7 / size) to stay RTOL on the state itself.
    narrowed = RTOL * math.sqrt(7.0 / y0.size)
    atol = np.full_like(y0, np.inf)
    atol[0:4] = narrowed
    atol[4:7] = narrowed * size
    # solve_ivp wants strictly increasing times: each distinct time once, and the end.
    targets, back = np.unique(np.clip(times, t0, t1), return_inverse=True)
    rhs = _rhs(
        J,
        g_body,
        g_inertial,
        G_α if G_α is not None else np.zeros((3, n)),
        dJ if dJ is not None else np.zeros((3, n)),
        n,
        jacobian,
    )
    t_eval = targets if targets.size and targets[-1] == t1 else np.append(targets, t1)
    if span == 0.0:
        values = np.repeat(y0[:, None], t_eval.size, axis=1)
    else:
        solution = solve_ivp(
            rhs, (t0, t1), y0, method="DOP853", t_eval=t_eval, rtol=narrowed, atol=atol
        )
        if not solution.success:
            raise InputError(f"the motion across the burn at t = {t0:.6g} s: {solution.message}")
        values = solution.y
    values = values.T
    at = values[back.ravel()]
    end = values[-1]
    q = at[:, 0:4] / np.linalg.norm(at[:, 0:4], axis=1)[:, None]
    q_end = end[0:4] / np.linalg.norm(end[0:4])
    return BurnFlow(
        m=at[:, 4:7],
        attitude=Rotation.from_quat(q, scalar_first=True),
        jacobian=at[:, 7:].reshape(-1, 6, n) if jacobian else None,
        m_end=end[4:7],
        attitude_end=Rotation.from_quat(q_end, scalar_first=True),
        jacobian_end=end[7:].reshape(6, n) if jacobian else None,
    )
