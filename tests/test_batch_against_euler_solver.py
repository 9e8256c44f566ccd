"""``EulerSolverBatch`` (many states at many times) against ``EulerSolver``, state by state.

- Every case in one batch (both sides of the separatrix and on it, states 1e-154 and
  1e-200 G from it, symmetric bodies, the sphere, rest, spin about each axis, moments in
  any order), each with its own attitude and t0: the batch's attitudes, momenta and
  angular velocities equal each state's ``EulerSolver`` to rounding (a few ulps of the
  angle turned), at times shared by every state and at a row of times per state; its
  properties are the solvers'.
- Tensors (a stack of symmetric 3×3) against ``EulerSolver`` on the same tensors.
- From ``backends.TABLE_MIN_SAMPLES`` times, each state alone: the bits of its
  ``EulerSolver`` (with its table).
- A few generic states against scipy's DOP853 at rtol 1e-13 (independent).
- Bad input: an InputError naming the argument, the state and the value.
"""

import numpy as np
import pytest
from reference_models import integrate_dop853
from scipy.spatial.transform import Rotation
from test_free_flow_against_euler_solver import _angle, _mixed_states

from attitude import EulerSolver, EulerSolverBatch, InputError
from attitude.solver.backends import TABLE_MIN_SAMPLES

EPS = np.finfo(float).eps


def _mixed(count, seed):
    states = _mixed_states(count, seed)
    moments = np.array([s[0] for s in states])
    momentum = np.array([s[1] for s in states])
    kinds = [s[2] for s in states]
    attitude = Rotation.random(count, random_state=seed)
    t0 = np.random.default_rng(seed).uniform(-20.0, 20.0, count)
    return moments, momentum, attitude, t0, kinds


def _tolerance(moments, momentum, τ, kind):
    """A few ulps of the angle turned (|ω| ≤ G/I1), and of the phase itself next to the
    separatrix ("hair": ν ≈ K ≈ 350–460), as in the free flow's batch test."""
    G = max(np.linalg.norm(momentum), 1e-300)
    turned = G / np.min(moments) * np.abs(τ) + (460.0 if kind == "hair" else 0.0)
    return 4.0 * EPS * (10.0 + turned), G


@pytest.mark.parametrize("per_state_times", [False, True])
def test_every_case_equals_euler_solver(per_state_times):
    moments, momentum, attitude, t0, kinds = _mixed(160, seed=3)
    batch = EulerSolverBatch(moments, momentum, attitude, t0)
    rng = np.random.default_rng(4)
    if per_state_times:
        t = np.sort(rng.uniform(-40.0, 60.0, (160, 23)), axis=1)
    else:
        t = np.linspace(-40.0, 60.0, 37)
    q, m, w = batch.attitude_quaternion(t), batch.angular_momentum(t), batch.angular_velocity(t)
    T = t.shape[-1]
    assert q.shape == (160, T, 4) and m.shape == (160, T, 3) and w.shape == (160, T, 3)
    for k in range(160):
        solver = EulerSolver(moments[k], momentum[k], attitude[k], t0[k])
        times = t[k] if per_state_times else t
        tolerance, G = _tolerance(moments[k], momentum[k], times - t0[k], kinds[k])
        q_one = solver.attitude_quaternion(times)
        # The same quaternion, not only the same rotation (both are M (Y ⊗ P)).
        assert np.all(np.abs(q[k] - q_one).max(axis=1) <= tolerance), kinds[k]
        assert np.all(np.abs(m[k] - solver.angular_momentum(times)).max(axis=1) <= tolerance * G)
        ω_scale = G / np.min(moments[k])
        assert np.all(
            np.abs(w[k] - solver.angular_velocity(times)).max(axis=1) <= tolerance * ω_scale
        ), kinds[k]
        assert batch.formula[k] == solver.formula, kinds[k]
        for name in ("mc", "t0"):  # correctly rounded in both
            np.testing.assert_equal(getattr(batch, name)[k], getattr(solver, name), err_msg=name)
        # λ from δ1, δ3: faithful in the batch's double-double, correctly rounded alone;
        # G from numpy's hypot and libm's, which may differ by an ulp.
        np.testing.assert_allclose(batch.period[k], solver.period, rtol=4 * EPS)
        np.testing.assert_allclose(
            batch.angular_momentum_norm[k], solver.angular_momentum_norm, rtol=2 * EPS
        )
        np.testing.assert_allclose(batch.kinetic_energy[k], solver.kinetic_energy, rtol=4 * EPS)
        np.testing.assert_allclose(
            batch.inertial_angular_momentum[k],
            solver.inertial_angular_momentum,
            rtol=0,
            atol=4 * EPS * G,
        )
    np.testing.assert_allclose(np.linalg.norm(q, axis=-1), 1.0, rtol=0, atol=3e-16)


def test_a_scalar_time_and_the_rotation():
    moments, momentum, attitude, t0, _ = _mixed(40, seed=5)
    batch = EulerSolverBatch(moments, momentum, attitude, t0)
    q = batch.attitude_quaternion(12.5)
    assert q.shape == (40, 4)
    np.testing.assert_array_equal(q, batch.attitude_quaternion(np.array([12.5]))[:, 0])
    rotation = batch.attitude(np.array([0.0, 12.5]))
    assert rotation.shape == (40, 2)
    np.testing.assert_array_equal(
        rotation.as_quat(scalar_first=True), batch.attitude_quaternion(np.array([0.0, 12.5]))
    )
    assert batch.attitude(12.5).shape == (40,)
    # At each state's own t0 the attitude is the one given.
    at_t0 = batch.attitude_quaternion(t0[:, None])[:, 0]
    assert np.all(
        (Rotation.from_quat(at_t0, scalar_first=True) * attitude.inv()).magnitude() < 1e-15
    )
    # batch[k] is state k's solver.
    assert batch[7].formula == batch.formula[7] and len(batch) == 40
    np.testing.assert_array_equal(batch[-1].initial_angular_momentum, momentum[-1])


