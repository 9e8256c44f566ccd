"""scipy's DOP853 as a peer: Euler's equations and the quaternion kinematics.

What an analyst without a closed form writes: ``solve_ivp(method="DOP853")`` on the
state (body momentum m, scalar-first quaternion q body → inertial) with
    dm/dt = m × ω,    dq/dt = ½ q ⊗ (0, ω),    ω = m / I,
output at every sample through ``t_eval`` (dense output), the quaternion normalized
afterwards.  atol is rtol/100 of each component's scale (|m0| for m, 1 for q).
"""

from __future__ import annotations

import time

import numpy as np
from scipy.integrate import solve_ivp

from benchmarks.cases import Case, PeerRun, Setting

NAME = "scipy"


def availability() -> str | None:
    return None


def start() -> dict:
    begin = time.perf_counter()
    import scipy.integrate  # noqa: F401

    return {"import_s": time.perf_counter() - begin}


def settings() -> list[Setting]:
    return [
        Setting(NAME, "scipy DOP853 rtol 1e-6", {"rtol": 1e-6}),
        Setting(NAME, "scipy DOP853 rtol 1e-12", {"rtol": 1e-12}),
    ]


def euler_rhs(t: float, y: np.ndarray, inverse_inertia: np.ndarray) -> np.ndarray:
    """d/dt of (m, q): dm/dt = m × ω and dq/dt = ½ q ⊗ (0, ω), with ω = m · I⁻¹ (q scalar first)."""
    m = y[:3]
    w, x, yy, z = y[3:]
    o1, o2, o3 = m * inverse_inertia
    return np.array(
        [
            m[1] * o3 - m[2] * o2,
            m[2] * o1 - m[0] * o3,
            m[0] * o2 - m[1] * o1,
            0.5 * (-x * o1 - yy * o2 - z * o3),
            0.5 * (w * o1 + yy * o3 - z * o2),
            0.5 * (w * o2 + z * o1 - x * o3),
            0.5 * (w * o3 + x * o2 - yy * o1),
        ]
    )


def run(case: Case, setting: Setting, times: np.ndarray) -> PeerRun:
    rtol = float(setting.params["rtol"])
    inertia = np.asarray(case.inertia)
    begin = time.perf_counter()
    m0 = inertia * np.asarray(case.omega0)
    y0 = np.concatenate([m0, case.q0])
    scale = np.concatenate([np.full(3, np.linalg.norm(m0)), np.ones(4)])
    solution = solve_ivp(
        euler_rhs,
        (0.0, float(times[-1])),
        y0,
        method="DOP853",
        t_eval=times,
        rtol=rtol,
        atol=rtol * 1e-2 * scale,
        args=(1.0 / inertia,),
    )
    if not solution.success:
        raise RuntimeError(f"solve_ivp failed: {solution.message}")
    q = solution.y[3:].T
    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    omega = solution.y[:3].T / inertia
    wall = time.perf_counter() - begin
    q[q[:, 0] < 0] *= -1.0
    return PeerRun(q, omega, wall, {"nfev": int(solution.nfev)})
