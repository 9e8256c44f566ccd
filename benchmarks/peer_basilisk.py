"""Basilisk (pip ``bsk``) as a peer: one rigid hub, no gravity, no effectors.

A ``spacecraft.Spacecraft`` hub with ``IHubPntBc_B = diag(I)``, its centre of mass at
the body origin, ``sigma_BNInit`` and ``omega_BN_BInit`` from the case, run by one task
of one process; a recorder on ``scStateOutMsg`` samples every output step.

Integrators (what Basilisk does, checked on bsk 2.12.1):
- RK4 (``svIntegratorRK4``, the default) takes one fixed step per task update, so
  the task period *is* the step (0.1 s or 0.01 s); the recorder decimates to the
  output step.
- RKF78 (``svIntegratorRKF78``) adapts inside each task call, starting every call
  with a trial step equal to the task period; we set the task period to the output
  step.  Tolerances are ``relTol``/``absTol`` (defaults 1e-4/1e-8; the "1e-12"
  setting sets both to 1e-12), applied per state vector.

Conventions, converted here and checked by ``check_conventions`` on a known rotation:
``sigma_BN`` is the MRP of B relative to N; ``[BN] = MRP2C(sigma_BN)`` maps inertial
components to body components (v_B = [BN] v_N).  Our attitude is body → inertial,
i.e. [NB] = [BN]ᵀ, whose Hamilton quaternion is ((1 − |σ|²), 2σ)/(1 + |σ|²).
``omega_BN_B`` is in body axes, as ours.  Basilisk's time is an integer number of
nanoseconds (the output steps here are exact in it).
"""

from __future__ import annotations

import time

import numpy as np
from scipy.spatial.transform import Rotation

from benchmarks.cases import Case, PeerRun, Setting

NAME = "basilisk"


# ------------------------------------------------------------ conventions (numpy only)


def mrp_to_quaternion(sigma_BN: np.ndarray) -> np.ndarray:
    """MRP σ_BN (N, 3) → scalar-first quaternion of [NB] (body → inertial), w ≥ 0."""
    s = np.atleast_2d(np.asarray(sigma_BN, dtype=float))
    s2 = np.sum(s * s, axis=1, keepdims=True)
    q = np.hstack([(1.0 - s2), 2.0 * s]) / (1.0 + s2)
    q[q[:, 0] < 0] *= -1.0  # the shadow set gives −q: the same rotation
    return q


def quaternion_to_mrp(q: np.ndarray) -> np.ndarray:
    """Scalar-first quaternion body → inertial → σ_BN with |σ| ≤ 1 (Basilisk's initial state)."""
    q = np.asarray(q, dtype=float)
    q = q / np.linalg.norm(q)
    if q[0] < 0:
        q = -q
    return q[1:] / (1.0 + q[0])


def mrp_to_dcm_bn(sigma_BN: np.ndarray) -> np.ndarray:
    """[BN] from σ_BN (Schaub & Junkins 3.152): I + (8[σ×]² − 4(1 − σ²)[σ×])/(1 + σ²)².

    The same as Basilisk's ``RigidBodyKinematics.MRP2C``; maps N components to B components.
    """
    s = np.asarray(sigma_BN, dtype=float)
    s2 = float(s @ s)
    cross = np.array([[0.0, -s[2], s[1]], [s[2], 0.0, -s[0]], [-s[1], s[0], 0.0]])
    return np.eye(3) + (8.0 * cross @ cross - 4.0 * (1.0 - s2) * cross) / (1.0 + s2) ** 2


# ------------------------------------------------------------------ the peer


def availability() -> str | None:
    """None if Basilisk imports, else why not (it is an optional ``bench`` dependency)."""
    try:
        from Basilisk.simulation import spacecraft, svIntegrators  # noqa: F401
    except Exception as error:  # ImportError, or a broken binary wheel
        return f"bsk not installed ({type(error).__name__}: {error}); pip install 'attitude[bench]'"
    return None


def start() -> dict:
    begin = time.perf_counter()
    from Basilisk.simulation import spacecraft, svIntegrators  # noqa: F401
    from Basilisk.utilities import SimulationBaseClass, macros  # noqa: F401

    return {"import_s": time.perf_counter() - begin}


def settings() -> list[Setting]:
    return [
        Setting(NAME, "Basilisk RK4 0.1 s", {"integrator": "rk4", "step": 0.1}),
        Setting(NAME, "Basilisk RK4 0.01 s", {"integrator": "rk4", "step": 0.01}),
        Setting(NAME, "Basilisk RKF78 default tol", {"integrator": "rkf78"}),
        Setting(NAME, "Basilisk RKF78 tol 1e-12", {"integrator": "rkf78", "tol": 1e-12}),
    ]


