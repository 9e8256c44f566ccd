"""Events: a propagated scenario against the exact solver restarted by hand, and physics.

- Across several angular impulses, the trajectory equals EulerSolver restarted by
  hand at each event from the state it computes then.
- The inertial angular momentum jumps by exactly the applied impulse (body or
  inertial axes) and is otherwise constant.
- An inertia change conserves the inertial angular momentum and changes the kinetic
  energy to ½ m·I⁻¹m with the new inertia; the attitude is continuous.
- A full tensor, rotated by a known rotation, gives the same inertial motion as its
  principal form; and a scenario with a full-tensor inertia change agrees with an
  independent DOP853 integration of Euler's equations written with the tensor.
- Ordering rules: events given out of order are sorted; events at the same epoch
  apply in the order given; an output at an event's epoch is post-event.
"""

import numpy as np
import pytest
from astropy import units as u
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from attitude import EulerSolver
from attitude.environment.timescales import as_time
from attitude.scenario.events import AngularImpulse, AttitudeReset, InertiaChange
from attitude.scenario.scenario import InitialState, Scenario
from attitude.scenario.spacecraft import Spacecraft
from attitude.trajectory.trajectory import propagate

EPOCH = "2027-05-01T00:00:00"
ATTITUDE0 = Rotation.from_euler("ZYX", [30.0, -20.0, 75.0], degrees=True)


def _at(seconds):
    return as_time(EPOCH) + seconds * u.s


def _scenario(events, inertia=(100.0, 200.0, 300.0), duration=900.0, ω0=(0.02, 0.15, -0.05)):
    return Scenario(
        "test",
        Spacecraft("test craft", inertia),
        EPOCH,
        InitialState(ATTITUDE0, angular_velocity=ω0),
        events,
        duration=duration,
        step=1.0,
    )


def test_impulses_equal_the_solver_restarted_by_hand():
    impulses = [
        (150.0, [0.0, 0.0, 4.0], "body"),
        (400.0, [1.5, -2.0, 0.5], "inertial"),
        (401.0, [0.0, 3.0, 0.0], "body"),
    ]
    scenario = _scenario([AngularImpulse(_at(t), v, frame) for t, v, frame in impulses])
    trajectory = propagate(scenario)
    offsets = [offset for offset, _ in scenario.events]

    # By hand: one solver per segment, each started from the previous one's state.
    inertia = np.array([100.0, 200.0, 300.0])
    solver = EulerSolver(inertia, inertia * [0.02, 0.15, -0.05], ATTITUDE0, t0=0.0)
    solvers = [solver]
    for offset, (_, v, frame) in zip(offsets, impulses, strict=True):
        attitude = solver.attitude(offset)
        m = solver.angular_momentum(offset)
        m = m + (np.array(v) if frame == "body" else attitude.inv().apply(v))
        solver = EulerSolver(inertia, m, attitude, t0=offset)
        solvers.append(solver)

    t = np.linspace(0.0, 900.0, 3601)
    # Post-event at an event's epoch, to within the trajectory's 1 ns.
    index = np.searchsorted(np.array(offsets) - 1e-9, t, side="right")
    for k, solver in enumerate(solvers):
        mask = index == k
        np.testing.assert_allclose(
            trajectory.angular_momentum(t[mask]),
            solver.angular_momentum(t[mask]),
            rtol=0,
            atol=1e-14,
        )
        error = (trajectory.attitude(t[mask]).inv() * solver.attitude(t[mask])).magnitude()
        assert np.max(error) <= 1e-14


@pytest.mark.parametrize("frame", ["body", "inertial"])
def test_inertial_momentum_jumps_by_exactly_the_impulse(frame):
    impulse = np.array([2.0, -1.0, 3.0])
    scenario = _scenario([AngularImpulse(_at(300.0), impulse, frame)])
    trajectory = propagate(scenario)
    before = trajectory.inertial_angular_momentum(np.linspace(0.0, 299.999, 500))
    after = trajectory.inertial_angular_momentum(np.linspace(300.0, 900.0, 500))
    # Constant in each segment, independently of the stored value: from R(t) m(t).
    t_before, t_after = np.linspace(0.0, 299.999, 500), np.linspace(300.0, 900.0, 500)
    H_before = trajectory.attitude(t_before).apply(trajectory.angular_momentum(t_before))
    H_after = trajectory.attitude(t_after).apply(trajectory.angular_momentum(t_after))
    G = np.linalg.norm(H_after[0])
    assert np.max(np.linalg.norm(H_before - before[0], axis=1)) <= 1e-13 * G
    assert np.max(np.linalg.norm(H_after - after[0], axis=1)) <= 1e-13 * G
    attitude_at_event = trajectory.attitude(300.0)
    expected = impulse if frame == "inertial" else attitude_at_event.apply(impulse)
    np.testing.assert_allclose(H_after[0] - H_before[0], expected, rtol=0, atol=1e-13 * G)


