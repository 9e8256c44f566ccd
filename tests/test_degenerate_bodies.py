"""Degenerate and "uncomfortably exciting" bodies and states.

Spheres, symmetric tops, zero momentum, steady spins about each principal axis
(the intermediate one included), states a hair away from each of those, moments in
any order, magnitudes near underflow and overflow.  References: the exact motion
where it is elementary (a constant angular velocity), otherwise DOP853.
"""

import numpy as np
import pytest
from reference_models import integrate_dop853, integrate_mpmath
from scipy.spatial.transform import Rotation

from attitude import EulerSolver

ATTITUDE0 = Rotation.from_euler("XYZ", [0.3, -1.2, 2.5])
EPS = np.finfo(float).eps


def _constant_rate_attitude(ω, t):
    """Body angular velocity ω constant: Q(t) = Q0 ∘ exp(t ω)."""
    return ATTITUDE0 * Rotation.from_rotvec(np.outer(t, ω))


def _check_against_dop853(inertia, m0, span, tolerance=1e-10):
    solver = EulerSolver(inertia, m0, ATTITUDE0)
    t = np.linspace(0.0, span, 201)
    m_ref, attitude_ref = integrate_dop853(inertia, m0, ATTITUDE0, t)
    G = np.linalg.norm(m0)
    assert np.max(np.linalg.norm(solver.angular_momentum(t) - m_ref, axis=1)) <= tolerance * G
    assert np.max((solver.attitude(t).inv() * attitude_ref).magnitude()) <= tolerance


def test_sphere_rotation_along_random_axis():
    rng = np.random.default_rng(5)
    for _ in range(10):
        m0 = rng.normal(size=3) * 3
        solver = EulerSolver([2.5, 2.5, 2.5], m0, ATTITUDE0)
        assert solver.formula == "steady"
        t = np.linspace(-30, 30, 301)
        np.testing.assert_array_equal(solver.angular_momentum(t), np.tile(m0, (301, 1)))
        expected = _constant_rate_attitude(m0 / 2.5, t)
        assert np.max((solver.attitude(t).inv() * expected).magnitude()) <= 1e-13


def test_zero_angular_momentum_leaves_the_body_at_rest():
    solver = EulerSolver([1.0, 2.0, 3.0], [0.0, 0.0, 0.0], ATTITUDE0)
    assert solver.formula == "rest"
    t = np.linspace(-1e9, 1e9, 11)
    np.testing.assert_array_equal(solver.angular_momentum(t), np.zeros((11, 3)))
    assert np.max((solver.attitude(t).inv() * ATTITUDE0).magnitude()) <= 2 * EPS
    assert solver.period == np.inf and solver.kinetic_energy == 0.0


@pytest.mark.parametrize("axis", [0, 1, 2], ids=["minor", "intermediate", "major"])
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_general_body_steady_spin_about_a_principal_axis(axis, sign):
    """Including the unstable intermediate axis: exactly steady, forever."""
    inertia = np.array([1.0, 2.0, 3.0])
    m0 = sign * 4.0 * np.eye(3)[axis]
    solver = EulerSolver(inertia, m0, ATTITUDE0)
    t = np.linspace(-1e4, 1e4, 2001)
    np.testing.assert_allclose(
        solver.angular_momentum(t), np.tile(m0, (2001, 1)), rtol=0, atol=1e-15
    )
    expected = _constant_rate_attitude(m0 / inertia, t)
    # The spin angle G/I t reaches 4e4 rad: allow its rounding.
    assert np.max((solver.attitude(t).inv() * expected).magnitude()) <= 1e4 * 4 * EPS * 10


@pytest.mark.parametrize("axis", [0, 2], ids=["minor", "major"])
@pytest.mark.parametrize("hair", [1e-8, -1e-12])
def test_a_hair_away_from_a_stable_principal_axis(axis, hair):
    inertia = np.array([1.0, 2.0, 3.0])
    m0 = 4.0 * np.eye(3)[axis] + hair * np.array([1.0, 1.0, -1.0])
    _check_against_dop853(inertia, m0, span=60.0)


