"""The compiled free flow (attitude.solver.numba_backend) against the numpy one
(``numpy_backend.advance``, the backend of every case) on the same states.

- Both are the exact flow to rounding, from different kernels (numba's against
  scipy's): they agree to a few ε per radian turned.
- The compiled flow takes exactly the states it is for (the elliptic cases with a
  certain case test and mc ≥ 2^-128) and leaves the others (the separatrix and its
  1e-13 neighbourhood, the sphere, rest, mc below 2^-128, magnitudes beyond 2^±60),
  which ``advance`` then sends down the numpy path: results for every case.
- Threads: the kernels release the GIL and keep no state between calls, so batches
  advanced in two threads at once give the bits of the same batches one after the
  other.
(A step whose angles leave the float range: test_free_flow_against_euler_solver.py.
Against EulerSolver and DOP853: test_free_flow_against_euler_solver.py and
test_free_flow_against_numerical_integration.py, which now run through this path.)
"""

from concurrent.futures import ThreadPoolExecutor

import numpy as np
from reference_models import state_with_delta2
from scipy.spatial.transform import Rotation

from attitude.solver.free_flow import advance
from attitude.solver.numba_backend import flow_many, flow_one
from attitude.solver.numpy_backend import advance as numpy_advance

EPS = np.finfo(float).eps


def _compiled(moments, momentum, q, dt):
    n = len(moments)
    m_out, q_out, ok = np.empty((n, 3)), np.empty((n, 4)), np.empty(n, dtype=bool)
    flow_many(moments, momentum, q, dt, m_out, q_out, ok)
    return m_out, q_out, ok


def _angle(q, r):
    return (
        Rotation.from_quat(q, scalar_first=True).inv() * Rotation.from_quat(r, scalar_first=True)
    ).magnitude()


def _states(count, seed, scale=(0.5, 5.0)):
    """Generic triaxial states, near-separatrix ones down to |δ2| = 1e-12 and symmetric
    tops, moments in random orders, steps of up to 40 s (up to ~100 periods)."""
    rng = np.random.default_rng(seed)
    moments, momentum = np.empty((count, 3)), np.empty((count, 3))
    for k in range(count):
        inertia = np.sort(rng.uniform(*scale, 3))
        kind = k % 3
        if kind == 0:
            m = rng.normal(size=3)
        elif kind == 1:
            ratio = rng.choice([-1.0, 1.0]) * 10 ** rng.uniform(-12, -4)
            m = state_with_delta2(inertia, ratio, weight=rng.uniform(0.1, 0.9), rng=rng)
        else:
            inertia[1] = inertia[0] if rng.random() < 0.5 else inertia[2]
            m = rng.normal(size=3)
        order = rng.permutation(3)
        moments[k], momentum[k] = inertia[order], m[order] * 10 ** rng.uniform(-2, 2)
    q = Rotation.random(count, random_state=seed).as_quat(scalar_first=True)
    dt = rng.uniform(-40.0, 40.0, count)
    return moments, momentum, q, dt


def test_compiled_equals_numpy_to_rounding():
    moments, momentum, q, dt = _states(3000, seed=2)
    m_c, q_c, ok = _compiled(moments, momentum, q, dt)
    m_n, q_n = numpy_advance(moments, momentum, q, dt)
    assert ok.mean() > 0.95  # nearly every state of these is the compiled flow's
    G = np.linalg.norm(momentum, axis=1)
    turned = G / moments.min(axis=1) * np.abs(dt)  # |ω| ≤ G/I1
    tolerance = np.maximum(1e-13, 10 * EPS * turned)
    angle = _angle(q_c[ok], q_n[ok])
    assert np.all(angle <= tolerance[ok]), np.max(angle / tolerance[ok])
    momentum_error = np.linalg.norm(m_c - m_n, axis=1)[ok]
    bound = (tolerance * G)[ok]
    assert np.all(momentum_error <= bound), np.max(momentum_error / bound)
    # Exactly conserved by both: |m| to rounding, and unit quaternions.
    np.testing.assert_allclose(np.linalg.norm(m_c[ok], axis=1), G[ok], rtol=8 * EPS)
    np.testing.assert_allclose(np.linalg.norm(q_c[ok], axis=1), 1.0, rtol=0, atol=4 * EPS)


