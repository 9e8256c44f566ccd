"""Every case of the test set, started from the linear (SVD) guess, converges to the
truth that generated the telemetry (the exact solver, with noise): within 5 of its
stated σ, with a reduced χ² near 1.  The cases: the bodies of tests/fit_cases.py, both
sides of the separatrix, quaternions alone, gyro with sparse fixes, misaligned
principal axes, a known impulse (absolute moments, in body and inertial axes), and
attitude fixes days apart started from an earlier fit (the radar use)."""

import numpy as np
import pytest
from fit_cases import BODIES, Q0, Body, _separatrix_rate
from scipy.spatial.transform import Rotation

from attitude import AngularImpulse, EulerSolver, FitRefused, fit_spin_state


def _close(value, truth, sigma, k=5.0):
    value, truth, sigma = map(np.atleast_1d, (value, truth, sigma))
    assert np.all(np.abs(value - truth) <= k * sigma + 1e-15), (value, truth, sigma)


def _assert_fit(fit, body: Body):
    _close(fit.inertia_ratios[1:], body.ratios[1:], fit.inertia_ratios_sigma[1:])
    _close(fit.angular_velocity, body.ω0, fit.angular_velocity_sigma)
    assert 0.7 < fit.reduced_chi2 < 1.4
    assert fit.notes and any("linear guess" in note for note in fit.notes)


@pytest.mark.parametrize("name", sorted(BODIES))
def test_each_body_from_gyro_rates(name):
    body = BODIES[name]
    rng = np.random.default_rng(1)
    fit = fit_spin_state(body.times, angular_velocity=body.gyro(rng), gyro_sigma=body.gyro_sigma)
    _assert_fit(fit, body)
    assert fit.formula == body.solver.formula


@pytest.mark.parametrize("offset", [2e-3, -2e-3, 3e-4])
def test_both_sides_of_the_separatrix(offset):
    moments = np.array([100.0, 200.0, 260.0])
    body = Body(
        "near",
        moments,
        _separatrix_rate(moments, 0.02, 0.04, offset),
        np.arange(0.0, 2400.0, 2.0),
        1e-4,
    )
    rng = np.random.default_rng(2)
    fit = fit_spin_state(body.times, angular_velocity=body.gyro(rng), gyro_sigma=body.gyro_sigma)
    _assert_fit(fit, body)
    assert fit.formula == body.solver.formula  # the side of the separatrix is found


def test_quaternions_alone():
    body = BODIES["generic"]
    rng = np.random.default_rng(3)
    fit = fit_spin_state(body.times, quaternions=body.quaternions(rng), attitude_sigma=1e-4)
    _assert_fit(fit, body)
    _close((fit.attitude.inv() * Q0).as_rotvec(), 0.0, fit.attitude_sigma)


def test_gyro_with_sparse_star_tracker_fixes_and_estimated_noise():
    body = BODIES["separatrix"]
    rng = np.random.default_rng(4)
    q = np.full((body.times.size, 4), np.nan)
    q[::25] = body.quaternions(rng, body.times[::25])
    fit = fit_spin_state(
        body.times, angular_velocity=body.gyro(rng), quaternions=q, attitude_sigma=1e-4
    )
    _assert_fit(fit, body)
    assert fit.noise["gyro"]["source"].startswith("estimated")
    _close((fit.attitude.inv() * Q0).as_rotvec(), 0.0, fit.attitude_sigma)


def test_misaligned_principal_axes():
    """The principal axes 25° off the gyro's: the fit finds them (principal_axes=True)."""
    A = Rotation.from_rotvec(
        np.radians(25.0) * np.array([0.6, -0.3, 0.74]) / np.linalg.norm([0.6, -0.3, 0.74])
    )
    J = np.array([100.0, 200.0, 260.0])
    R = A.as_matrix()
    tensor = R @ np.diag(J) @ R.T
    ω0 = np.array([0.05, 0.02, 0.03])
    solver = EulerSolver(tensor, tensor @ ω0, Q0)
    t = np.arange(0.0, 900.0, 2.0)
    rng = np.random.default_rng(5)
    ω = solver.angular_velocity(t) + 1e-4 * rng.standard_normal((t.size, 3))
    fit = fit_spin_state(t, angular_velocity=ω, gyro_sigma=1e-4, principal_axes=True)
    _close(fit.inertia_ratios[1:], J[1:] / J[0], fit.inertia_ratios_sigma[1:])
    for k in range(3):  # each principal axis, up to its sign, against A's columns
        angle = np.arccos(min(1.0, abs(fit.principal_axes[k] @ R[:, k])))
        assert angle < 5.0 * np.max(fit.principal_axes_sigma) + 1e-9
    assert 0.7 < fit.reduced_chi2 < 1.4


