"""attitude.solver.free_flow.advance (many states, one step each) against EulerSolver, itself.

- Every case in one batch (both sides of the separatrix and on it, states 1e-154 G
  from it, symmetric bodies, the sphere, rest, spin about each axis, moments in any
  order): ``advance`` equals ``EulerSolver`` evaluated at t0 + dt, to rounding, and a
  batch equals its states advanced one at a time (the float path).
- Composition: advance(advance(x, a), b) = advance(x, a + b), quaternion sign included.
- Conservation: |m|, T and the inertial momentum q ⊗ m ⊗ q* after any step.
- Bad input: an InputError naming the argument, the state and the value.
(Against an independent integration: test_free_flow_against_numerical_integration.py.)
"""

import numpy as np
import pytest
from reference_models import state_with_delta2
from scipy.spatial.transform import Rotation

from attitude import EulerSolver, InputError
from attitude.solver.free_flow import advance


def _mixed_states(count, seed):
    """(moments, momentum, kind) of every case, shuffled, moments in random orders."""
    rng = np.random.default_rng(seed)
    kinds = ["generic", "near", "separatrix", "hair", "symmetric", "sphere", "rest", "axis"]
    states = []
    for k in range(count):
        kind = kinds[k % len(kinds)]
        inertia = np.sort(rng.uniform(0.5, 5.0, 3))
        if kind == "generic":
            m = rng.normal(size=3)
        elif kind == "near":  # |Δ2|/G² from 1e-4 to 1e-13, both sides
            ratio = rng.choice([-1.0, 1.0]) * 10 ** rng.uniform(-13, -4)
            m = state_with_delta2(inertia, ratio, weight=rng.uniform(0.1, 0.9), rng=rng)
        elif kind == "separatrix":  # inertia = (2, 3, 6)·s: Δ2 = 0 exactly when |m1| = |m3|
            inertia = np.array([2.0, 3.0, 6.0]) * 2.0 ** rng.integers(-3, 4)
            a = rng.integers(1, 9) / 8.0
            m = np.array([a, rng.integers(-8, 9) / 8.0, a]) * rng.choice([-1.0, 1.0], 3)
        elif kind == "hair":  # mc ~ 1e-308 and below the float range
            x = 10.0 ** rng.choice([-154.0, -200.0])
            m = np.array([x, 1.0, x]) * rng.choice([-1.0, 1.0], 3)
        elif kind == "symmetric":
            inertia[1] = inertia[0] if rng.random() < 0.5 else inertia[2]
            m = rng.normal(size=3)
        elif kind == "sphere":
            inertia[:] = inertia[0]
            m = rng.normal(size=3)
        elif kind == "rest":
            m = np.zeros(3)
        else:  # spin exactly about one principal axis, the intermediate one included
            m = np.eye(3)[rng.integers(3)] * rng.choice([-1.0, 1.0])
        m = m * 10 ** rng.uniform(-1, 1)
        order = rng.permutation(3)
        states.append((inertia[order], m[order], kind))
    return states


def _batch(count, seed, span=30.0):
    rng = np.random.default_rng(seed + 1)
    states = _mixed_states(count, seed)
    moments = np.array([s[0] for s in states])
    momentum = np.array([s[1] for s in states])
    kinds = [s[2] for s in states]
    q = Rotation.random(count, random_state=seed).as_quat(scalar_first=True)
    dt = rng.uniform(-span, span, count)
    return moments, momentum, q, dt, kinds


def _quaternion_distance(q, r):
    """|q − r| up to the sign of the quaternion (the same rotation)."""
    return np.minimum(np.linalg.norm(q - r, axis=-1), np.linalg.norm(q + r, axis=-1))


def _angle(q, r):
    return (
        Rotation.from_quat(q, scalar_first=True).inv() * Rotation.from_quat(r, scalar_first=True)
    ).magnitude()


def test_a_mixed_batch_equals_euler_solver_state_by_state():
    moments, momentum, q, dt, kinds = _batch(400, seed=1)
    m_new, q_new = advance(moments, momentum, q, dt)
    assert m_new.shape == (400, 3) and q_new.shape == (400, 4)
    for k in range(400):
        solver = EulerSolver(moments[k], momentum[k], Rotation.from_quat(q[k], scalar_first=True))
        G = max(np.linalg.norm(momentum[k]), 1e-300)
        assert np.linalg.norm(m_new[k] - solver.angular_momentum(dt[k])) <= 1e-13 * G, kinds[k]
        # Rounding grows with the angle turned (|ω| ≤ G/I1): a few ε per radian.
        turned = G / np.min(moments[k]) * abs(dt[k])
        tolerance = max(1e-13, 10 * np.finfo(float).eps * turned)
        assert _angle(q_new[k], solver.attitude_quaternion(dt[k])) <= tolerance, kinds[k]
    np.testing.assert_allclose(np.linalg.norm(q_new, axis=1), 1.0, rtol=0, atol=3e-16)


