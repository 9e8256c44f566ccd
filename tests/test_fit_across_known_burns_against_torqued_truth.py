"""The fit across known burns, against telemetry made by ``TorquedSolver`` (the
splitting at a 0.5 s step, within 3e-11 rad/s of its 0.05 s one): not the fit's own
model, which integrates the burn by DOP853 with its sensitivities
(attitude.estimation.burns).

The issue's case: a body-frame burn at 200–260 s of a 700 s gyro arc gave numpy
overflow warnings and ``inertia must be finite, got inf`` (the start's scale was 1 kg m²
whatever the burn), and a burn at 20–80 s took 53 s of CPU (forward differences of a
propagated scenario).  Now each fits in the time class of a torque-free fit, with the
absolute moments within their stated σ; the model's Jacobian through the burns is
checked against central differences of the model itself."""

import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from attitude import Burn, ConstantTorque, ScenarioTorques, TorquedSolver, fit_spin_state
from attitude.environment.timescales import as_time, time_from_tt_seconds
from attitude.estimation.burns import known_burns
from attitude.estimation.model import ExactModel, Impulse, Layout

J = np.array([100.0, 200.0, 260.0])
ω0 = np.array([0.05, 0.02, 0.03])
Q0 = Rotation.from_rotvec([0.3, -0.2, 0.5])
EPOCH = as_time("2027-03-01T00:00:00")
BODY_TORQUE = np.array([0.3, -0.2, 0.25])  # N m: 18 N m s over 60 s, the rates tripled


def _truth(torques, step=0.5):
    return TorquedSolver(J, J * ω0, Q0, torques=torques, step=step)


@pytest.mark.parametrize("start", [200.0, 20.0, 600.0])
def test_a_body_burn_in_the_arc_gives_the_absolute_moments(start):
    truth = _truth([ConstantTorque(BODY_TORQUE, start, start + 60.0, "body")])
    t = np.arange(0.0, 700.0, 2.0)
    rng = np.random.default_rng(int(start))
    ω = truth.angular_velocity(t) + 1e-4 * rng.standard_normal((t.size, 3))
    burn = Burn(time_from_tt_seconds(EPOCH, start), 60.0, BODY_TORQUE, "body")
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)  # no overflow on the way
        fit = fit_spin_state(
            time_from_tt_seconds(EPOCH, t),
            angular_velocity=ω,
            gyro_sigma=1e-4,
            torques=ScenarioTorques(burns=(burn,)),
        )
    assert fit.absolute_moments
    assert np.all(np.abs(fit.principal_moments - J) <= 3.0 * fit.principal_moments_sigma)
    assert np.all(np.abs(fit.angular_velocity - ω0) <= 3.0 * fit.angular_velocity_sigma)
    assert 0.8 < fit.reduced_chi2 < 1.25
    # After the arc the prediction is the exact torque-free motion after the burn.
    later = np.array([800.0, 900.0])
    predicted, _ = fit.predict(later)
    σ_rate = fit.uncertainty(later)[1]
    assert np.all(np.abs(predicted - truth.angular_velocity(later)) <= 4.0 * σ_rate[:, None])


def test_body_and_inertial_burns_overlapping_with_misaligned_axes():
    """Two overlapping burns, one in body axes and one in ICRF axes, seen by a gyro and a
    star tracker whose axes are 4° off the principal ones: the moments, the axes and
    the attitude come back within their σ."""
    misalignment = Rotation.from_rotvec(np.radians([3.0, -2.0, 1.5]))  # principal -> sensor
    Γ_i = np.array([-0.1, 0.25, 0.15])
    truth = _truth(
        [
            ConstantTorque(BODY_TORQUE, 200.0, 260.0, "body"),
            ConstantTorque(Γ_i, 230.0, 300.0, "inertial"),
        ]
    )
    t = np.arange(0.0, 700.0, 2.0)
    rng = np.random.default_rng(7)
    ω = misalignment.apply(truth.angular_velocity(t)) + 1e-4 * rng.standard_normal((t.size, 3))
    noise = Rotation.from_rotvec(1e-4 * rng.standard_normal((t.size, 3)))
    q = np.full((t.size, 4), np.nan)
    fixes = truth.attitude(t[::5]) * misalignment.inv() * noise[::5]  # every 10 s
    q[::5] = fixes.as_quat(scalar_first=True)
    burns = (
        Burn(time_from_tt_seconds(EPOCH, 200.0), 60.0, misalignment.apply(BODY_TORQUE), "body"),
        Burn(230.0, 70.0, Γ_i, "inertial"),  # TT seconds after the first sample
    )
    fit = fit_spin_state(
        time_from_tt_seconds(EPOCH, t),
        angular_velocity=ω,
        quaternions=q,
        gyro_sigma=1e-4,
        attitude_sigma=1e-4,
        principal_axes=True,
        torques=ScenarioTorques(burns=burns),
    )
    assert np.all(np.abs(fit.principal_moments - J) <= 3.0 * fit.principal_moments_sigma)
    axes_error = Rotation.from_matrix(fit.principal_axes.T).inv() * misalignment
    assert axes_error.magnitude() <= 3.0 * np.linalg.norm(fit.principal_axes_sigma)
    attitude_error = (fit.attitude.inv() * Q0 * misalignment.inv()).as_rotvec()
    assert np.all(np.abs(attitude_error) <= 3.0 * fit.attitude_sigma)
    assert 0.8 < fit.reduced_chi2 < 1.25


