"""The solver's fast paths against its general ones: one answer, whatever the path.

- ``EulerSolver``: a scalar time (Python floats) against the same time in an array
  (numpy); ``attitude`` against ``attitude_quaternion``; no result depends on the size
  of the slices the arrays are evaluated in, or on the other times of the array;
  scipy's private one-quaternion constructor gives the public constructor's rotation;
  a symmetric body computes no R_J.
- ``free_flow.advance``: a state alone against the same state in a batch of 1e5, and a
  batch evaluated in slices of any size; ``free_flow.advance_floats`` (tuples) against
  ``advance`` on the same state; ``free_flow.UnitBatch`` (its moments' sorting and
  case-test constants kept from flow to flow) against ``advance_unit_batch`` (all made
  again in each call), flow after flow with new momenta.
(The table of ψ's periodic part, the other fast path: test_phase_table_against_mpmath.py.)
"""

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import attitude.solver.free_flow as free_flow
import attitude.solver.numpy_backend as numpy_backend
from attitude import EulerSolver
from attitude.base.errors import InputError
from attitude.solver.backends import TABLE_MIN_SAMPLES as _TABLE_MIN_SAMPLES
from attitude.solver.euler_solver import _one_rotation

ATTITUDE0 = Rotation.from_euler("ZYX", [10.0, 20.0, 30.0], degrees=True)
STATES = {
    "case i": ([3.0, 1.0, 2.0], [0.6, -0.5, 0.4]),
    "case ii": ([100.0, 200.0, 300.0], [0.1, 200.0, 0.3]),
    "separatrix": ([2.0, 3.0, 6.0], [1.0, 0.7, -1.0]),
    "symmetric": ([2.0, 2.0, 5.0], [0.3, 0.4, 0.5]),
    "mc below the float range": ([1.0, 2.0, 3.0], [1e-200, 1.0, 2e-200]),
    "tensor": ([[3.0, 0.1, 0.2], [0.1, 2.0, 0.05], [0.2, 0.05, 1.0]], [0.3, -0.2, 0.5]),
    "sphere": ([2.0, 2.0, 2.0], [1.0, 0.7, -1.0]),
    "rest": ([1.0, 2.0, 3.0], [0.0, 0.0, 0.0]),
}
TIMES = [0.0, 1.0, -37.25, 1234.5, 8.0e5]


@pytest.mark.parametrize("name", list(STATES))
def test_a_scalar_time_equals_the_same_time_in_an_array(name):
    """Floats (math) and numpy: the same formulas; numpy's vectorized tan may differ
    from libm's by an ulp, so the results agree to a few ulps of the angles turned."""
    solver = EulerSolver(*STATES[name], ATTITUDE0)
    G = max(np.linalg.norm(solver.initial_angular_momentum), 1e-300)
    in_array = solver.attitude_quaternion(np.array(TIMES))
    momentum = solver.angular_momentum(np.array(TIMES))
    velocity = solver.angular_velocity(np.array(TIMES))
    scale = G / min(solver.moments_of_inertia)
    for k, t in enumerate(TIMES):
        turned = 1.0 + scale * abs(t)  # rad
        q = solver.attitude_quaternion(t)
        assert min(np.abs(q - in_array[k]).max(), np.abs(q + in_array[k]).max()) <= 4e-16 * turned
        assert np.abs(solver.angular_momentum(t) - momentum[k]).max() <= 4e-16 * G * turned
        assert np.abs(solver.angular_velocity(t) - velocity[k]).max() <= 4e-16 * scale * turned
        one = solver.attitude(t)
        assert one.single
        np.testing.assert_array_equal(one.as_quat(scalar_first=True), q)


@pytest.mark.parametrize("name", ["case i", "case ii", "separatrix", "tensor"])
def test_attitude_and_attitude_quaternion_are_the_same_numbers(name):
    solver = EulerSolver(*STATES[name], ATTITUDE0)
    for n in (7, _TABLE_MIN_SAMPLES + 5):  # the formula, and the table
        t = np.linspace(-100.0, 5000.0, n)
        q = solver.attitude_quaternion(t)
        np.testing.assert_array_equal(solver.attitude(t).as_quat(scalar_first=True), q)
        np.testing.assert_array_equal(
            solver.attitude_quaternion(t, scalar_first=False), q[:, [1, 2, 3, 0]]
        )
        np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, rtol=0, atol=3e-16)


