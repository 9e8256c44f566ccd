"""Pointing quantities against hand calculations and independent references.

- A fixed attitude at a known epoch: the Sun angle on each body axis is the angle
  between that axis, carried into ICRF by the attitude written by hand, and the Sun
  from astropy's own ephemeris (epv00, independent of the DE421 used by skyfield).
- A spinning spacecraft: the incidence on a side panel is max(0, s1 cos ωt + s2 sin ωt),
  written by hand from the Sun's body coordinates at t = 0, and so follows the spin.
- Boresight right ascension and declination against astropy's SkyCoord.
- Nadir angles against skyfield's own satellite positions (no interpolation).
- Interval ends: the condition changes on either side, within the stated precision;
  eclipse ends against the shadow computed from direct skyfield positions.
- Earth limb angles by hand on constructed geometries; a spacecraft pointing its
  +z at nadir (frame LVLH) has nadir angle 0 there.
"""

import math

import numpy as np
import pytest
from astropy.coordinates import CartesianRepresentation, SkyCoord
from reference_models import astropy_apparent_sun
from scipy.spatial.transform import Rotation

from attitude.environment.ephemeris import sun_position_from_earth, timescale
from attitude.environment.orbit import Orbit
from attitude.pointing.eclipse import sunlit_fraction
from attitude.pointing.sampling import pointing_samples
from attitude.pointing.search import pointing_analysis
from attitude.pointing.spec import BodyVector, PointingSpec
from attitude.scenario.scenario import InitialState, Scenario
from attitude.scenario.spacecraft import Spacecraft
from attitude.trajectory.trajectory import propagate

ARCSEC = math.radians(1 / 3600)
TLE = (
    "1 59001U 27042A   27171.50000000  .00000120  00000-0  18000-4 0  9999",
    "2 59001  98.2100 175.3000 0012000  95.0000 265.2000 14.57123456    14",
)
AXES = [
    BodyVector("x_axis", [1.0, 0.0, 0.0], math.radians(30.0)),
    BodyVector("y_axis", [0.0, 1.0, 0.0]),
    BodyVector("z_axis", [0.0, 0.0, 1.0], math.radians(20.0)),
]


def _scenario(attitude, ω, duration, step, epoch="2027-06-21T00:00:00"):
    craft = Spacecraft("test", [10.0, 12.0, 15.0])
    state = InitialState(attitude, angular_velocity=ω)
    return Scenario("pointing", craft, epoch, state, duration=duration, step=step)


def compute_pointing(trajectory, spec, seconds):
    """The samples at ``seconds`` and the analysis over the output span, as one object."""
    samples = pointing_samples(trajectory, spec, seconds)
    analysis = pointing_analysis(trajectory, spec)
    samples.analysis = analysis
    samples.shadow, samples.umbra = analysis.shadow, analysis.umbra
    samples.precision_s = analysis.precision_s
    for item, found in zip(samples.vectors, analysis.vectors, strict=True):
        item.sun_exclusion, item.sun_visible = found.sun_exclusion, found.sun_visible
    return samples


def _angle(u_vectors, v_vectors):
    return np.arctan2(
        np.linalg.norm(np.cross(u_vectors, v_vectors), axis=-1), np.sum(u_vectors * v_vectors, -1)
    )


def test_fixed_attitude_sun_angles_match_a_hand_calculation():
    # Body x along ICRF z, body y along ICRF x, body z along ICRF y: the columns of the
    # body -> ICRF matrix are the body axes in ICRF (a cyclic permutation, det +1).
    matrix = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])
    scenario = _scenario(Rotation.from_matrix(matrix), [0.0, 0.0, 0.0], 600.0, 60.0)
    result = compute_pointing(propagate(scenario), PointingSpec(AXES), scenario.output_seconds())
    sun, _ = astropy_apparent_sun(scenario.times(result.seconds))
    # By hand: body x is ICRF z, so its Sun angle is the Sun's colatitude, and so on.
    expected = {
        "x_axis": np.arccos(sun[:, 2]),
        "y_axis": np.arccos(sun[:, 0]),
        "z_axis": np.arccos(sun[:, 1]),
    }
    for item in result.vectors:
        np.testing.assert_allclose(
            item.sun_angle_rad, expected[item.vector.name], rtol=0, atol=0.05 * ARCSEC
        )
    # The June solstice: the Sun near declination +23.44°, RA 90°: body z (ICRF y) sees it
    # at about 23.4° (outside its 20° cone), body x (ICRF z) at 66.6°.
    z = next(v for v in result.vectors if v.vector.name == "z_axis")
    assert math.degrees(z.sun_angle_rad[0]) == pytest.approx(23.44, abs=0.05)
    assert not np.any(z.sun_violated) and not z.sun_exclusion