@pytest.mark.parametrize("hair", [1e-8, pytest.param(-1e-12, marks=pytest.mark.slow)])
def test_a_hair_away_from_the_intermediate_axis(hair):
    """mc ≈ 1e-17 to 1e-25: the state leaves the axis, flips, and comes back.

    DOP853 cannot follow this (after the first flip it is off by 1e-5 at a hair of
    1e-8), so the reference is a 30-digit Taylor integration.
    """
    inertia = np.array([1.0, 2.0, 3.0])
    m0 = 4.0 * np.eye(3)[1] + hair * np.array([1.0, 1.0, -1.0])
    solver = EulerSolver(inertia, m0, ATTITUDE0)
    times = [8.0, 16.0, 24.0, 28.0]
    reference = integrate_mpmath(inertia, m0, ATTITUDE0.as_quat(scalar_first=True), times, 25)
    m = solver.angular_momentum(times)
    attitude = solver.attitude(times)
    if hair > 1e-10:  # the flip happens within the span (at ~18 s)
        assert np.sign(m[0, 1]) != np.sign(m[-1, 1])
    for k, (m_ref, q_ref) in enumerate(reference):
        assert np.linalg.norm(m[k] - m_ref) <= 1e-13 * 4.0
        reference_attitude = Rotation.from_quat(q_ref, scalar_first=True)
        assert (attitude[k].inv() * reference_attitude).magnitude() <= 1e-12


@pytest.mark.parametrize(
    "inertia", [(2.0, 2.0, 3.0), (2.0, 3.0, 3.0), (3.0, 2.0, 2.0), (2.0, 3.0, 2.0)]
)
def test_symmetric_bodies_generic_state(inertia):
    _check_against_dop853(inertia, [1.2, -0.7, 2.1], span=40.0)


@pytest.mark.parametrize("inertia", [(2.0, 2.0, 2.0 * (1 + 1e-9)), (2.0, 2.0 * (1 + 1e-12), 2.0)])
def test_a_hair_away_from_the_sphere(inertia):
    _check_against_dop853(inertia, [1.2, -0.7, 2.1], span=40.0)


@pytest.mark.parametrize(
    "m0", [(1.0, 2.0, 1.0), (1.0, 2.0, -1.0), (-1.0, -0.5, 1.0), (-1.0, 0.1, -1.0)]
)
def test_on_the_separatrix_both_signs(m0):
    """I = (2, 3, 6): Δ2 = (m3² − m1²)/2 vanishes exactly when |m1| = |m3|."""
    assert EulerSolver([2.0, 3.0, 6.0], m0).formula == "iii"
    _check_against_dop853([2.0, 3.0, 6.0], m0, span=15.0)


@pytest.mark.parametrize("m0", [(0.0, 2.0, 1.0), (1.0, 2.0, 0.0)])
def test_symmetric_bodies_on_their_separatrix(m0):
    """I1 = I2 with m3 = 0, or I2 = I3 with m1 = 0: Δ2 = 0 and m is an eigenvector."""
    inertia = [2.0, 2.0, 3.0] if m0[2] == 0.0 else [2.0, 3.0, 3.0]
    solver = EulerSolver(inertia, m0, ATTITUDE0)
    assert solver.formula == "iii"
    t = np.linspace(-50, 50, 101)
    np.testing.assert_allclose(
        solver.angular_momentum(t), np.tile(m0, (101, 1)), rtol=0, atol=1e-15
    )
    expected = _constant_rate_attitude(np.array(m0) / np.array(inertia), t)
    assert np.max((solver.attitude(t).inv() * expected).magnitude()) <= 1e-13


def test_initial_state_is_recovered():
    rng = np.random.default_rng(11)
    for _ in range(300):
        inertia = rng.uniform(0.1, 10.0, 3)
        m0 = rng.uniform(-10.0, 10.0, 3)
        attitude0 = Rotation.random(random_state=rng.integers(2**31))
        solver = EulerSolver(inertia, m0, attitude0, t0=7.0)
        np.testing.assert_allclose(solver.angular_momentum(7.0), m0, rtol=0, atol=64 * EPS * 10)
        assert (solver.attitude(7.0).inv() * attitude0).magnitude() <= 8 * EPS


@pytest.mark.parametrize("cyclic", [[1, 2, 0], [2, 0, 1]])
def test_moments_in_any_order_describe_the_same_motion(cyclic):
    """Relabelling the body axes cyclically is a rotation P of the body frame."""
    inertia = np.array([1.0, 2.0, 3.0])
    m0 = np.array([0.3, 2.0, -0.4])
    P = Rotation.from_matrix(np.eye(3)[cyclic])  # x' = P x
    solver = EulerSolver(inertia, m0, ATTITUDE0)
    relabelled = EulerSolver(inertia[cyclic], m0[cyclic], ATTITUDE0 * P.inv())
    t = np.linspace(-20, 20, 81)
    np.testing.assert_allclose(
        relabelled.angular_momentum(t), solver.angular_momentum(t)[:, cyclic], rtol=0, atol=1e-14
    )
    assert (
        np.max((relabelled.attitude(t) * P).inv().__mul__(solver.attitude(t)).magnitude()) <= 1e-13
    )


