"""Independent references for the torqued solver: nothing here uses the package's code.

- ``integrate_dop853``: the full torqued equations, body axes, a full inertia tensor,

      dm/dt = m × I⁻¹m + τ(t, q, m),   dq/dt = ½ q ⊗ (0, I⁻¹m),

  with scipy's DOP853 at tight tolerances, restarted at the torque's breakpoints;
  q scalar first, body → inertial.
- ``circular_orbit``: a Keplerian circular orbit, position (m) as a function of time.
- ``gravity_gradient``: τ = 3μ/r³ r̂_b × (I r̂_b), with r̂_b computed here from q.
- ``lvlh_attitude``: the local-vertical local-horizontal frame of the circular orbit.
- ``angle``: rotation angle between quaternion stacks.
"""

from __future__ import annotations

import itertools

import numpy as np
from scipy.integrate import solve_ivp

MU = 3.986004418e14  # m³/s², IERS 2010


def matrix_body_to_inertial(q):
    w, x, y, z = np.asarray(q, dtype=float) / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


class circular_orbit:  # a callable position, named like one
    """r(t) = a (cos nt, sin nt, 0) turned by ``tilt`` (a 3×3 matrix), n = √(μ/a³)."""

    def __init__(self, radius_m, mu=MU, tilt=None):
        self.a = float(radius_m)
        self.mu = float(mu)
        self.n = np.sqrt(self.mu / self.a**3)
        self.tilt = np.eye(3) if tilt is None else np.asarray(tilt, dtype=float)

    @property
    def period(self):
        return 2 * np.pi / self.n

    @property
    def normal(self):
        return self.tilt @ np.array([0.0, 0.0, 1.0])

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        planar = self.a * np.stack([np.cos(self.n * t), np.sin(self.n * t), 0 * t], axis=-1)
        return planar @ self.tilt.T


def gravity_gradient(orbit, tensor):
    """τ_body(t, q, m) = 3μ/r³ r̂_b × (I r̂_b)."""
    tensor = np.asarray(tensor, dtype=float)

    def torque(t, q, m, t_mid=None):
        r = orbit(t)
        radius = np.linalg.norm(r)
        u = matrix_body_to_inertial(q).T @ (r / radius)
        return 3 * orbit.mu / radius**3 * np.cross(u, tensor @ u)

    return torque


def lvlh_attitude(orbit, t):
    """Body → inertial matrix of the LVLH frame at t: x along track, y = −normal, z nadir."""
    r = orbit(t)
    z = -r / np.linalg.norm(r)
    y = -orbit.normal
    return np.column_stack([np.cross(y, z), y, z])


def _rhs(t, y, tensor, inverse, torque, t_mid):
    m = y[:3]
    q = y[3:]
    ω = inverse @ m
    dm = np.cross(m, ω) + torque(t, q, m, t_mid)
    w0, x, yy, z = q
    dq = 0.5 * np.array(
        [
            -x * ω[0] - yy * ω[1] - z * ω[2],
            w0 * ω[0] + yy * ω[2] - z * ω[1],
            w0 * ω[1] + z * ω[0] - x * ω[2],
            w0 * ω[2] + x * ω[1] - yy * ω[0],
        ]
    )
    return np.concatenate([dm, dq])


def integrate_dop853(inertia, m0, q0, torque, t_eval, breakpoints=(), rtol=1e-13, atol=1e-15):
    """Body momentum (N, 3) and quaternions (N, 4) at ``t_eval`` (≥ 0, increasing) from t = 0.

    ``inertia``: 3 moments along body axes or a 3×3 tensor; ``torque(t, q, m, t_mid)``
    in body axes, where t_mid is the middle of the interval between breakpoints being
    integrated (a switched torque is on or off for the whole interval).  The
    integration restarts at each breakpoint, so no step straddles a discontinuity.
    """
    tensor = np.diag(inertia) if np.ndim(inertia) == 1 else np.asarray(inertia, dtype=float)
    inverse = np.linalg.inv(tensor)
    t_eval = np.asarray(t_eval, dtype=float)
    y = np.concatenate([np.asarray(m0, dtype=float), np.asarray(q0, dtype=float)])
    scale = max(np.linalg.norm(m0), 1e-300)
    atol_vector = np.concatenate([np.full(3, atol * scale), np.full(4, atol)])
    edges = [0.0, *sorted(b for b in breakpoints if 0.0 < b < t_eval[-1]), float(t_eval[-1])]
    out = np.empty((t_eval.size, 7))
    for start, end in itertools.pairwise(edges):
        inside = (t_eval >= start) & ((t_eval < end) | (end == edges[-1]))
        sol = solve_ivp(
            _rhs,
            (start, end),
            y,
            method="DOP853",
            t_eval=np.unique(np.concatenate([t_eval[inside], [end]])),
            rtol=rtol,
            atol=atol_vector,
            args=(tensor, inverse, torque, 0.5 * (start + end)),
        )
        assert sol.success, sol.message
        out[inside] = sol.y[:, : np.count_nonzero(inside)].T
        y = sol.y[:, -1]
    return out[:, :3], out[:, 3:]


def angle(qa, qb):
    """Rotation angles (rad) between quaternions (..., 4), either sign."""
    qa = np.asarray(qa, dtype=float)
    qb = np.asarray(qb, dtype=float)
    qa = qa / np.linalg.norm(qa, axis=-1, keepdims=True)
    qb = qb / np.linalg.norm(qb, axis=-1, keepdims=True)
    diff = np.minimum(np.linalg.norm(qa - qb, axis=-1), np.linalg.norm(qa + qb, axis=-1))
    return 4.0 * np.arcsin(np.minimum(1.0, 0.5 * diff))
