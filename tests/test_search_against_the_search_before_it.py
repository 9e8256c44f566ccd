"""The pointing search against the search before the structural one, frozen.

``tests/data/search_baseline`` holds what ``pointing_analysis`` found at commit 395033d
(every segment on a grid of 64 points a turn, golden-section extrema, the exact
surroundings at every point) on the examples with a pointing and on the issue's tumbler
over 20 minutes (``tests/freeze_search_baseline.py``).  Within the precision each states:

- every interval it found is found, its ends within twice the interval precision, with
  the same flags; an interval found now and not then must be shorter than its grid
  step (it could fall between two of its points: the tumbler has two, of 19 and 28 ms,
  against a 69 ms step);
- every extremum within 1e-8 (each refines to 5e-9 and 1 µs), or more extreme now;
- the mean incidence within 2e-3 and the lit fraction's mean within 2e-4: the
  trapezoid rule on its grid, across the kinks of max(cos, 0) and of the penumbra
  (the nadir CubeSat's lit fraction was 9e-5 off, where the search now agrees with a
  sampling every 10 ms to 4e-11: test_extrema_against_dense_sampling.py); the eclipses
  the same;
- the points a run's limit and the output budget count (64 a turn of the fastest
  rotation: ``SearchGrid.turn_points``) as many as its grid had: the same spans refused.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from attitude import (
    BodyVector,
    InitialState,
    PointingSpec,
    Scenario,
    Spacecraft,
    load_scenario,
    pointing_analysis,
    propagate,
)

ROOT = Path(__file__).parents[1]
DATA = Path(__file__).parent / "data" / "search_baseline"
CASES = sorted(p.stem for p in DATA.glob("*.json"))


def _case(name: str):
    if name == "tumbler_20_min":
        from scipy.spatial.transform import Rotation

        craft = Spacecraft("tumbler", [100.0, 200.0, 300.0])
        state = InitialState(Rotation.identity(), angular_velocity=[0.001, 1.0, 0.001])
        scenario = Scenario(
            "tumbler", craft, "2027-03-20T12:00:00", state, duration=1200.0, step=10.0
        )
        cone = BodyVector("cone", [0.0, 0.0, 1.0], math.radians(30.0), "star_tracker")
        return propagate(scenario), PointingSpec([cone])
    loaded = load_scenario(ROOT / "scenarios" / f"{name}.toml")
    return propagate(loaded.scenario), loaded.pointing


def _matches(found: list, before: list, tolerance: float, step: float, where: str) -> None:
    """Every interval ``before`` is among ``found``; the others are shorter than
    ``step``."""
    unmatched = list(found)
    for start, end, starts_before, ends_after in before:
        match = next(
            (
                i
                for i in unmatched
                if abs(i.start_s - start) <= tolerance and abs(i.end_s - end) <= tolerance
            ),
            None,
        )
        assert match is not None, (where, start, end)
        assert (match.starts_before, match.ends_after) == (starts_before, ends_after), where
        unmatched.remove(match)
    for interval in unmatched:
        assert interval.duration_s < step, (where, interval)


@pytest.mark.parametrize("name", CASES)
def test_the_same_intervals_extrema_and_means_as_before(name):
    before = json.loads((DATA / f"{name}.json").read_text())
    trajectory, spec = _case(name)
    analysis = pointing_analysis(trajectory, spec)
    tolerance = 2.0 * before["precision_s"]
    step = before["search_step_s"]
    for kind in ("shadow", "umbra", "moon_hidden"):
        _matches(getattr(analysis, kind), before[kind], tolerance, 0.0, kind)
    assert abs(analysis.sunlit_fraction_mean - before["sunlit_fraction_mean"]) <= 2e-4
    for item in analysis.vectors:
        old = before["vectors"][item.vector.name]
        for kind in ("sun_visible", "sun_exclusion", "moon_exclusion", "earth_limb_exclusion"):
            _matches(getattr(item, kind), old[kind], tolerance, step, f"{item.vector.name} {kind}")
        for kind in ("blinded", "sun_in_view"):
            if kind in old:
                where = f"{item.vector.name} {kind}"
                _matches(getattr(item, kind), old[kind], tolerance, step, where)
        for quantity, (low, high) in item.extrema.items():
            _, old_low, _, old_high = old["extrema"][quantity]
            assert low.value <= old_low + 1e-8, (item.vector.name, quantity, low, old_low)
            assert high.value >= old_high - 1e-8, (item.vector.name, quantity, high, old_high)
            if quantity != "cos_incidence" or old_low > 0.0:
                # More extreme than before only by what the grid missed: an interval's
                # worth of a turn at most, and never on these cases by more than 1e-8.
                assert low.value >= old_low - 1e-8, (item.vector.name, quantity)
                assert high.value <= old_high + 1e-8, (item.vector.name, quantity)
        assert abs(item.mean_cos_incidence - old["mean_cos_incidence"]) <= 2e-3


@pytest.mark.parametrize("name", CASES)
def test_the_run_limit_counts_the_points_it_counted_before(name):
    from attitude.pointing.search import search_grid

    before = json.loads((DATA / f"{name}.json").read_text())
    trajectory, spec = _case(name)
    grid = search_grid(trajectory, spec)
    # Its grid spread its points evenly over the span: span / (count - 1) apart.
    count = round((grid.stop_s - grid.start_s) / before["search_step_s"]) + 1
    assert grid.turn_points == count
