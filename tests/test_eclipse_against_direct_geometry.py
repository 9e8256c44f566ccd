"""The conical shadow model against direct geometry: cones in space, rays to the Sun.

Two independent computations:

- the **edges** of the shadow from the tangent cones of the Sun and Earth spheres
  in space (the penumbra's cone through the inner centre of similitude, between
  the two bodies; the umbra's through the outer one, behind the Earth), with direct
  skyfield positions at every trial epoch and a scalar root search (brentq).  Our
  edges come from angles seen *from the spacecraft* (SGP4 at every epoch), searched
  every 30 s and bisected to 1 µs.  Measured: they agree to 0.44 µs over a day of ISS
  orbits (0.12 ms with the former 60 s spline of the orbit);
- the **lit fraction** by counting the rays from the spacecraft to points spread
  evenly (equal solid angle) over the Sun's disc that miss the Earth's sphere.
  Measured: within 2.6e-4 of M&G's plane-disc formula on the ISS orbit (the
  plane-disc approximation; 400 000 rays), 4e-5 beyond the umbra's tip.  With the
  100 000 rays used here the count itself is good to ≈ 1e-4.
"""

import numpy as np
import pytest
from astropy.time import Time
from scipy.optimize import brentq

from attitude.environment.earth import EARTH_EQUATORIAL_RADIUS_M as EARTH_RADIUS_M
from attitude.environment.ephemeris import _ephemeris, sun_position_from_earth, timescale
from attitude.environment.orbit import TleOrbit
from attitude.environment.timescales import offline_time, time_from_tt_seconds, tt_seconds
from attitude.pointing.eclipse import (
    SUN_RADIUS_M,
    EclipseState,
    eclipse_intervals,
    eclipse_state,
    shadow_angles,
    sunlit_fraction,
)

# ISS (ZARYA), a real element set (as printed in the skyfield documentation).
LINE1 = "1 25544U 98067A   14020.93268519  .00009878  00000-0  18200-3 0  5082"
LINE2 = "2 25544  51.6498 109.4756 0003572  55.9686 274.8005 15.49815350868473"
START = Time("2014-01-21T00:00:00", scale="utc")
STOP = Time("2014-01-22T00:00:00", scale="utc")


@pytest.fixture(scope="module")
def orbit():
    return TleOrbit(LINE1, LINE2, "ISS (ZARYA)")


@pytest.fixture(scope="module")
def intervals(orbit):
    return eclipse_intervals(orbit, START, STOP)


def _angle(u, v):
    return np.arctan2(np.linalg.norm(np.cross(u, v)), np.dot(u, v))


class DirectCones:
    """Signed angular distance of the spacecraft from the shadow cones (direct skyfield)."""

    def __init__(self, orbit):
        self.satellite = orbit.satellite
        with offline_time():
            self.jd1, self.jd2 = START.tt.jd1, START.tt.jd2
        eph = _ephemeris()
        self.earth, self.sun = eph["earth"], eph["sun"]

    def _state(self, seconds):
        t = timescale().tt_jd(self.jd1, self.jd2 + seconds / 86400.0)
        r_m = self.satellite.at(t).position.m
        s_m = self.earth.at(t).observe(self.sun).apparent().position.m
        distance_m = np.linalg.norm(s_m)
        return r_m, s_m / distance_m, distance_m

    def penumbra(self, seconds):
        """< 0 inside the cone of the internal tangents (some sunlight hidden)."""
        r_m, sun, distance_m = self._state(seconds)
        apex_m = sun * EARTH_RADIUS_M * distance_m / (SUN_RADIUS_M + EARTH_RADIUS_M)
        half_angle = np.arcsin((SUN_RADIUS_M + EARTH_RADIUS_M) / distance_m)
        return _angle(r_m - apex_m, -sun) - half_angle

    def umbra(self, seconds):
        """< 0 inside the cone of the external tangents (all sunlight hidden)."""
        r_m, sun, distance_m = self._state(seconds)
        apex_m = -sun * EARTH_RADIUS_M * distance_m / (SUN_RADIUS_M - EARTH_RADIUS_M)
        half_angle = np.arcsin((SUN_RADIUS_M - EARTH_RADIUS_M) / distance_m)
        return _angle(r_m - apex_m, sun) - half_angle


