"""The laws' degenerate and hostile cases: each ends in one clear line (an InputError
naming what and where), or is regular and checked against finite differences; never a
NaN.  Cases: parallel body vectors, the same or opposite directions, directions
parallel at an instant (Sun yaw steering over the subsolar point), zero-Doppler
steering over a pole, a site at the pole, a site below the horizon, a law that needs an
orbit without one, a direction with no length, bad values of every parameter."""

import math

import astropy.units as u
import numpy as np
import pytest
from astropy.time import Time
from law_finite_differences import reference_rates
from scipy.spatial.transform import Rotation

from attitude import (
    AlignConstrainLaw,
    CelestialTarget,
    DegenerateLawError,
    FixedDirection,
    GroundSite,
    InputError,
    KeplerianOrbit,
    NadirLaw,
    OrbitFrameLaw,
    SunLaw,
    TargetLaw,
    visible_intervals,
)
from attitude.environment.earth_rotation import itrs_to_gcrs
from attitude.environment.ephemeris import EphemerisRangeError
from attitude.environment.timescales import as_time
from attitude.laws.inputs import LawInputs

EPOCH = Time("2024-06-15T00:00:00", scale="utc")
SSO = KeplerianOrbit(
    EPOCH, 7_078_137.0, 0.0012, math.radians(98.19), math.radians(63.0), math.radians(90.0),
    mean_anomaly=math.radians(10.0), j2=True,
)  # fmt: skip


def _one_line(error: Exception) -> str:
    text = str(error)
    assert "\n" not in text and text
    return text


def _circular_orbit_through(
    direction: np.ndarray, radius: float, across: np.ndarray
) -> KeplerianOrbit:
    """A circular two-body orbit at ``EPOCH`` whose position then is ``radius`` along
    ``direction`` (ICRF), moving towards ``across``."""
    r = radius * direction / np.linalg.norm(direction)
    v_dir = across - np.dot(across, r) * r / radius**2
    h = np.cross(r, v_dir)
    h /= np.linalg.norm(h)
    inclination = math.acos(h[2])
    raan = math.atan2(h[0], -h[1])
    node = np.array([math.cos(raan), math.sin(raan), 0.0])
    latitude_argument = math.atan2(np.dot(np.cross(node, r), h), np.dot(node, r))
    return KeplerianOrbit(
        EPOCH, radius, 0.0, inclination, raan, 0.0, true_anomaly=latitude_argument
    )


# ---------------------------------------------------------------- refused when made


@pytest.mark.parametrize(
    "arguments, words",
    [
        (("+z", "sun", "+z", "moon"), "body vectors are parallel"),
        (("+z", "sun", [0.0, 0.0, -2.0], "moon"), "body vectors are parallel"),
        (("+z", "sun", "+x", "sun"), "same direction"),
        (("+z", "sun", "+x", "-sun"), "opposite"),
        (("+z", "nadir", "+x", "earth_centre"), "within 0.2 deg"),
        (("+z", [0, 0, 1], "+x", [0, 0, -5]), "fixed directions"),
        (("+z", "sunn", "+x", "moon"), "unknown direction 'sunn'"),
        (("q", "sun", "+x", "moon"), "primary_axis"),
        (("+z", "sun", [np.nan, 0.0, 1.0], "moon"), "secondary_axis must be finite"),
        (("+z", "sun", [0.0, 0.0, 0.0], "moon"), "must not be zero"),
        (("+z", "sun", "+x", [0.0, 0.0, 0.0]), "must not be zero"),
        (("+z", "sun", True, "moon"), "secondary_axis"),
    ],
)
def test_bad_pairs_are_refused_in_one_line(arguments, words):
    with pytest.raises(InputError) as caught:
        AlignConstrainLaw(*arguments)
    assert words in _one_line(caught.value)


