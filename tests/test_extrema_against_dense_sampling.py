"""Extrema found on the exact motion against a sampling 100× denser than the output grid.

The case of the issue: a 3U CubeSat spinning with a 31 s period, written every 10 s.
The output grid sees a few points per turn, and its least Sun angle on the star
tracker is off by 0.7°; ``pointing_analysis`` searches the exact motion on its own
nodes (attitude.pointing.free_search: bounds from the motion's structure, then Newton's
method or golden-section search in every cell that could beat the best value), or on a
grid of 64 points a turn of the fastest rotation (the search of segments under
torques; the chunks' test runs this case both ways).  The reference samples every
0.1 s (100× the output step) over the same span.

A sampled extremum is never more extreme than the true one, so the analysis must be at
least as extreme as every sample.  And within 0.01° of the reference: the extreme sample
refined by the parabola through it and its two neighbours (the raw samples are off by
up to f''·(Δt/2)²/2, 0.016° for the tracker's greatest Sun angle, 10° from a pole).
Near a kink (an angle through 0 or 180°, where the parabola does not apply) the samples
are off by up to ω·Δt/2 ≈ 0.6°, and cannot judge: there the reported time is checked
instead, by sampling ±0.1 s around it every 0.1 ms (1000× denser again): nothing there
is more extreme than the value reported.  Measured: ≤ 7e-5° from the refined reference
on smooth extrema, where the 10 s output grid misses the tracker's least Sun angle by
5.8°.
"""

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from attitude.pointing.sampling import pointing_samples
from attitude.pointing.search import pointing_analysis
from attitude.pointing.spec import BodyVector, PointingSpec
from attitude.scenario.scenario import InitialState, Scenario
from attitude.scenario.spacecraft import Spacecraft
from attitude.trajectory.trajectory import propagate

TLE = (
    "1 59001U 27042A   27171.50000000  .00000120  00000-0  18000-4 0  9999",
    "2 59001  98.2100 175.3000 0012000  95.0000 265.2000 14.57123456    14",
)
QUANTITIES = {
    "sun_angle": "sun_angle_rad",
    "moon_angle": "moon_angle_rad",
    "nadir_angle": "nadir_angle_rad",
    "earth_limb_angle": "earth_limb_angle_rad",
    "cos_incidence": "cos_incidence",
}


@pytest.fixture(scope="module")
def cubesat():
    """A 3U CubeSat (10 × 10 × 34 cm, 4 kg) spinning about its long axis every 31 s,
    with a little wobble, on a sun-synchronous orbit; outputs every 10 s for 100 min."""
    craft = Spacecraft("3U", [0.0067, 0.0419, 0.0431])
    spin = 2.0 * math.pi / 31.0
    state = InitialState(
        Rotation.from_euler("ZYX", [30.0, 20.0, 10.0], degrees=True),
        angular_velocity=[spin, 0.012, 0.018],
    )
    scenario = Scenario("3U", craft, "2027-06-21T00:00:00", state, duration=6000.0, step=10.0)
    tracker = BodyVector(
        "star_tracker",
        [0.0, 0.5, math.sqrt(0.75)],
        math.radians(40.0),
        "star_tracker",
        moon_exclusion_half_angle_rad=math.radians(20.0),
        earth_limb_exclusion_angle_rad=math.radians(20.0),
    )
    panel = BodyVector("panel", [0.0, -1.0, 0.0], kind="panel")
    spec = PointingSpec([tracker, panel], TLE)
    trajectory = propagate(scenario)
    analysis = pointing_analysis(trajectory, spec)
    grid = pointing_samples(trajectory, spec, scenario.output_seconds())
    dense = pointing_samples(trajectory, spec, np.linspace(0.0, 6000.0, 60_001))
    return analysis, grid, dense, trajectory, spec


def _cases():
    return [(v, q) for v in ("star_tracker", "panel") for q in QUANTITIES]


def _refined(t, values, largest: bool) -> float:
    """The extreme sample refined by the parabola through it and its neighbours."""
    k = int(np.argmax(values) if largest else np.argmin(values))
    if not 0 < k < values.size - 1:
        return float(values[k])
    y0, y1, y2 = values[k - 1], values[k], values[k + 1]
    curvature = y0 - 2.0 * y1 + y2
    if curvature == 0.0:
        return float(y1)
    shift = 0.5 * (y0 - y2) / curvature
    return float(y1 - 0.25 * (y0 - y2) * shift)


def _near_kink(dense, vector: str, quantity: str, largest: bool) -> bool:
    """Whether the extremum sits on a kink: its angle (the nadir angle, for the limb
    angle) within 1° of 0 or 180°."""
    if quantity == "cos_incidence":
        return False
    item = next(v for v in dense.vectors if v.vector.name == vector)
    values = getattr(item, QUANTITIES[quantity])
    k = int(np.argmax(values) if largest else np.argmin(values))
    angle = (item.nadir_angle_rad if quantity == "earth_limb_angle" else values)[k]
    return min(angle, math.pi - angle) < math.radians(1.0)


