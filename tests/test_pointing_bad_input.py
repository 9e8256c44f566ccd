"""Bad input to the pointing layer gets a clear InputError naming the field and value."""

import numpy as np
import pytest
from astropy import units as u
from sgp4.io import fix_checksum

from attitude.base.errors import InputError
from attitude.environment.ephemeris import sun_position_from_observer
from attitude.environment.orbit import TleOrbit
from attitude.pointing.eclipse import eclipse_intervals, eclipse_state, sunlit_fraction

LINE1 = "1 25544U 98067A   14020.93268519  .00009878  00000-0  18200-3 0  5082"
LINE2 = "2 25544  51.6498 109.4756 0003572  55.9686 274.8005 15.49815350868473"
SUN_M = [1.496e11, 0.0, 0.0]


@pytest.mark.parametrize(
    "line1, line2, message",
    [
        (None, LINE2, r"line1 must be a string, got None"),
        (LINE1[:60], LINE2, r"line1 must have 69 characters, got 60: '1 25544U"),
        (LINE2, LINE1, r"line1 must start with '1 ', got '2 25544"),
        (LINE1, LINE2 + "é", r"line2 must be ASCII"),
        (LINE1[:-1] + "7", LINE2, r"line1: checksum is '7' but the line tallies to 2"),
        (LINE1, LINE2[:-1] + "0", r"line2: checksum is '0' but the line tallies to 3"),
        (
            LINE1,
            fix_checksum(LINE2.replace("2 25544", "2 25545")),
            r"line2: catalog number '25545' differs from line1's '25544'",
        ),
        (
            LINE1,
            fix_checksum(LINE2.replace(" 51.6498", "51.64980")),
            r"line2: columns do not follow the TLE layout '2 NNNNN NNN.NNNN",
        ),
        (
            fix_checksum(LINE1.replace("14020.93", "14x20.93")),
            LINE2,
            r"line1: columns 21-32 \(epoch day\) hold 'x20\.93268519', not a number as the TLE "
            r"layout writes it",
        ),
        (
            LINE1,
            fix_checksum(LINE2.replace("0003572", "00035x2")),
            r"line2: columns 27-33 \(eccentricity\) hold '00035x2', not a number",
        ),
        (
            LINE1,
            fix_checksum(LINE2.replace("15.49815350", "00.00000000")),
            r"line2: SGP4 cannot start from these elements \(a division by zero in its "
            r"initialisation; mean motion 00.00000000 rev/day",
        ),
        (
            LINE1,
            fix_checksum(LINE2.replace("0003572", "9993572")),
            r"line2: SGP4 rejects the elements: semilatus rectum is less than zero "
            r"\(eccentricity 0.9993572",
        ),
    ],
)
def test_bad_tle(line1, line2, message):
    with pytest.raises(InputError, match=message):
        TleOrbit(line1, line2)


def test_surrounding_blanks_are_fine():
    assert TleOrbit(f"  {LINE1} \n", f"{LINE2}\r\n").satellite.model.satnum == 25544


@pytest.mark.parametrize("step_s", [0.0, -60.0, -1 * u.min, np.nan, 1e6])
def test_bad_rotation_step(step_s):
    with pytest.raises(InputError, match="rotation_step_s must be"):
        TleOrbit(LINE1, LINE2, rotation_step_s=step_s)


def test_step_in_minutes_is_converted():
    assert TleOrbit(LINE1, LINE2, rotation_step_s=0.5 * u.h).rotation_step_s == 1800.0


def test_bad_epochs_for_an_orbit():
    orbit = TleOrbit(LINE1, LINE2)
    with pytest.raises(InputError, match="times: not an ISO 8601 epoch: 'yesterday'"):
        orbit.position_velocity("yesterday")
    # 26 years on, SGP4's mean eccentricity has left [0, 1).
    with pytest.raises(InputError, match=r"times: SGP4 fails near 2040-01-01 .* eccentricity"):
        orbit.position_velocity(["2014-01-21T00:00:00", "2040-01-01T00:00:00"])


@pytest.mark.parametrize(
    "r_sat_m, message",
    [
        ([1.0e6, 0.0, 0.0], r"r_sat_m: the spacecraft is inside the Earth, 1000000.0 m from "),
        ([[7.0e6, 0.0, 0.0], [0.0, 1.0e6, 0.0]], r"inside the Earth, .* at index 1"),
        ([1.496e11, 1.0e8, 0.0], r"r_sun_m - r_sat_m: the spacecraft is inside the Sun"),
        ([7.0e6, 0.0], r"r_sat_m must be vectors of shape \(..., 3\), got shape \(2,\)"),
        ([7.0e6, np.nan, 0.0], r"r_sat_m must be finite, got nan at index 1"),
        (["a", "b", "c"], r"r_sat_m must be numeric"),
        ([7.0e6, 0.0, 0.0] * u.s, r"r_sat_m has unit s, which cannot be converted to m"),
    ],
)
def test_bad_vectors_for_the_shadow(r_sat_m, message):
    with pytest.raises(InputError, match=message):
        sunlit_fraction(r_sat_m, SUN_M)
    with pytest.raises(InputError, match=message):
        eclipse_state(r_sat_m, SUN_M)


def test_lengths_may_be_quantities():
    assert sunlit_fraction([-7.0e3, 0.0, 0.0] * u.km, np.array(SUN_M) * u.m) == 0.0
    assert sunlit_fraction([7.0e6, 0.0, 0.0], SUN_M, earth_radius_m=6400 * u.km) == 1.0


@pytest.mark.parametrize("radius", [0.0, -1.0, np.inf, [1.0, 2.0]])
def test_bad_radii(radius):
    with pytest.raises(InputError, match="earth_radius_m must be"):
        sunlit_fraction([7.0e6, 0.0, 0.0], SUN_M, earth_radius_m=radius)


def test_observer_vectors_must_match_the_epochs():
    with pytest.raises(
        InputError, match=r"position_m must have shape \(2, 3\) \(times.shape \+ \(3,\)\)"
    ):
        sun_position_from_observer(["2020-01-01", "2020-01-02"], [7e6, 0, 0], [0, 7e3, 0])


def test_eclipse_span_must_go_forward():
    orbit = TleOrbit(LINE1, LINE2)
    with pytest.raises(InputError, match="stop must be after start, got 2014-01-21T01:00:00"):
        eclipse_intervals(orbit, "2014-01-21T01:00:00", "2014-01-21T00:00:00")
    with pytest.raises(InputError, match=r"step_s must be positive, got 0\.0"):
        eclipse_intervals(orbit, "2014-01-21T00:00:00", "2014-01-21T01:00:00", step_s=0.0)
