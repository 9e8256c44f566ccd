"""Symmetric tops: the textbook precession, in the body and in space.

Body frame (Landau & Lifshitz, Mechanics, §36; the two cases of Principia's
``ShortFatSymmetricTopPrecession`` and ``TallSkinnySymmetricTopPrecession``): the
momentum component across the symmetry axis turns about that axis at a constant
rate.  With Ω = m3 (I1 − I3)/(I1 I3) for the oblate top I = (3, 3, 9), m = (0, 5, 7),
    m(t) = (5 sin Ωt, 5 cos Ωt, 7),
and with Ω = m1 (I2 − I1)/(I1 I2) for the prolate top I = (3, 9, 9), m = (7, 0, 5),
    m(t) = (7, 5 sin Ωt, 5 cos Ωt).
(The transverse momentum turns at −Ω: anticlockwise about +e3 for the oblate top,
dm/dt = m × ω.)

Space frame: the symmetry axis circles the angular momentum H at the rate G/I⊥
(I⊥ the transverse moment), anticlockwise seen from the tip of H, at a constant
angle; checked against a DOP853 integration.
"""

import numpy as np
import pytest
from reference_models import integrate_dop853
from scipy.spatial.transform import Rotation

from attitude import EulerSolver

TIMES = np.arange(0.0, 5.0, 0.1)


def test_short_fat_symmetric_top_precession_in_the_body():
    inertia, m0 = (3.0, 3.0, 9.0), (0.0, 5.0, 7.0)
    Ω = m0[2] * (inertia[0] - inertia[2]) / (inertia[0] * inertia[2])
    solver = EulerSolver(inertia, m0)
    expected = np.stack(
        [5 * np.sin(Ω * TIMES), 5 * np.cos(Ω * TIMES), np.full_like(TIMES, 7.0)], -1
    )
    np.testing.assert_allclose(solver.angular_momentum(TIMES), expected, rtol=0, atol=1e-14 * 8.7)
    assert solver.period == pytest.approx(2 * np.pi / abs(Ω), rel=1e-15)


def test_tall_skinny_symmetric_top_precession_in_the_body():
    inertia, m0 = (3.0, 9.0, 9.0), (7.0, 0.0, 5.0)
    Ω = m0[0] * (inertia[1] - inertia[0]) / (inertia[0] * inertia[1])
    solver = EulerSolver(inertia, m0)
    expected = np.stack(
        [np.full_like(TIMES, 7.0), 5 * np.sin(Ω * TIMES), 5 * np.cos(Ω * TIMES)], -1
    )
    np.testing.assert_allclose(solver.angular_momentum(TIMES), expected, rtol=0, atol=1e-14 * 8.7)
    assert solver.period == pytest.approx(2 * np.pi / abs(Ω), rel=1e-15)


@pytest.mark.parametrize(
    "inertia, m0, axis, transverse",
    [((3.0, 3.0, 9.0), (0.0, 5.0, 7.0), 2, 3.0), ((3.0, 9.0, 9.0), (7.0, 0.0, 5.0), 0, 9.0)],
    ids=["oblate", "prolate"],
)
def test_symmetry_axis_circles_the_angular_momentum_anticlockwise(inertia, m0, axis, transverse):
    attitude0 = Rotation.from_euler("ZXZ", [0.4, 1.1, -0.3])
    solver = EulerSolver(inertia, m0, attitude0)
    t = np.linspace(0.0, 20.0, 801)
    e_axis = np.eye(3)[axis]
    figure_axis = solver.attitude(t).apply(e_axis)
    H = solver.inertial_angular_momentum
    G = np.linalg.norm(H)
    h = H / G

    # Constant cone angle, cos θ = m_axis / G.
    np.testing.assert_allclose(figure_axis @ h, m0[axis] / G, rtol=0, atol=1e-14)

    # Azimuth about h: increasing (anticlockwise about H) at the rate G/I⊥.
    u = np.cross(h, [1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(h, u)
    azimuth = np.unwrap(np.arctan2(figure_axis @ v, figure_axis @ u))
    np.testing.assert_allclose(azimuth - azimuth[0], G / transverse * t, rtol=0, atol=1e-12)

    # And the integrator agrees on the figure axis's motion.
    _, attitude_ref = integrate_dop853(inertia, m0, attitude0, t)
    figure_ref = attitude_ref.apply(e_axis)
    assert np.max(np.linalg.norm(figure_axis - figure_ref, axis=1)) <= 1e-10
