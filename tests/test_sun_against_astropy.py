"""The apparent Sun from DE421 (skyfield) against astropy's own ephemeris, 1900–2050.

astropy's builtin ephemeris is ERFA's epv00 (VSOP2000-based), independent of JPL
DE421.  The comparison is the one docs/pointing.md describes ("The Sun's direction:
which place, which frame"): the astrometric vector (light time, one iteration) from
``get_body_barycentric``, then astropy's ICRS→GCRS transform applied to it **as a
direction** (a ``UnitSphericalRepresentation``), so that astropy adds the aberration
only.  ``get_body("sun")`` itself is not used: it keeps the Sun's distance, and astropy
then deflects the Sun's light by the Sun along a "Sun → object" vector that is a
few-km residual of arbitrary direction (erratic errors, up to 4.6" measured).  The
pair agrees to 0.0156" every 10 days over 1900–2050; over the 500 epochs here to
0.0143" (mean 0.0044"), and the distances to 3.5e-8 (5 km).
"""

import numpy as np
import pytest
from astropy.coordinates import get_body_barycentric, solar_system_ephemeris
from astropy.time import Time
from reference_models import astropy_apparent_sun

from attitude.base.errors import InputError
from attitude.environment.ephemeris import (
    EphemerisRangeError,
    sun_direction_from_earth,
    sun_position_from_earth,
)
from attitude.environment.timescales import offline_time

ARCSEC = np.pi / (180 * 3600)


def _angle(u_vectors, v_vectors):
    return np.arctan2(
        np.linalg.norm(np.cross(u_vectors, v_vectors), axis=-1),
        np.sum(u_vectors * v_vectors, axis=-1),
    )


def test_sun_direction_agrees_with_astropy_1900_to_2050():
    times = Time(np.linspace(2415021.0, 2469807.0, 500), format="jd", scale="tt")
    expected, distance_m = astropy_apparent_sun(times)
    position_m = sun_position_from_earth(times)
    direction = sun_direction_from_earth(times)
    assert position_m.shape == direction.shape == (500, 3)
    assert np.allclose(np.linalg.norm(direction, axis=-1), 1.0, rtol=0, atol=1e-15)
    error = _angle(direction, expected) / ARCSEC
    # 0.016" is the difference of the two ephemerides; without aberration it would
    # be 20", without light time ≈ 0.01" more.
    assert error.max() < 0.03, f"max {error.max():.4f} arcsec"
    # Distances: epv00 and DE421 differ by a few km in 150 million.
    assert np.max(np.abs(np.linalg.norm(position_m, axis=-1) / distance_m - 1)) < 1e-7


def test_direction_is_the_apparent_place_not_the_geometric_one():
    # The annual aberration, 20.5" ± 0.35" (eccentric orbit), separates the two.
    times = Time(np.linspace(2451545.0, 2451545.0 + 365.0, 25), format="jd", scale="tt")
    with offline_time(), solar_system_ephemeris.set("builtin"):
        geometric = get_body_barycentric("sun", times) - get_body_barycentric("earth", times)
        geometric = np.moveaxis(geometric.xyz.value, 0, -1)
    shift = _angle(sun_direction_from_earth(times), geometric) / ARCSEC
    assert np.all((shift > 20.0) & (shift < 21.0)), shift


def test_scalar_and_shaped_epochs():
    scalar = Time("2026-03-20T14:46:00", scale="utc")
    assert sun_position_from_earth(scalar).shape == (3,)
    grid = Time(["2026-03-20T14:46:00"] * 6, scale="utc").reshape(2, 3)
    assert sun_direction_from_earth(grid).shape == (2, 3, 3)
    # ISO strings are UTC epochs.
    assert np.array_equal(
        sun_position_from_earth("2026-03-20T14:46:00"), sun_position_from_earth(scalar)
    )


@pytest.mark.parametrize(
    "epoch, scale",
    [
        ("1899-07-28T23:00:00", "tdb"),
        ("1850-01-01T00:00:00", "utc"),
        ("2053-10-09T00:00:01", "tdb"),
        ("2100-01-01T00:00:00", "tt"),
    ],
)
def test_epochs_outside_de421_raise_a_clear_error(epoch, scale):
    with offline_time():
        times = Time(epoch, scale=scale)
    with pytest.raises(EphemerisRangeError) as caught:
        sun_position_from_earth(times)
    message = str(caught.value)
    assert "1899-07-29 to 2053-10-09" in message
    assert epoch[:10] in message
    assert isinstance(caught.value, InputError) and isinstance(caught.value, ValueError)


def test_the_offending_epoch_of_an_array_is_named():
    with offline_time():
        times = Time(["2000-01-01", "2020-01-01", "2060-05-05", "2070-01-01"], scale="tt")
    with pytest.raises(EphemerisRangeError, match=r"2060-05-05.*\(index 2, 2 of 4 outside\)"):
        sun_direction_from_earth(times)


def test_the_edges_of_the_span():
    with offline_time():
        inside = Time(["1899-07-29T00:10:01", "2053-10-08T23:59:59"], scale="tdb")
        too_early = Time("1899-07-29T00:05:00", scale="tdb")  # less than a light time in
    assert np.all(np.isfinite(sun_position_from_earth(inside)))
    with pytest.raises(EphemerisRangeError, match="1899-07-29T00:05:00"):
        sun_position_from_earth(too_early)