@pytest.mark.parametrize("name", ["case i", "case ii", "separatrix", "tensor", "rest"])
def test_no_result_depends_on_the_slice_size_or_on_the_other_times(name, monkeypatch):
    """Arrays evaluate in slices of ``numpy_backend.CHUNK`` samples: every sample is computed alone
    (no reduction across samples), so a time gives the same bits in any slice and
    beside any other times (on either side of the table threshold)."""
    t = np.random.default_rng(4).uniform(-1e4, 1e5, 3 * _TABLE_MIN_SAMPLES)
    solver = EulerSolver(*STATES[name], ATTITUDE0)
    q, m, w = solver.attitude_quaternion(t), solver.angular_momentum(t), solver.angular_velocity(t)
    monkeypatch.setattr(numpy_backend, "CHUNK", 1000)
    other = EulerSolver(*STATES[name], ATTITUDE0)
    np.testing.assert_array_equal(other.attitude_quaternion(t), q)
    np.testing.assert_array_equal(other.angular_momentum(t), m)
    np.testing.assert_array_equal(other.angular_velocity(t), w)
    # The same times among others (still above the threshold): the same bits.
    mixed = np.concatenate([t, np.linspace(0.0, 1.0, 5000)])
    np.testing.assert_array_equal(other.attitude_quaternion(mixed)[: t.size], q)
    # Below the threshold every array takes the formula: alone or in any small array.
    small = t[:50]
    formula = solver.attitude_quaternion(small)
    np.testing.assert_array_equal(
        solver.attitude_quaternion(np.concatenate([small, t[50:900]]))[:50], formula
    )


def test_the_one_quaternion_rotation_is_the_public_constructors():
    """``_one_rotation`` uses scipy's private constructor (a fifth of the public one's
    cost for one quaternion) where it exists: it must be the same rotation, with the
    same stored quaternion."""
    for q in Rotation.random(50, random_state=9).as_quat():
        fast, public = _one_rotation(q.copy()), Rotation(q, normalize=False)
        assert fast.single
        np.testing.assert_array_equal(
            fast.as_quat(canonical=False), public.as_quat(canonical=False)
        )
        np.testing.assert_array_equal(fast.as_matrix(), public.as_matrix())
        np.testing.assert_array_equal(fast.apply([1.0, 2.0, 3.0]), public.apply([1.0, 2.0, 3.0]))
        # and from_quat, which renormalizes: the same rotation to rounding
        assert (fast * Rotation.from_quat(q).inv()).magnitude() <= 5e-16


def test_a_symmetric_body_computes_no_elliptic_integral_of_the_third_kind(monkeypatch):
    """I1 = I2 (or I2 = I3): n = 0, so Π − F = 0; R_J would only be multiplied by zero."""
    import attitude.elliptic.functions as elliptic

    def refuse(*args, **kwargs):
        raise AssertionError("R_J computed for a symmetric body")

    monkeypatch.setattr(elliptic.special, "elliprj", refuse)
    for inertia in ([2.0, 2.0, 5.0], [2.0, 5.0, 5.0]):
        solver = EulerSolver(inertia, [0.3, 0.4, 0.5], ATTITUDE0)
        assert solver._formula.n == 0.0
        solver.attitude(12.5)
        solver.attitude(np.linspace(0.0, 100.0, 2 * _TABLE_MIN_SAMPLES))
        assert solver._table is None  # nothing to tabulate either


def _mixed_batch(count, seed):
    from test_free_flow_against_euler_solver import _batch

    return _batch(count, seed)


def test_a_state_alone_equals_the_same_state_in_a_batch_of_1e5():
    """The batch (numpy, double-double case test) and a state alone (floats, exact
    integers) run the same formulas with the same constants (the AGM and Bulirsch's
    cel stop for each state at its own convergence): they agree within an ulp of the
    angle the state turns (libm's and numpy's tan and arctan may differ by one)."""
    moments, momentum, q, dt, kinds = _mixed_batch(100_000, seed=11)
    m_new, q_new = free_flow.advance(moments, momentum, q, dt)
    G = np.maximum(np.linalg.norm(momentum, axis=1), 1e-300)
    for k in np.random.default_rng(12).choice(100_000, 300, replace=False):
        m_one, q_one = free_flow.advance(moments[k], momentum[k], q[k], dt[k])
        turned = 1.0 + G[k] / np.min(moments[k]) * abs(dt[k])
        ulp = 2.0**-52 * turned
        assert np.abs(m_one - m_new[k]).max() <= ulp * G[k], kinds[k]
        assert np.abs(q_one - q_new[k]).max() <= ulp, kinds[k]


