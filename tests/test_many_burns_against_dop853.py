"""Many constant torques (burns) against DOP853, at a cost that does not grow with them.

The solver gathers every ``ConstantTorque`` into one ``ConstantTorqueSchedule``: their
sum, piecewise constant between switches, found by bisection.  Against DOP853 at rtol
1e-13 (``tests/torqued_reference.py``, restarted at every switch), overlapping burns in
body and inertial axes give the same motion; and a kick evaluates one model for the
burns whatever their number (300 burns used to mean 300 torque evaluations a kick, and
2 × 300 more breakpoints to step through: a cost that grew as N²).
"""

import numpy as np
from scipy.spatial.transform import Rotation
from torqued_reference import angle, integrate_dop853, matrix_body_to_inertial

from attitude import ConstantTorque, TorquedSolver
from attitude.torques import models

INERTIA = np.array([100.0, 200.0, 300.0])
M0 = INERTIA * np.array([0.05, 0.02, 0.03])
Q0 = Rotation.from_euler("ZYX", [10.0, 20.0, 30.0], degrees=True)
BURNS = [  # (torque N m, start, stop, frame): two overlapping, both frames
    ([0.02, -0.01, 0.0], 10.0, 70.0, "body"),
    ([0.0, 0.015, -0.01], 40.0, 100.0, "inertial"),
    ([-0.01, 0.0, 0.02], 95.0, 96.5, "body"),
    ([0.005, 0.005, 0.005], 120.0, 180.0, "inertial"),
    ([0.0, 0.0, -0.03], 150.0, 151.0, "body"),
]


def _reference_torque(t, q, m, t_mid):
    """The burns on over the interval being integrated (t_mid), in body axes."""
    total = np.zeros(3)
    for torque, start, stop, frame in BURNS:
        if start <= t_mid < stop:
            torque = np.asarray(torque)
            total += torque if frame == "body" else matrix_body_to_inertial(q).T @ torque
    return total


def test_overlapping_burns_in_both_frames_against_dop853():
    torques = [ConstantTorque(*burn) for burn in BURNS]
    solver = TorquedSolver(INERTIA, M0, Q0, 0.0, torques, step=2.0)
    t = np.linspace(1.0, 240.0, 97)
    breakpoints = sorted({b for _, start, stop, _ in BURNS for b in (start, stop)})
    _, q = integrate_dop853(
        INERTIA, M0, Q0.as_quat(scalar_first=True), _reference_torque, t, breakpoints
    )
    assert np.max(angle(q, solver.attitude_quaternion(t))) < 1e-8


def test_a_kick_evaluates_the_burns_once_whatever_their_number(monkeypatch):
    calls = {"count": 0}
    for cls in (models.ConstantTorque, models.ConstantTorqueSchedule):
        original = cls.principal_torque

        def counted(self, *args, _original=original):
            calls["count"] += 1
            return _original(self, *args)

        monkeypatch.setattr(cls, "principal_torque", counted)
    burns = [ConstantTorque([0.0, 0.0, 1e-4], 5.0 * k, 5.0 * k + 1.0) for k in range(300)]
    solver = TorquedSolver(INERTIA, M0, Q0, 0.0, burns, step=20.0)
    solver.attitude_quaternion(1500.0)
    kicks = solver.steps_computed * len(solver.method.kicks)
    assert calls["count"] <= kicks, (calls["count"], kicks)  # one model, not 300