@pytest.mark.parametrize("vector, quantity", _cases())
def test_extrema_against_dense_sampling(cubesat, vector, quantity):
    analysis, _, dense, _, _ = cubesat
    found = next(v for v in analysis.vectors if v.vector.name == vector)
    sampled = getattr(
        next(v for v in dense.vectors if v.vector.name == vector), QUANTITIES[quantity]
    )
    low, high = found.extrema[quantity]
    scale = 1.0 if quantity == "cos_incidence" else 180.0 / math.pi
    tolerance = 0.01 if quantity != "cos_incidence" else 1e-4
    t = dense.seconds
    for ours, largest in ((low.value, False), (high.value, True)):
        extreme = sampled.max() if largest else sampled.min()
        # At least as extreme as any sample ...
        assert (ours - extreme if largest else extreme - ours) * scale >= -1e-9, (ours, extreme)
        # ... and within 0.01° of the refined samples where they can judge (no kink).
        if not _near_kink(dense, vector, quantity, largest):
            clipped = quantity == "cos_incidence" and not largest  # max(cos, 0): flat at 0
            reference = extreme if clipped else _refined(t, sampled, largest)
            assert abs(reference - ours) * scale <= tolerance, (quantity, ours, reference)


@pytest.mark.parametrize("vector, quantity", _cases())
def test_nothing_more_extreme_next_to_the_reported_times(cubesat, vector, quantity):
    analysis, _, _, trajectory, spec = cubesat
    found = next(v for v in analysis.vectors if v.vector.name == vector)
    for extremum, largest in zip(found.extrema[quantity], (False, True), strict=True):
        around = np.clip(extremum.time_s + np.linspace(-0.1, 0.1, 2001), 0.0, 6000.0)
        samples = pointing_samples(trajectory, spec, around)
        item = next(v for v in samples.vectors if v.vector.name == vector)
        values = getattr(item, QUANTITIES[quantity])
        if largest:
            assert values.max() <= extremum.value + 1e-9, (quantity, extremum)
        else:
            assert values.min() >= extremum.value - 1e-9, (quantity, extremum)


def test_the_times_are_where_the_values_are(cubesat):
    analysis = cubesat[0]
    tracker = analysis.vectors[0]
    low, high = tracker.extrema["sun_angle"]
    assert 0.0 <= low.time_s <= 6000.0 and 0.0 <= high.time_s <= 6000.0
    # The least Sun angle is below the exclusion half-angle: a violation holds it.
    if low.value < math.radians(40.0):
        assert any(i.start_s <= low.time_s <= i.end_s for i in tracker.sun_exclusion) or any(
            u.start_s <= low.time_s <= u.end_s for u in analysis.umbra
        )


def test_mean_incidence_against_dense_sampling(cubesat):
    # The time average of each vector's Sun incidence (max(cos, 0) times the lit
    # fraction) against the trapezoid rule on the 0.1 s sampling: within 1e-4, the
    # trapezoid's own error across the kinks (the search integrates the quintic through
    # its cells' ends, cut at the crossings, to ~1e-6: test_search_against_grid_search).
    analysis, _, dense, _, _ = cubesat
    for found, sampled in zip(analysis.vectors, dense.vectors, strict=True):
        reference = np.trapezoid(sampled.cos_incidence, dense.seconds) / 6000.0
        assert abs(found.mean_cos_incidence - reference) <= 1e-4, found.vector.name
    reference = np.trapezoid(dense.sunlit_fraction, dense.seconds) / 6000.0
    assert abs(analysis.sunlit_fraction_mean - reference) <= 1e-6


def test_the_output_grid_alone_would_be_wrong(cubesat):
    # What the summary reported before: the 10 s grid's least Sun angle on the tracker.
    analysis, grid, dense, _, _ = cubesat
    found = analysis.vectors[0].extrema["sun_angle"][0].value
    on_grid = grid.vectors[0].sun_angle_rad.min()
    assert math.degrees(on_grid - found) > 1.0  # the grid misses it by 5.8°
    assert math.degrees(dense.vectors[0].sun_angle_rad.min() - found) < 0.01


