"""Local minima: a plain least squares over the whole arc from a rough start (ratios
5 % off) lands in one, a cycle slip whose residuals are several times the noise; the
fit detects such minima by their residuals and recovers from the same start by
growing the arc; and where no start fits, it refuses rather than reports."""

import numpy as np
import pytest
from fit_cases import BODIES
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from attitude import EulerSolver, FitRefused, fit_spin_state
from attitude.estimation.model import ExactModel, Layout
from attitude.estimation.solve import RMS_LIMIT, Data, fit_from_starts, residuals

BODY = BODIES["generic"]
LONG = np.arange(0.0, 4000.0, 2.0)


def _rough_start():
    model = ExactModel(Layout(attitude=False, scale=False, axes=False))
    return model.start(
        BODY.moments * np.array([1.0, 1.05, 0.96]), Rotation.identity(), BODY.ω0, None
    )


def _data(rng):
    return Data(LONG, BODY.gyro(rng, LONG), np.full(3, BODY.gyro_sigma), None, None, None)


def test_plain_least_squares_from_a_rough_start_lands_in_a_local_minimum():
    rng = np.random.default_rng(21)
    data = _data(rng)
    model, x0 = _rough_start()
    result = least_squares(lambda x: residuals(model, x, data, False), x0, method="lm")
    rms = np.sqrt(np.mean(result.fun**2))
    assert rms > RMS_LIMIT  # not a fit, though the optimizer converged


def test_the_growing_arc_recovers_from_the_same_start():
    rng = np.random.default_rng(21)
    data = _data(rng)
    model, x0 = _rough_start()
    solution = fit_from_starts([(model, x0, "rough", 0.5 * BODY.solver.period)], data)
    assert solution.rms < 1.1
    J = solution.model.moments(solution.x)
    np.testing.assert_allclose(J / J[0], BODY.moments / BODY.moments[0], rtol=1e-3)


def test_a_motion_no_rigid_body_makes_is_refused():
    """Rates of one body for the first half, of another after (an unmodelled event):
    every start ends with residuals far above the noise, and nothing is reported."""
    rng = np.random.default_rng(22)
    other = EulerSolver(np.array([100.0, 150.0, 240.0]), np.array([100.0, 150.0, 240.0]) * BODY.ω0)
    half = BODY.times < 350.0
    ω = np.where(
        half[:, None], BODY.solver.angular_velocity(BODY.times), other.angular_velocity(BODY.times)
    )
    ω = ω + BODY.gyro_sigma * rng.standard_normal(ω.shape)
    with pytest.raises(FitRefused, match=r"local minimum|does not describe"):
        fit_spin_state(BODY.times, angular_velocity=ω, gyro_sigma=BODY.gyro_sigma)