def test_incidence_on_a_side_panel_follows_the_spin():
    ω = 0.5  # rad/s about body z, a steady spin
    attitude0 = Rotation.from_euler("ZYX", [20.0, 35.0, -10.0], degrees=True)
    scenario = _scenario(attitude0, [0.0, 0.0, ω], 60.0, 0.05)
    panel = BodyVector("panel", [1.0, 0.0, 0.0], kind="panel")
    result = compute_pointing(propagate(scenario), PointingSpec([panel]), scenario.output_seconds())
    t = result.seconds
    sun, _ = astropy_apparent_sun(scenario.times(t))
    # By hand: R(t) = R0 Rz(ωt), so the Sun in body axes is Rz(−ωt) R0ᵀ s.
    s = attitude0.apply(sun, inverse=True)
    expected = np.maximum(0.0, s[:, 0] * np.cos(ω * t) + s[:, 1] * np.sin(ω * t))
    np.testing.assert_allclose(result.vectors[0].cos_incidence, expected, rtol=0, atol=1e-7)
    # It follows the spin: lit half the time, with the spin's period.
    lit = result.vectors[0].sun_visible
    starts = np.array([i.start_s for i in lit if not i.starts_before])
    np.testing.assert_allclose(np.diff(starts), 2 * math.pi / ω, rtol=0, atol=2e-3)


def test_boresight_right_ascension_and_declination_against_astropy():
    attitude0 = Rotation.from_euler("XYZ", [40.0, -25.0, 110.0], degrees=True)
    scenario = _scenario(attitude0, [0.01, -0.02, 0.03], 100.0, 10.0)
    result = compute_pointing(propagate(scenario), PointingSpec(AXES), scenario.output_seconds())
    trajectory = propagate(scenario)
    for item in result.vectors:
        icrf = trajectory.attitude(result.seconds).apply(item.vector.vector)
        coords = SkyCoord(CartesianRepresentation(*icrf.T), frame="icrs")
        np.testing.assert_allclose(np.degrees(item.declination_rad), coords.dec.deg, atol=1e-10)
        difference = (np.degrees(item.right_ascension_rad) - coords.ra.deg + 180.0) % 360.0 - 180.0
        np.testing.assert_allclose(difference, 0.0, atol=1e-10)


@pytest.fixture(scope="module")
def on_orbit():
    """A spinning spacecraft on a TLE orbit over 3 hours (two eclipses)."""
    scenario = _scenario(
        Rotation.from_euler("X", 30.0, degrees=True), [0.0, 0.05, 0.3], 3 * 3600.0, 1.0
    )
    spec = PointingSpec(AXES, TLE, interval_precision_s=1e-3)
    trajectory = propagate(scenario)
    return scenario, trajectory, compute_pointing(trajectory, spec, scenario.output_seconds())


def _satellite(scenario, seconds):
    """Positions (m) from skyfield directly: EarthSatellite at every epoch, no interpolation."""
    from skyfield.api import EarthSatellite

    satellite = EarthSatellite(*TLE, "test", timescale())
    tt = scenario.times(seconds).tt
    return satellite.at(timescale().tt_jd(tt.jd1, tt.jd2)).position.m.T


def test_nadir_angles_against_direct_skyfield_positions(on_orbit):
    scenario, trajectory, result = on_orbit
    seconds = result.seconds[::97]
    down = -_satellite(scenario, seconds)
    down /= np.linalg.norm(down, axis=1, keepdims=True)
    for item in result.vectors:
        icrf = trajectory.attitude(seconds).apply(item.vector.vector)
        # The orbit is SGP4 at every epoch (only the TEME rotation is interpolated).
        np.testing.assert_allclose(item.nadir_angle_rad[::97], _angle(icrf, down), atol=1e-10)


def test_eclipse_ends_against_direct_geometry(on_orbit):
    scenario, _, result = on_orbit
    assert len(result.shadow) == 2 and len(result.umbra) == 2
    δ = 2 * result.precision_s
    for interval in result.shadow:
        probes = np.array(
            [interval.start_s - δ, interval.start_s + δ, interval.end_s - δ, interval.end_s + δ]
        )
        fraction = sunlit_fraction(
            _satellite(scenario, probes), sun_position_from_earth(scenario.times(probes))
        )
        assert fraction[0] == 1.0 and fraction[1] < 1.0  # entering the penumbra
        assert fraction[2] < 1.0 and fraction[3] == 1.0  # leaving it


