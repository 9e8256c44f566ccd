"""TorquedSolver against the exact torque-free solver and the momentum laws.

1. Zero torque: with no torque model the solver *is* EulerSolver; with a torque that
   is identically zero the splitting runs (kicks of zero, exact flows) and reproduces
   EulerSolver to rounding.
2. Angular momentum theorem: dH/dt = τ in inertial axes.  A constant inertial torque
   changes H by exactly τ × (time under the burn), at any step, whether the burn
   starts and ends on grid points or not; a body torque along the spin axis of a
   symmetric spinner spins it up exactly (ω3 = ω3(0) + τ t/I3, the axis fixed).
3. propagate_batch: N spacecraft advanced together give what N solvers give.
4. departure_time: against the crossing found on a DOP853 integration.
5. The orbit sources (a TLE, Keplerian elements, an OEM file) are accepted as the
   position of the gravity gradient, through their ``position_velocity``: each gives
   the orbit's own positions; an OEM has no epoch of its own and needs ``epoch=``.
"""

import math

import numpy as np
import pytest
import torqued_reference as ref
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from attitude import (
    ConstantTorque,
    EulerSolver,
    GravityGradient,
    TorquedSolver,
    departure_time,
    propagate_batch,
)

INERTIA = np.array([300.0, 100.0, 200.0])  # any order along the body axes
M0 = np.array([2.0, -3.0, 5.0])
ATTITUDE = Rotation.from_rotvec([0.2, -0.9, 0.4])
ORBIT = ref.circular_orbit(7.0e6)
GG = GravityGradient(ORBIT, mu=ORBIT.mu)


def test_no_torque_is_euler_solver():
    solver = TorquedSolver(INERTIA, M0, ATTITUDE, t0=3.0, torques=[])
    free = EulerSolver(INERTIA, M0, ATTITUDE, t0=3.0)
    t = np.array([3.0, 17.5, 1e5])
    assert np.array_equal(solver.attitude_quaternion(t), free.attitude_quaternion(t))
    assert np.array_equal(solver.angular_momentum(t), free.angular_momentum(t))
    assert np.array_equal(solver.angular_velocity(t), free.angular_velocity(t))


@pytest.mark.parametrize("method", ["strang", "aba1064", "srkn11"])
def test_zero_torque_reproduces_euler_solver_to_rounding(method):
    zero = ConstantTorque([0.0, 0.0, 0.0], 0.0, math.inf)
    solver = TorquedSolver(INERTIA, M0, ATTITUDE, t0=3.0, torques=[zero], step=2.5, method=method)
    free = EulerSolver(INERTIA, M0, ATTITUDE, t0=3.0)
    t = np.array([3.0, 4.1, 77.7, 253.0])  # 100 steps; between grid points too
    # Rounding of ~ε per flow over up to 900 flows (900 ε = 2e-13); kernels of equal
    # accuracy (scipy's or the compiled ones) give 0.4 to 1.1e-13 here.
    assert np.max(ref.angle(solver.attitude_quaternion(t), free.attitude_quaternion(t))) <= 2e-13
    # The same for the momentum (negative coefficients among the flows): 0.4 to 6.4e-14
    # |m| with those kernels.
    momentum_error = np.max(np.abs(solver.angular_momentum(t) - free.angular_momentum(t)))
    assert momentum_error <= 1e-13 * np.linalg.norm(M0)


@pytest.mark.parametrize(
    "start, stop",
    [(10.0, 40.0), (10.3, 40.9)],  # on grid points (step 5 s), inside steps
)
def test_inertial_burn_changes_momentum_by_its_impulse(start, stop):
    τ = np.array([0.3, -0.1, 0.25])  # N m, inertial
    burn = ConstantTorque(τ, start, stop, frame="inertial")
    solver = TorquedSolver(INERTIA, M0, ATTITUDE, torques=[burn], step=5.0)
    t = np.array([5.0, 21.3, stop, 77.7])
    H = solver.attitude(t).apply(solver.angular_momentum(t))
    expected = ATTITUDE.apply(M0) + np.clip(t - start, 0.0, stop - start)[:, None] * τ
    assert np.max(np.abs(H - expected)) <= 1e-13 * np.max(np.abs(expected))


def test_body_torque_spins_up_a_symmetric_spinner_exactly():
    inertia = np.array([80.0, 80.0, 120.0])
    ω0 = 0.4
    torque = 0.6  # N m about the body z (spin) axis
    spin_up = ConstantTorque([0.0, 0.0, torque], 5.0, 65.0, frame="body")
    solver = TorquedSolver(
        inertia, [0.0, 0.0, inertia[2] * ω0], ATTITUDE, torques=[spin_up], step=7.0
    )
    t = np.array([3.0, 30.0, 65.0, 100.0])
    ω3 = solver.angular_velocity(t)[:, 2]
    burned = np.clip(t - 5.0, 0.0, 60.0)
    assert np.max(np.abs(ω3 - (ω0 + torque * burned / inertia[2]))) <= 1e-14
    # The spin angle is the integral of ω3: exact too.
    angle = (
        ω0 * t
        + 0.5 * torque / inertia[2] * burned**2
        + torque / inertia[2] * 60.0 * np.clip(t - 65.0, 0.0, None)
    )
    expected = ATTITUDE * Rotation.from_rotvec(np.outer(angle, [0.0, 0.0, 1.0]))
    assert np.max((solver.attitude(t).inv() * expected).magnitude()) <= 1e-12