def _counted_fraction(r_m, s_m, count=100_000):
    """Lit fraction: rays to ``count`` points of equal solid angle on the Sun's disc."""
    to_sun = s_m - r_m
    distance_m = np.linalg.norm(to_sun)
    w = to_sun / distance_m
    radius = np.arcsin(SUN_RADIUS_M / distance_m)
    k = np.arange(count) + 0.5
    # Fibonacci spiral on the spherical cap: 1 − cos ρ uniform, golden-angle azimuths.
    one_minus_cos = 2.0 * np.sin(radius / 2.0) ** 2 * k / count
    sin_rho = np.sqrt(one_minus_cos * (2.0 - one_minus_cos))
    phi = k * np.pi * (3.0 - np.sqrt(5.0))
    u = np.cross(w, [0.0, 0.0, 1.0])
    u /= np.linalg.norm(u)
    v = np.cross(w, u)
    rays = (1.0 - one_minus_cos)[:, None] * w + sin_rho[:, None] * (
        np.cos(phi)[:, None] * u + np.sin(phi)[:, None] * v
    )
    # A ray from r along d meets the sphere if it heads towards the Earth and passes
    # closer to its centre than its radius.
    towards = rays @ r_m < 0.0
    closest_m = np.linalg.norm(np.cross(r_m, rays), axis=-1)
    return 1.0 - np.mean(towards & (closest_m < EARTH_RADIUS_M))


def test_edges_match_the_tangent_cones(orbit, intervals):
    cones = DirectCones(orbit)
    day_s = float(tt_seconds(STOP, START))
    for edges, function in ((intervals.shadow, cones.penumbra), (intervals.umbra, cones.umbra)):
        ours_s = tt_seconds(edges, START).ravel()
        ours_s = ours_s[(ours_s > 0.0) & (ours_s < day_s)]  # not the clipped ends
        assert ours_s.size >= 30  # 16 eclipses in a day, entry and exit
        direct_s = np.array([brentq(function, x - 5.0, x + 5.0, xtol=1e-7) for x in ours_s])
        error = np.abs(ours_s - direct_s).max()
        assert error < 5e-6, error  # measured 0.44 µs


def test_intervals_are_nested_and_the_penumbra_lasts_8_seconds(intervals):
    shadow_s = tt_seconds(intervals.shadow, START)
    umbra_s = tt_seconds(intervals.umbra, START)
    assert shadow_s.shape == umbra_s.shape == (16, 2)
    assert shadow_s[0, 0] == 0.0  # the day starts in the shadow: clipped
    assert np.all(shadow_s[:, 0] <= umbra_s[:, 0]) and np.all(umbra_s[:, 1] <= shadow_s[:, 1])
    entry_s = (umbra_s[:, 0] - shadow_s[:, 0])[1:]
    exit_s = umbra_s[:, 1] - shadow_s[:, 1]
    assert np.all((entry_s > 8.3) & (entry_s < 8.5)), entry_s
    assert np.all((exit_s < -8.3) & (exit_s > -8.5)), exit_s
    # An orbit is 92.9 min; the umbra lasts 36 min.
    assert np.allclose(np.diff(shadow_s[1:, 0]), 5575.0, atol=5.0)
    assert np.allclose(np.diff(umbra_s[1:], axis=1), 2153.0, atol=10.0)


def test_lit_fraction_matches_counted_rays_through_a_penumbra(orbit, intervals):
    entry_s = tt_seconds(intervals.shadow, START)[1, 0]
    times = time_from_tt_seconds(START, entry_s + np.linspace(-0.5, 9.0, 15))
    r_m, _ = orbit.position_velocity(times)
    s_m = sun_position_from_earth(times)
    ours = sunlit_fraction(r_m, s_m)
    counted = np.array([_counted_fraction(r, s) for r, s in zip(r_m, s_m, strict=True)])
    assert ours[0] == 1.0 and ours[-1] == 0.0 and np.any((ours > 0.1) & (ours < 0.9))
    assert np.abs(ours - counted).max() < 3.5e-4  # measured 2.6e-4 (plane discs)