def test_sun_exclusion_ends_are_refined_to_the_stated_precision(on_orbit):
    scenario, trajectory, result = on_orbit
    x = next(v for v in result.vectors if v.vector.name == "x_axis")
    assert len(x.sun_exclusion) > 100  # the spin sweeps body x through the Sun every turn
    half = x.vector.sun_exclusion_half_angle_rad
    δ = result.precision_s
    inner = [i for i in x.sun_exclusion if not (i.starts_before or i.ends_after)]
    ends = np.array([[i.start_s - δ, i.start_s + δ, i.end_s - δ, i.end_s + δ] for i in inner])
    sun = astropy_apparent_sun(scenario.times(ends.ravel()))[0]
    # From the spacecraft the Sun is 9.5" away from this geocentric one at most: the
    # cone's edge moves by far less than δ times the angular rate (0.3 rad/s).
    body_sun = trajectory.attitude(ends.ravel()).apply(sun, inverse=True)
    angle = _angle(body_sun, np.array([1.0, 0.0, 0.0])).reshape(-1, 4)
    assert np.all(angle[:, 0] > half) and np.all(angle[:, 1] < half)
    assert np.all(angle[:, 2] < half) and np.all(angle[:, 3] > half)
    # Flags on the output grid agree with the intervals (away from their ends, which are
    # known to the precision δ only).
    t = result.seconds
    inside = np.zeros(t.size, dtype=bool)
    near_an_end = np.zeros(t.size, dtype=bool)
    for i in x.sun_exclusion:
        inside |= (t >= i.start_s) & (t <= i.end_s)
        near_an_end |= (np.abs(t - i.start_s) <= δ) | (np.abs(t - i.end_s) <= δ)
    assert np.array_equal(inside[~near_an_end], x.sun_violated[~near_an_end])


def test_no_sun_exclusion_in_umbra(on_orbit):
    _, _, result = on_orbit
    x = next(v for v in result.vectors if v.vector.name == "x_axis")
    assert len(result.umbra) == 2
    for exclusion in x.sun_exclusion:
        for umbra in result.umbra:
            assert (
                exclusion.end_s <= umbra.start_s + 1e-9 or exclusion.start_s >= umbra.end_s - 1e-9
            )


def test_body_vector_names_must_fit_a_column():
    with pytest.raises(ValueError, match="body vector name must be letters, digits and _"):
        BodyVector("star tracker", [0.0, 0.0, 1.0])
    with pytest.raises(ValueError, match="body vector 'v' must be non-zero"):
        BodyVector("v", [0.0, 0.0, 0.0])


class _Fixed(Orbit):
    """A spacecraft held at one place (a constructed geometry, not an orbit)."""

    def __init__(self, position_m, velocity_m_s):
        self.r = np.asarray(position_m, dtype=float)
        self.v = np.asarray(velocity_m_s, dtype=float)

    def state_tt(self, jd1, jd2):
        n = np.size(jd1)
        return np.tile(self.r, (n, 1)), np.tile(self.v, (n, 1))

    def describe(self):
        return "fixed"


@pytest.mark.parametrize("height_m", [0.0, 100e3])
def test_earth_limb_angles_by_hand(height_m):
    # Body axes = ICRF axes; the spacecraft 7000 km out on ICRF +x.  The Earth (plus
    # ``height_m``) has the angular radius ρ = asin((R + h)/7000 km); a direction θ from
    # nadir is θ − ρ above the limb.
    rho = math.asin((6_378_137.0 + height_m) / 7.0e6)
    directions = {
        "down": ([-1.0, 0.0, 0.0], -rho),
        "side": ([0.0, 1.0, 0.0], math.pi / 2 - rho),
        "grazing": ([-math.cos(rho), math.sin(rho), 0.0], 0.0),
        "up": ([1.0, 0.0, 0.0], math.pi - rho),
        "oblique": ([-1.0, 0.0, 1.0], math.pi / 4 - rho),
    }
    vectors = [
        BodyVector(name, d, earth_limb_exclusion_angle_rad=math.radians(23.0))
        for name, (d, _) in directions.items()
    ]
    spec = PointingSpec(vectors, _Fixed([7.0e6, 0.0, 0.0], [0.0, 7.5e3, 0.0]), 1e-3, height_m)
    scenario = _scenario(Rotation.identity(), [0.0, 0.0, 0.0], 120.0, 60.0)
    trajectory = propagate(scenario)
    samples = pointing_samples(trajectory, spec, scenario.output_seconds())
    analysis = pointing_analysis(trajectory, spec)
    for item, found in zip(samples.vectors, analysis.vectors, strict=True):
        expected = directions[item.vector.name][1]
        np.testing.assert_allclose(item.earth_limb_angle_rad, expected, rtol=0, atol=1e-12)
        low, high = found.extrema["earth_limb_angle"]
        assert low.value == pytest.approx(expected, abs=1e-12)
        assert high.value == pytest.approx(expected, abs=1e-12)
        violated = expected < math.radians(23.0)
        assert np.all(item.earth_limb_violated == violated)
        assert [(i.starts_before, i.ends_after) for i in found.earth_limb_exclusion] == (
            [(True, True)] if violated else []
        )
    # 100 km of atmosphere lifts the limb by 2.1° seen from 7000 km: "side" (24.3° above
    # the solid limb) comes within the 23° exclusion.
    side = next(v for v in samples.vectors if v.vector.name == "side")
    assert bool(side.earth_limb_violated[0]) == (height_m > 0.0)
