"""This package's exact solver as a peer: ``EulerSolver`` evaluated at every output time."""

from __future__ import annotations

import time

import numpy as np
from scipy.spatial.transform import Rotation

from benchmarks.cases import Case, PeerRun, Setting

NAME = "attitude"


def availability() -> str | None:
    """None: the package under test is always there."""
    return None


def start() -> dict:
    """One-time costs (the import of the package), reported apart from the runs."""
    begin = time.perf_counter()
    import attitude  # noqa: F401  (imported here to time it; cached by Python afterwards)

    return {"import_s": time.perf_counter() - begin}


def settings() -> list[Setting]:
    return [Setting(NAME, "attitude (closed form)")]


def run(case: Case, setting: Setting, times: np.ndarray) -> PeerRun:
    """Build the solver from the case's ω0 and q0, then the quaternion and ω at ``times``.

    The timed work is everything a user does to get the two arrays: construction,
    ``attitude_quaternion(t)`` and ``angular_velocity(t)``.
    """
    from attitude import EulerSolver

    begin = time.perf_counter()
    solver = EulerSolver.from_angular_velocity(
        case.inertia, case.omega0, Rotation.from_quat(case.q0, scalar_first=True)
    )
    q = solver.attitude_quaternion(times)
    omega = solver.angular_velocity(times)
    wall = time.perf_counter() - begin
    q[q[:, 0] < 0] *= -1.0
    return PeerRun(q, omega, wall, {"formula": solver.formula, "mc": solver.mc})