@pytest.mark.parametrize(
    "distance_m, name",
    [(4.2164e7, "geostationary"), (1.5e9, "beyond the umbra's tip: annular")],
)
def test_lit_fraction_matches_counted_rays_far_out(distance_m, name):
    s_m = np.array([1.47e11, 2.0e10, 8.0e9])
    sun = s_m / np.linalg.norm(s_m)
    across = np.cross(sun, [0.0, 0.0, 1.0])
    across /= np.linalg.norm(across)
    a, b, _ = shadow_angles(-sun * distance_m, s_m)
    # Across the shadow, from outside the penumbra through the umbra (or the annulus).
    c = np.linspace(max(b - a, 0.0) - 0.2 * a, b + a + 0.2 * a, 21)
    r_m = -sun * distance_m + np.tan(c)[:, None] * distance_m * across
    ours = sunlit_fraction(r_m, s_m)
    counted = np.array([_counted_fraction(r, s_m) for r in r_m])
    assert ours[-1] == 1.0 and np.any((ours > 0.05) & (ours < 0.95)), name
    assert np.abs(ours - counted).max() < 2e-4, name


def test_limits():
    s_m = np.array([1.496e11, 0.0, 0.0])
    deep_in_shadow = np.array([-7.0e6, 0.0, 0.0])
    sunward = np.array([7.0e6, 0.0, 0.0])
    far_away = np.array([0.0, 3.0e9, 0.0])
    r_m = np.stack([deep_in_shadow, sunward, far_away])
    assert np.array_equal(sunlit_fraction(r_m, s_m), [0.0, 1.0, 1.0])
    assert np.array_equal(
        eclipse_state(r_m, s_m), [EclipseState.UMBRA, EclipseState.SUNLIT, EclipseState.SUNLIT]
    )
    assert sunlit_fraction(deep_in_shadow, s_m).shape == ()
    # Beyond the umbra's tip (1.38e9 m) on the axis: an annular eclipse, 1 − b²/a².
    annular = sunlit_fraction([-2.0e9, 0.0, 0.0], s_m)
    a, b, _ = shadow_angles([-2.0e9, 0.0, 0.0], s_m)
    assert annular == pytest.approx(1.0 - (b / a) ** 2, rel=1e-12)
    assert eclipse_state([-2.0e9, 0.0, 0.0], s_m) == EclipseState.PENUMBRA


def test_continuous_and_monotonic_through_the_penumbra(orbit, intervals):
    shadow_s = tt_seconds(intervals.shadow, START)[1]
    umbra_s = tt_seconds(intervals.umbra, START)[1]
    for start_s, stop_s in ((shadow_s[0], umbra_s[0]), (umbra_s[1], shadow_s[1])):
        seconds = np.linspace(start_s - 0.2, stop_s + 0.2, 9601)  # 1 ms steps
        times = time_from_tt_seconds(START, seconds)
        r_m, _ = orbit.position_velocity(times)
        s_m = sun_position_from_earth(times)
        fraction = sunlit_fraction(r_m, s_m)
        state = eclipse_state(r_m, s_m)
        step = np.diff(fraction)
        entering = start_s == shadow_s[0]
        assert np.all(step <= 0.0) if entering else np.all(step >= 0.0)
        # Continuous: no jump, and the edges are where our intervals put them.
        assert np.abs(step).max() < 5e-4
        outside = (seconds < start_s - 1e-3) | (seconds > stop_s + 1e-3)
        inside = (seconds > start_s + 1e-3) & (seconds < stop_s - 1e-3)
        assert np.all(np.isin(fraction[outside], [0.0, 1.0]))
        assert np.all((fraction[inside] > 0.0) & (fraction[inside] < 1.0))
        # The states say the same as the fraction.
        assert np.array_equal(state == EclipseState.UMBRA, fraction == 0.0)
        assert np.array_equal(state == EclipseState.SUNLIT, fraction == 1.0)
