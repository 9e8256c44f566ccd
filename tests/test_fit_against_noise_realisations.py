"""``fit_spin_state`` over 100 noise realisations per body, against the truth that
generated the telemetry (the exact solver): the estimates are unbiased (their mean
within 3 σ/√100 of the truth, σ the stated 1σ) and the stated 1σ matches the scatter
of the estimates within 20 %.  The bodies of tests/fit_cases.py: generic, near the
separatrix (mc = 1e-3), nearly symmetric, a slow tumbler with gaps; and gyro with
star-tracker fixes, for the attitude.  The generic body runs by default; the others
are ``slow``."""

import numpy as np
import pytest
from fit_cases import BODIES, Q0
from scipy.spatial.transform import Rotation

from attitude import fit_spin_state

REALISATIONS = 100


def _estimates(body, attitude: bool, seed: int = 0):
    rng = np.random.default_rng(seed)
    values, sigmas = [], []
    for _ in range(REALISATIONS):
        ω = body.gyro(rng)
        q = None
        if attitude:
            q = np.full((body.times.size, 4), np.nan)
            q[::5] = body.quaternions(rng, body.times[::5])
        fit = fit_spin_state(
            body.times,
            angular_velocity=ω,
            quaternions=q,
            gyro_sigma=body.gyro_sigma,
            attitude_sigma=body.attitude_sigma if attitude else None,
        )
        row = [*fit.inertia_ratios[1:], *fit.angular_velocity]
        σ = [*fit.inertia_ratios_sigma[1:], *fit.angular_velocity_sigma]
        if attitude:
            row += list((fit.attitude.inv() * Q0).as_rotvec())  # Q_true = Q_fit exp(δθ)
            σ += list(fit.attitude_sigma)
        values.append(row)
        sigmas.append(σ)
    return np.array(values), np.array(sigmas)


def _check(body, attitude: bool) -> None:
    values, sigmas = _estimates(body, attitude)
    truth = [*body.ratios[1:], *body.ω0] + ([0.0, 0.0, 0.0] if attitude else [])
    stated = np.sqrt(np.mean(sigmas**2, axis=0))
    bias = (values.mean(axis=0) - truth) / (stated / np.sqrt(REALISATIONS))
    scatter = values.std(axis=0, ddof=1) / stated
    assert np.all(np.abs(bias) < 3.0), f"{body.name}: bias / (σ/√N) = {bias}"
    assert np.all(np.abs(scatter - 1.0) < 0.2), f"{body.name}: scatter / σ = {scatter}"


def test_generic_body_unbiased_with_the_stated_sigma():
    _check(BODIES["generic"], attitude=False)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["separatrix", "symmetric", "slow_gaps"])
def test_each_body_unbiased_with_the_stated_sigma(name):
    _check(BODIES[name], attitude=False)


@pytest.mark.slow
def test_with_attitude_fixes_unbiased_with_the_stated_sigma():
    _check(BODIES["generic"], attitude=True)


def test_rotation_helper_convention():
    """The attitude error above is δθ with Q_true = Q_fit exp([δθ]×), as the fit's."""
    δ = np.array([1e-3, -2e-3, 5e-4])
    fitted = Q0 * Rotation.from_rotvec(-δ)
    np.testing.assert_allclose((fitted.inv() * Q0).as_rotvec(), δ, atol=1e-12)