@pytest.mark.parametrize(
    "make, words",
    [
        (lambda: NadirLaw(yaw_steering="zero-doppler"), "none, zero_doppler, sun"),
        (lambda: NadirLaw(vertical="geoid"), "geodetic, geocentric"),
        (lambda: NadirLaw("sun", phasing_axis="+z"), "across z"),
        (lambda: OrbitFrameLaw("vvlh"), "lvlh, rtn"),
        (lambda: OrbitFrameLaw("lvlh", offset="identity"), "single scipy Rotation"),
        (lambda: GroundSite(100 * u.deg, 0.0), "latitude must be between"),
        (lambda: GroundSite(0.0, 0.0, 1e9), "height must be between"),
        (lambda: GroundSite(0.0, 0.0, 3 * u.s), "height"),
        (lambda: CelestialTarget(0.0, 91 * u.deg), "dec must be between"),
        (lambda: TargetLaw("nadirr"), "unknown direction"),
    ],
)
def test_bad_parameters_are_refused_in_one_line(make, words):
    with pytest.raises(InputError) as caught:
        make()
    assert words in _one_line(caught.value)


def test_a_law_that_needs_an_orbit_is_refused_without_one():
    for law in (NadirLaw(), OrbitFrameLaw(), TargetLaw(GroundSite(0.1, 0.2))):
        with pytest.raises(InputError) as caught:
            law.bind(EPOCH, 0.0, 60.0, orbit=None, key="initial_state.law")
        text = _one_line(caught.value)
        assert text.startswith("initial_state.law: the ") and "needs an orbit" in text
    # The Sun, the Moon and fixed targets need none: the observer is the Earth's centre.
    state = SunLaw().bind(EPOCH, 0.0, 60.0).state([0.0, 60.0])
    assert np.all(np.isfinite(state.angular_velocity))
    assert TargetLaw("moon").needs == frozenset({"moon"})


def test_epochs_outside_the_span_or_not_finite_are_refused():
    bound = NadirLaw().bind(EPOCH, 0.0, 600.0, SSO)
    for seconds, words in (
        ([700.0], "outside the law's span"),
        ([np.nan], "finite"),
        ([[0.0]], "1-D"),
    ):
        with pytest.raises(InputError) as caught:
            bound.state(seconds)
        assert words in _one_line(caught.value)


def test_ephemeris_and_eop_ranges():
    with pytest.raises(EphemerisRangeError) as caught:
        SunLaw().bind(as_time("2100-01-01T00:00:00"), 0.0, 60.0)
    assert "DE421" in _one_line(caught.value)
    # Beyond the EOP table the end values are held, and the bound law says so.
    future = as_time("2035-01-01T00:00:00")
    orbit = KeplerianOrbit(future, 7.0e6, 0.001, 1.7, 0.3, 0.4, mean_anomaly=1.0)
    bound = NadirLaw("zero_doppler").bind(future, 0.0, 60.0, orbit, key="law")
    assert np.all(np.isfinite(bound.state([0.0, 60.0]).angular_velocity))
    assert len(bound.notes) == 1 and "held" in bound.notes[0]
    assert NadirLaw().bind(EPOCH, 0.0, 60.0, SSO).notes == []


# ---------------------------------------------------------------- at an instant


def test_directions_parallel_at_an_instant_raise_there_and_are_regular_around():
    """Sun yaw steering on the geocentric vertical, the spacecraft placed exactly
    between the Earth and the apparent Sun at t = 0: nadir and the Sun are opposite."""
    inputs = LawInputs(EPOCH, -1.0, 1.0, None, frozenset({"sun"}))
    direction = inputs.at([0.0]).apparent("sun").value[0]
    for _ in range(3):  # the apparent Sun from the spacecraft moves with it (parallax)
        orbit = _circular_orbit_through(direction, 7.0e6, np.array([0.0, 0.0, 1.0]))
        inputs = LawInputs(EPOCH, -1.0, 1.0, orbit, frozenset({"sun"}))
        direction = inputs.at([0.0]).apparent("sun").value[0]
    law = NadirLaw("sun", vertical="geocentric")
    bound = law.bind(EPOCH, -30.0, 30.0, orbit, key="mode_change[2].law")
    assert bound.separation([0.0])[0] > math.pi - 1e-6  # opposite: parallel lines
    with pytest.raises(DegenerateLawError) as caught:
        bound.state([-10.0, 0.0, 10.0])
    text = _one_line(caught.value)
    assert text.startswith("mode_change[2].law: the nadir law is undefined at 2024-06-15T00:00:00")
    assert "parallel" in text
    # Around the instant, the law is defined and finite.  With the Sun exactly in the
    # orbit plane the yaw does not turn fast: it flips by 180° at the instant (the Sun's
    # projection on the horizontal plane goes from ahead to behind), as Orekit's
    # YawSteering documents; it is the separation that tells it beforehand.
    state = bound.state([-10.0, 10.0])
    assert np.all(np.isfinite(state.angular_velocity))
    x = state.attitude.apply([1.0, 0.0, 0.0])
    assert np.dot(x[0], x[1]) < -0.999