@pytest.mark.parametrize("search", ["torque-free", "grid"])
def test_nothing_depends_on_the_chunks(cubesat, monkeypatch, search):
    # The torque-free search runs in windows of WINDOW_NODES nodes, the grid search in
    # chunks of CHUNK_POINTS points: with windows of 150 nodes (chunks of 1000 points)
    # the intervals are the same (joined at the windows' ends), and so are the extrema.
    import dataclasses

    import attitude.pointing.free_search as free_search
    import attitude.pointing.search as pointing_search

    analysis, _, _, trajectory, spec = cubesat
    grid = analysis.grid
    if search == "grid":
        grid = dataclasses.replace(grid, plans=())
        analysis = pointing_analysis(trajectory, spec, grid=grid)
        assert grid.stop_s / grid.grid_step_s > 10_000  # so that there are a dozen chunks
    else:
        assert grid.count > 1500  # so that there are a dozen windows
    monkeypatch.setattr(pointing_search, "CHUNK_POINTS", 1000)
    monkeypatch.setattr(free_search, "WINDOW_NODES", 150)
    chunked = pointing_analysis(trajectory, spec, grid=grid)
    for one, other in zip(analysis.vectors, chunked.vectors, strict=True):
        for kind in ("sun_visible", "sun_exclusion", "moon_exclusion", "earth_limb_exclusion"):
            a, b = getattr(one, kind), getattr(other, kind)
            assert len(a) == len(b), kind
            for x, y in zip(a, b, strict=True):
                assert abs(x.start_s - y.start_s) <= 2e-3 and abs(x.end_s - y.end_s) <= 2e-3
                assert (x.starts_before, x.ends_after) == (y.starts_before, y.ends_after)
        for quantity, (low, high) in one.extrema.items():
            other_low, other_high = other.extrema[quantity]
            assert abs(low.value - other_low.value) < 1e-8, quantity
            assert abs(high.value - other_high.value) < 1e-8, quantity
        assert abs(one.mean_cos_incidence - other.mean_cos_incidence) < 1e-6
    assert len(analysis.shadow) == len(chunked.shadow) and len(analysis.umbra) == 1


@pytest.mark.parametrize(
    "name", ["spinner_thruster_pulse", "dzhanibekov_t_handle", "tumbling_defunct_satellite"]
)
def test_vector_rate_bounds_against_finite_differences(name):
    # The search prunes brackets with each body vector's own rate bound (a vector on
    # the spin axis turns far slower than the body): no chord of the vector's inertial
    # direction, 1 ms apart over the first 20 min, may be faster than the bound, and the
    # bound is within 5 % of the fastest chord (it is meant to prune).
    from pathlib import Path

    from attitude.files.scenario_reader import load_scenario
    from attitude.pointing.search import search_grid

    file = load_scenario(Path(__file__).parents[1] / "scenarios" / f"{name}.toml")
    vectors = file.pointing.body_vectors or [BodyVector("x", [1.0, 0.0, 0.0])]
    spec = PointingSpec(vectors, file.pointing.orbit)
    trajectory = propagate(file.scenario)
    stop = min(1200.0, file.scenario.stop_s)
    grid = search_grid(trajectory, spec, 0.0, stop)
    τ = np.arange(0.0, stop, 1e-3)
    attitude = trajectory.attitude(τ)
    for vector in vectors:
        u = attitude.apply(vector.vector)
        chords = np.linalg.norm(np.diff(u, axis=0), axis=1) / np.diff(τ)
        bound = grid.vector_rates_rad_s[vector.name]
        assert np.max(chords) <= bound * (1.0 + 1e-9), vector.name
        assert bound <= 1.05 * np.max(chords), vector.name
        assert bound <= grid.body_rate_rad_s


@pytest.mark.parametrize("lipschitz", [3.95, math.inf])
def test_least_against_scipy_bounded_minimization(lipschitz):
    # f = cos 3t + 0.1 t + 0.05 sin 17t on [0, 10], |f'| ≤ 3 + 0.1 + 0.85 < 4: the
    # least of its many local minima, against scipy's bounded Brent search started in
    # each of them (found on a grid 100x finer); with a rate bound that prunes brackets
    # (3.95) and with none (inf: every bracket refined).
    from scipy.optimize import minimize_scalar

    from attitude.pointing.extrema import least

    def f(t):
        return np.cos(3.0 * t) + 0.1 * t + 0.05 * np.sin(17.0 * t)

    grid = np.linspace(0.0, 10.0, 1001)
    found = least(f, grid, f(grid), lipschitz, 1e-12, 1e-9)
    fine = np.linspace(0.0, 10.0, 100_001)
    values = f(fine)
    local = np.flatnonzero((values[1:-1] < values[:-2]) & (values[1:-1] <= values[2:])) + 1
    reference = min(
        minimize_scalar(
            f, bounds=(fine[k - 1], fine[k + 1]), method="bounded", options={"xatol": 1e-12}
        ).fun
        for k in local
    )
    assert found.value <= reference + 1e-12
    assert abs(found.value - reference) < 1e-10
    assert abs(f(found.time_s) - found.value) == 0.0
