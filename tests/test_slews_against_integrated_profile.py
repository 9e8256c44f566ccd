"""Slews against an independent integration of their own commanded rate, and against
their limits and boundary conditions.

1. The attitude of a slew is the integral of its rate: DOP853 of dq/dt = ½ q ⊗ (0, ω(t))
   from the start attitude, ω(t) the slew's analytic body rate, integrated piece by
   piece between the profile's switches, agrees with the slew's attitude to 1e-12 rad
   everywhere (measured 6e-14); the slew's acceleration is the derivative of its rate (central
   differences).
2. The boundary conditions hold exactly: at the start the attitude and the rate are
   the old law's, at the end the new law's; the angle is the one between the start
   attitude and the new law's at the start (scipy's Rotation, computed apart).
3. The limits hold on dense sampling: |ω| ≤ max_rate and |ω̇| ≤ max_acceleration.
4. A tumbling body is captured within the limits (control_resume), and refused, in one
   line naming why, when it turns faster than the slew's maximum rate; a slew that
   cannot end before the next event is refused with the time it would take.
"""

import itertools

import astropy.units as u
import numpy as np
import pytest
from eo_orbit import EPOCH, ORBIT
from scipy.integrate import solve_ivp

from attitude import GroundSite, InputError, NadirLaw, SunLaw, TargetLaw
from attitude.laws.slews import Slew, SlewLimits

LIMITS = SlewLimits(1.0 * u.deg / u.s, 0.05 * u.deg / u.s**2)
T0 = 1000.0


def _slew(source, target, start_rate=None, limits=LIMITS, deadline=4000.0):
    a = source.bind(EPOCH, 0.0, 6000.0, ORBIT).state([T0])
    b = target.bind(EPOCH, T0, 6000.0, ORBIT)
    rate = a.angular_velocity[0] if start_rate is None else start_rate
    return Slew(T0, a.attitude[0], rate, b, limits, deadline), a, b


def _kinematics(slew):
    def rhs(t, q):
        ω = slew.state([t]).angular_velocity[0]
        w, x, y, z = q
        return 0.5 * np.array(
            [
                -x * ω[0] - y * ω[1] - z * ω[2],
                w * ω[0] + y * ω[2] - z * ω[1],
                w * ω[1] + z * ω[0] - x * ω[2],
                w * ω[2] + x * ω[1] - y * ω[0],
            ]
        )

    return rhs


def _integrate(slew, start_attitude, t_eval):
    """DOP853 of the kinematics, restarted at the slew's switches."""
    switches = sorted(
        {slew.start_s + slew.accelerating_s, slew.end_s - slew.accelerating_s}
        | {slew.start_s + slew.correction_s}
    )
    edges = [slew.start_s, *[s for s in switches if slew.start_s < s < slew.end_s], slew.end_s]
    q = start_attitude.as_quat(scalar_first=True)
    out = np.empty((t_eval.size, 4))
    for a, b in itertools.pairwise(edges):
        inside = (t_eval >= a) & (t_eval <= b)
        sol = solve_ivp(
            _kinematics(slew),
            (a, b),
            q,
            method="DOP853",
            rtol=1e-13,
            atol=1e-15,
            t_eval=np.unique(np.concatenate([t_eval[inside], [b]])),
        )
        assert sol.success
        out[inside] = sol.y[:, : np.count_nonzero(inside)].T
        q = sol.y[:, -1]
    return out / np.linalg.norm(out, axis=1, keepdims=True)


def _angle(qa, qb):
    diff = np.minimum(np.linalg.norm(qa - qb, axis=-1), np.linalg.norm(qa + qb, axis=-1))
    return 4.0 * np.arcsin(np.minimum(1.0, 0.5 * diff))


