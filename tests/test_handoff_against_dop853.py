"""The exact hand-off at a control loss, against DOP853 of Euler's and the gyrostat's
equations (tests/gyrostat_reference.py) started from the law's state.

At τ the law (nadir with zero-Doppler steering on a sun-synchronous orbit) gives R(τ)
and ω(τ); the free motion starts from R(τ) with the total momentum I ω(τ) + h:

1. locked wheels: the exact solver (EulerSolver) against DOP853 of Euler's equations
   with M = I ω + h, over an hour: to 1e-12 rad (measured 1.4e-14);
2. spinning wheels: the gyrostat (ω stays I⁻¹(M − h) = ω_law at τ: no jump of the
   rate) against DOP853 of the gyrostat's equations, at a step of 5 s: to 1e-11 rad
   (measured 2.1e-13);
3. the same hand-off through a scenario (``control_loss`` event): the trajectory after
   τ is the hand-off's motion, and before τ the law's; under the scenario's gravity
   gradient (a torqued segment, with or without the wheels' term) against DOP853 with
   the torque computed here;
4. ``hand_off_states`` for many τ at once equals the hand-off at each.
"""

import numpy as np
import pytest
from eo_orbit import EPOCH, ORBIT
from gyrostat_reference import angle, integrate_gyrostat
from scipy.spatial.transform import Rotation

from attitude import (
    EulerSolver,
    InitialState,
    NadirLaw,
    Scenario,
    Spacecraft,
    TorquedSolver,
    propagate,
)
from attitude.scenario.modes import ControlLoss, Wheels
from attitude.trajectory.handoff import hand_off, hand_off_at, hand_off_states

INERTIA = np.array([820.0, 1040.0, 610.0])
H = np.array([0.3, 2.0, -0.4])  # N m s, body axes
LAW = NadirLaw("zero_doppler")
TAUS = (1234.5, 4321.0)


@pytest.fixture(scope="module")
def bound():
    return LAW.bind(EPOCH, 0.0, 6000.0, ORBIT)


def _window(tau):
    return tau + np.array([0.0, 1.0, 77.7, 1200.0, 3600.0])


@pytest.mark.parametrize("tau", TAUS)
def test_locked_wheels_against_euler_equations(bound, tau):
    state = bound.state([tau])
    motion = hand_off_at(bound, tau, INERTIA, Wheels("locked", H))
    assert isinstance(motion, EulerSolver)
    M0 = INERTIA * state.angular_velocity[0] + H
    t = _window(tau)
    M_ref, q_ref = integrate_gyrostat(
        INERTIA, M0, state.attitude[0].as_quat(scalar_first=True), np.zeros(3), t, t0=tau
    )
    assert np.max(angle(motion.attitude_quaternion(t), q_ref)) < 1e-12  # measured 1.4e-14
    assert np.max(np.abs(motion.angular_momentum(t) - M_ref)) < 1e-12 * np.linalg.norm(M0)
    # At τ the attitude is the law's; the wheels' momentum has passed to the body.
    assert (
        angle(motion.attitude_quaternion(tau), state.attitude[0].as_quat(scalar_first=True)) < 1e-15
    )
    assert np.allclose(motion.angular_velocity(tau), state.angular_velocity[0] + H / INERTIA)


@pytest.mark.parametrize("tau", TAUS)
def test_spinning_wheels_against_gyrostat_equations(bound, tau):
    state = bound.state([tau])
    motion = hand_off_at(bound, tau, INERTIA, Wheels("spinning", H), step=5.0)
    assert isinstance(motion, TorquedSolver)
    M0 = INERTIA * state.angular_velocity[0] + H
    t = _window(tau)
    M_ref, q_ref = integrate_gyrostat(
        INERTIA, M0, state.attitude[0].as_quat(scalar_first=True), H, t, t0=tau
    )
    assert np.max(angle(motion.attitude_quaternion(t), q_ref)) < 1e-11  # measured 2.1e-13
    assert np.max(np.abs(motion.angular_momentum(t) - M_ref)) < 1e-11 * np.linalg.norm(M0)
    # No jump of the rate: the body keeps turning at the law's rate at τ.
    assert np.allclose(motion.angular_velocity(tau), state.angular_velocity[0], rtol=0, atol=1e-16)


