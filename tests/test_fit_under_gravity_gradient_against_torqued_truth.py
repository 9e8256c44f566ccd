"""A fit through the splitting, against telemetry made by ``TorquedSolver`` at a fine
step (5 s, against the fit's 20 s): a tumbler on a 7000 km orbit under gravity
gradient.  The fit that models the gradient recovers the ratios, the rate and the
attitude within its stated σ with residuals at the noise; only the ratios are
observable (the gradient scales with the inertia), and it says so."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from attitude import (
    FitRefused,
    GravityGradient,
    ScenarioTorques,
    TorquedSolver,
    fit_spin_state,
)
from attitude.environment.keplerian import KeplerianOrbit
from attitude.environment.timescales import as_time, time_from_tt_seconds

MU = 3.986004418e14


@pytest.fixture(scope="module")
def setup():
    epoch = as_time("2027-03-01T00:00:00")
    orbit = KeplerianOrbit(
        epoch=epoch,
        semi_major_axis_m=7.0e6,
        eccentricity=0.0,
        inclination=np.radians(51.6),
        raan=0.0,
        argument_of_perigee=0.0,
        mean_anomaly=0.0,
    )
    J = np.array([100.0, 200.0, 260.0])
    ω0 = np.array([0.02, 0.01, 0.015])
    Q0 = Rotation.from_rotvec([0.3, -0.2, 0.5])
    truth = TorquedSolver(J, J * ω0, Q0, torques=[GravityGradient(orbit, epoch=epoch)], step=5.0)
    t = np.arange(0.0, 1500.0, 3.0)
    rng = np.random.default_rng(51)
    ω = truth.angular_velocity(t) + 2e-5 * rng.standard_normal((t.size, 3))
    q = np.full((t.size, 4), np.nan)
    fixes = truth.attitude(t[::5]) * Rotation.from_rotvec(
        1e-4 * rng.standard_normal((t[::5].size, 3))
    )
    q[::5] = fixes.as_quat(scalar_first=True)
    return epoch, orbit, J, ω0, Q0, time_from_tt_seconds(epoch, t), ω, q


def test_the_fit_through_the_splitting_recovers_the_truth(setup):
    _, orbit, J, ω0, Q0, times, ω, q = setup
    torques = ScenarioTorques(gravity_gradient=orbit, step=20.0)
    fit = fit_spin_state(
        times,
        angular_velocity=ω,
        quaternions=q,
        gyro_sigma=2e-5,
        attitude_sigma=1e-4,
        torques=torques,
    )
    assert np.all(np.abs(fit.inertia_ratios - J / J[0]) <= 4 * fit.inertia_ratios_sigma + 1e-12)
    assert np.all(np.abs(fit.angular_velocity - ω0) <= 4 * fit.angular_velocity_sigma)
    assert np.all(np.abs((fit.attitude.inv() * Q0).as_rotvec()) <= 4 * fit.attitude_sigma)
    assert 0.8 < fit.reduced_chi2 < 1.25
    assert not fit.absolute_moments
    assert any("gravity gradient scales with the inertia" in line for line in fit.observability)


def test_the_torque_free_fit_of_the_same_telemetry_is_off(setup):
    """Without the gradient the motion is not the telemetry's: refused, or biased."""
    _, _, J, _, _, times, ω, q = setup
    try:
        fit = fit_spin_state(
            times, angular_velocity=ω, quaternions=q, gyro_sigma=2e-5, attitude_sigma=1e-4
        )
    except FitRefused:
        return
    assert fit.reduced_chi2 > 1.5 or np.any(
        np.abs(fit.inertia_ratios - J / J[0]) > 4 * fit.inertia_ratios_sigma + 1e-12
    )


def test_gravity_gradient_without_attitude_fixes_is_refused(setup):
    _, orbit, _, _, _, times, ω, _ = setup
    with pytest.raises(Exception, match="needs attitude fixes"):
        fit_spin_state(
            times,
            angular_velocity=ω,
            gyro_sigma=2e-5,
            torques=ScenarioTorques(gravity_gradient=orbit, step=20.0),
        )
