"""TleOrbit against direct SGP4 (skyfield's ``EarthSatellite.at``) on Vallado's satellites.

The verification TLEs of Vallado, Crawford, Hujsak and Kelso, "Revisiting Spacetrack
Report #3", AIAA 2006-6753 (file SGP4-VER.TLE, shipped in the ``sgp4`` package): the
eccentric and deep-space ones included.  The reference is skyfield's own
``EarthSatellite.at`` at every epoch (SGP4 in TEME, rotated to the GCRS with the full
IAU 2000A nutation, 45–80 µs an epoch).  ``TleOrbit`` runs the same SGP4 at every epoch
and interpolates only the TEME → GCRS rotation (whole TT hours, cubic Lagrange).
Measured over a day at 10 s: ≤ 3 µm and ≤ 0.6 nm/s on every satellite below.
"""

import importlib.resources
import itertools
import pickle

import numpy as np
import pytest
from astropy.time import Time

from attitude.environment.earth import EARTH_EQUATORIAL_RADIUS_M, angular_radius
from attitude.environment.ephemeris import _ephemeris, sun_position_from_observer, timescale
from attitude.environment.orbit import TleOrbit
from attitude.environment.timescales import offline_time, time_from_tt_seconds

# ISS (ZARYA), a real element set (as printed in the skyfield documentation).
LINE1 = "1 25544U 98067A   14020.93268519  .00009878  00000-0  18200-3 0  5082"
LINE2 = "2 25544  51.6498 109.4756 0003572  55.9686 274.8005 15.49815350868473"
START = Time("2014-01-21T00:00:00", scale="utc")
ARCSEC = np.pi / (180 * 3600)

# Vallado et al. (2006), by catalogue number: what each one exercises.
VALLADO = {
    "00005": "near-Earth, e = 0.186",
    "06251": "near-Earth, perigee 377 km, drag",
    "28057": "near-Earth, sun-synchronous, e = 0.0001",
    "08195": "Molniya 2-14, 12 h resonant, e = 0.69",
    "09880": "Molniya 1-36, 12 h resonant, e = 0.71",
    "21897": "Molniya 1-83, e = 0.74, negative drag term",
    "11801": "deep space, e = 0.73 (Spacetrack Report #3's SDP4 case)",
    "23599": "Ariane R/B, e = 0.58, Lyddane choice",
    "14128": "Eutelsat 1-F1, 24 h resonant, i = 11°",
    "28626": "XM-3, geostationary",
}


def _vallado_tles() -> dict[str, tuple[str, str]]:
    text = (importlib.resources.files("sgp4") / "SGP4-VER.TLE").read_text()
    lines = text.splitlines()
    found = {}
    for first, second in itertools.pairwise(lines):
        if first.startswith("1 ") and second.startswith("2 "):
            found[first[2:7]] = (first[:69], second[:69])  # past column 69: the test span
    return found


TLES = _vallado_tles()


def _skyfield(times):
    with offline_time():
        return timescale().tt_jd(np.ravel(times.tt.jd1), np.ravel(times.tt.jd2))


def _angle(u, v):
    return np.arctan2(np.linalg.norm(np.cross(u, v), axis=-1), np.sum(u * v, axis=-1))


def _errors(orbit: TleOrbit, times) -> tuple[float, float]:
    position_m, velocity_m_s = orbit.position_velocity(times)
    direct = orbit.satellite.at(_skyfield(times))
    return (
        float(np.linalg.norm(position_m - direct.position.m.T, axis=-1).max()),
        float(np.linalg.norm(velocity_m_s - direct.velocity.m_per_s.T, axis=-1).max()),
    )


@pytest.mark.parametrize("number", list(VALLADO), ids=[f"{k} {v}" for k, v in VALLADO.items()])
def test_vallado_satellites_against_direct_sgp4(number):
    orbit = TleOrbit(*TLES[number])
    times = time_from_tt_seconds(orbit.epoch, np.arange(0.0, 86400.0, 10.0))
    position_error_m, velocity_error_m_s = _errors(orbit, times)
    assert position_error_m < 1e-4, position_error_m  # measured ≤ 3e-6 m
    assert velocity_error_m_s < 1e-7, velocity_error_m_s  # measured ≤ 6e-10 m/s


@pytest.mark.slow
@pytest.mark.parametrize("number", list(VALLADO))
def test_vallado_satellites_every_second_for_three_days(number):
    orbit = TleOrbit(*TLES[number])
    times = time_from_tt_seconds(orbit.epoch, np.arange(-86400.0, 2 * 86400.0, 1.0))
    position_error_m, velocity_error_m_s = _errors(orbit, times)
    assert position_error_m < 1e-4 and velocity_error_m_s < 1e-7


