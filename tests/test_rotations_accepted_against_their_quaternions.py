"""An attitude goes in as a ``scipy.spatial.transform.Rotation`` wherever the public API
takes quaternions (the package returns Rotations everywhere): the fit's telemetry,
``advance``'s states and an AEM segment give, from the Rotation, what they give from its
scalar-first quaternions (the fit to a millionth of its σ: the Rotation's quaternions
are normalized again, to the last bit)."""

import numpy as np
import pytest
from fit_cases import BODIES
from scipy.spatial.transform import Rotation

from attitude import InputError, advance, fit_spin_state
from attitude.environment.timescales import as_time
from attitude.outputs.aem_writer import AemSegment


def test_the_fit_takes_the_star_tracker_as_rotations():
    body = BODIES["generic"]
    rng = np.random.default_rng(11)
    t = body.times[::4]
    ω = body.gyro(rng, t)
    q = body.quaternions(rng, t)
    common = {"angular_velocity": ω, "gyro_sigma": body.gyro_sigma, "attitude_sigma": 1e-4}
    from_quaternions = fit_spin_state(t, quaternions=q, **common)
    from_rotations = fit_spin_state(
        t, quaternions=Rotation.from_quat(q, scalar_first=True), **common
    )
    difference = from_rotations.parameter_values - from_quaternions.parameter_values
    assert np.all(np.abs(difference) <= 1e-6 * from_quaternions.parameter_sigma)
    with pytest.raises(InputError, match="one attitude per time"):
        fit_spin_state(t, quaternions=Rotation.from_quat(q[:10], scalar_first=True), **common)


def test_advance_takes_rotations():
    moments = np.array([100.0, 200.0, 260.0])
    m = moments * np.array([0.05, 0.02, 0.03])
    R = Rotation.from_rotvec([[0.3, -0.2, 0.5], [1.0, 2.0, -0.5]])
    q = R.as_quat(scalar_first=True)
    for given, quaternions in ((R[0], q[0]), (R, q)):
        m_r, q_r = advance(moments, m, given, 37.5)
        m_q, q_q = advance(moments, m, quaternions, 37.5)
        np.testing.assert_array_equal(m_r, m_q)
        np.testing.assert_array_equal(q_r, q_q)


def test_an_aem_segment_takes_rotations():
    times = as_time("2027-01-01T00:00:00") + np.arange(5.0) * 1.0 / 86400.0
    R = Rotation.from_rotvec(np.outer(np.arange(5.0), [0.0, 0.0, 0.1]))
    rates = np.tile([0.0, 0.0, 0.1], (5, 1))
    from_rotations = AemSegment(times, R, rates)
    from_quaternions = AemSegment(times, R.as_quat(scalar_first=True), rates)
    np.testing.assert_array_equal(
        from_rotations.quaternion_body_to_inertial_scalar_first,
        from_quaternions.quaternion_body_to_inertial_scalar_first,
    )