def _simulate(
    inertia,
    omega0,
    sigma0,
    t_end: float,
    dt_out: float,
    integrator: str,
    step: float | None = None,
    tol: float | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Run the hub; (t, σ_BN, ω_BN_B) at every dt_out from 0 to t_end."""
    from Basilisk.simulation import spacecraft, svIntegrators
    from Basilisk.utilities import SimulationBaseClass, macros

    step_ns = macros.sec2nano(step if step is not None else dt_out)
    out_ns = macros.sec2nano(dt_out)
    if out_ns % step_ns:
        raise ValueError(f"the output step {dt_out} s is not a multiple of the step {step} s")
    sim = SimulationBaseClass.SimBaseClass()
    sim.SetProgressBar(False)
    process = sim.CreateNewProcess("dynamics")
    process.addTask(sim.CreateNewTask("task", step_ns))
    body = spacecraft.Spacecraft()
    body.ModelTag = "hub"
    body.hub.mHub = 1.0
    body.hub.r_BcB_B = [[0.0], [0.0], [0.0]]
    body.hub.IHubPntBc_B = np.diag(np.asarray(inertia, dtype=float)).tolist()
    body.hub.r_CN_NInit = [[0.0], [0.0], [0.0]]
    body.hub.v_CN_NInit = [[0.0], [0.0], [0.0]]
    body.hub.sigma_BNInit = [[float(x)] for x in sigma0]
    body.hub.omega_BN_BInit = [[float(x)] for x in omega0]
    integ = None
    if integrator == "rkf78":
        integ = svIntegrators.svIntegratorRKF78(body)
        if tol is not None:
            integ.relTol = float(tol)
            integ.absTol = float(tol)
        body.setIntegrator(integ)
    elif integrator != "rk4":
        raise ValueError(f"unknown integrator {integrator!r}")
    sim.AddModelToTask("task", body)
    recorder = body.scStateOutMsg.recorder(out_ns)
    sim.AddModelToTask("task", recorder)
    sim.InitializeSimulation()
    sim.ConfigureStopTime(macros.sec2nano(t_end))
    sim.ExecuteSimulation()
    t = np.asarray(recorder.times()) * macros.NANO2SEC
    sigma = np.array(recorder.sigma_BN, dtype=float)
    omega = np.array(recorder.omega_BN_B, dtype=float)
    del integ  # the SWIG integrator must outlive the run
    return t, sigma, omega


def run(case: Case, setting: Setting, times: np.ndarray) -> PeerRun:
    params = setting.params
    begin = time.perf_counter()
    t, sigma, omega = _simulate(
        case.inertia,
        case.omega0,
        quaternion_to_mrp(np.asarray(case.q0)),
        float(times[-1]),
        case.step,
        params["integrator"],
        params.get("step"),
        params.get("tol"),
    )
    q = mrp_to_quaternion(sigma)
    wall = time.perf_counter() - begin
    if len(t) != len(times) or np.max(np.abs(t - times)) > 1e-6:
        raise RuntimeError(f"Basilisk sampled {len(t)} times, expected {len(times)}")
    return PeerRun(q, omega, wall)


def check_conventions() -> dict:
    """Run Basilisk on two known rotations and measure the converted attitude's error.

    1. A spin of 0.1 rad/s about body z from σ = 0, for a quarter turn (RKF78 at
       1e-12): σ must be tan(π/8) ẑ, [BN] N_x = −y_B, and our quaternion the +90°
       turn about z.  2. The generic initial attitude of the cases with a spin about
       body x: q(t) = q0 ⊗ exp(x̂ ω t), which fails if q0 were given or read back as
       its inverse, or if ω were taken in inertial axes.
    """
    from Basilisk.utilities import RigidBodyKinematics

    from benchmarks.cases import CASES
    from benchmarks.reference import quaternion_angle

    w = 0.1
    quarter = (np.pi / 2) / w
    _, sigma, _ = _simulate(
        [100, 200, 300], [0, 0, w], [0, 0, 0], quarter, quarter, "rkf78", tol=1e-12
    )
    bn = np.asarray(RigidBodyKinematics.MRP2C(sigma[-1]))
    # Basilisk rounds 5π s to whole nanoseconds: the exact answer is at that time.
    t_ns = round(quarter * 1e9) / 1e9
    expected = Rotation.from_rotvec([0, 0, w * t_ns]).as_quat(scalar_first=True)
    quarter_error = float(quaternion_angle(mrp_to_quaternion(sigma[-1]), expected)[0])

    q0 = np.asarray(next(iter(CASES.values())).q0)
    _, sigma2, _ = _simulate(
        [100, 200, 300], [w, 0, 0], quaternion_to_mrp(q0), 7.0, 7.0, "rkf78", tol=1e-12
    )
    exact = Rotation.from_quat(q0, scalar_first=True) * Rotation.from_rotvec([w * 7.0, 0, 0])
    generic_error = float(
        quaternion_angle(mrp_to_quaternion(sigma2[-1]), exact.as_quat(scalar_first=True))[0]
    )
    return {
        "quarter_turn_sigma_BN": sigma[-1].tolist(),
        "quarter_turn_BN_times_Nx": (bn @ [1.0, 0.0, 0.0]).tolist(),
        "MRP2C_vs_ours_max_abs": float(np.max(np.abs(bn - mrp_to_dcm_bn(sigma[-1])))),
        "quarter_turn_error_rad": quarter_error,
        "generic_q0_spin_x_error_rad": generic_error,
        "passed": quarter_error < 1e-9 and generic_error < 1e-9,
    }