def test_inertia_change_conserves_inertial_momentum_and_sets_the_energy():
    new_tensor = np.array([[180.0, 12.0, -5.0], [12.0, 260.0, 8.0], [-5.0, 8.0, 330.0]])
    scenario = _scenario([InertiaChange(_at(200.0), new_tensor)])
    trajectory = propagate(scenario)
    t = np.linspace(0.0, 900.0, 1801)
    H = trajectory.attitude(t).apply(trajectory.angular_momentum(t))
    G = np.linalg.norm(H[0])
    assert np.max(np.linalg.norm(H - H[0], axis=1)) <= 1e-13 * G

    t_event = scenario.events[0][0]  # 200 s, to the rounding of the UTC -> TT conversion
    m_event = trajectory.segments[0].solver.angular_momentum(t_event)
    expected_T = 0.5 * m_event @ np.linalg.solve(new_tensor, m_event)
    T_before = 0.5 * m_event @ (m_event / np.array([100.0, 200.0, 300.0]))
    T = trajectory.kinetic_energy(t)
    np.testing.assert_allclose(T[t < 199.0], T_before, rtol=1e-14)
    np.testing.assert_allclose(T[t >= 200.0], expected_T, rtol=1e-14)
    # The kinetic energy computed from the rates agrees: ½ ω·I ω with the new tensor.
    ω = trajectory.angular_velocity(t[t >= 200.0])
    np.testing.assert_allclose(
        0.5 * np.einsum("ni,ij,nj->n", ω, new_tensor, ω), expected_T, rtol=1e-13
    )
    # The attitude is continuous across the event.
    after = trajectory.attitude(t_event)
    jump = (after.inv() * trajectory.segments[0].solver.attitude(t_event)).magnitude()
    assert jump <= 1e-15


def test_rotated_tensor_gives_the_same_inertial_motion_as_its_principal_form():
    moments = np.array([120.0, 250.0, 310.0])
    C = Rotation.from_rotvec([0.4, -1.1, 0.7])  # body' = C body
    tensor = C.as_matrix() @ np.diag(moments) @ C.as_matrix().T
    m0 = np.array([3.0, -20.0, 6.0])
    principal = EulerSolver(moments, m0, ATTITUDE0)
    rotated = EulerSolver(tensor, C.apply(m0), ATTITUDE0 * C.inv())
    # About 40 periods: eigh's rounding of the moments (~1e-16) becomes a phase drift.
    t = np.linspace(-200.0, 800.0, 2001)
    G = np.linalg.norm(m0)
    np.testing.assert_allclose(
        rotated.angular_momentum(t), C.apply(principal.angular_momentum(t)), rtol=0, atol=1e-12 * G
    )
    np.testing.assert_allclose(
        rotated.angular_velocity(t),
        C.apply(principal.angular_velocity(t)),
        rtol=0,
        atol=1e-12 * G / 120,
    )
    error = ((rotated.attitude(t) * C).inv() * principal.attitude(t)).magnitude()
    assert np.max(error) <= 1e-12


def _dop853_with_tensor(tensor, m0, attitude0, t_eval):
    """Euler's equations with a full tensor: dm/dt = m × I⁻¹m, dq/dt = ½ q ⊗ (0, I⁻¹m)."""
    inverse = np.linalg.inv(tensor)

    def rhs(t, y):
        m, (w, x, yy, z) = y[:3], y[3:]
        ω = inverse @ m
        return np.concatenate(
            [
                np.cross(m, ω),
                0.5
                * np.array(
                    [
                        -x * ω[0] - yy * ω[1] - z * ω[2],
                        w * ω[0] + yy * ω[2] - z * ω[1],
                        w * ω[1] + z * ω[0] - x * ω[2],
                        w * ω[2] + x * ω[1] - yy * ω[0],
                    ]
                ),
            ]
        )

    y0 = np.concatenate([m0, attitude0.as_quat(scalar_first=True)])
    sol = solve_ivp(
        rhs, (t_eval[0], t_eval[-1]), y0, method="DOP853", t_eval=t_eval, rtol=1e-13, atol=1e-14
    )
    return sol.y[:3].T, Rotation.from_quat(sol.y[3:].T, scalar_first=True)


