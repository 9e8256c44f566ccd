"""An independent reference for bodies with spinning wheels (gyrostats): nothing here
uses the package's code.

``integrate_gyrostat`` integrates, with scipy's DOP853 at tight tolerances, the
gyrostat's equations in body axes (P. C. Hughes, *Spacecraft Attitude Dynamics*, ch. 3)

    dM/dt = M × ω + τ(t, q, M),   ω = I⁻¹(M − h),   dq/dt = ½ q ⊗ (0, ω),

M the total angular momentum (body plus wheels), h the wheels' constant momentum
relative to the body, q scalar first, body → inertial.  With h = 0 these are Euler's
equations of the rigid body.
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp


def _rhs(t, y, tensor, inverse, h, torque):
    M = y[:3]
    q = y[3:]
    ω = inverse @ (M - h)
    dM = np.cross(M, ω) + (0.0 if torque is None else torque(t, q, M))
    w0, x, yy, z = q
    dq = 0.5 * np.array(
        [
            -x * ω[0] - yy * ω[1] - z * ω[2],
            w0 * ω[0] + yy * ω[2] - z * ω[1],
            w0 * ω[1] + z * ω[0] - x * ω[2],
            w0 * ω[2] + x * ω[1] - yy * ω[0],
        ]
    )
    return np.concatenate([dM, dq])


def integrate_gyrostat(inertia, M0, q0, h, t_eval, t0=0.0, torque=None, rtol=1e-13, atol=1e-15):
    """Total momentum M (N, 3) and quaternions (N, 4) at ``t_eval`` (≥ t0, increasing).

    ``inertia``: 3 moments along body axes or a 3×3 tensor; ``h``: the wheels' momentum
    (body axes); ``torque(t, q, M)``: an external torque in body axes, or None.
    """
    tensor = np.diag(inertia) if np.ndim(inertia) == 1 else np.asarray(inertia, dtype=float)
    inverse = np.linalg.inv(tensor)
    t_eval = np.asarray(t_eval, dtype=float)
    y0 = np.concatenate([np.asarray(M0, dtype=float), np.asarray(q0, dtype=float)])
    scale = max(np.linalg.norm(M0), np.linalg.norm(h), 1e-300)
    atol_vector = np.concatenate([np.full(3, atol * scale), np.full(4, atol)])
    sol = solve_ivp(
        _rhs,
        (t0, float(t_eval[-1])),
        y0,
        method="DOP853",
        t_eval=t_eval,
        rtol=rtol,
        atol=atol_vector,
        args=(tensor, inverse, np.asarray(h, dtype=float), torque),
    )
    assert sol.success, sol.message
    return sol.y[:3].T, sol.y[3:].T


def angle(qa, qb):
    """Rotation angles (rad) between quaternion stacks (..., 4), either sign."""
    qa = np.asarray(qa, dtype=float)
    qb = np.asarray(qb, dtype=float)
    qa = qa / np.linalg.norm(qa, axis=-1, keepdims=True)
    qb = qb / np.linalg.norm(qb, axis=-1, keepdims=True)
    diff = np.minimum(np.linalg.norm(qa - qb, axis=-1), np.linalg.norm(qa + qb, axis=-1))
    return 4.0 * np.arcsin(np.minimum(1.0, 0.5 * diff))