def test_batch_equals_one_solver_per_spacecraft():
    rng = np.random.default_rng(7)
    moments = np.array([100.0, 200.0, 300.0]) * rng.uniform(0.9, 1.1, (4, 3))
    m0 = moments * rng.normal(0.0, 0.03, (4, 3))
    attitudes = Rotation.random(4, random_state=3)
    burn = ConstantTorque([0.01, 0.0, -0.02], 20.0, 31.3)
    times = np.array([0.0, 12.5, 31.3, 47.9, 60.0])
    m, q = propagate_batch(moments, m0, attitudes, 0.0, times, [GG, burn], step=6.0)
    assert m.shape == (5, 4, 3) and q.shape == (5, 4, 4)
    for k in range(4):
        solver = TorquedSolver(moments[k], m0[k], attitudes[k], torques=[GG, burn], step=6.0)
        assert (
            np.max(np.abs(m[:, k] - solver.angular_momentum(times)))
            <= 1e-14 * np.linalg.norm(m0[k]) + 1e-16
        )
        assert np.max(ref.angle(q[:, k], solver.attitude_quaternion(times))) <= 1e-13


def test_departure_time_against_dop853():
    """When gravity gradient has turned the tumbler 1° away from its torque-free motion."""
    inertia = np.array([100.0, 200.0, 300.0])
    m0 = inertia * np.array([0.05, 0.02, 0.03])
    attitude = Rotation.from_euler("ZYX", [10.0, 20.0, 30.0], degrees=True)
    found = departure_time(inertia, m0, attitude, 0.0, [GG], horizon=6000.0, step=10.0)
    free = EulerSolver(inertia, m0, attitude)
    torque = ref.gravity_gradient(ORBIT, np.diag(inertia))

    def rhs(t, y):
        return ref._rhs(t, y, np.diag(inertia), np.diag(1.0 / inertia), torque, None)

    def off_by_one_degree(t, y):
        return ref.angle(y[3:], free.attitude_quaternion(t)) - math.radians(1.0)

    off_by_one_degree.terminal = True
    solution = solve_ivp(
        rhs,
        (0.0, 6000.0),
        np.concatenate([m0, attitude.as_quat(scalar_first=True)]),
        method="DOP853",
        rtol=1e-12,
        atol=1e-14,
        events=off_by_one_degree,
    )
    assert solution.t_events[0].size == 1
    assert abs(found - solution.t_events[0][0]) <= 2e-3, (found, solution.t_events[0])
    assert departure_time(inertia, m0, attitude, 0.0, [GG], horizon=100.0, step=10.0) == math.inf


def test_tle_orbit_as_the_position():
    from astropy import units as u
    from astropy.time import Time

    from attitude import TleOrbit

    orbit = TleOrbit(
        "1 25544U 98067A   14020.93268519  .00009878  00000-0  18200-3 0  5082",
        "2 25544  51.6498 109.4756 0003572  55.9686 274.8005 15.49815350868473",
    )
    epoch = Time("2014-01-21T00:00:00", scale="utc")
    gg = GravityGradient(orbit, epoch=epoch)
    t = np.array([0.0, 1234.5])
    direct = orbit.position_velocity(epoch + t * u.s)[0]
    assert np.max(np.abs(gg.position(t) - direct)) <= 1e-6
    solver = TorquedSolver(INERTIA, M0, ATTITUDE, torques=[gg], step=10.0)
    assert np.all(np.isfinite(solver.attitude_quaternion(t)))


def test_keplerian_and_oem_orbits_as_the_position(tmp_path):
    import ccsds_ndm
    from astropy import units as u
    from astropy.time import Time

    from attitude import InputError, KeplerianOrbit, OemOrbit
    from attitude.environment.timescales import offline_time

    epoch = Time("2024-03-01T00:00:00", scale="utc")
    kepler = KeplerianOrbit(epoch, 7.0e6, 0.01, 0.9, 0.3, 0.2, mean_anomaly=0.1)
    t = np.array([0.0, 1234.5, 3000.0])
    gg = GravityGradient(kepler)  # the elements' epoch is t = 0
    direct = kepler.position_velocity(epoch + t * u.s)[0]
    assert np.max(np.abs(gg.position(t) - direct)) <= 1e-6

    # The same orbit every 60 s in an OEM (ICRF, UTC), read back.
    nodes = epoch + np.arange(0.0, 3600.0 + 1.0, 60.0) * u.s
    r, v = kepler.position_velocity(nodes)
    with offline_time():
        texts = list(nodes.utc.isot)
    metadata = ccsds_ndm.OemMetadata(
        object_name="SAT",
        object_id="2024-001A",
        start_time=texts[0],
        stop_time=texts[-1],
        center_name="EARTH",
        ref_frame="ICRF",
        time_system="UTC",
    )
    data = ccsds_ndm.OemData.from_numpy(texts, np.hstack([r, v]) / 1e3)
    header = ccsds_ndm.OdmHeader(creation_date="2024-03-01T00:00:00", originator="TEST")
    path = tmp_path / "sat.oem"
    path.write_text(ccsds_ndm.Oem(header, [ccsds_ndm.OemSegment(metadata, data)]).to_str("kvn"))
    oem = OemOrbit(path)
    with pytest.raises(InputError, match="epoch="):
        GravityGradient(oem)
    gg = GravityGradient(oem, epoch=epoch)
    assert np.max(np.abs(gg.position(t) - oem.position_velocity(epoch + t * u.s)[0])) <= 1e-6
    solver = TorquedSolver(INERTIA, M0, ATTITUDE, torques=[gg], step=10.0)
    assert np.all(np.isfinite(solver.attitude_quaternion(t)))
