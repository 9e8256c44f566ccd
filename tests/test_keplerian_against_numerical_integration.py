"""Keplerian orbits against an independent integration of the two-body problem.

scipy's DOP853 at rtol 1e-13 integrates r'' = −μ r/|r|³ from the state our closed form
gives at the epoch; the two must agree along the orbit.  Measured over a day: 0.3 mm on
a Molniya orbit (e = 0.74), less on the others.  The J2 secular rates are checked
against the sun-synchronous condition: at 700 km (a = 7078.137 km, e = 0) an orbit
inclined 98.19° turns its node with the mean Sun, 360° in 365.2422 days (the inclination
tabulated for that altitude, e.g. Wertz and Larson, *Space Mission Analysis and Design*,
3rd ed., 1999, on sun-synchronous orbits).
"""

import math

import numpy as np
import pytest
from astropy import units as u
from scipy.integrate import solve_ivp

from attitude.base.errors import InputError
from attitude.environment.earth import GM_EARTH_M3_S2
from attitude.environment.frames import eme2000_to_icrf
from attitude.environment.keplerian import KeplerianOrbit, solve_kepler
from attitude.environment.timescales import time_from_tt_seconds

EPOCH = "2027-06-21T00:00:00"
ORBITS = {
    "circular LEO": dict(semi_major_axis_m=6_878_137.0, eccentricity=0.0, inclination=0.9),
    "e = 0.1": dict(semi_major_axis_m=8_000_000.0, eccentricity=0.1, inclination=0.5),
    "Molniya e = 0.74": dict(
        semi_major_axis_m=26_600_000.0, eccentricity=0.74, inclination=math.radians(63.4)
    ),
    "GEO": dict(semi_major_axis_m=42_164_000.0, eccentricity=0.0002, inclination=0.001),
}


def _two_body(t, y):
    r = y[:3]
    return np.concatenate([y[3:], -GM_EARTH_M3_S2 * r / np.linalg.norm(r) ** 3])


@pytest.mark.parametrize("name", list(ORBITS))
def test_two_body_against_dop853(name):
    orbit = KeplerianOrbit(
        EPOCH, raan=0.7, argument_of_perigee=4.0, mean_anomaly=2.5, **ORBITS[name]
    )
    seconds = np.linspace(0.0, 86400.0, 1441)
    r, v = orbit.position_velocity(time_from_tt_seconds(orbit.epoch, seconds))
    solution = solve_ivp(
        _two_body,
        (0.0, 86400.0),
        np.concatenate([r[0], v[0]]),
        method="DOP853",
        rtol=1e-13,
        atol=1e-7,
        t_eval=seconds,
    )
    assert np.abs(solution.y[:3].T - r).max() < 3e-3  # m; measured ≤ 0.3 mm
    assert np.abs(solution.y[3:].T - v).max() < 1e-6  # m/s


def test_elements_at_the_epoch_by_hand():
    # At perigee on the x axis (Ω = ω = 0, i = 0): r = a (1 − e), v = √(μ (1 + e)/(a (1 − e))).
    a, e = 7_500_000.0, 0.05
    orbit = KeplerianOrbit(EPOCH, a, e, 0.0, 0.0, 0.0, true_anomaly=0.0)
    r, v = orbit.position_velocity(orbit.epoch)
    np.testing.assert_allclose(r, [a * (1 - e), 0.0, 0.0], atol=1e-6)
    speed = math.sqrt(GM_EARTH_M3_S2 * (1 + e) / (a * (1 - e)))
    np.testing.assert_allclose(v, [0.0, speed, 0.0], atol=1e-9)
    # A true anomaly of 90° from perigee: r = p = a (1 − e²), on the y axis.
    r, _ = KeplerianOrbit(EPOCH, a, e, 0.0, 0.0, 0.0, true_anomaly=90 * u.deg).position_velocity(
        orbit.epoch
    )
    np.testing.assert_allclose(r, [0.0, a * (1 - e * e), 0.0], atol=1e-6)


def test_kepler_equation():
    M = np.linspace(-10.0, 10.0, 2001)
    for e in (0.0, 0.3, 0.9, 0.999):
        E = solve_kepler(M, e)
        wrapped = np.remainder(M + math.pi, 2 * math.pi) - math.pi
        assert np.abs(E - e * np.sin(E) - wrapped).max() < 1e-14


def test_j2_turns_a_sun_synchronous_node_with_the_sun():
    orbit = KeplerianOrbit(
        EPOCH, 7_078_137.0, 0.0, 98.19 * u.deg, 0.0, 0.0, mean_anomaly=0.0, j2=True
    )
    degrees_per_day = math.degrees(orbit.raan_rate) * 86400.0
    assert degrees_per_day == pytest.approx(360.0 / 365.2422, rel=2e-3)
    # The velocity is the derivative of the position, the turning node included.
    h = 0.01
    seconds = np.array([5000.0 - h, 5000.0, 5000.0 + h])
    r, v = orbit.position_velocity(time_from_tt_seconds(orbit.epoch, seconds))
    np.testing.assert_allclose((r[2] - r[0]) / (2 * h), v[1], atol=2e-4)


def test_eme2000_elements_are_rotated_by_the_frame_bias():
    elements = dict(mean_anomaly=1.0, **ORBITS["e = 0.1"])
    icrf = KeplerianOrbit(EPOCH, raan=0.7, argument_of_perigee=4.0, **elements)
    eme = KeplerianOrbit(EPOCH, raan=0.7, argument_of_perigee=4.0, frame="EME2000", **elements)
    r_icrf, _ = icrf.position_velocity(icrf.epoch)
    r_eme, _ = eme.position_velocity(eme.epoch)
    np.testing.assert_allclose(r_eme, eme2000_to_icrf().apply(r_icrf), atol=1e-6)
    shift = np.arccos(np.dot(r_eme, r_icrf) / np.linalg.norm(r_eme) / np.linalg.norm(r_icrf))
    assert 0.0 < math.degrees(shift) * 3.6e6 < 23.1  # mas: the bias, no more


@pytest.mark.parametrize(
    "change, message",
    [
        (dict(eccentricity=1.0), r"eccentricity: must be in \[0, 1\)"),
        (dict(semi_major_axis_m=6_000_000.0), r"the perigee, .* is inside the Earth"),
        (dict(inclination=4.0), r"inclination: must be between 0 and 180 deg"),
        (dict(inclination=30.0 * u.s), r"inclination has unit s"),
        (dict(frame="ITRF"), r"frame: must be one of ICRF, EME2000"),
    ],
)
def test_bad_elements(change, message):
    elements = dict(
        semi_major_axis_m=7_000_000.0,
        eccentricity=0.01,
        inclination=1.0,
        raan=0.0,
        argument_of_perigee=0.0,
        mean_anomaly=0.0,
    )
    with pytest.raises(InputError, match=message):
        KeplerianOrbit(EPOCH, **(elements | change))