def test_a_batch_gives_the_same_bits_in_slices_of_any_size(monkeypatch):
    moments, momentum, q, dt, _ = _mixed_batch(20_000, seed=13)
    m_new, q_new = free_flow.advance(moments, momentum, q, dt)
    monkeypatch.setattr(numpy_backend, "FLOW_CHUNK", 777)
    m_other, q_other = free_flow.advance(moments, momentum, q, dt)
    np.testing.assert_array_equal(m_other, m_new)
    np.testing.assert_array_equal(q_other, q_new)


def test_the_float_entry_point_gives_the_bits_of_advance():
    """``advance_floats`` (tuples, for the torqued solver's one spacecraft) runs what
    ``advance`` runs on one state after its checks and normalization: the same bits."""
    moments, momentum, q, dt, kinds = _mixed_batch(300, seed=14)
    for k in range(300):
        w, x, y, z = q[k].tolist()
        norm = math.sqrt(w * w + x * x + y * y + z * z)  # as advance normalizes
        unit = (w / norm, x / norm, y / norm, z / norm)
        m_floats, q_floats = free_flow.advance_floats(
            tuple(moments[k].tolist()), tuple(momentum[k].tolist()), unit, float(dt[k])
        )
        m_one, q_one = free_flow.advance(moments[k], momentum[k], q[k], dt[k])
        assert isinstance(m_floats, tuple) and isinstance(q_floats[0], float)
        np.testing.assert_array_equal(np.array(m_floats), m_one, err_msg=kinds[k])
        np.testing.assert_array_equal(np.array(q_floats), q_one, err_msg=kinds[k])


@pytest.mark.parametrize("bad", [math.nan, math.inf])
def test_the_float_entry_point_refuses_a_non_finite_momentum(bad):
    with pytest.raises(InputError, match="finite"):
        free_flow.advance_floats((1.0, 2.0, 3.0), (0.1, bad, 0.2), (1.0, 0.0, 0.0, 0.0), 1.0)


@pytest.mark.parametrize(
    "quaternion, dt",
    [
        ((math.nan, 0.0, 0.0, 0.0), 1.0),
        ((1.0, 0.0, 0.0, 0.0), math.nan),
        ((1.0, 0.0, 0.0, 0.0), math.inf),
    ],
)
def test_the_float_entry_point_names_a_non_finite_quaternion_or_step(quaternion, dt):
    """The compiled flow leaves such a state (its result is not finite), and the float
    path refuses it with every value of the state in the message."""
    with pytest.raises(InputError, match=r"quaternion_wxyz \[.*\] .* and dt") as refused:
        free_flow.advance_floats((1.0, 2.0, 3.0), (0.1, 0.2, 0.3), quaternion, dt)
    message = str(refused.value)
    assert f"quaternion_wxyz {list(quaternion)}" in message and f"dt {dt!r}" in message


def test_a_unit_batch_kept_over_many_flows_gives_the_bits_of_fresh_calls(monkeypatch):
    """One ``UnitBatch`` reused across flows, as the torqued solver's batch is between
    kicks: each flow gives the bits of ``advance_unit_batch``, which starts afresh.
    Every kind of state of the mixed batch (near and on the separatrix, symmetric,
    sphere, rest), with momenta that change between flows (the kicks), so that states
    cross from one case to another under the same moments; the states the compiled
    flow leaves take the numpy path in slices."""
    moments, momentum, q, dt, kinds = _mixed_batch(3000, seed=15)
    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    monkeypatch.setattr(numpy_backend, "FLOW_CHUNK", 1100)  # three slices, the last short
    unit_batch = free_flow.UnitBatch(moments)
    rng = np.random.default_rng(16)
    for flow in range(4):
        m_kept, q_kept = unit_batch.advance(momentum, q, dt)
        m_fresh, q_fresh = free_flow.advance_unit_batch(moments.copy(), momentum, q, dt)
        np.testing.assert_array_equal(m_kept, m_fresh, err_msg=f"flow {flow}")
        np.testing.assert_array_equal(q_kept, q_fresh, err_msg=f"flow {flow}")
        # A kick: the momenta of a third of the states move (those at rest stay so, the
        # others cross cases: the separatrix ones move off it, generic ones may cross it).
        kicked = rng.random(len(kinds)) < 1.0 / 3.0
        momentum = np.where(
            kicked[:, None], m_kept * (1.0 + 0.3 * rng.normal(size=m_kept.shape)), m_kept
        )
        q = q_kept