def test_the_velocity_is_sgp4s_not_the_derivative_of_its_positions():
    # On an eccentric orbit SGP4's velocity and the derivative of its positions differ
    # by about a metre per second: each output is SGP4's own, as direct SGP4 gives it.
    orbit = TleOrbit(*TLES["00005"])
    seconds = np.arange(0.0, 8000.0, 20.0)
    step = 0.05
    times = [time_from_tt_seconds(orbit.epoch, seconds + d) for d in (-step, 0.0, step)]
    (before, _), (_, velocity_m_s), (after, _) = (orbit.position_velocity(t) for t in times)
    derivative = (after - before) / (2 * step)
    assert np.linalg.norm(velocity_m_s - derivative, axis=-1).max() > 0.3
    assert _errors(orbit, times[1])[1] < 1e-7


def test_without_rotation_nodes_it_is_skyfield():
    exact = TleOrbit(LINE1, LINE2, rotation_step_s=None)
    times = time_from_tt_seconds(START, [0.0, 12.345, 1e5])
    position_m, velocity_m_s = exact.position_velocity(times)
    direct = exact.satellite.at(_skyfield(times))
    assert np.array_equal(position_m, direct.position.m.T)
    assert np.array_equal(velocity_m_s, direct.velocity.m_per_s.T)


def test_sparse_epochs_years_apart():
    # Far-apart epochs take only the rotation nodes around them; each is still exact.
    orbit = TleOrbit(LINE1, LINE2)
    times = time_from_tt_seconds(START, [-86400.0 * 2 + 7.5, 3.25, 86400.0 * 5 + 59.9])
    assert _errors(orbit, times)[0] < 1e-4


def test_shapes_and_pickling():
    orbit = TleOrbit(LINE1, LINE2, "ISS (ZARYA)")
    scalar = orbit.position_velocity(START)
    assert scalar[0].shape == scalar[1].shape == (3,)
    grid = time_from_tt_seconds(START, np.arange(6.0).reshape(2, 3) * 1000.0)
    assert orbit.position_velocity(grid)[0].shape == (2, 3, 3)
    assert orbit.position_velocity("2014-01-21T06:00:00")[0].shape == (3,)
    # Monte Carlo workers receive orbits by pickle (sgp4's Satrec alone cannot be).
    copy = pickle.loads(pickle.dumps(orbit))
    assert np.array_equal(copy.position_velocity(grid)[0], orbit.position_velocity(grid)[0])


def test_sun_from_spacecraft_is_skyfields_apparent_place():
    orbit = TleOrbit(LINE1, LINE2)
    times = time_from_tt_seconds(START, np.linspace(0.0, 86400.0, 300))
    eph = _ephemeris()
    t = _skyfield(times)
    expected = (eph["earth"] + orbit.satellite).at(t).observe(eph["sun"]).apparent()
    sun_m = sun_position_from_observer(times, *orbit.position_velocity(times))
    error = _angle(sun_m, expected.position.m.T) / ARCSEC
    assert error.max() < 0.002, error.max()
    assert np.allclose(np.linalg.norm(sun_m, axis=-1), expected.distance().m, rtol=1e-10)
    # The geometric vector (Sun minus spacecraft, same instant) is 19–24" away:
    # aberration of the Earth's 30 km/s and the orbit's 7.7 km/s.
    geometric = (eph["sun"] - eph["earth"]).at(t).position.m - orbit.satellite.at(t).position.m
    shift = _angle(sun_m, geometric.T) / ARCSEC
    assert 18.0 < shift.min() and shift.max() < 25.0, (shift.min(), shift.max())


def test_earth_angular_radius_by_hand():
    # From 7000 km the sphere of 6378.137 km subtends asin(6378.137/7000); with 100 km
    # of atmosphere, asin(6478.137/7000); from inside, half the sky.
    r = np.array([[7.0e6, 0.0, 0.0], [0.0, -7.0e6, 0.0], [0.0, 0.0, 6.0e6]])
    expected = np.arcsin(EARTH_EQUATORIAL_RADIUS_M / 7.0e6)
    assert np.allclose(angular_radius(r[:2]), expected, rtol=0, atol=1e-15)
    assert angular_radius(r[0], 1e5) == pytest.approx(np.arcsin(6478137.0 / 7.0e6), abs=1e-15)
    assert angular_radius(r[2]) == pytest.approx(np.pi / 2)


def test_the_epoch_is_the_tles():
    with offline_time():
        assert TleOrbit(LINE1, LINE2).epoch.utc.isot == "2014-01-20T22:23:04.000"
