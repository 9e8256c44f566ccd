"""Spinning wheels (a gyrostat) in TorquedSolver and propagate_batch, against DOP853 of
the gyrostat's equations (tests/gyrostat_reference.py, written apart from the package).

1. Without torques the splitting of the free flow and the exact gyroscopic rotation
   keeps its classical order: halving the step divides the error by 16 (order 4) and 4
   (Strang); at a practical step it agrees with DOP853 to 1e-8 rad after an hour.
2. |M| is kept to rounding by both flows, and the energy ½ω·Iω stays bounded.
3. A full inertia tensor (body axes not principal) and a batch of states with their
   own wheels (propagate_batch), against the same reference.
4. Under gravity gradient, each kick is G(w/2) T(w) G(w/2): the error falls at least
   as the second order the module states, and is small at a practical step.
5. No wheel momentum is the exact solver to rounding; order 6 is refused with wheels.
"""

import numpy as np
import pytest
from gyrostat_reference import angle, integrate_gyrostat
from scipy.spatial.transform import Rotation

from attitude import EulerSolver, GravityGradient, InputError, TorquedSolver, propagate_batch

INERTIA = np.array([120.0, 180.0, 210.0])
RATE = np.array([0.01, -0.02, 0.015])
WHEELS = np.array([0.0, 3.0, 1.0])  # |I⁻¹h| = 0.017 rad/s, as fast as the body turns
M0 = INERTIA * RATE + WHEELS
R0 = Rotation.from_rotvec([0.3, -0.2, 0.5])
TIMES = np.array([0.0, 13.7, 611.1, 1799.3, 3600.0])


@pytest.fixture(scope="module")
def reference():
    return integrate_gyrostat(INERTIA, M0, R0.as_quat(scalar_first=True), WHEELS, TIMES)


@pytest.mark.parametrize("order, ratio", [(4, 16.0), (2, 4.0)])
def test_convergence_order_without_torques(reference, order, ratio):
    _M_ref, q_ref = reference
    steps = (20.0, 10.0, 5.0) if order == 4 else (4.0, 2.0, 1.0)
    errors = []
    for step in steps:
        solver = TorquedSolver(
            INERTIA, M0, R0, 0.0, (), step=step, order=order, wheel_momentum=WHEELS
        )
        M, q = solver.states(TIMES)
        errors.append(np.max(angle(q, q_ref)))
        # The rate is the gyrostat's: I⁻¹(M − h).
        ω = solver.angular_velocity(TIMES)
        assert np.allclose(ω, (M - WHEELS) / INERTIA, rtol=0.0, atol=1e-15)
    measured = np.array(errors[:-1]) / np.array(errors[1:])
    # Measured: 16.2 and 16.0 (order 4); 4.0 and 4.0 (Strang).
    assert np.all(np.abs(np.log2(measured) - np.log2(ratio)) < 0.3), (errors, measured)


def test_practical_step_against_dop853(reference):
    M_ref, q_ref = reference
    # 0.08 rad of the body's turn a step: measured 4.2e-9 rad after an hour.
    solver = TorquedSolver(INERTIA, M0, R0, 0.0, (), step=2.5, wheel_momentum=WHEELS)
    M, q = solver.states(TIMES)
    assert np.max(angle(q, q_ref)) < 1e-8
    assert np.max(np.abs(M - M_ref)) < 1e-8 * np.linalg.norm(M0)


def test_momentum_norm_kept_and_energy_bounded():
    solver = TorquedSolver(INERTIA, M0, R0, 0.0, (), step=10.0, wheel_momentum=WHEELS)
    t = np.linspace(0.0, 86400.0, 2001)
    M = solver.angular_momentum(t)
    ω = solver.angular_velocity(t)
    norms = np.linalg.norm(M, axis=-1)
    # 8640 steps of 10 flows and 10 rotations: rounding only (measured 3.4e-13).
    assert np.max(np.abs(norms - np.linalg.norm(M0))) < 2e-12 * np.linalg.norm(M0)
    energy = 0.5 * np.sum(ω * ω * INERTIA, axis=-1)
    assert np.max(np.abs(energy / energy[0] - 1.0)) < 1e-6  # bounded, not drifting
    # The inertial momentum is kept too (no torque): R M.
    inertial = solver.attitude(t).apply(M)
    assert np.max(np.abs(inertial - inertial[0])) < 1e-11 * np.linalg.norm(M0)


