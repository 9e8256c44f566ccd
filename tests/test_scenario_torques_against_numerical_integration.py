"""The example scenario under torques against DOP853: its error, its flips, its largest rate.

``scenarios/tumbler_gravity_gradient_burn.toml``: one orbit of a tumbler under gravity
gradient (a Keplerian circular orbit at 51.6°), a 5-minute inertial burn, and an
inertia change halfway through the burn, with ``accuracy = 1e-6 rad``.  The reference
integrates Euler's equations with the torques and the quaternion kinematics by DOP853
at rtol 1e-13 (``tests/torqued_reference.py``, which uses none of the package's code),
restarted at the burn's edges and at the event with the new inertia, sampled every
0.25 s.

- The run meets the accuracy it asks for: the step is chosen for the run's error, the
  error carried across the event and grown after it included (measured: 7.6e-8 rad,
  against the run's estimate of 3.9e-7 and the 1e-6 asked for).
- Its flips (the momentum crossing the intermediate axis while that axis swings
  beyond 45° of it) are the reference's, located on its samples, to a millisecond.
- Its largest body rate is the reference's, found on the motion, not on the grid.
"""

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from torqued_reference import (
    angle,
    circular_orbit,
    gravity_gradient,
    integrate_dop853,
    matrix_body_to_inertial,
)

from attitude.files.scenario_reader import load_scenario
from attitude.trajectory.motion import analyze, largest_rate_of
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


@pytest.fixture(scope="module")
def reference():
    """(scenario, trajectory, t, m, q): the run and DOP853's, every 0.25 s."""
    loaded = load_scenario(EXAMPLE)
    trajectory = propagate(loaded.scenario)
    # The scenario's orbit is the reference's circle (to 0.1 mm).
    t = np.array([0.0, 1000.0, 5000.0])
    r, _ = loaded.pointing.orbit.position_velocity(loaded.scenario.times(t))
    assert np.max(np.abs(r - ORBIT(t))) < 1e-4
    ta = np.arange(0.25, EVENT_S + 1e-9, 0.25)
    tb = np.arange(EVENT_S + 0.25, loaded.scenario.stop_s + 1e-9, 0.25)
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
    mb, qb = integrate_dop853(new, ma[-1], qa[-1], _torque(new, EVENT_S), tb - EVENT_S, [150.0])
    return (
        loaded.scenario,
        trajectory,
        np.concatenate([ta, tb]),
        np.concatenate([ma, mb]),
        np.concatenate([qa, qb]),
    )


def test_the_run_meets_the_accuracy_it_asks_for_against_dop853(reference):
    scenario, trajectory, t, _, q = reference
    accuracy = scenario.torques.accuracy_rad
    first, second = trajectory.segments
    error = angle(q, trajectory.attitude_quaternion(t))
    error_first = float(np.max(error[t <= EVENT_S]))
    error_run = float(np.max(error))
    estimate = trajectory.error_estimate
    assert error_run <= accuracy, (error_run, accuracy)
    assert estimate <= accuracy
    for found, stated in ((error_first, first.solver.error_estimate), (error_run, estimate)):
        assert found <= 1.5 * stated, (found, stated)
        assert stated <= 30.0 * found, (found, stated)
    # The run's error is the second segment's: carried across the event, then grown.
    assert second.solver.error_estimate == estimate


def _reference_flips(t, m):
    """Sign changes of the momentum's intermediate (y) component on the reference, where
    that axis swings beyond 45° of the momentum between the neighbouring crossings,
    by linear interpolation between samples."""
    y = m[:, 1]
    change = np.flatnonzero(np.signbit(y[1:]) != np.signbit(y[:-1]))
    times = t[change] - y[change] * (t[change + 1] - t[change]) / (y[change + 1] - y[change])
    ratio = np.abs(y) / np.linalg.norm(m, axis=1)
    bounds = np.concatenate([[0], change, [t.size - 1]])
    flips = []
    for k, at in enumerate(times):
        swing = max(
            ratio[bounds[k] : bounds[k + 1] + 1].max(),
            ratio[bounds[k + 1] : bounds[k + 2] + 1].max(),
        )
        if swing > np.sqrt(0.5):
            flips.append(at)
    return np.array(flips)


def test_flips_on_the_torqued_motion_against_dop853(reference):
    _, trajectory, t, m, _ = reference
    motion = analyze(trajectory)
    ours = np.concatenate([item.flip_times_s for item in motion])
    expected = _reference_flips(t, m)
    assert sum(item.flip_count for item in motion) == ours.size == expected.size > 10
    assert np.max(np.abs(ours - expected)) < 1e-3, np.abs(ours - expected)


def test_the_largest_rate_against_dop853(reference):
    _, trajectory, t, m, _ = reference
    moments = np.where(t[:, None] <= EVENT_S, [100.0, 200.0, 300.0], [110.0, 230.0, 320.0])
    rate = np.linalg.norm(m / moments, axis=1)
    k = int(np.argmax(rate))
    # A parabola through the largest sample and its neighbours: the reference's peak.
    a, b, c = rate[k - 1 : k + 2]
    shift = 0.5 * (a - c) / (a - 2.0 * b + c)
    peak = b - 0.25 * (a - c) * shift
    found = largest_rate_of(analyze(trajectory))
    assert found is not None
    assert abs(found[0] - peak) < 1e-9, (found[0], peak)
    assert abs(found[1] - (t[k] + shift * 0.25)) < 0.05, (found[1], t[k])