def test_compiled_leaves_the_states_it_is_not_for():
    """Each state below is one the compiled flow must not take (ok False)."""
    x = 1e-200
    states = [
        ([2.0, 3.0, 6.0], [0.5, 0.25, 0.5]),  # the separatrix: Δ2 = 0 exactly
        ([2.0, 3.0, 6.0], [0.5, 0.25, 0.5 + 2.0**-53]),  # |δ2| ~ 1e-16: case test uncertain
        ([2.0, 2.0, 2.0], [1.0, 2.0, 3.0]),  # the sphere
        ([1.0, 2.0, 3.0], [0.0, 0.0, 0.0]),  # rest
        ([1.0, 2.0, 3.0], [1e-30, 1.0, 1e-30]),  # mc ~ 1e-60 < 2^-128
        ([1.0, 2.0, 3.0], [x, 1.0, 0.3]),  # a component below 2^-60
        ([1e20, 2e20, 3e20], [1.0, 2.0, 3.0]),  # moments beyond 2^60
    ]
    moments = np.array([s[0] for s in states])
    momentum = np.array([s[1] for s in states])
    q = np.tile([1.0, 0.0, 0.0, 0.0], (len(states), 1))
    _, _, ok = _compiled(moments, momentum, q, np.full(len(states), 1.5))
    assert not ok.any(), ok
    # ... and ``advance`` still gives each of them, through the numpy path.
    m_new, q_new = advance(moments, momentum, q, 1.5)
    assert np.isfinite(m_new).all() and np.isfinite(q_new).all()


def test_a_state_alone_and_in_a_batch_give_the_same_bits():
    moments, momentum, q, dt = _states(50, seed=4)
    m_c, q_c, ok = _compiled(moments, momentum, q, dt)
    for k in np.flatnonzero(ok):
        one = flow_one(*moments[k].tolist(), *momentum[k].tolist(), *q[k].tolist(), float(dt[k]))
        assert one[0]
        assert one[1:4] == tuple(m_c[k]) and one[4:] == tuple(q_c[k])


def test_zero_step_is_the_identity_and_steps_compose():
    moments, momentum, q, dt = _states(300, seed=6)
    m0, q0, ok0 = _compiled(moments, momentum, q, np.zeros(len(dt)))
    # m(0) comes from the formula, not from the state (free_flow: so that the step's
    # rounding cancels): a few ε of G, 6.3 here and 5.9 for the numpy path.
    G0 = np.linalg.norm(momentum, axis=1)
    assert np.all(np.abs(m0 - momentum)[ok0] <= 16 * EPS * G0[ok0, None])
    assert np.all(_angle(q0[ok0], q[ok0]) <= 4 * EPS)
    half_m, half_q, ok1 = _compiled(moments, momentum, q, 0.5 * dt)
    two_m, two_q, ok2 = _compiled(moments, half_m, half_q, 0.5 * dt)
    one_m, one_q, ok3 = _compiled(moments, momentum, q, dt)
    # Not the near-separatrix states (every third, see _states): there a rounding of
    # the intermediate state moves |δ2| ~ 1e-12 by ε/|δ2|, and the motion with it.
    ok = ok1 & ok2 & ok3 & (np.arange(len(dt)) % 3 != 1)
    turned = np.linalg.norm(momentum, axis=1) / moments.min(axis=1) * np.abs(dt)
    tolerance = np.maximum(1e-13, 10 * EPS * turned[ok])
    assert np.all(_angle(two_q[ok], one_q[ok]) <= tolerance)
    G = np.linalg.norm(momentum, axis=1)[ok]
    assert np.all(np.linalg.norm(two_m[ok] - one_m[ok], axis=1) <= tolerance * G)
    # The quaternion of two steps is that of the whole step, sign included.
    assert np.all(np.sum(two_q[ok] * one_q[ok], axis=1) > 0.0)


def test_two_threads_give_the_bits_of_one():
    batches = [_states(2000, seed=s) for s in (8, 9)]
    serial = [_compiled(*b) for b in batches]
    with ThreadPoolExecutor(2) as pool:
        threaded = list(pool.map(lambda b: _compiled(*b), batches))
    for one, other in zip(serial, threaded, strict=True):
        for a, b in zip(one, other, strict=True):
            np.testing.assert_array_equal(a, b)


def test_a_kernel_that_cannot_be_cached_is_still_compiled():
    """Where numba has no writable cache location it refuses cache=True; ``jit`` then
    compiles without caching instead of failing the import.  A function with no
    source file (made by exec) has no cache location either."""
    from attitude.base.jit import jit

    namespace: dict = {}
    exec("def twice(x):\n    return 2.0 * x / 0.0 if x == 0.0 else 2.0 * x", namespace)
    compiled = jit(namespace["twice"])
    assert compiled(1.5) == 3.0
    assert np.isnan(compiled(0.0))  # error_model="numpy": 0/0 is a NaN, not an exception