def test_full_tensor_against_dop853():
    turn = Rotation.from_rotvec([0.4, -0.7, 0.2]).as_matrix()
    tensor = turn @ np.diag(INERTIA) @ turn.T
    M_start = tensor @ RATE + WHEELS
    M_ref, q_ref = integrate_gyrostat(tensor, M_start, R0.as_quat(scalar_first=True), WHEELS, TIMES)
    solver = TorquedSolver(tensor, M_start, R0, 0.0, (), step=2.5, wheel_momentum=WHEELS)
    M, q = solver.states(TIMES)
    assert np.max(angle(q, q_ref)) < 1e-8
    assert np.max(np.abs(M - M_ref)) < 1e-8 * np.linalg.norm(M_start)
    assert np.allclose(solver.wheel_momentum, WHEELS, rtol=0.0, atol=1e-15)


def test_batch_with_wheels_against_dop853():
    rng = np.random.default_rng(3)
    n = 5
    rates = rng.normal(0.0, 0.02, (n, 3))
    wheels = rng.normal(0.0, 2.0, (n, 3))
    attitudes = Rotation.from_rotvec(rng.normal(0.0, 1.0, (n, 3)))
    M = rates * INERTIA + wheels
    times = np.array([0.0, 97.3, 1200.0])
    M_out, q_out = propagate_batch(
        INERTIA, M, attitudes, 0.0, times, step=1.25, wheel_momentum=wheels
    )
    for k in range(n):
        M_ref, q_ref = integrate_gyrostat(
            INERTIA, M[k], attitudes[k].as_quat(scalar_first=True), wheels[k], times
        )
        # Up to 0.06 rad/s: measured 1.4e-9 rad after 1200 s at 1.25 s.
        assert np.max(angle(q_out[:, k], q_ref)) < 1e-8
        assert np.max(np.abs(M_out[:, k] - M_ref)) < 1e-8 * np.linalg.norm(M[k])


class _Orbit:
    """A circular 7000 km orbit, r(t) in metres."""

    mu = 3.986004418e14
    a = 7.0e6
    n = np.sqrt(mu / a**3)

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        c, s = np.cos(self.n * t), np.sin(self.n * t)
        return self.a * np.stack([c, 0.6 * s, 0.8 * s], axis=-1)


def _gravity_gradient_reference(orbit, inertia):
    tensor = np.diag(inertia)

    def torque(t, q, M):
        r = orbit(t)
        R = Rotation.from_quat(q / np.linalg.norm(q), scalar_first=True)
        u = R.inv().apply(r / np.linalg.norm(r))
        return 3.0 * orbit.mu / np.linalg.norm(r) ** 3 * np.cross(u, tensor @ u)

    return torque


def test_gravity_gradient_with_wheels_against_dop853():
    """Slowly turning body (1 mrad/s) with 0.5 N m s wheels under gravity gradient."""
    orbit = _Orbit()
    inertia = np.array([800.0, 1000.0, 600.0])
    wheels = np.array([0.0, 0.5, 0.1])
    M_start = inertia * np.array([2e-4, -1.1e-3, 3e-4]) + wheels
    times = np.array([0.0, 311.7, 2900.0, 5800.0])
    _M_ref, q_ref = integrate_gyrostat(
        inertia,
        M_start,
        R0.as_quat(scalar_first=True),
        wheels,
        times,
        torque=_gravity_gradient_reference(orbit, inertia),
    )
    errors = []
    for step in (40.0, 20.0, 10.0):
        solver = TorquedSolver(
            inertia,
            M_start,
            R0,
            0.0,
            [GravityGradient(orbit, mu=orbit.mu)],
            step=step,
            wheel_momentum=wheels,
        )
        errors.append(np.max(angle(solver.attitude_quaternion(times), q_ref)))
    measured = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all(measured > 3.5), (errors, measured)  # at least the stated second order
    assert errors[-1] < 1e-7, errors  # measured 3e-9 at 10 s


def test_no_wheel_momentum_is_the_exact_solver():
    exact = EulerSolver(INERTIA, INERTIA * RATE, R0)
    split = TorquedSolver(INERTIA, INERTIA * RATE, R0, 0.0, (), step=7.0, wheel_momentum=[0, 0, 0])
    t = np.linspace(0.0, 3600.0, 37)
    # 514 steps of the flows composed: their rounding only (measured 1.1e-12).
    assert np.max(angle(split.attitude_quaternion(t), exact.attitude_quaternion(t))) < 1e-11


def test_order_six_refused_with_wheels():
    with pytest.raises(InputError, match="spinning wheels allow order 2 or 4"):
        TorquedSolver(INERTIA, M0, R0, 0.0, (), step=5.0, order=6, wheel_momentum=WHEELS)
    with pytest.raises(InputError, match="spinning wheels allow order 2 or 4"):
        propagate_batch(INERTIA, M0[None], R0, 0.0, [1.0], order=6, wheel_momentum=WHEELS)