def test_a_direction_with_no_length_is_a_clear_error():
    class Hovering:
        """An 'orbit' at rest: its velocity has no direction."""

        def state_tt(self, jd1, jd2):
            n = np.size(jd2)
            return np.tile([7.0e6, 0.0, 0.0], (n, 1)), np.zeros((n, 3))

    bound = NadirLaw().bind(EPOCH, 0.0, 60.0, Hovering())
    with pytest.raises(DegenerateLawError) as caught:
        bound.state([30.0])
    assert "the secondary direction (the velocity (GCRS)) has no length" in _one_line(caught.value)


def test_zero_doppler_steering_over_the_pole_is_regular():
    """A polar orbit passing exactly over the north pole (the ITRS z axis) at t = 0:
    no latitude or longitude is formed, so the pole is an ordinary point; the rates
    agree with 40-digit differences of the attitude there and around."""
    tt = EPOCH.tt
    pole = itrs_to_gcrs(np.array([tt.jd1]), np.array([tt.jd2]), order=0).value[0][:, 2]
    orbit = _circular_orbit_through(pole, 7.078e6, np.array([1.0, 0.0, 0.0]))
    law = NadirLaw("zero_doppler")
    bound = law.bind(EPOCH, -60.0, 60.0, orbit)
    state = bound.state([0.0])
    z = state.attitude.apply([0.0, 0.0, 1.0])[0]
    assert np.linalg.norm(z + pole) < 1e-9  # geodetic nadir at the pole: straight down
    for t0 in (-20.0, 0.0, 20.0):
        omega, alpha = reference_rates(bound, t0, 2.0)
        got = bound.state([t0])
        assert np.abs(got.angular_velocity[0] - omega).max() < 1e-14
        assert np.abs(got.angular_acceleration[0] - alpha).max() < 1e-14


def test_site_at_the_pole_and_a_site_that_never_rises():
    pole_site = GroundSite(90 * u.deg, 123 * u.deg, 0.0, name="North Pole")
    bound = TargetLaw(pole_site).bind(EPOCH, 0.0, 6000.0, SSO)
    state = bound.state(np.linspace(0.0, 6000.0, 61))
    assert np.all(np.isfinite(state.angular_velocity))
    assert len(visible_intervals(bound)) >= 1  # a polar orbit sees the pole every pass
    # An equatorial orbit never rises above the South Pole's horizon: the law is still
    # defined (it points through the Earth), and the visibility says so.
    equatorial = KeplerianOrbit(EPOCH, 7.0e6, 0.0, 0.0, 0.0, 0.0, mean_anomaly=0.0)
    south = GroundSite(-90 * u.deg, 0.0, 0.0)
    bound = TargetLaw(south).bind(EPOCH, 0.0, 86400.0, equatorial)
    assert np.all(np.isfinite(bound.state(np.linspace(0.0, 86400.0, 25)).angular_velocity))
    assert visible_intervals(bound) == []
    elevation, _ = south.elevation(bound.at([0.0, 43200.0]))
    assert np.all(elevation < -math.radians(30.0))


def test_inertial_law_holds_its_attitude():
    held = Rotation.from_rotvec([0.3, -1.1, 0.7])
    state = SunLaw(constraint=FixedDirection([1.0, 0.0, 0.0])).state(EPOCH)
    assert np.all(np.isfinite(state.angular_velocity))
    from attitude import InertialLaw

    state = InertialLaw(held).bind(EPOCH, 0.0, 10.0).state([0.0, 10.0])
    assert (held.inv() * state.attitude).magnitude().max() < 1e-15
    assert np.all(state.angular_velocity == 0.0) and np.all(state.angular_acceleration == 0.0)
