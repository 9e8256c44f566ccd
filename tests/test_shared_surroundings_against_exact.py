"""The shared surroundings (interpolated once for a span) against the exact ones.

``SharedSurroundings`` interpolates the orbit, the apparent Sun and Moon and the shadow's
axis on Chebyshev pieces and states its bound: every checked point within 1 mm in
position and 1e-11 rad in every direction.  Here, at random times of the spinner's
LEO orbit and of the Earth's centre (none of them a node or a check point), every
quantity of the surroundings against the exact path of ``SunMoonEarth`` (SGP4 and the
ephemeris at every time): the directions within 1e-11 rad, the position within 1 mm,
the shadow's angles, the Earth's angular radius and nadir within 1e-11 rad.  The rates
the search takes (``targets``) against central differences of the values, and the rate
bounds against the rates seen.  And the cache: the same span, epoch and orbit content
give the same object, another orbit another; the exact path it lends to the samples
gives the samples' values bit for bit.
"""

import math
from pathlib import Path

import numpy as np
import pytest

from attitude.files.scenario_reader import load_scenario
from attitude.pointing.sampling import pointing_samples
from attitude.pointing.shared_surroundings import (
    SharedSurroundings,
    clear_cache,
    exact_surroundings,
    shared_surroundings,
)
from attitude.pointing.spec import PointingSpec, for_scenario
from attitude.pointing.surroundings import SunMoonEarth, unit_angle
from attitude.trajectory.trajectory import propagate

ROOT = Path(__file__).parents[1]


@pytest.fixture(scope="module")
def spinner():
    loaded = load_scenario(ROOT / "scenarios" / "spinner_thruster_pulse.toml")
    trajectory = propagate(loaded.scenario)
    spec = for_scenario(loaded.pointing, loaded.scenario)
    return trajectory, spec


def _random_times(stop_s: float, count: int = 4000) -> np.ndarray:
    return np.sort(np.random.default_rng(20).uniform(0.0, stop_s, count))


@pytest.mark.parametrize("on_orbit", [True, False])
def test_interpolated_surroundings_within_the_stated_bound(spinner, on_orbit):
    trajectory, spec = spinner
    if not on_orbit:
        spec = PointingSpec(spec.body_vectors, None)  # the Earth's centre
    stop = trajectory.scenario.stop_s
    shared = SharedSurroundings(
        (trajectory.scenario.epoch.tt.jd1, trajectory.scenario.epoch.tt.jd2),
        spec.orbit,
        spec.earth_limb_atmosphere_height_m,
        0.0,
        stop,
    )
    assert shared.direction_error_rad <= 1e-11 and shared.position_error_m <= 1e-3
    τ = _random_times(stop)
    model = shared.at(τ)
    exact = SunMoonEarth(trajectory, spec, 0.0, stop).at(τ)
    for name in ("sun_direction", "moon_direction"):
        assert np.max(unit_angle(getattr(model, name), getattr(exact, name))) <= 1e-11, name
    if not on_orbit:
        assert model.position_m is None and np.all(model.sunlit_fraction == 1.0)
        return
    assert np.max(np.linalg.norm(model.position_m - exact.position_m, axis=1)) <= 1e-3
    assert np.max(unit_angle(model.nadir, exact.nadir)) <= 1e-11
    for a, b in zip(model.shadow_angles, exact.shadow_angles, strict=True):
        assert np.max(np.abs(a - b)) <= 1e-11
    assert np.max(np.abs(model.earth_angular_radius_rad - exact.earth_angular_radius_rad)) <= 1e-11
    # The lit fraction: within its rate times the angles' error, in the penumbra.
    assert np.max(np.abs(model.sunlit_fraction - exact.sunlit_fraction)) <= 1e-6