CASES = {
    "nadir to Sun": (NadirLaw("zero_doppler"), SunLaw("-z", "+x", "orbit_normal")),
    "Sun to nadir": (SunLaw("-z", "+x", "orbit_normal"), NadirLaw("zero_doppler")),
    "nadir to a ground station": (
        NadirLaw(),
        TargetLaw(GroundSite(67.857 * u.deg, 20.964 * u.deg, 400 * u.m, name="kiruna")),
    ),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_slew_is_the_integral_of_its_rate(case):
    source, target = CASES[case]
    slew, a, _ = _slew(source, target)
    t = np.linspace(slew.start_s, slew.end_s, 41)
    q_ref = _integrate(slew, a.attitude[0], t)
    q = slew.state(t).attitude.as_quat(scalar_first=True)
    assert np.max(_angle(q, q_ref)) < 1e-12, case  # measured 6e-14
    # ω̇ is the derivative of ω (central differences, away from the switches).
    h = 1e-3
    inner = t[1:-1] + 0.37
    plus, minus = slew.state(inner + h), slew.state(inner - h)
    difference = (plus.angular_velocity - minus.angular_velocity) / (2 * h)
    smooth = np.all(
        [
            np.abs(inner - s) > 2 * h
            for s in (
                slew.start_s + slew.accelerating_s,
                slew.end_s - slew.accelerating_s,
                slew.start_s + slew.correction_s,
            )
        ],
        axis=0,
    )
    α = slew.state(inner).angular_acceleration
    assert np.max(np.abs(difference - α)[smooth]) < 1e-9


@pytest.mark.parametrize("case", sorted(CASES))
def test_boundary_conditions_and_angle(case):
    source, target = CASES[case]
    slew, a, b = _slew(source, target)
    ends = slew.state([slew.start_s, slew.end_s])
    start_law = a
    end_law = b.state([slew.end_s])
    # Exact but for the rounding of the products (rates of 1e-3 rad/s).
    assert (ends.attitude[0].inv() * start_law.attitude[0]).magnitude() < 1e-15
    assert np.allclose(ends.angular_velocity[0], start_law.angular_velocity[0], rtol=0, atol=1e-16)
    assert (ends.attitude[1].inv() * end_law.attitude[0]).magnitude() < 1e-15
    assert np.allclose(ends.angular_velocity[1], end_law.angular_velocity[0], rtol=0, atol=1e-16)
    expected = (b.state([T0]).attitude[0].inv() * start_law.attitude[0]).magnitude()
    assert abs(slew.angle_rad - expected) < 1e-14
    assert slew.duration_s > 0.0


@pytest.mark.parametrize("case", sorted(CASES))
def test_limits_hold_on_dense_sampling(case):
    source, target = CASES[case]
    slew, _, _ = _slew(source, target)
    t = np.linspace(slew.start_s, slew.end_s, 20001)
    state = slew.state(t)
    rate = np.linalg.norm(state.angular_velocity, axis=1)
    acceleration = np.linalg.norm(state.angular_acceleration, axis=1)
    assert np.max(rate) <= LIMITS.max_rate * (1 + 1e-12)
    assert np.max(acceleration) <= LIMITS.max_acceleration * (1 + 1e-12)
    # Not needlessly slow: the target's rate is bounded over the slew itself.
    target = slew.target.state(t)
    assert slew.target_rate_bound < 1.1 * np.max(np.linalg.norm(target.angular_velocity, axis=1))


def test_capture_of_a_tumbling_body():
    tumble = np.radians([0.2, -0.3, 0.25])  # 0.44 deg/s
    slew, a, b = _slew(NadirLaw(), NadirLaw("zero_doppler"), start_rate=tumble)
    state = slew.state([slew.start_s, slew.end_s])
    assert np.allclose(state.angular_velocity[0], tumble, rtol=0, atol=1e-17)
    assert np.allclose(
        state.angular_velocity[1], b.state([slew.end_s]).angular_velocity[0], atol=1e-17
    )
    t = np.linspace(slew.start_s, slew.end_s, 5001)
    dense = slew.state(t)
    assert np.max(np.linalg.norm(dense.angular_velocity, axis=1)) <= LIMITS.max_rate * (1 + 1e-12)
    assert np.max(np.linalg.norm(dense.angular_acceleration, axis=1)) <= LIMITS.max_acceleration * (
        1 + 1e-12
    )
    q_ref = _integrate(slew, a.attitude[0], t[::250])
    assert np.max(_angle(dense.attitude[::250].as_quat(scalar_first=True), q_ref)) < 1e-12


def test_too_fast_a_tumble_is_refused():
    with pytest.raises(InputError, match="cannot capture it; give a larger max_rate"):
        _slew(NadirLaw(), NadirLaw(), start_rate=np.radians([1.2, 0.0, 0.3]))


def test_a_slew_that_cannot_end_before_the_deadline_is_refused():
    with pytest.raises(
        InputError, match=r"takes 1\d\d\.?\d* s .* and would end at .*after the end of the span"
    ):
        _slew(NadirLaw(), SunLaw("-z", "+x", "orbit_normal"), deadline=T0 + 60.0)


def test_limits_are_checked():
    with pytest.raises(InputError, match=r"slew\.max_rate: must be positive"):
        SlewLimits(0.0, 1.0)
    with pytest.raises(InputError, match=r"slew\.max_acceleration"):
        SlewLimits(1.0, 1e9)
    with pytest.raises(InputError, match="cannot be converted"):
        SlewLimits(1.0 * u.deg / u.s, 1.0 * u.deg / u.s)