def test_full_tensor_inertia_change_against_dop853():
    tensor0 = np.array([[210.0, 15.0, 0.0], [15.0, 160.0, -9.0], [0.0, -9.0, 300.0]])
    tensor1 = np.array([[260.0, -20.0, 11.0], [-20.0, 180.0, 4.0], [11.0, 4.0, 330.0]])
    ω0 = np.array([0.03, -0.01, 0.12])
    scenario = _scenario(
        [InertiaChange(_at(120.0), tensor1)], inertia=tensor0, duration=300.0, ω0=ω0
    )
    trajectory = propagate(scenario)

    t0 = np.linspace(0.0, 120.0, 241)
    m_ref0, attitude_ref0 = _dop853_with_tensor(tensor0, tensor0 @ ω0, ATTITUDE0, t0)
    t1 = np.linspace(120.0, 300.0, 361)
    m_ref1, attitude_ref1 = _dop853_with_tensor(tensor1, m_ref0[-1], attitude_ref0[-1], t1)
    G = np.linalg.norm(tensor0 @ ω0)
    for t, m_ref, attitude_ref in (
        (t0[:-1], m_ref0[:-1], attitude_ref0[:-1]),
        (t1, m_ref1, attitude_ref1),
    ):
        assert np.max(np.linalg.norm(trajectory.angular_momentum(t) - m_ref, axis=1)) <= 1e-10 * G
        assert np.max((trajectory.attitude(t).inv() * attitude_ref).magnitude()) <= 1e-9


def test_attitude_reset_places_the_spacecraft():
    commanded = Rotation.from_euler("X", 90.0, degrees=True)
    scenario = _scenario([AttitudeReset(_at(500.0), commanded, angular_velocity=[0.0, 0.0, 0.1])])
    trajectory = propagate(scenario)
    t_event = scenario.events[0][0]
    assert (trajectory.attitude(t_event).inv() * commanded).magnitude() <= 1e-15
    np.testing.assert_allclose(trajectory.angular_velocity(t_event), [0.0, 0.0, 0.1], atol=1e-16)
    # A steady spin about z from there on.
    expected = commanded * Rotation.from_rotvec([0.0, 0.0, 0.1 * (600.0 - t_event)])
    assert (trajectory.attitude(600.0).inv() * expected).magnitude() <= 1e-13


def test_events_out_of_order_and_at_the_same_epoch():
    a = AngularImpulse(_at(300.0), [0.0, 0.0, 2.0], label="a")
    b = AngularImpulse(_at(100.0), [1.0, 0.0, 0.0], label="b")
    c = AttitudeReset(_at(300.0), angular_momentum=[0.0, 0.0, 10.0], label="c")
    scenario = _scenario([a, b, c])
    assert [event.label for _, event in scenario.events] == ["b", "a", "c"]
    trajectory = propagate(scenario)
    # At 300 s: a then c, so the momentum is c's, whatever a did.
    np.testing.assert_allclose(trajectory.angular_momentum(300.0), [0.0, 0.0, 10.0], atol=1e-15)
    # An output exactly at an event's epoch, given as a Time, is post-event.
    assert trajectory.segment_index(_at(100.0)) == 1
    assert trajectory.segment_index(_at(99.999)) == 0


def test_events_outside_the_span_are_refused():
    after = r"events\[0\]\.epoch: the angular_impulse at .* is after the end"
    with pytest.raises(ValueError, match=after):
        _scenario([AngularImpulse(_at(901.0), [0.0, 0.0, 1.0])])
    before = r"events\[0\]\.epoch: the inertia_change at .* is before the scenario epoch"
    with pytest.raises(ValueError, match=before):
        _scenario([InertiaChange(_at(-1.0), [1.0, 2.0, 2.5])])
    # At the end of the span exactly: applied, and the output at stop is post-event.
    trajectory = propagate(_scenario([AngularImpulse(_at(900.0), [0.0, 0.0, 1.0])]))
    assert trajectory.segment_index(900.0) == 1


def test_evaluating_outside_the_trajectory_span_is_an_error():
    trajectory = propagate(_scenario([]))
    with pytest.raises(
        ValueError, match=r"time .* \(-5 s after the epoch\) is outside the trajectory span"
    ):
        trajectory.attitude(-5.0)
    with pytest.raises(ValueError, match="outside the trajectory span"):
        trajectory.angular_velocity(_at(1000.0))