def test_the_motion_across_burns_against_torqued_solver():
    """The model at the true parameters against the splitting at 0.2 s, within and
    after a body burn, an inertial one and an impulse: the same motion to 1e-8."""
    Γ_i = np.array([-0.1, 0.25, 0.15])
    truth = _truth(
        [
            ConstantTorque(BODY_TORQUE, 20.0, 80.0, "body"),
            ConstantTorque(Γ_i, 50.0, 110.0, "inertial"),
        ],
        step=0.2,
    )
    layout = Layout(attitude=True, scale=True, axes=False)
    burns = known_burns(
        (Burn(20.0, 60.0, BODY_TORQUE, "body"), Burn(50.0, 60.0, Γ_i, "inertial")), None
    )
    model, x = ExactModel(layout, (), burns).start(J, Rotation.identity(), ω0, Q0)
    t = np.linspace(0.0, 150.0, 61)
    rates, attitude = model.predict(x, t, t, jacobian=False)
    scale = np.max(np.abs(truth.angular_velocity(t)))
    np.testing.assert_allclose(rates.ω, truth.angular_velocity(t), rtol=0, atol=1e-8 * scale)
    assert np.max((attitude.attitude.inv() * truth.attitude(t)).magnitude()) < 1e-8


def test_the_sensitivities_across_burns_against_central_differences():
    """∂(rates, attitudes)/∂x through body and inertial burns, an impulse inside one,
    with the axes estimated (the torque's terms in the axes and the attitude), against
    central differences of the model's own predictions."""
    layout = Layout(attitude=True, scale=True, axes=True)
    burns = known_burns(
        (
            Burn(20.0, 60.0, BODY_TORQUE, "body"),
            Burn(50.0, 60.0, [-0.1, 0.25, 0.15], "inertial"),
        ),
        None,
    )
    impulses = (Impulse(65.0, np.array([2.0, -1.0, 0.5]), "inertial"),)
    axes = Rotation.from_rotvec([0.05, -0.03, 0.02])
    model, x = ExactModel(layout, impulses, burns).start(J, axes, ω0, Q0)
    x = x + 1e-2 * np.random.default_rng(3).standard_normal(x.size)  # off the references
    t = np.array([10.0, 30.0, 55.0, 64.0, 70.0, 90.0, 140.0])
    rates, attitude = model.predict(x, t, t, jacobian=True)
    h = 1e-6
    for k in range(x.size):
        step = np.zeros(x.size)
        step[k] = h
        r_plus, a_plus = model.predict(x + step, t, t, jacobian=False)
        r_minus, a_minus = model.predict(x - step, t, t, jacobian=False)
        dω = (r_plus.ω - r_minus.ω) / (2 * h)
        dθ = (a_minus.attitude.inv() * a_plus.attitude).as_rotvec() / (2 * h)
        size = max(np.max(np.abs(rates.dω)), 1e-300)
        np.testing.assert_allclose(rates.dω[:, :, k], dω, rtol=0, atol=1e-6 * size)
        # The attitude's: δθ is a right (body-axes) variation of the predicted attitude.
        θ_size = max(np.max(np.abs(attitude.dθ)), 1e-300)
        np.testing.assert_allclose(attitude.dθ[:, :, k], dθ, rtol=0, atol=1e-6 * θ_size)
