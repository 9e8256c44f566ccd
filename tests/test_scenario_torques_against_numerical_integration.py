"""The example scenario under torques against DOP853, and its stated error estimates.

``scenarios/tumbler_gravity_gradient_burn.toml``: one orbit of a tumbler under gravity
gradient (a Keplerian circular orbit at 51.6°), a 5-minute inertial burn, and an
inertia change halfway through the burn.  The reference integrates Euler's equations
with the torques and the quaternion kinematics by DOP853 at rtol 1e-13
(``tests/torqued_reference.py``, which uses none of the package's code), restarted at
the burn's edges and at the event with the new inertia.

Measured: each segment's own error (from its start state) is 2.9e-7 and 1.5e-7 rad
against its estimate of 3.3e-7 and 8.9e-7; the run's error, the error at the event
carried on and grown by the tumble, 6.1e-6 rad against the run's estimate of 1.5e-5.
"""

from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation
from torqued_reference import (
    angle,
    circular_orbit,
    gravity_gradient,
    integrate_dop853,
    matrix_body_to_inertial,
)

from attitude.files.scenario_reader import load_scenario
from attitude.trajectory.trajectory import propagate

EXAMPLE = Path(__file__).parents[1] / "scenarios" / "tumbler_gravity_gradient_burn.toml"
ORBIT = circular_orbit(7.0e6, tilt=Rotation.from_euler("x", 51.6, degrees=True).as_matrix())
BURN = np.array([-0.02, -0.01, -0.03])  # N m, inertial, over [1800, 2100) s
EVENT_S = 1950.0


def _torque(moments, offset):
    """Gravity gradient and the inertial burn, body axes, for a run started at ``offset``."""
    gradient = gravity_gradient(ORBIT, np.diag(moments))

    def torque(t, q, m, t_mid=None):
        on = 1800.0 <= t_mid + offset < 2100.0
        burn = matrix_body_to_inertial(q).T @ BURN if on else 0.0
        return gradient(t + offset, q, m) + burn

    return torque


def test_the_example_and_its_error_estimates_against_dop853():
    loaded = load_scenario(EXAMPLE)
    trajectory = propagate(loaded.scenario)
    first, second = trajectory.segments
    # The scenario's orbit is the reference's circle (to 0.1 mm).
    t = np.array([0.0, 1000.0, 5000.0])
    r, _ = loaded.pointing.orbit.position_velocity(loaded.scenario.times(t))
    assert np.max(np.abs(r - ORBIT(t))) < 1e-4

    ta = np.linspace(0.0, EVENT_S, 131)[1:]
    tb = np.linspace(EVENT_S, loaded.scenario.stop_s, 261)[1:]
    state = loaded.scenario.initial_state
    m0 = np.diag([100.0, 200.0, 300.0]) @ state.angular_velocity
    ma, qa = integrate_dop853(
        [100.0, 200.0, 300.0],
        m0,
        state.attitude.as_quat(scalar_first=True),
        _torque([100.0, 200.0, 300.0], 0.0),
        ta,
        breakpoints=[1800.0],
    )
    new = [110.0, 230.0, 320.0]
    # After the event: from the reference's own state (the run), and from the
    # scenario's (the segment's own error).
    _, qb = integrate_dop853(new, ma[-1], qa[-1], _torque(new, EVENT_S), tb - EVENT_S, [150.0])
    own_m = second.state.angular_momentum
    own_q = second.state.attitude.as_quat(scalar_first=True)
    _, qc = integrate_dop853(new, own_m, own_q, _torque(new, EVENT_S), tb - EVENT_S, [150.0])

    error_first = np.max(angle(qa, trajectory.attitude_quaternion(ta)))
    error_second_own = np.max(angle(qc, trajectory.attitude_quaternion(tb)))
    error_run = max(error_first, np.max(angle(qb, trajectory.attitude_quaternion(tb))))
    for error, estimate in [
        (error_first, first.solver.error_estimate),
        (error_second_own, second.solver.error_estimate),
        (error_run, trajectory.error_estimate),
    ]:
        assert error <= 1.5 * estimate, (error, estimate)
        assert estimate <= 30.0 * error, (error, estimate)
    # The segments' estimates do not add up to the run's error: it grows after the event.
    assert error_run > 3.0 * (first.solver.error_estimate + second.solver.error_estimate)