def test_rates_against_central_differences_and_their_bounds(spinner):
    trajectory, spec = spinner
    shared = shared_surroundings(trajectory, spec)
    τ = _random_times(trajectory.scenario.stop_s - 1.0, 1000) + 0.5
    h = 1e-2
    here = shared.targets(τ, accelerations=True)
    ahead, behind = shared.targets(τ + h, True), shared.targets(τ - h, True)
    bounds = shared.rate_bounds()
    for name in ("sun", "moon", "nadir"):
        rate = getattr(here, f"{name}_rate")
        difference = (getattr(ahead, name) - getattr(behind, name)) / (2.0 * h)
        assert np.max(np.linalg.norm(rate - difference, axis=1)) <= 1e-9 * (
            1.0 + bounds[f"{name}_1"]
        )
        accel = getattr(here, f"{name}_accel")
        difference = (getattr(ahead, f"{name}_rate") - getattr(behind, f"{name}_rate")) / (2.0 * h)
        assert np.max(np.linalg.norm(accel - difference, axis=1)) <= 1e-9
        # The bounds of the search's bends hold at every time seen, and are not loose by
        # more than a factor 10 (they set the nodes' spacing).
        assert np.max(np.linalg.norm(rate, axis=1)) <= bounds[f"{name}_1"]
        assert np.max(np.linalg.norm(accel, axis=1)) <= bounds[f"{name}_2"]
    assert np.max(np.abs(here.limb_rate)) <= bounds["limb_1"]


def test_the_cache_shares_one_object_per_span_epoch_and_orbit(spinner):
    trajectory, spec = spinner
    clear_cache()
    first = shared_surroundings(trajectory, spec)
    # The same scenario read again: another Orbit object, the same content.
    again = load_scenario(ROOT / "scenarios" / "spinner_thruster_pulse.toml")
    other = propagate(again.scenario)
    assert shared_surroundings(other, again.pointing) is first
    assert shared_surroundings(trajectory, spec, 0.0, trajectory.scenario.stop_s / 2) is first
    higher = PointingSpec(spec.body_vectors, spec.orbit, earth_limb_atmosphere_height_m=50e3)
    assert shared_surroundings(trajectory, higher) is not first
    # What the samples take from it is what they would compute alone.
    seconds = np.linspace(0.0, trajectory.scenario.stop_s, 101)
    assert exact_surroundings(trajectory, spec, 0.0, seconds[-1]) is first._exact
    lent = pointing_samples(trajectory, spec, seconds)
    clear_cache()
    alone = pointing_samples(trajectory, spec, seconds)
    for a, b in zip(lent.vectors, alone.vectors, strict=True):
        assert np.array_equal(a.sun_angle_rad, b.sun_angle_rad)
        assert np.array_equal(a.earth_limb_angle_rad, b.earth_limb_angle_rad)
    assert np.array_equal(lent.sunlit_fraction, alone.sunlit_fraction)


def test_a_span_not_covered_builds_another(spinner):
    trajectory, spec = spinner
    clear_cache()
    short = shared_surroundings(trajectory, spec, 0.0, 600.0)
    assert short.covers(0.0, 600.0) and not short.covers(0.0, trajectory.scenario.stop_s)
    full = shared_surroundings(trajectory, spec)
    assert full is not short and full.covers(0.0, trajectory.scenario.stop_s)
    assert math.isfinite(full.position_error_m)


def test_pieces_left_exact_bound_nothing_and_the_search_still_runs(spinner, monkeypatch):
    """Pieces no series fits (a TLE propagated months from its epoch: from 196 days on,
    the spinner's orbit) are evaluated exactly; their rate bounds are infinite, and the
    least distance comes from the fitted pieces, not from the exact pieces' empty
    series (which read as a position at the Earth's centre, and divided by zero).  Here
    every piece is left exact (tolerances no fit meets), and the search on those
    surroundings finds the eclipses the exact path has (within twice the interval
    precision, 1 ms)."""
    import attitude.pointing.shared_surroundings as module
    from attitude.pointing.search import pointing_analysis

    trajectory, spec = spinner
    monkeypatch.setattr(module, "_POSITION_TOLERANCE_M", 0.0)
    monkeypatch.setattr(module, "_HALVINGS", 0)
    stop = trajectory.scenario.stop_s
    epoch = trajectory.scenario.epoch.tt
    shared = SharedSurroundings(
        (epoch.jd1, epoch.jd2), spec.orbit, spec.earth_limb_atmosphere_height_m, 0.0, stop
    )
    bounds = shared.rate_bounds()
    assert all(math.isinf(bounds[name]) for name in ("nadir_1", "nadir_2", "limb_1", "sun_1"))
    exact = pointing_analysis(trajectory, spec)
    found = pointing_analysis(trajectory, spec, surroundings=shared)
    assert exact.shadow
    for name in ("shadow", "umbra"):
        ends = [(i.start_s, i.end_s) for i in getattr(exact, name)]
        assert len(getattr(found, name)) == len(ends)
        np.testing.assert_allclose(
            [(i.start_s, i.end_s) for i in getattr(found, name)], ends, rtol=0.0, atol=2e-3
        )
