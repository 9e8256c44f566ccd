"""Bad input to EulerSolver gets a clear InputError naming the field and the value."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from attitude import EulerSolver, InputError

GOOD_I = [1.0, 2.0, 3.0]
GOOD_M = [0.1, 0.2, 0.3]


@pytest.mark.parametrize(
    "inertia, message",
    [
        ([1.0, 0.0, 3.0], r"inertia: principal moments must be positive, got \[1.0, 0.0, 3.0\]"),
        ([1.0, -2.0, 3.0], r"must be positive, got \[1.0, -2.0, 3.0\]"),
        ([1.0, np.nan, 3.0], r"inertia must be finite, got nan at index 1"),
        ([1.0, 2.0, np.inf], r"inertia must be finite, got inf at index 2"),
        ([1.0, 2.0], r"inertia must be 3 principal moments or a 3x3 tensor, got shape \(2,\)"),
        ([[1.0, 2.0, 3.0]], r"inertia must be 3 principal moments or a 3x3 tensor, got shape"),
        ([[1, 0, 0], [0.5, 2, 0], [0, 0, 3]], r"inertia: tensor is not symmetric"),
        ([[1, 0, 0], [0, -2, 0], [0, 0, 3]], r"inertia: tensor is not positive definite"),
        ([[2, 3, 0], [3, 2, 0], [0, 0, 3]], r"tensor is not positive definite \(eigenvalues"),
        (["a", "b", "c"], r"inertia must be numeric"),
    ],
)
def test_bad_moments(inertia, message):
    with pytest.raises(InputError, match=message):
        EulerSolver(inertia, GOOD_M)


@pytest.mark.parametrize("m0", [[0.1, np.nan, 0.3], [np.inf, 0.0, 0.0], [-np.inf, 1.0, 1.0]])
def test_non_finite_momentum(m0):
    with pytest.raises(InputError, match="angular_momentum must be finite"):
        EulerSolver(GOOD_I, m0)


def test_non_finite_angular_velocity():
    with pytest.raises(InputError, match="angular_velocity must be finite, got nan at index 1"):
        EulerSolver.from_angular_velocity(GOOD_I, [0.1, np.nan, 0.3])


@pytest.mark.parametrize(
    "attitude, message",
    [
        (np.eye(3), "attitude must be a scipy.spatial.transform.Rotation"),
        ([1.0, 0.0, 0.0, 0.0], "attitude must be a scipy.spatial.transform.Rotation"),
        (
            Rotation.random(3, random_state=1),
            "attitude must be a single rotation, got a stack of 3",
        ),
    ],
)
def test_non_rotation_attitude(attitude, message):
    with pytest.raises(InputError, match=message):
        EulerSolver(GOOD_I, GOOD_M, attitude)


@pytest.mark.parametrize("t", [np.nan, np.inf, [0.0, 1.0, np.nan], [-np.inf]])
def test_non_finite_times(t):
    solver = EulerSolver(GOOD_I, GOOD_M)
    for method in (solver.angular_momentum, solver.angular_velocity, solver.attitude):
        with pytest.raises(InputError, match="t must be finite"):
            method(t)


def test_non_finite_epoch():
    with pytest.raises(InputError, match=r"t0 must be finite, got nan$"):
        EulerSolver(GOOD_I, GOOD_M, t0=np.nan)


def test_attitude_refuses_more_than_one_dimension_of_times():
    solver = EulerSolver(GOOD_I, GOOD_M)
    with pytest.raises(InputError, match=r"scalar or a 1-D array .* got shape \(2, 2\)"):
        solver.attitude(np.zeros((2, 2)))
    assert solver.angular_momentum(np.zeros((2, 2))).shape == (2, 2, 3)


def test_wrong_units_are_named():
    from astropy import units as u

    with pytest.raises(InputError, match="inertia has unit m, which cannot be converted to kg m2"):
        EulerSolver([1.0, 2.0, 3.0] * u.m, GOOD_M)
    with pytest.raises(InputError, match="t has unit kg"):
        EulerSolver(GOOD_I, GOOD_M).attitude(3.0 * u.kg)


def test_input_error_is_a_value_error():
    assert issubclass(InputError, ValueError)
