"""Each law's definition against the same geometry computed another way: the LVLH and
RTN frames of attitude.environment.frames, ERFA's geodetic conversions (gc2gd, gd2gc),
differences of the sub-satellite point, skyfield's apparent Sun and Moon at every
epoch, the pointing layer's interpolated Sun and Moon, and astropy's GCRS of a site."""

import math

import astropy.units as u
import erfa
import numpy as np
import pytest
from astropy.coordinates import EarthLocation
from astropy.time import Time
from scipy.spatial.transform import Rotation

from attitude.environment.earth_rotation import itrs_to_gcrs
from attitude.environment.ephemeris import (
    SunMoonFromEarth,
    apparent_from_observer,
    moon_position_from_observer,
    sun_position_from_observer,
)
from attitude.environment.frames import lvlh_to_icrf, rtn_to_icrf
from attitude.environment.keplerian import KeplerianOrbit
from attitude.environment.orbit import TleOrbit
from attitude.environment.timescales import offline_time, time_from_tt_seconds
from attitude.laws.directions import GroundSite, geodetic_nadir
from attitude.laws.named_laws import NadirLaw, OrbitFrameLaw, SunLaw, TargetLaw

EPOCH = Time("2024-06-15T00:00:00", scale="utc")
SECONDS = np.linspace(0.0, 6000.0, 41)
TLE = (
    "1 25544U 98067A   24166.50000000  .00016717  00000-0  10270-3 0  9001",
    "2 25544  51.6416 247.4627 0006703 130.5360 325.0288 15.72125391563537",
)
SSO = KeplerianOrbit(
    EPOCH, 7_078_137.0, 0.0012, math.radians(98.19), math.radians(63.0), math.radians(90.0),
    mean_anomaly=math.radians(10.0), j2=True,
)  # fmt: skip


def _angle(a, b):
    a = a / np.linalg.norm(a, axis=-1, keepdims=True)
    b = b / np.linalg.norm(b, axis=-1, keepdims=True)
    return np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.sum(a * b, axis=-1))


def _state(law, orbit):
    bound = law.bind(EPOCH, SECONDS[0], SECONDS[-1], orbit)
    at = bound.at(SECONDS)
    return bound.state(SECONDS), at


@pytest.mark.parametrize("orbit", [SSO, TleOrbit(*TLE)], ids=["keplerian", "sgp4"])
def test_orbit_frame_laws_are_the_frames_of_environment_frames(orbit):
    offset = Rotation.from_rotvec([0.2, -0.4, 1.1])
    for frame, to_icrf in (("lvlh", lvlh_to_icrf), ("rtn", rtn_to_icrf)):
        state, at = _state(OrbitFrameLaw(frame, offset), orbit)
        expected = to_icrf(at.position.value, at.velocity.value) * offset
        assert (expected.inv() * state.attitude).magnitude().max() < 1e-15
    state, at = _state(NadirLaw(vertical="geocentric"), orbit)
    expected = lvlh_to_icrf(at.position.value, at.velocity.value)
    assert (expected.inv() * state.attitude).magnitude().max() < 1e-15


def test_geodetic_nadir_against_erfa_gc2gd():
    """+z of the nadir law is down the WGS 84 normal through the spacecraft.  ERFA's
    gc2gd (Fukushima's closed form) is good to ~2e-13 rad and 1e-6 m here; our foot
    point is checked to rounding directly: on the ellipsoid, and below the spacecraft
    along the ellipsoid's normal there."""
    state, at = _state(NadirLaw(), SSO)
    p = at.position_itrs.value
    longitude, latitude, _ = erfa.gc2gd(1, p)
    normal = np.stack(
        [
            np.cos(latitude) * np.cos(longitude),
            np.cos(latitude) * np.sin(longitude),
            np.sin(latitude),
        ],
        axis=-1,
    )
    down = -np.einsum("nij,nj->ni", at.itrs_to_gcrs.value, normal)
    z = state.attitude.apply([0.0, 0.0, 1.0])
    assert _angle(z, down).max() < 1e-12
    _, foot = geodetic_nadir(at.position_itrs)
    expected = np.stack(
        [erfa.gd2gc(1, lo, la, 0.0) for lo, la in zip(longitude, latitude, strict=True)]
    )
    assert np.abs(foot.value - expected).max() < 1e-5  # m
    a, f = erfa.eform(1)
    scale = np.array([a, a, a * (1.0 - f)])
    assert np.abs(np.sum((foot.value / scale) ** 2, axis=-1) - 1.0).max() < 2e-15
    gradient = foot.value / scale**2
    up_itrs = gradient / np.linalg.norm(gradient, axis=-1, keepdims=True)
    assert _angle(p - foot.value, up_itrs).max() < 3e-15
    assert _angle(-np.einsum("nij,nj->ni", at.itrs_to_gcrs.value, up_itrs), z).max() < 3e-15


