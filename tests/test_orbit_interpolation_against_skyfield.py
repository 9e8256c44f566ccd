"""TleOrbit's interpolated states and Sun vectors against direct skyfield calls.

The reference is skyfield's own ``EarthSatellite.at`` at every second of a day
(86 400 epochs, ≈ 6 s, the cost the interpolation avoids), and skyfield's
``(earth + satellite).at(t).observe(sun).apparent()`` for the Sun seen from the
spacecraft.  Measured: position ≤ 0.380 m, velocity ≤ 0.033 m/s (60 s nodes),
Sun direction from the spacecraft ≤ 0.0006".
"""

import numpy as np
import pytest
from astropy.time import Time

from attitude.ephemeris import _ephemeris, timescale
from attitude.orbit import EARTH_EQUATORIAL_RADIUS_M, TleOrbit
from attitude.timescales import offline_time, time_from_tt_seconds

# ISS (ZARYA), a real element set (as printed in the skyfield documentation).
LINE1 = "1 25544U 98067A   14020.93268519  .00009878  00000-0  18200-3 0  5082"
LINE2 = "2 25544  51.6498 109.4756 0003572  55.9686 274.8005 15.49815350868473"
START = Time("2014-01-21T00:00:00", scale="utc")
ARCSEC = np.pi / (180 * 3600)


def _angle(u, v):
    return np.arctan2(np.linalg.norm(np.cross(u, v), axis=-1), np.sum(u * v, axis=-1))


def _skyfield(times):
    with offline_time():
        return timescale().tt_jd(np.ravel(times.tt.jd1), np.ravel(times.tt.jd2))


@pytest.fixture(scope="module")
def orbit():
    return TleOrbit(LINE1, LINE2, "ISS (ZARYA)")


def test_one_day_at_one_second(orbit):
    times = time_from_tt_seconds(START, np.arange(86400.0))
    position_m, velocity_m_s = orbit.position_velocity(times)
    direct = orbit.satellite.at(_skyfield(times))
    position_error_m = np.linalg.norm(position_m - direct.position.m.T, axis=-1)
    velocity_error_m_s = np.linalg.norm(velocity_m_s - direct.velocity.m_per_s.T, axis=-1)
    assert position_error_m.max() < 0.4, position_error_m.max()
    assert velocity_error_m_s.max() < 0.04, velocity_error_m_s.max()


def test_exact_at_the_nodes(orbit):
    # The nodes are every 60 s of TT from a whole TT Julian day.
    with offline_time():
        nodes = Time(2456679.0, np.arange(0.0, 86400.0, 600.0) / 86400.0, format="jd", scale="tt")
    position_m, velocity_m_s = orbit.position_velocity(nodes)
    direct = orbit.satellite.at(_skyfield(nodes))
    assert np.abs(position_m - direct.position.m.T).max() < 1e-6
    assert np.abs(velocity_m_s - direct.velocity.m_per_s.T).max() < 1e-9


def test_without_interpolation_it_is_skyfield(orbit):
    exact = TleOrbit(LINE1, LINE2, step_s=None)
    times = time_from_tt_seconds(START, [0.0, 12.345, 1e5])
    position_m, velocity_m_s = exact.position_velocity(times)
    direct = orbit.satellite.at(_skyfield(times))
    assert np.array_equal(position_m, direct.position.m.T)
    assert np.array_equal(velocity_m_s, direct.velocity.m_per_s.T)


def test_sparse_epochs_days_apart(orbit):
    # Only the node intervals around each epoch are computed; each is still exact.
    times = time_from_tt_seconds(START, [-86400.0 * 2 + 7.5, 3.25, 86400.0 * 5 + 59.9])
    position_m, _ = orbit.position_velocity(times)
    direct = orbit.satellite.at(_skyfield(times)).position.m.T
    assert np.linalg.norm(position_m - direct, axis=-1).max() < 0.4


def test_shapes(orbit):
    scalar = orbit.position_velocity(START)
    assert scalar[0].shape == scalar[1].shape == (3,)
    grid = time_from_tt_seconds(START, np.arange(6.0).reshape(2, 3) * 1000.0)
    assert orbit.position_velocity(grid)[0].shape == (2, 3, 3)
    assert orbit.sun_position_from_spacecraft(grid).shape == (2, 3, 3)
    assert orbit.nadir_direction(grid).shape == (2, 3, 3)
    assert orbit.earth_angular_radius(grid).shape == (2, 3)
    assert orbit.position_velocity("2014-01-21T06:00:00")[0].shape == (3,)


def test_sun_from_spacecraft_is_skyfields_apparent_place(orbit):
    times = time_from_tt_seconds(START, np.linspace(0.0, 86400.0, 300))
    eph = _ephemeris()
    t = _skyfield(times)
    expected = (eph["earth"] + orbit.satellite).at(t).observe(eph["sun"]).apparent()
    sun_m = orbit.sun_position_from_spacecraft(times)
    error = _angle(sun_m, expected.position.m.T) / ARCSEC
    assert error.max() < 0.002, error.max()
    assert np.allclose(np.linalg.norm(sun_m, axis=-1), expected.distance().m, rtol=1e-10)
    # The geometric vector (Sun minus spacecraft, same instant) is 19–24" away:
    # aberration of the Earth's 30 km/s and the orbit's 7.7 km/s.
    geometric = (eph["sun"] - eph["earth"]).at(t).position.m - orbit.satellite.at(t).position.m
    shift = _angle(sun_m, geometric.T) / ARCSEC
    assert 18.0 < shift.min() and shift.max() < 25.0, (shift.min(), shift.max())


def test_nadir_and_earth_angular_radius(orbit):
    times = time_from_tt_seconds(START, np.linspace(0.0, 6000.0, 50))
    r_m = orbit.satellite.at(_skyfield(times)).position.m.T
    nadir = orbit.nadir_direction(times)
    assert np.allclose(np.linalg.norm(nadir, axis=-1), 1.0, atol=1e-15)
    assert (_angle(nadir, -r_m) / ARCSEC).max() < 0.01  # 0.4 m at 6 800 km: 0.01"
    radius_rad = orbit.earth_angular_radius(times)
    expected = np.arcsin(EARTH_EQUATORIAL_RADIUS_M / np.linalg.norm(r_m, axis=-1))
    # d(asin(R/r))/dr = −tan(b)/r = 4e-7 rad per metre: 0.4 m gives 0.03".
    assert np.allclose(radius_rad, expected, rtol=0, atol=2e-7)
    assert np.all((np.degrees(radius_rad) > 69.0) & (np.degrees(radius_rad) < 71.0))


def test_the_epoch_is_the_tles():
    with offline_time():
        assert TleOrbit(LINE1, LINE2).epoch.utc.isot == "2014-01-20T22:23:04.000"