def test_tensors_equal_euler_solver():
    rng = np.random.default_rng(6)
    count = 30
    rotations = Rotation.random(count, random_state=6).as_matrix()
    principal = np.sort(rng.uniform(1.0, 5.0, (count, 3)), axis=1)
    principal[::5, 1] = principal[::5, 0]  # some symmetric bodies
    tensors = np.einsum("nji,nj,njk->nik", rotations, principal, rotations)
    tensors = 0.5 * (tensors + np.swapaxes(tensors, 1, 2))
    momentum = rng.normal(size=(count, 3))
    batch = EulerSolverBatch(tensors, momentum)
    t = np.linspace(0.0, 30.0, 11)
    q, m = batch.attitude_quaternion(t), batch.angular_momentum(t)
    for k in range(count):
        solver = EulerSolver(tensors[k], momentum[k])
        # The principal axes of eigh are the same, to rounding, in both; the rotation of
        # EulerSolver's goes through scipy's from_matrix (orthogonalized): ~10 ε apart.
        tolerance, G = _tolerance(principal[k], momentum[k], t, "tensor")
        assert np.all(_angle(q[k], solver.attitude_quaternion(t)) <= 10.0 * tolerance)
        assert np.all(np.abs(m[k] - solver.angular_momentum(t)).max(axis=1) <= 10.0 * tolerance * G)
        np.testing.assert_allclose(
            batch.moments_of_inertia[k], solver.moments_of_inertia, rtol=1e-14
        )


def test_long_time_grids_take_each_state_alone_with_its_table():
    moments, momentum, attitude, t0, kinds = _mixed(8, seed=7)
    batch = EulerSolverBatch(moments, momentum, attitude, t0)
    t = np.linspace(0.0, 100.0, TABLE_MIN_SAMPLES)
    q = batch.attitude_quaternion(t)
    for k in range(8):
        np.testing.assert_array_equal(q[k], batch[k].attitude_quaternion(t), err_msg=kinds[k])


def test_generic_states_against_dop853():
    rng = np.random.default_rng(8)
    count = 6
    moments = rng.uniform(1.0, 5.0, (count, 3))
    momentum = rng.normal(size=(count, 3))
    attitude = Rotation.random(count, random_state=8)
    batch = EulerSolverBatch(moments, momentum, attitude)
    t = np.linspace(0.0, 20.0, 9)
    q, m = batch.attitude_quaternion(t), batch.angular_momentum(t)
    for k in range(count):
        m_ref, r_ref = integrate_dop853(moments[k], momentum[k], attitude[k], t)
        G = np.linalg.norm(momentum[k])
        assert np.abs(m[k] - m_ref).max() <= 1e-11 * G
        assert np.all(_angle(q[k], r_ref.as_quat(scalar_first=True)) <= 1e-10)


@pytest.mark.parametrize(
    "arguments, message",
    [
        (([[1.0, 2.0, 3.0], [1.0, -2.0, 3.0]], [[0.1, 0.2, 0.3]] * 2), r"inertia\[1\].*positive"),
        (([1.0, 2.0, 3.0], [[0.1, 0.2, 0.3]] * 3, Rotation.random(2)), "numbers of states"),
        (([1.0, 2.0, 3.0], [[0.1, np.nan, 0.3]]), "angular_momentum must be finite"),
        (([1.0, 2.0, 3.0], [[0.1, 0.2]]), r"shape \(3,\) or \(N, 3\)"),
        (([[[1.0, 0.5, 0], [0, 2.0, 0], [0, 0, 3.0]]] * 2, [0.1, 0.2, 0.3]), "not symmetric"),
        (([1.0, 2.0, 3.0], [[1.7e308, 1.7e308, 0.0]], None, 0.0), "beyond the float range"),
        (([1e-300, 2.0, 3.0], [[1e10, 0.0, 0.0]], None, 0.0), "beyond the float range"),
        (([1.0, 2.0, 3.0], [0.1, 0.2, 0.3], "identity"), "must be a scipy"),
    ],
)
def test_bad_input_is_named(arguments, message):
    with pytest.raises(InputError, match=message):
        EulerSolverBatch(*arguments)


def test_bad_times_are_named():
    batch = EulerSolverBatch([1.0, 2.0, 3.0], [[0.1, 1.0, 0.2], [1.0, 50.0, 2.0]])
    with pytest.raises(InputError, match=r"\(N, T\) = \(2, T\)"):
        batch.attitude_quaternion(np.zeros((3, 4)))
    with pytest.raises(InputError, match="t must be finite"):
        batch.angular_momentum([0.0, np.inf])
    # λ t beyond the float range for the second state only (EulerSolver refuses it too),
    # a few times (state by state on floats) and many (numpy over the batch).
    for t in ([0.0, 1e308], np.r_[np.zeros(39), 1e308]):
        with pytest.raises(InputError, match=r"state 1: t = 1e\+308 s is too far from t0 = 0\.0"):
            batch.attitude_quaternion(t)
    with pytest.raises(InputError, match="state 1: t = 1e"):
        batch.angular_momentum([[0.0, 1.0], [0.0, 1e308]])
    with pytest.raises(InputError, match="state 1: t = 1e"):
        batch.angular_momentum(np.stack([np.zeros(30), np.r_[np.zeros(29), 1e308]]))
