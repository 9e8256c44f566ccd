"""Bad input to EulerSolver gets a clear InputError naming the field and the value."""

import re

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


@pytest.mark.parametrize("t", [1e300, -1.7e308, [0.0, 1.0, 1e305]])
def test_times_whose_angles_leave_the_float_range_are_named(t):
    """A fast spinner at t = 1e300 s: λ(t − t0) overflows; an InputError, not a NaN."""
    solver = EulerSolver([100.0, 200.0, 300.0], [1e202, 2e202, 0.0])
    bad = float(np.ravel(t)[np.argmax(np.abs(np.ravel(t)))])
    message = re.escape(f"t = {bad!r} s is too far from t0 = 0.0 s")
    for method in (
        solver.angular_momentum,
        solver.angular_velocity,
        solver.attitude,
        solver.attitude_quaternion,
    ):
        with pytest.raises(InputError, match=message):
            method(t)
    with pytest.raises(InputError, match=r"t_end = 1e\+300 s is too far from t0"):
        solver.flip_count(0.0, 1e300)


def test_subnormal_rates_give_finite_attitudes():
    """λ subnormal (|m| ~ 1e-310 on unit moments): finite unit quaternions at any time.

    At |m| = 5e-324 nothing turns by a representable angle before t = 1e308 s; at
    1e-310 the body has turned by about 0.01 rad at t = −1e308 s.
    """
    for m0 in ([5e-324, 5e-324, 5e-324], [1e-310, 1e-310, 1e-310]):
        solver = EulerSolver(GOOD_I, m0)
        q = solver.attitude_quaternion([0.0, 1.0, 1e300, -1e308])
        assert np.all(np.isfinite(q))
        np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, rtol=1e-15)
        assert q[3, 0] > 0.9999


def test_flip_times_refuses_a_span_that_would_not_fit_and_flip_count_counts_it():
    """A tumbler over (0, 1e12) s flips 3.6e10 times: 271 GiB of times, refused by count."""
    solver = EulerSolver.from_angular_velocity([100.0, 200.0, 300.0], [1e-3, 1.0, 1e-3])
    count = solver.flip_count(0.0, 1e12)
    assert count == pytest.approx(1e12 / (0.5 * solver.period), abs=1)
    with pytest.raises(InputError, match=rf"flips {count} times in this span \(271 GiB"):
        solver.flip_times(0.0, 1e12)
    assert solver.flip_times(0.0, 1e6, limit=10**6).size == solver.flip_count(0.0, 1e6)


def test_flip_times_of_a_spin_beyond_any_span_is_refused_not_a_raw_error():
    """[1e200, 1e200, 0] rad/s (issue 8): 2e203 flips in 1e4 s, named as a count."""
    solver = EulerSolver.from_angular_velocity([100.0, 200.0, 300.0], [1e200, 1e200, 0.0])
    assert solver.flip_count(0.0, 1e4) > 10**203
    with pytest.raises(InputError, match=r"flips 2.\d+e\+203 times in this span"):
        solver.flip_times(0.0, 1e4)


@pytest.mark.parametrize(
    "inertia, m0",
    [
        ([1.0, 2.0, 3.0], [1e-154, 1.0, 1e-154]),  # refused before (mc below 1e-300)
        ([1.0, 2.0, 2.25], "round trip"),  # the output of a separatrix state
    ],
)
def test_states_next_to_the_separatrix_are_accepted(inertia, m0):
    if m0 == "round trip":
        m0 = EulerSolver(inertia, [1.0, 1e150, 3.0]).angular_momentum(0.0)
    solver = EulerSolver(inertia, m0)
    assert solver.formula == "i" and 0.0 < solver.mc < 1e-300
    assert np.isfinite(solver.period)


def test_an_energy_beyond_the_float_range_is_named_not_inf():
    """|m| = 1.4e200 on unit moments: the motion is computed, T (~1e400 J) is refused."""
    solver = EulerSolver(GOOD_I, [1e200, 1e200, 0.0])
    assert np.all(np.isfinite(solver.angular_momentum([0.0, 1e-200])))
    with pytest.raises(InputError, match=r"kinetic energy .* about 1e400 J, is beyond the float"):
        solver.kinetic_energy  # noqa: B018