@pytest.mark.parametrize("scale", [1e-150, 1e-300, 1e150, 1e300])
def test_momentum_near_underflow_and_overflow(scale):
    """Scaling m by s scales the motion's rates by s: m_s(t) = s m(s t)."""
    inertia = np.array([1.0, 2.0, 3.0])
    m0 = np.array([0.3, 2.0, -0.4])
    reference = EulerSolver(inertia, m0, ATTITUDE0)
    scaled = EulerSolver(inertia, scale * m0, ATTITUDE0)
    t = np.linspace(0.0, 30.0, 31)
    np.testing.assert_allclose(
        scaled.angular_momentum(t / scale) / scale,
        reference.angular_momentum(t),
        rtol=0,
        atol=1e-13,
    )
    assert np.max((scaled.attitude(t / scale).inv() * reference.attitude(t)).magnitude()) <= 1e-12


def test_quantities_with_units_are_accepted():
    from astropy import units as u

    plain = EulerSolver.from_angular_velocity([1.0, 2.0, 3.0], [0.1, 0.2, 0.3], t0=5.0)
    with_units = EulerSolver.from_angular_velocity(
        [1.0, 2.0, 3.0] * u.kg * u.m**2,
        [0.1, 0.2, 0.3] * u.rad / u.s * (180 / np.pi) * u.deg / u.rad,
        t0=5.0 * u.s,
    )
    t = [0.0, 10.0, 1.0e3]
    np.testing.assert_allclose(
        with_units.angular_momentum(np.array(t) * u.s), plain.angular_momentum(t), rtol=1e-12
    )
    np.testing.assert_allclose(
        with_units.angular_velocity((np.array(t) / 60) * u.min),
        plain.angular_velocity(t),
        rtol=1e-12,
    )


_EPS = np.finfo(float).eps
_BODIES = [
    (1.0, 1.0, 1.0),
    (1.0, 1.0, 2.0),
    (1.0, 2.0, 2.0),
    (1.0, 1.0 + _EPS, 1.0 + 2 * _EPS),
    (1.0, 2.0 - 2 * _EPS, 2.0),
    (1e-9, 2e-9, 2.5e-9),
    (1e9, 2e9, 2.5e9),
    (3.0, 1.0, 2.0),
    (1e-200, 1e-200, 2e-200),
]
_MOMENTA = [
    (0.0, 0.0, 0.0),
    (1.0, 0.0, 0.0),
    (0.0, 1.0, 0.0),
    (1.0, 1.0, 0.0),
    (-1.0, 2.0, -3.0),
    (1e-300, 1.0, 1e-300),
    (1e-160, 0.0, 1e-160),
    (5e-324, 0.0, 0.0),
    (1.0, 1e-200, 0.0),
    (1e-155, 1.0, 0.0),
    (1e300, 1e300, 1e-300),
]


@pytest.mark.parametrize("inertia", _BODIES)
def test_extreme_states_give_a_finite_motion_or_a_clear_error(inertia):
    """Never a NaN: a finite motion that conserves |m| and H, or an InputError.

    The only refusal expected is an angular velocity beyond the float range: every
    other finite state is propagated, however close to the separatrix (mc below the
    float range included).  Times too far from t0 for the angles to stay in the
    float range are refused by name (test_solver_bad_input.py).
    """
    import warnings

    t = np.array([-1e7, -3.3, 0.0, 1.7, 1e3, 1e7])
    for momentum in _MOMENTA:
        for signs in ((1, 1, 1), (-1, 1, -1), (1, -1, -1)):
            m0 = np.array(momentum) * signs
            with warnings.catch_warnings():
                warnings.simplefilter("error")
                try:
                    solver = EulerSolver(inertia, m0, ATTITUDE0)
                except ValueError as error:
                    assert "beyond the float range" in str(error)
                    continue
                q = solver.attitude_quaternion(t)
                m = solver.angular_momentum(t)
                ω = solver.angular_velocity(t)
            assert np.all(np.isfinite(q)) and np.all(np.isfinite(m)) and np.all(np.isfinite(ω))
            G = solver.angular_momentum_norm
            if G > 1e-300:  # a subnormal momentum has too few digits to rotate
                norms = np.hypot(np.hypot(m[:, 0] / G, m[:, 1] / G), m[:, 2] / G)
                np.testing.assert_allclose(norms, 1.0, atol=1e-12)
                H = solver.attitude(t).apply(m / G)
                H0 = solver.inertial_angular_momentum / G
                np.testing.assert_allclose(H, np.tile(H0, (t.size, 1)), atol=1e-12)
