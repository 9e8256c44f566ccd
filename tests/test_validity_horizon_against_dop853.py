"""The validity horizon against DOP853: where the torqued motion and the torque-free one
part by the threshold, each integrated by scipy's DOP853 at tight tolerances.

The horizon runs its gravity gradient alongside on an interpolated orbit, by the
compiled splitting loop, over the whole span: the cases here go through all three on
an eccentric, inclined Keplerian orbit (its exact positions in the reference).  The
slow case's crossing lies beyond 20 000 steps of the run alongside, where an earlier
search stopped; its fast representative is the tumbler.  Also tested: the orbit's
interpolant against the orbit itself (its stated bound, ``ORBIT_TOLERANCE_M``), on that
orbit and on a TLE, and the compiled loop against the splitting's Python loop (the same
method: their states agree bit for bit here).
"""

import math

import numpy as np
import pytest
import torqued_reference as ref
from astropy.time import Time
from scipy.spatial.transform import Rotation

from attitude.environment.keplerian import KeplerianOrbit
from attitude.environment.orbit import TleOrbit
from attitude.environment.timescales import offline_time
from attitude.scenario.scenario import InitialState, Scenario
from attitude.scenario.spacecraft import Spacecraft
from attitude.torques import solver as torques_solver
from attitude.torques.models import GravityGradient
from attitude.torques.solver import TorquedSolver
from attitude.trajectory import horizon
from attitude.trajectory.horizon import (
    HORIZON_RELATIVE_ACCURACY,
    ORBIT_TOLERANCE_M,
    validity_horizon,
)
from attitude.trajectory.trajectory import propagate

EPOCH = "2027-03-01T00:00:00"
INERTIA = np.array([100.0, 200.0, 300.0])
R0 = Rotation.from_euler("ZYX", [10, 20, 30], degrees=True)
ORBIT = KeplerianOrbit(
    Time(EPOCH, scale="utc"),
    7.0e6,
    0.05,
    math.radians(40.0),
    math.radians(30.0),
    math.radians(60.0),
    mean_anomaly=0.0,
)
TLE = (
    "1 59001U 27042A   27171.50000000  .00000120  00000-0  18000-4 0  9999",
    "2 59001  98.2100 175.3000 0012000  95.0000 265.2000 14.57123456    14",
)


class _Positions:
    """The orbit's exact position at t (s after the epoch), for the reference torque."""

    mu = 3.986004418e14

    def __init__(self, orbit, epoch: str) -> None:
        with offline_time():
            tt = Time(epoch, scale="utc").tt
        self.orbit, self.jd1, self.jd2 = orbit, float(tt.jd1), float(tt.jd2)

    def __call__(self, t):
        t = np.atleast_1d(np.asarray(t, dtype=float))
        r, _ = self.orbit.state_tt(np.full(t.shape, self.jd1), self.jd2 + t / 86400.0)
        return r[0] if r.shape[0] == 1 else r


def _scenario(rate, duration: float) -> Scenario:
    state = InitialState(R0, angular_velocity=np.asarray(rate, dtype=float))
    return Scenario("h", Spacecraft("sat", INERTIA), EPOCH, state, [], duration=duration)


def _dop853_crossing(rate, end: float, sample: float) -> float:
    """The first time the two DOP853 runs part by 1°, linear between samples."""
    torque = ref.gravity_gradient(_Positions(ORBIT, EPOCH), np.diag(INERTIA))
    t = np.arange(sample, end, sample)
    m0, q0 = INERTIA * np.asarray(rate), R0.as_quat(scalar_first=True)
    _, torqued = ref.integrate_dop853(INERTIA, m0, q0, torque, t, rtol=1e-11)
    _, free = ref.integrate_dop853(INERTIA, m0, q0, lambda *_: np.zeros(3), t, rtol=1e-11)
    angle = ref.angle(torqued, free)
    k = int(np.flatnonzero(angle >= math.radians(1.0))[0])
    return t[k - 1] + (math.radians(1.0) - angle[k - 1]) / (angle[k] - angle[k - 1]) * sample


def test_a_tumblers_horizon_on_an_eccentric_orbit_against_dop853():
    rate = (0.05, 0.02, 0.03)
    found = validity_horizon(propagate(_scenario(rate, 3000.0)), ORBIT)
    crossing = _dop853_crossing(rate, 600.0, 0.1)
    assert 100.0 < crossing < 600.0 and found.within_span
    assert abs(found.horizon_s - crossing) < 0.01, (found.horizon_s, crossing)
    assert found.searched_s == found.horizon_s  # the search stops at the crossing


@pytest.mark.slow
def test_a_spinners_horizon_after_tens_of_thousands_of_steps_against_dop853():
    rate = (0.01, 0.02, 0.65)
    found = validity_horizon(propagate(_scenario(rate, 86400.0)), ORBIT)
    assert found.horizon_s / found.step_s > 15_000  # the run alongside went that far
    crossing = _dop853_crossing(rate, 33_000.0, 0.5)
    # The stated accuracy (1 %): the angle's wobble within a step of the run alongside
    # (the horizon samples it there, 0.3 of a turn apart) puts it 14 s late here,
    # 4.6e-4 of the horizon.
    assert abs(found.horizon_s - crossing) < HORIZON_RELATIVE_ACCURACY * crossing


def test_a_horizon_beyond_the_span_says_the_whole_span_was_searched():
    found = validity_horizon(propagate(_scenario((0.01, 0.02, 0.65), 3600.0)), ORBIT)
    assert not found.within_span and found.searched_s == 3600.0
    assert "over the whole span (3600 s)" in found.describe(lambda t: f"{t:g} s")


@pytest.mark.parametrize("orbit", [ORBIT, TleOrbit(*TLE)], ids=["keplerian", "tle"])
def test_the_interpolated_orbit_against_the_orbit(orbit):
    scenario = _scenario((0.0, 0.0, 0.1), 86400.0)
    position = horizon._interpolated(orbit, scenario)
    assert position is not orbit  # interpolated
    exact = _Positions(orbit, EPOCH)
    t = np.sort(np.random.default_rng(3).uniform(0.0, 86400.0, 20_000))
    assert np.max(np.linalg.norm(position(t) - exact(t), axis=-1)) <= ORBIT_TOLERANCE_M


def test_the_compiled_steps_against_the_python_steps(monkeypatch):
    circle = _Positions(ORBIT, EPOCH)
    t = np.linspace(0.0, 2000.0, 101)

    def run():
        solver = TorquedSolver(
            INERTIA, INERTIA * [0.05, 0.02, 0.3], R0, 0.0, [GravityGradient(circle)], step=3.0
        )
        return solver.states(t)

    monkeypatch.setattr(torques_solver, "PYTHON_LOOP_STEPS", 0)  # compiled from the start
    compiled = run()
    original = torques_solver._Engine.compiled_steps
    monkeypatch.setattr(torques_solver._Engine, "compiled_steps", lambda *a: 0)
    python = run()
    monkeypatch.setattr(torques_solver._Engine, "compiled_steps", original)
    np.testing.assert_array_equal(compiled[0], python[0])
    np.testing.assert_array_equal(compiled[1], python[1])
