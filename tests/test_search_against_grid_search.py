"""The torque-free search (from the motion's structure) against the grid search, and
both against dense sampling on hostile cases.

The grid search is the search of every segment before the structural one (64 points a
turn of the fastest rotation, each sign change refined, golden-section extrema), with
the rate bound now also splitting the grid wherever a condition could change sign twice
unseen; it still searches segments under torques.  ``pointing_analysis`` takes it for
every segment when the search grid has no plans (``dataclasses.replace(grid,
plans=())``).  On each example scenario with a pointing and on constructed cases, the
two must report the same intervals (ends within twice the interval precision, the same
flags), the same extrema (within 1e-8: both refine to 5e-9 and 1 µs) and the same means
(the incidence's within 2e-3: the grid's trapezoid across the kinks of max(cos, 0) is
that far off where dense sampling and the structural search agree to 1e-5; see
``test_mean_incidence_against_dense_sampling``).

Hostile cases, each also against dense sampling: a grazing pass (a cone that a vector
enters for about 2 ms a turn, by 1e-6 rad), a vector on the spin axis (the Sun crosses
its cone by its own motion alone), a body at rest on an orbit (only the sky moves),
an attitude reset (the values jump at the event), and the issue's tumbler near its
intermediate axis.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from attitude.files.scenario_reader import load_scenario
from attitude.pointing.sampling import pointing_samples
from attitude.pointing.search import pointing_analysis, search_grid
from attitude.pointing.spec import BodyVector, PointingSpec
from attitude.scenario.events import AttitudeReset
from attitude.scenario.scenario import InitialState, Scenario
from attitude.scenario.spacecraft import Spacecraft
from attitude.trajectory.trajectory import propagate

ROOT = Path(__file__).parents[1]
TLE = (
    "1 59001U 27042A   27171.50000000  .00000120  00000-0  18000-4 0  9999",
    "2 59001  98.2100 175.3000 0012000  95.0000 265.2000 14.57123456    14",
)
KINDS = ("sun_visible", "sun_exclusion", "moon_exclusion", "earth_limb_exclusion", "sun_in_view")


def both(trajectory, spec):
    """The analysis by the structural search and by the grid search."""
    grid = search_grid(trajectory, spec)
    structural = pointing_analysis(trajectory, spec, grid=grid)
    gridded = pointing_analysis(trajectory, spec, grid=dataclasses.replace(grid, plans=()))
    return structural, gridded


def assert_same(a, b, extremum_tolerance: float = 1e-8) -> None:
    precision = a.precision_s
    for one, other in zip(a.vectors, b.vectors, strict=True):
        name = one.vector.name
        for kind in KINDS:
            x, y = getattr(one, kind), getattr(other, kind)
            assert len(x) == len(y), (name, kind, len(x), len(y))
            for p, q in zip(x, y, strict=True):
                assert abs(p.start_s - q.start_s) <= 2.0 * precision, (name, kind, p, q)
                assert abs(p.end_s - q.end_s) <= 2.0 * precision, (name, kind, p, q)
                assert (p.starts_before, p.ends_after) == (q.starts_before, q.ends_after)
        for quantity, (low, high) in one.extrema.items():
            other_low, other_high = other.extrema[quantity]
            assert abs(low.value - other_low.value) <= extremum_tolerance, (name, quantity)
            assert abs(high.value - other_high.value) <= extremum_tolerance, (name, quantity)
        assert abs(one.mean_cos_incidence - other.mean_cos_incidence) <= 2e-3, name
    for kind in ("shadow", "umbra", "moon_hidden"):
        assert getattr(a, kind) == getattr(b, kind)
    assert a.sunlit_fraction_mean == b.sunlit_fraction_mean


def dense_intervals(trajectory, spec, name: str, kind: str, start: float, stop: float, step: float):
    """Where the condition holds on a sampling every ``step`` over [start, stop]."""
    τ = np.arange(start, stop, step)
    samples = pointing_samples(trajectory, spec, τ)
    item = next(v for v in samples.vectors if v.vector.name == name)
    vector = item.vector
    if kind == "sun_exclusion":
        holds = item.sun_angle_rad < vector.sun_exclusion_half_angle_rad
    elif kind == "earth_limb_exclusion":
        holds = item.earth_limb_angle_rad < vector.earth_limb_exclusion_angle_rad
    else:
        holds = item.sun_cosine > 0.0
    change = np.flatnonzero(holds[1:] != holds[:-1])
    return τ, holds, τ[change] + 0.5 * step


@pytest.mark.parametrize(
    "name",
    [
        "spinner_dispersions",
        pytest.param("spinner_thruster_pulse", marks=pytest.mark.slow),
        pytest.param("nadir_cubesat_star_tracker", marks=pytest.mark.slow),
        pytest.param("tumbling_defunct_satellite", marks=pytest.mark.slow),
        pytest.param("tumbler_gravity_gradient_burn", marks=pytest.mark.slow),
    ],
)
def test_every_example_against_the_grid_search(name):
    loaded = load_scenario(ROOT / "scenarios" / f"{name}.toml")
    trajectory = propagate(loaded.scenario)
    assert_same(*both(trajectory, loaded.pointing))


def _spin(
    duration: float,
    vector,
    epoch: str = "2027-03-20T12:00:00",
    orbit=None,
    rate: float = 1.0,
    axis_from_sun_deg: float = 60.0,
    events=(),
    **constraints,
):
    """A steady spin about body z (a symmetric body) whose axis is ``axis_from_sun_deg``
    from the Sun near +x (the epoch is an equinox), and a body vector."""
    craft = Spacecraft("spinner", [10.0, 10.0, 20.0])
    # Body z (the spin axis) tilted from +x towards +z by the given angle.
    tilt = Rotation.from_euler("y", -(90.0 - axis_from_sun_deg), degrees=True)
    attitude = tilt * Rotation.from_euler("y", 90.0, degrees=True)
    state = InitialState(attitude, angular_velocity=[0.0, 0.0, rate])
    scenario = Scenario(
        "spinner", craft, epoch, state, list(events), duration=duration, step=1.0, orbit=orbit
    )
    spec = PointingSpec([BodyVector("v", vector, **constraints)])
    return propagate(scenario), spec


def _sun_axis_angle(trajectory) -> float:
    from attitude.pointing.shared_surroundings import shared_surroundings

    spec = PointingSpec([BodyVector("v", [1.0, 0.0, 0.0])])
    sun = shared_surroundings(trajectory, spec).exact(np.array([0.0])).sun_direction[0]
    axis = trajectory.segments[0].solver.inertial_angular_momentum
    return math.acos(float(np.dot(sun, axis / np.linalg.norm(axis))))


def test_a_grazing_pass_of_a_few_milliseconds_against_dense_sampling():
    # A vector 40° from the spin axis, which is ~60° from the Sun: it passes ~20° from
    # the Sun each turn.  The cone is set 1e-6 rad wider than that least angle at the
    # epoch: the Sun is inside for ~2 ms a turn, and the Sun's own motion (1e-5 rad
    # over the minute) makes the passes come and go.
    probe, _ = _spin(60.0, [math.sin(math.radians(40.0)), 0.0, math.cos(math.radians(40.0))])
    σ = _sun_axis_angle(probe)
    half_angle = abs(σ - math.radians(40.0)) + 1e-6
    trajectory, spec = _spin(
        60.0,
        [math.sin(math.radians(40.0)), 0.0, math.cos(math.radians(40.0))],
        sun_exclusion_half_angle_rad=half_angle,
    )
    structural, gridded = both(trajectory, spec)
    found = structural.vectors[0].sun_exclusion
    assert found, "the grazing passes are found"
    assert max(i.duration_s for i in found) < 0.01
    # Dense sampling every 20 µs around each pass (the angle's least every turn).
    coarse = pointing_samples(trajectory, spec, np.arange(0.0, 60.0, 0.005))
    angle = coarse.vectors[0].sun_angle_rad
    minima = np.flatnonzero((angle[1:-1] < angle[:-2]) & (angle[1:-1] <= angle[2:])) + 1
    reference = []
    for k in minima:
        t = coarse.seconds[k]
        τ, holds, _ = dense_intervals(
            trajectory, spec, "v", "sun_exclusion", t - 0.02, t + 0.02, 2e-5
        )
        if holds.any():
            reference.append((τ[holds][0], τ[holds][-1]))
    assert len(found) == len(reference)
    for interval, (start, end) in zip(found, reference, strict=True):
        assert abs(interval.start_s - start) <= 1e-3 + 2e-5
        assert abs(interval.end_s - end) <= 1e-3 + 2e-5
    # The grid search finds them too, since it splits wherever its rate bound allows a
    # pass: the two agree.
    assert_same(structural, gridded)


def test_a_vector_on_the_spin_axis_against_dense_sampling():
    # The vector along the spin axis stays where it is: only the Sun moves (1e-7 rad/s).
    # The cone is set to the Sun's angle at mid-span: the Sun enters it once.
    probe, _ = _spin(3600.0, [0.0, 0.0, 1.0])
    middle = pointing_samples(
        probe, PointingSpec([BodyVector("v", [0.0, 0.0, 1.0])]), [1800.0, 1800.0]
    )
    half_angle = float(middle.vectors[0].sun_angle_rad[0])
    trajectory, spec = _spin(3600.0, [0.0, 0.0, 1.0], sun_exclusion_half_angle_rad=half_angle)
    structural, gridded = both(trajectory, spec)
    found = structural.vectors[0].sun_exclusion
    assert len(found) == 1 and (found[0].starts_before or found[0].ends_after)
    assert abs((found[0].end_s if found[0].starts_before else found[0].start_s) - 1800.0) <= 1e-3
    assert structural.grid.step_s > 1.0  # nodes far apart: a vector that does not turn
    assert_same(structural, gridded)


def test_a_body_at_rest_on_an_orbit_against_dense_sampling():
    craft = Spacecraft("rest", [10.0, 20.0, 30.0])
    state = InitialState(
        Rotation.from_euler("zyx", [10.0, 20.0, 30.0], degrees=True),
        angular_velocity=[0.0, 0.0, 0.0],
    )
    scenario = Scenario(
        "rest", craft, "2027-06-21T00:00:00", state, duration=6000.0, step=10.0, orbit=TLE
    )
    vector = BodyVector(
        "v", [0.0, 0.0, 1.0], earth_limb_exclusion_angle_rad=math.radians(10.0), kind="star_tracker"
    )
    spec = PointingSpec([vector])
    trajectory = propagate(scenario)
    structural, gridded = both(trajectory, spec)
    assert_same(structural, gridded)
    _, _, changes = dense_intervals(
        trajectory, spec, "v", "earth_limb_exclusion", 0.0, 6000.0, 0.05
    )
    found = structural.vectors[0].earth_limb_exclusion
    ends = sorted(
        [i.start_s for i in found if not i.starts_before]
        + [i.end_s for i in found if not i.ends_after]
    )
    assert len(ends) == changes.size
    assert np.max(np.abs(np.array(ends) - changes)) <= 0.05


def test_an_attitude_reset_against_the_grid_search():
    # At 30 s the attitude is reset: the vector's angles jump; intervals end or start
    # at the event, flagged as neither before nor after the span.
    reset = AttitudeReset(
        30.0, Rotation.from_euler("x", 90.0, degrees=True), angular_velocity=[0.3, 0.0, 1.0]
    )
    trajectory, spec = _spin(
        60.0,
        [1.0, 0.0, 0.0],
        events=[reset],
        sun_exclusion_half_angle_rad=math.radians(50.0),
    )
    structural, gridded = both(trajectory, spec)
    assert_same(structural, gridded)
    for interval in structural.vectors[0].sun_visible:
        if abs(interval.start_s - 30.0) < 1e-6 or abs(interval.end_s - 30.0) < 1e-6:
            assert not (interval.starts_before or interval.ends_after)


def test_the_issue_tumbler_against_the_grid_search():
    # I = 100, 200, 300, ω0 = (0.001, 1, 0.001) rad/s: near the intermediate axis, it
    # flips every 27.5 s; a 30° cone on +z, the Sun near +x; 20 minutes.
    craft = Spacecraft("tumbler", [100.0, 200.0, 300.0])
    state = InitialState(Rotation.identity(), angular_velocity=[0.001, 1.0, 0.001])
    scenario = Scenario("tumbler", craft, "2027-03-20T12:00:00", state, duration=1200.0, step=10.0)
    spec = PointingSpec([BodyVector("cone", [0.0, 0.0, 1.0], math.radians(30.0), "star_tracker")])
    trajectory = propagate(scenario)
    assert_same(*both(trajectory, spec))


def test_mean_incidence_against_dense_sampling():
    # The attitude reset case: the structural search integrates max(cos, 0) on the
    # quintic through each cell's ends, cut at the refined crossings; a trapezoid on
    # 600 001 samples of each segment is the reference.
    reset = AttitudeReset(
        30.0, Rotation.from_euler("x", 90.0, degrees=True), angular_velocity=[0.3, 0.0, 1.0]
    )
    trajectory, spec = _spin(60.0, [1.0, 0.0, 0.0], events=[reset])
    analysis = pointing_analysis(trajectory, spec)
    total = 0.0
    for start, stop in ((0.0, 30.0 - 2e-9), (30.0, 60.0)):
        τ = np.linspace(start, stop, 600_001)
        samples = pointing_samples(trajectory, spec, τ)
        total += np.trapezoid(samples.vectors[0].cos_incidence, τ)
    assert abs(analysis.vectors[0].mean_cos_incidence - total / 60.0) <= 1e-5