@pytest.mark.parametrize("frame", ["body", "inertial"])
def test_a_known_impulse_shows_the_absolute_moments(frame):
    J = np.array([100.0, 200.0, 260.0])
    ω0 = np.array([0.05, 0.02, 0.03])
    t = np.arange(0.0, 900.0, 2.0)
    ΔH = np.array([3.0, -2.0, 1.5])
    first = EulerSolver(J, J * ω0, Q0)
    t_e = 401.0
    Q_e = first.attitude(t_e)
    m_after = first.angular_momentum(t_e) + (ΔH if frame == "body" else Q_e.inv().apply(ΔH))
    second = EulerSolver(J, m_after, Q_e, t0=t_e)
    before = t < t_e
    rng = np.random.default_rng(6)
    ω = np.where(before[:, None], first.angular_velocity(t), second.angular_velocity(t))
    ω = ω + 1e-4 * rng.standard_normal(ω.shape)
    q = None
    if frame == "inertial":
        R = Rotation.concatenate([first.attitude(t[before]), second.attitude(t[~before])])
        q = np.full((t.size, 4), np.nan)
        noisy = (R * Rotation.from_rotvec(1e-4 * rng.standard_normal((t.size, 3)))).as_quat(
            scalar_first=True
        )
        q[::5] = noisy[::5]
    fit = fit_spin_state(
        t,
        angular_velocity=ω,
        quaternions=q,
        gyro_sigma=1e-4,
        attitude_sigma=1e-4 if q is not None else None,
        impulses=[AngularImpulse(t_e, ΔH, frame)],
    )
    assert fit.absolute_moments
    _close(fit.principal_moments, J, fit.principal_moments_sigma)
    assert np.all(fit.principal_moments_sigma < 0.1 * J)
    _close(fit.angular_velocity, ω0, fit.angular_velocity_sigma)


def test_attitude_fixes_days_apart_from_an_earlier_fit():
    """The radar use: an hour of gyro rates, then attitude fixes every 3 hours over two
    days, fitted from the first fit (the fixes alone are too sparse for a linear guess).
    The long baseline pins the motion's two frequencies: the ratios sharpen, and the
    prediction's horizon grows by far more."""
    body = BODIES["generic"]
    rng = np.random.default_rng(8)
    hour = np.arange(0.0, 3600.0, 2.0)
    first = fit_spin_state(hour, angular_velocity=body.gyro(rng, hour), gyro_sigma=body.gyro_sigma)
    fixes = np.arange(0.0, 2 * 86400.0, 3 * 3600.0) + 3600.0
    times = np.concatenate([hour, fixes])
    ω = np.vstack([body.gyro(rng, hour), np.full((fixes.size, 3), np.nan)])
    q = np.vstack([np.full((hour.size, 4), np.nan), body.quaternions(rng, fixes)])
    fit = fit_spin_state(
        times,
        angular_velocity=ω,
        quaternions=q,
        gyro_sigma=body.gyro_sigma,
        attitude_sigma=1e-4,
        guess=first,
    )
    _close(fit.inertia_ratios[1:], body.ratios[1:], fit.inertia_ratios_sigma[1:])
    assert np.all(fit.inertia_ratios_sigma[1:] < 0.7 * first.inertia_ratios_sigma[1:])
    assert fit.horizon() > 20.0 * first.horizon()


def test_a_gyro_bias_is_estimated_when_asked():
    """A bias of 50 σ on each axis: without gyro_bias the motion is no rigid body's (refused,
    or residuals far above the noise); with it, the bias and the ratios come back."""
    body = BODIES["generic"]
    rng = np.random.default_rng(9)
    bias = 50.0 * body.gyro_sigma * np.array([1.0, -0.6, 0.4])
    ω = body.gyro(rng) + bias
    try:
        unbiased = fit_spin_state(body.times, angular_velocity=ω, gyro_sigma=body.gyro_sigma)
        assert unbiased.reduced_chi2 > 1.5
    except FitRefused:
        pass
    fit = fit_spin_state(body.times, angular_velocity=ω, gyro_sigma=body.gyro_sigma, gyro_bias=True)
    _close(fit.gyro_bias, bias, fit.gyro_bias_sigma)
    _assert_fit(fit, body)