def test_through_a_scenario(bound):
    tau = TAUS[0]
    scenario = Scenario(
        "hand-off",
        Spacecraft("eo", INERTIA),
        EPOCH,
        InitialState(law=LAW),
        [ControlLoss(tau, Wheels("spinning", H))],
        duration=tau + 3600.0,
        orbit=ORBIT,
    )
    trajectory = propagate(scenario)
    assert [s.solver.formula for s in trajectory.segments] == ["guided", "gyrostat"]
    before = np.linspace(0.0, tau - 1e-3, 50)
    law = bound.state(before)
    assert (
        np.max(
            angle(trajectory.attitude_quaternion(before), law.attitude.as_quat(scalar_first=True))
        )
        < 1e-15
    )
    assert np.allclose(
        trajectory.angular_velocity(before), law.angular_velocity, rtol=0, atol=1e-18
    )
    state = bound.state([tau])
    t = _window(tau)
    M0 = INERTIA * state.angular_velocity[0] + H
    M_ref, q_ref = integrate_gyrostat(
        INERTIA, M0, state.attitude[0].as_quat(scalar_first=True), H, t, t0=tau
    )
    # The step is chosen for the scenario's accuracy, 1e-6 rad by default.
    assert np.max(angle(trajectory.attitude_quaternion(t), q_ref)) < 1e-6
    assert np.max(np.abs(trajectory.angular_momentum(t) - M_ref)) < 1e-6 * np.linalg.norm(M0)
    # The kinetic energy column is the body's, ½ω·Iω, which the gyrostat keeps.
    energy = trajectory.kinetic_energy(t)
    assert np.max(np.abs(energy / energy[0] - 1.0)) < 1e-6


def test_many_failure_times_at_once(bound):
    taus = np.linspace(0.0, 6000.0, 7)
    attitudes, momenta = hand_off_states(bound.state(taus), INERTIA, Wheels("spinning", H))
    for k, tau in enumerate(taus):
        state = bound.state([tau])
        one = hand_off(
            state.attitude[0], state.angular_velocity[0], INERTIA, tau, Wheels("locked", H)
        )
        assert np.allclose(one.angular_momentum(tau), momenta[k], rtol=1e-15, atol=1e-15)
        assert angle(one.attitude_quaternion(tau), attitudes[k].as_quat(scalar_first=True)) < 1e-15


@pytest.mark.parametrize("case", ["locked", "spinning"])
def test_under_gravity_gradient_through_a_scenario(bound, case):
    """The scenario's torques act after the loss (a torqued segment, with or without the
    gyroscopic term): against DOP853 of the equations with the gravity-gradient torque,
    computed here from the orbit's positions."""
    from attitude import ScenarioTorques

    tau = TAUS[0]
    scenario = Scenario(
        "hand-off under gravity gradient",
        Spacecraft("eo", INERTIA),
        EPOCH,
        InitialState(law=LAW),
        [ControlLoss(tau, Wheels(case, H))],
        duration=tau + 3600.0,
        orbit=ORBIT,
        torques=ScenarioTorques(gravity_gradient=True, accuracy=1e-9),
    )
    trajectory = propagate(scenario)
    assert trajectory.segments[1].solver.formula == "torqued"
    mu = 3.986004418e14
    jd1, jd2 = float(EPOCH.tt.jd1), float(EPOCH.tt.jd2)

    def torque(t, q, M):
        r = ORBIT.state_tt(np.array([jd1]), np.array([jd2 + t / 86400.0]))[0][0]
        R = Rotation.from_quat(q / np.linalg.norm(q), scalar_first=True)
        u = R.inv().apply(r / np.linalg.norm(r))
        return 3.0 * mu / np.linalg.norm(r) ** 3 * np.cross(u, INERTIA * u)

    state = bound.state([tau])
    M0 = INERTIA * state.angular_velocity[0] + H
    t = _window(tau)
    h = H if case == "spinning" else np.zeros(3)
    _, q_ref = integrate_gyrostat(
        INERTIA, M0, state.attitude[0].as_quat(scalar_first=True), h, t, t0=tau, torque=torque
    )
    # The gravity gradient turns this slow body by degrees in the hour; the run's
    # accuracy, 1e-9 rad, holds against DOP853.
    free = propagate(scenario.with_torques(None))
    assert np.max(angle(free.attitude_quaternion(t), q_ref)) > 1e-3
    assert np.max(angle(trajectory.attitude_quaternion(t), q_ref)) < 1e-8