def test_zero_doppler_x_axis_follows_the_differenced_ground_track():
    """+x along the velocity of the sub-satellite point relative to the ground: here the
    foot point (ERFA gc2gd then gd2gc) differenced over ±0.05 s in the ITRS."""
    law = NadirLaw("zero_doppler")
    state, at = _state(law, SSO)
    h = 0.05
    bound = law.bind(EPOCH, SECONDS[0] - 1.0, SECONDS[-1] + 1.0, SSO)

    def foot(seconds):
        lon, lat, _ = erfa.gc2gd(1, bound.at(seconds).position_itrs.value)
        return np.stack([erfa.gd2gc(1, a, b, 0.0) for a, b in zip(lon, lat, strict=True)])

    ground_itrs = (foot(SECONDS + h) - foot(SECONDS - h)) / (2 * h)
    ground = np.einsum("nij,nj->ni", at.itrs_to_gcrs.value, ground_itrs)
    x = state.attitude.apply([1.0, 0.0, 0.0])
    z = state.attitude.apply([0.0, 0.0, 1.0])
    across = ground - np.sum(ground * z, axis=-1, keepdims=True) * z
    assert _angle(x, across).max() < 1e-8
    # Over the poles too: a polar orbit (tested in test_law_degenerate_cases.py).


def test_sun_and_moon_against_skyfield_at_every_epoch():
    """The apparent Sun and Moon the laws point at, against skyfield's at each epoch
    (DE421 read directly, aberration by ERFA): the Hermite interpolation and the jets."""
    times = time_from_tt_seconds(EPOCH, SECONDS)
    for law, body, direct, limit in (
        (SunLaw(), "sun", sun_position_from_observer, 5e-10),
        (TargetLaw("moon"), "moon", moon_position_from_observer, 5e-10),
    ):
        state, at = _state(law, SSO)
        r, v = at.position.value, at.velocity.value
        expected = direct(times, r, v)
        assert _angle(state.attitude.apply([0.0, 0.0, 1.0]), expected).max() < limit, body


def test_sun_and_moon_are_the_pointing_layers_to_rounding():
    """The same apparent directions as the pointing layer's (SunMoonFromEarth.at and
    apparent_from_observer, as attitude.pointing.surroundings calls them)."""
    _, at = _state(SunLaw(), TleOrbit(*TLE))
    bodies = SunMoonFromEarth(at.inputs.jd1, at.jd2[0], at.jd2[-1]).at(at.jd2)
    r, v = at.position.value, at.velocity.value
    distance = np.linalg.norm(bodies["sun_m"] - r, axis=-1)
    for body in ("sun", "moon"):
        expected = apparent_from_observer(
            bodies[f"{body}_m"],
            bodies[f"{body}_velocity_m_s"],
            bodies["earth_velocity_m_s"],
            r,
            v,
            distance,
        )
        assert _angle(at.apparent(body).value, expected).max() < 1e-15
        assert (
            np.abs(
                np.linalg.norm(at.apparent(body).value, axis=-1) / np.linalg.norm(expected, axis=-1)
                - 1
            ).max()
            < 1e-14
        )


def test_site_position_against_astropy():
    """A site's GCRS position: C(t) · ITRS against astropy's EarthLocation.get_gcrs_posvel.
    astropy leaves out the IERS offsets of the celestial pole dX, dY (0.2–0.5 mas, about
    1 cm on the ground), which our C, as the IERS Conventions and Orekit, applies."""
    site = GroundSite(math.radians(43.5605), math.radians(1.4688), 150.0)
    with offline_time():
        location = EarthLocation.from_geodetic(
            site.longitude * u.rad, site.latitude * u.rad, site.height * u.m
        )
        assert (
            np.abs(
                np.array([location.x.value, location.y.value, location.z.value]) - site.itrs_m
            ).max()
            < 1e-8
        )
        for text in ("2024-06-15T00:00:00", "2024-06-15T07:30:00", "2019-03-01T13:00:00"):
            t = Time(text, scale="utc")
            position, _ = location.get_gcrs_posvel(t)
            tt = t.tt
            ours = (
                itrs_to_gcrs(np.array([tt.jd1]), np.array([tt.jd2]), order=0).value[0] @ site.itrs_m
            )
            assert np.abs(position.xyz.to_value(u.m) - ours).max() < 0.03