@pytest.mark.parametrize("count", [1, 10_000])
def test_a_batch_equals_its_states_one_at_a_time(count):
    """N = 1 and N = 10000 with every case mixed: the batch (numpy, double-double case
    test) and the single-state path (floats, exact integers) agree to rounding."""
    moments, momentum, q, dt, kinds = _batch(count, seed=2)
    m_new, q_new = advance(moments, momentum, q, dt)
    for k in range(count):
        m_one, q_one = advance(moments[k], momentum[k], q[k], dt[k])
        G = max(np.linalg.norm(momentum[k]), 1e-300)
        # Rounding: a few ulps of the angles turned (up to ~600 rad here), as numpy's and
        # libm's functions may differ by an ulp; next to the separatrix ("hair") the phase
        # itself is ν ≈ K ≈ 350–460 (ulps of 6e-14).
        phase = G / np.min(moments[k]) * abs(dt[k]) + (460.0 if kinds[k] == "hair" else 0.0)
        tolerance = 1e-15 * (10.0 + phase)
        assert np.linalg.norm(m_new[k] - m_one) <= tolerance * G, kinds[k]
        # Not only the same rotation: the same quaternion (the step is continuous in dt).
        assert np.linalg.norm(q_new[k] - q_one) <= tolerance, kinds[k]
    # A subset against EulerSolver as well.
    for k in range(0, count, max(1, count // 100)):
        solver = EulerSolver(moments[k], momentum[k], Rotation.from_quat(q[k], scalar_first=True))
        assert _angle(q_new[k], solver.attitude_quaternion(dt[k])) <= 1e-13


def test_single_state_shapes_and_units():
    from astropy import units as u

    m, q = advance([1.0, 2.0, 3.0], [0.3, 2.0, -0.4], [1.0, 0.0, 0.0, 0.0], 2.5)
    assert m.shape == (3,) and q.shape == (4,)
    m_u, q_u = advance(
        [1.0, 2.0, 3.0] * u.kg * u.m**2,
        [0.3, 2.0, -0.4] * u.kg * u.m**2 / u.s,
        [2.0, 0.0, 0.0, 0.0],  # normalized
        2500.0 * u.ms,
    )
    np.testing.assert_allclose(m_u, m, rtol=1e-15)
    np.testing.assert_allclose(q_u, q, rtol=1e-15)
    # One state broadcast against many steps.
    m_b, q_b = advance([1.0, 2.0, 3.0], [0.3, 2.0, -0.4], [1.0, 0.0, 0.0, 0.0], [0.0, 2.5])
    assert m_b.shape == (2, 3)
    np.testing.assert_allclose(m_b[1], m, atol=1e-15)
    np.testing.assert_allclose(q_b[0], [1.0, 0.0, 0.0, 0.0], atol=1e-16)


def test_composition_of_steps_is_the_whole_step():
    """advance(advance(x, a), b) = advance(x, a + b), to rounding, sign included.

    Steps short enough (|λ| (|a| + |b|) ≲ 6) that a state next to the separatrix, whose
    intermediate rounding moves it by eps, has not yet amplified that by e^(λt).
    """
    moments, momentum, q, _, kinds = _batch(800, seed=3)
    rng = np.random.default_rng(4)
    G = np.linalg.norm(momentum, axis=1)
    scale = np.min(moments, axis=1) / np.maximum(G, 1e-300)  # 1/rate
    a = rng.uniform(-3.0, 3.0, 800) * scale
    b = rng.uniform(-3.0, 3.0, 800) * scale
    m_a, q_a = advance(moments, momentum, q, a)
    m_ab, q_ab = advance(moments, m_a, q_a, b)
    m_whole, q_whole = advance(moments, momentum, q, a + b)
    tolerance = np.where(np.isin(kinds, ["near", "separatrix", "hair", "axis"]), 1e-11, 1e-13)
    assert np.all(np.linalg.norm(m_ab - m_whole, axis=1) <= tolerance * np.maximum(G, 1e-300))
    assert np.all(np.linalg.norm(q_ab - q_whole, axis=1) <= tolerance)


def test_conservation_of_norm_energy_and_inertial_momentum():
    moments, momentum, q, _, kinds = _batch(2000, seed=5)
    rng = np.random.default_rng(6)
    dt = 10 ** rng.uniform(-3, 4, 2000) * rng.choice([-1.0, 1.0], 2000)
    m_new, q_new = advance(moments, momentum, q, dt)
    G = np.linalg.norm(momentum, axis=1)
    moving = G > 0.0
    np.testing.assert_allclose(np.linalg.norm(m_new, axis=1)[moving], G[moving], rtol=2e-15)
    T0 = 0.5 * np.sum(momentum**2 / moments, axis=1)
    T1 = 0.5 * np.sum(m_new**2 / moments, axis=1)
    np.testing.assert_allclose(T1[moving], T0[moving], rtol=4e-15)
    H0 = Rotation.from_quat(q, scalar_first=True).apply(momentum)
    H1 = Rotation.from_quat(q_new, scalar_first=True).apply(m_new)
    error = np.linalg.norm(H1 - H0, axis=1)[moving] / G[moving]
    assert np.max(error) <= 1e-13, kinds[int(np.argmax(error))]
    np.testing.assert_array_equal(m_new[~moving], 0.0)


def test_a_zero_step_returns_the_state():
    moments, momentum, q, _, _ = _batch(500, seed=7)
    m_new, q_new = advance(moments, momentum, q, 0.0)
    G = np.maximum(np.linalg.norm(momentum, axis=1), 1e-300)
    assert np.all(np.linalg.norm(m_new - momentum, axis=1) <= 8e-16 * G * 4)
    np.testing.assert_allclose(q_new, q, rtol=0, atol=3e-16)


@pytest.mark.parametrize(
    "arguments, message",
    [
        (([1.0, 0.0, 3.0], [1.0, 1.0, 1.0], [1, 0, 0, 0], 1.0), r"inertia must be positive"),
        (([1.0, 2.0, 3.0], [1.0, np.nan, 1.0], [1, 0, 0, 0], 1.0), r"angular_momentum must be"),
        (([1.0, 2.0, 3.0], [1.0, 1.0, 1.0], [0, 0, 0, 0], 1.0), r"non-zero quaternion"),
        (([1.0, 2.0, 3.0], [1.0, 1.0, 1.0], [1, 0, 0, 0], np.inf), r"dt must be finite"),
        (([1.0, 2.0, 3.0], [1.0, 1.0], [1, 0, 0, 0], 1.0), r"angular_momentum must have shape"),
        (([1.0, 2.0, 3.0], [1.0, 1.0, 1.0], [1, 0, 0], 1.0), r"quaternion_wxyz must have shape"),
        (([[1.0, 2.0, 3.0]] * 2, [[1.0, 1.0, 1.0]] * 3, [1, 0, 0, 0], 1.0), r"do not match"),
        (([[1.0, 2.0, 3.0], [1.0, -2, 3.0]], [1.0, 1.0, 1.0], [1, 0, 0, 0], 1.0), r"inertia\[1\]"),
        ((["a", 2.0, 3.0], [1.0, 1.0, 1.0], [1, 0, 0, 0], 1.0), r"inertia must be numeric"),
        (([1e-300, 2.0, 3.0], [1e10, 0.0, 0.0], [1, 0, 0, 0], 1.0), r"beyond the float range"),
    ],
)
def test_bad_input_is_named(arguments, message):
    with pytest.raises(InputError, match=message):
        advance(*arguments)


def test_a_step_whose_angles_overflow_is_named_not_nan():
    with pytest.raises(InputError, match=r"dt = 1e\+300 s is too long for this state"):
        advance([1.0, 2.0, 3.0], [1e10, 2e10, 0.0], [1, 0, 0, 0], 1e300)
    with pytest.raises(InputError, match=r"dt\[1\] = 1e\+300 s is too long"):
        advance([1.0, 2.0, 3.0], [1e10, 2e10, 0.0], [1, 0, 0, 0], [1.0, 1e300])


def test_bad_states_in_a_large_batch_are_named_by_index():
    """Past the small-batch threshold the checks run vectorized; they still name the state."""
    moments = np.tile([1.0, 2.0, 3.0], (40, 1))
    momentum = np.tile([0.3, 2.0, -0.4], (40, 1))
    bad_moments = moments.copy()
    bad_moments[17, 1] = -2.0
    with pytest.raises(InputError, match=r"inertia\[17\] must be positive"):
        advance(bad_moments, momentum, [1, 0, 0, 0], 1.0)
    bad_momentum = momentum.copy()
    bad_momentum[33, 2] = np.inf
    with pytest.raises(InputError, match=r"angular_momentum\[33\] must be finite"):
        advance(moments, bad_momentum, [1, 0, 0, 0], 1.0)
    dt = np.ones(40)
    dt[25] = 1e300
    with pytest.raises(InputError, match=r"dt\[25\] = 1e\+300 s is too long"):
        advance(moments, momentum * 1e10, [1, 0, 0, 0], dt)
    q = np.tile([1.0, 0.0, 0.0, 0.0], (40, 1))
    q[39] = 0.0
    with pytest.raises(InputError, match=r"quaternion_wxyz\[39\] must be a finite, non-zero"):
        advance(moments, momentum, q, 1.0)
