"""The fitted motion predicted beyond the telemetry, against the truth that generated
it: over noise realisations, the attitude error at 3 and 10 arc lengths, measured in
its own predicted covariance (d² = δθᵀ P⁻¹ δθ, χ² with 3 degrees of freedom if the
stated uncertainty is right), has a mean of 3; and the prediction's 1σ grows from the
arc as the covariance says (``horizon`` where it reaches 10°)."""

import numpy as np
import pytest
from fit_cases import BODIES

from attitude import fit_spin_state


def _mahalanobis(realisations: int, seed: int) -> np.ndarray:
    body = BODIES["generic"]
    rng = np.random.default_rng(seed)
    arc = body.times[-1]
    later = np.array([3.0 * arc, 10.0 * arc])
    truth = body.solver.attitude(later)
    d2 = []
    for _ in range(realisations):
        q = np.full((body.times.size, 4), np.nan)
        q[::7] = body.quaternions(rng, body.times[::7])
        fit = fit_spin_state(
            body.times,
            angular_velocity=body.gyro(rng),
            quaternions=q,
            gyro_sigma=body.gyro_sigma,
            attitude_sigma=body.attitude_sigma,
        )
        _, predicted = fit.predict(later)
        P, _ = fit.prediction_covariance(later)
        δθ = (predicted.inv() * truth).as_rotvec()
        assert np.all(np.sqrt(np.linalg.eigvalsh(P)[:, -1]) < 0.05)  # linear regime
        d2.append(np.einsum("ni,nij,nj->n", δθ, np.linalg.inv(P), δθ))
    return np.array(d2)


def test_prediction_within_its_stated_uncertainty():
    d2 = _mahalanobis(30, seed=11)  # the mean of 30 χ²(3) is 3 ± 0.45
    assert np.all(np.abs(d2.mean(axis=0) - 3.0) < 1.4), d2.mean(axis=0)


@pytest.mark.slow
def test_prediction_within_its_stated_uncertainty_many():
    d2 = _mahalanobis(200, seed=12)  # 3 ± 0.17
    assert np.all(np.abs(d2.mean(axis=0) - 3.0) < 0.55), d2.mean(axis=0)


def test_horizon_is_where_the_uncertainty_reaches_ten_degrees():
    body = BODIES["generic"]
    rng = np.random.default_rng(13)
    fit = fit_spin_state(body.times, angular_velocity=body.gyro(rng), gyro_sigma=body.gyro_sigma)
    horizon = fit.horizon()
    assert body.times[-1] < horizon < np.inf
    before, _ = fit.envelope([0.9 * horizon])
    after, _ = fit.envelope([horizon])
    assert np.degrees(before[0]) < 10.0 <= np.degrees(after[0]) * (1 + 1e-3)
    assert fit.horizon(np.radians(1.0)) < horizon  # a smaller angle comes sooner
