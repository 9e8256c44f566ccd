""" "Blinded by any" and the Sun sensor's view, against interval sets and dense sampling.

A tumbling CubeSat on a polar orbit near new Moon, its star tracker sweeping the sky
with Sun, Moon and Earth-limb exclusions that overlap (the Moon is 6° from the Sun),
and a Sun sensor whose 60° field of view must contain the Sun; the spacecraft enters
the Earth's shadow half way through.  ``attitude run`` writes intervals.csv and
summary.json; the checks:

- ``blinded`` (intervals.csv rows, summary.json totals and fraction) is the union of
  the tracker's three exclusions as intervals.csv lists them, computed here by a sweep
  over the interval ends (a counter of open intervals: the script an analyst would
  write), not by the package's merge;
- the same intervals against a dense sampling (every 20 ms) of the exclusion flags
  that ``pointing_samples`` gives, and the Sun sensor's ``sun_in_view`` against the
  Sun's angle from the sensor's axis computed here from the attitude and the Sun's
  direction (inside 60° and outside the umbra): every sample agrees except within the
  refinement precision of an interval end, and the fractions of the span agree to a
  sample step per interval end;
- the union itself on random interval sets, against a boolean mask;
- a bad inclusion cone is refused by ``check`` with the file and key named.
"""

import csv
import itertools
import json
import math
from pathlib import Path

import numpy as np
import pytest
from cli_lines import said

from attitude.base.errors import InputError
from attitude.cli.main import main
from attitude.files.scenario_reader import ScenarioFileError, load_scenario
from attitude.pointing.intervals import Interval, union
from attitude.pointing.sampling import pointing_samples
from attitude.pointing.spec import BodyVector
from attitude.trajectory.trajectory import propagate

SCENARIO = """
[scenario]
name = "Tumbling CubeSat: a star tracker blinded by the Sun, the Moon and the limb; a Sun sensor"
epoch = "2027-03-08T12:00:00"

[spacecraft]
name = "CubeSat"
principal_moments = [0.03, 0.05, 0.06]

[initial_state]
quaternion = [1.0, 0.0, 0.0, 0.0]
angular_velocity = { value = [0.5, 3.0, 0.5], unit = "deg/s" }

[output]
duration = 1800.0
step = 10.0

[pointing]
interval_precision = 1e-4

[pointing.keplerian]
semi_major_axis = { value = 6878.137, unit = "km" }
eccentricity = 0.001
inclination = { value = 97.4, unit = "deg" }
raan = { value = 0.0, unit = "deg" }
argument_of_perigee = { value = 0.0, unit = "deg" }
mean_anomaly = { value = 60.0, unit = "deg" }

[[pointing.body_vectors]]
name = "tracker"
vector = [1.0, 0.0, 0.0]
kind = "star_tracker"
sun_exclusion_half_angle = { value = 50.0, unit = "deg" }
moon_exclusion_half_angle = { value = 40.0, unit = "deg" }
earth_limb_exclusion_angle = { value = 15.0, unit = "deg" }

[[pointing.body_vectors]]
name = "sun_sensor"
vector = [0.0, 0.0, 1.0]
kind = "sun_sensor"
sun_inclusion_half_angle = { value = 60.0, unit = "deg" }
"""

SPAN_S = 1800.0
PRECISION_S = 1e-4
DENSE_STEP_S = 0.02


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("blinded")
    path = folder / "blinded.toml"
    path.write_text(SCENARIO)
    out = folder / "out"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 0
    rows = [
        row
        for row in csv.reader(
            line for line in (out / "intervals.csv").read_text().splitlines() if line[:1] != "#"
        )
    ]
    header, rows = rows[0], rows[1:]
    intervals: dict[tuple[str, str], list[tuple[float, float]]] = {}
    for row in rows:
        entry = dict(zip(header, row, strict=True))
        key = (entry["kind"], entry["body_vector"])
        intervals.setdefault(key, []).append((float(entry["start_s"]), float(entry["end_s"])))
    summary = json.loads((out / "summary.json").read_text())
    return path, out, intervals, summary


def _sweep_union(*lists: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """The union by a counter of open intervals over the sorted ends (starts before ends
    at the same time, so that touching intervals join)."""
    events = sorted(
        [(start, 0) for items in lists for start, _ in items]
        + [(end, 1) for items in lists for _, end in items]
    )
    out, open_count, start = [], 0, 0.0
    for time, kind in events:
        if kind == 0:
            if open_count == 0:
                start = time
            open_count += 1
        else:
            open_count -= 1
            if open_count == 0:
                out.append((start, time))
    return out


def _inside(times: np.ndarray, intervals: list[tuple[float, float]]) -> np.ndarray:
    inside = np.zeros(times.size, dtype=bool)
    for start, end in intervals:
        inside |= (times >= start) & (times <= end)
    return inside


def _near_an_end(times: np.ndarray, intervals: list[tuple[float, float]]) -> np.ndarray:
    ends = np.array([t for interval in intervals for t in interval])
    if ends.size == 0:
        return np.zeros(times.size, dtype=bool)
    return np.min(np.abs(times[:, None] - ends[None, :]), axis=1) <= 2.0 * PRECISION_S


def test_the_scenario_exercises_overlaps_the_moon_and_the_shadow(run):
    summary = run[3]
    tracker = summary["pointing"]["body_vectors"]["tracker"]
    for kind in ("sun_exclusion", "moon_exclusion", "earth_limb_exclusion"):
        assert tracker[kind]["count"] >= 5, kind
    # The exclusions overlap: their union is shorter than their sum.
    total = sum(tracker[kind]["total_s"] for kind in tracker["blinded"]["by"])
    assert tracker["blinded"]["total_s"] < total - 100.0
    assert summary["pointing"]["eclipses"]["umbra"]["count"] == 1
    assert summary["pointing"]["moon_behind_earth"]["count"] == 1


def test_blinded_is_the_union_of_the_exclusions_in_intervals_csv(run):
    _, out, intervals, summary = run
    exclusions = [
        intervals.get((kind, "tracker"), [])
        for kind in ("sun_exclusion", "moon_exclusion", "earth_limb_exclusion")
    ]
    expected = _sweep_union(*exclusions)
    found = intervals[("blinded", "tracker")]
    assert len(found) == len(expected)
    np.testing.assert_allclose(np.array(found), np.array(expected), rtol=0.0, atol=1e-9)
    blinded = summary["pointing"]["body_vectors"]["tracker"]["blinded"]
    assert blinded["by"] == ["sun_exclusion", "moon_exclusion", "earth_limb_exclusion"]
    assert blinded["count"] == len(expected)
    total = sum(end - start for start, end in expected)
    assert blinded["total_s"] == pytest.approx(total, abs=1e-7)
    assert blinded["fraction_of_span"] == pytest.approx(total / SPAN_S, abs=1e-10)
    assert blinded["longest_s"] == pytest.approx(max(e - s for s, e in expected), abs=1e-8)
    # A vector with no exclusion has no "blinded", and none appears in intervals.csv.
    assert "blinded" not in summary["pointing"]["body_vectors"]["sun_sensor"]
    assert ("blinded", "sun_sensor") not in intervals
    page = (out / "report.html").read_text()
    assert "blinded by any" in page
    assert f"{blinded['total_s']:.6g} s ({100.0 * blinded['fraction_of_span']:.4g} %)" in page


@pytest.fixture(scope="module")
def dense(run):
    path = run[0]
    loaded = load_scenario(path)
    trajectory = propagate(loaded.scenario)
    # Offset by a third of a step: no sample falls on a grid point of the search.
    times = np.arange(DENSE_STEP_S / 3.0, SPAN_S, DENSE_STEP_S)
    return loaded, trajectory, times, pointing_samples(trajectory, loaded.pointing, times)


def test_blinded_against_dense_sampling(run, dense):
    _, _, intervals, summary = run
    _, _, times, samples = dense
    tracker = next(v for v in samples.vectors if v.vector.name == "tracker")
    flagged = tracker.sun_violated | tracker.moon_violated | tracker.earth_limb_violated
    blinded = intervals[("blinded", "tracker")]
    inside = _inside(times, blinded)
    disagree = (inside != flagged) & ~_near_an_end(times, blinded)
    assert not np.any(disagree), times[disagree][:5]
    fraction = summary["pointing"]["body_vectors"]["tracker"]["blinded"]["fraction_of_span"]
    edges = 2 * len(blinded)
    assert abs(np.mean(flagged) - fraction) <= edges * DENSE_STEP_S / SPAN_S


def test_sun_sensor_view_against_the_sun_angle_computed_here(run, dense):
    _, _, intervals, summary = run
    _, trajectory, times, samples = dense
    axis = trajectory.attitude(times).apply([0.0, 0.0, 1.0])
    cosine = np.einsum("ij,ij->i", axis, samples.sun_direction_icrf)
    angle = np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))
    umbra = _inside(times, intervals[("umbra", "")])
    seen = (angle < 60.0) & ~umbra
    assert np.any(seen) and np.any((angle < 60.0) & umbra)  # the shadow hides some
    view = intervals[("sun_in_view", "sun_sensor")]
    near = _near_an_end(times, view) | _near_an_end(times, intervals[("umbra", "")])
    assert not np.any((_inside(times, view) != seen) & ~near)
    flag = next(v for v in samples.vectors if v.vector.name == "sun_sensor").sun_in_view
    assert not np.any((flag != seen) & ~near)
    entry = summary["pointing"]["body_vectors"]["sun_sensor"]
    assert entry["sun_inclusion_half_angle_deg"] == 60.0
    assert entry["sun_in_view"]["count"] == len(view)
    edges = 2 * len(view) + 2
    assert abs(np.mean(seen) - entry["sun_in_view"]["fraction_of_span"]) <= (
        edges * DENSE_STEP_S / SPAN_S
    )
    header = next(
        line
        for line in (run[1] / "timeseries.csv").read_text().splitlines()
        if line.startswith("time_utc")
    )
    assert "sun_sensor_sun_in_view" in header.split(",")


def test_union_against_a_boolean_mask():
    rng = np.random.default_rng(23)
    grid = np.arange(0.0, 100.0, 0.001)
    for _ in range(50):
        lists = []
        for _ in range(rng.integers(1, 4)):
            ends = np.sort(rng.choice(np.arange(0.0, 100.0, 0.5), size=2 * rng.integers(0, 8)))
            pairs = ends.reshape(-1, 2)
            lists.append([Interval(float(a), float(b)) for a, b in pairs if b > a])
        merged = union(*lists)
        mask = np.zeros(grid.size, dtype=bool)
        for items in lists:
            mask |= _inside(grid, [(i.start_s, i.end_s) for i in items])
        assert np.array_equal(_inside(grid, [(i.start_s, i.end_s) for i in merged]), mask)
        starts = [i.start_s for i in merged]
        assert starts == sorted(starts)
        assert all(a.end_s < b.start_s for a, b in itertools.pairwise(merged))


def test_union_keeps_what_the_span_cuts():
    cut = union(
        [Interval(0.0, 2.0, starts_before=True), Interval(8.0, 10.0, ends_after=True)],
        [Interval(1.0, 3.0), Interval(9.0, 10.0)],
    )
    assert cut == [Interval(0.0, 3.0, True, False), Interval(8.0, 10.0, False, True)]


@pytest.mark.parametrize(
    ("value", "message"),
    [
        ('{ value = 30.0, unit = "deg" }', "is within sun_exclusion_half_angle"),
        ('{ value = 190.0, unit = "deg" }', "must be between 0 and 180 deg"),
        ('{ value = 0.0, unit = "deg" }', "must be between 0 and 180 deg"),
        ("60.0", "an angle needs its unit"),
        ('"60 deg"', "an angle needs its unit"),
    ],
)
def test_a_bad_inclusion_cone_is_refused_with_the_key(tmp_path, capsys, value, message):
    text = SCENARIO.replace(
        'sun_inclusion_half_angle = { value = 60.0, unit = "deg" }',
        f"sun_inclusion_half_angle = {value}\n"
        'sun_exclusion_half_angle = { value = 40.0, unit = "deg" }',
    )
    path = tmp_path / "sensor.toml"
    path.write_text(text)
    with pytest.raises(ScenarioFileError) as caught:
        load_scenario(path)
    where = "sensor.toml: pointing.body_vectors[1].sun_inclusion_half_angle: "
    assert str(caught.value).startswith(where) and message in str(caught.value)
    assert main(["check", str(path)]) == 2
    err = said(capsys.readouterr().err)  # without its progress lines
    assert len(err) == 1 and where in err[0]


def test_a_bad_inclusion_cone_is_refused_in_python():
    with pytest.raises(InputError, match="the Sun could never be seen"):
        BodyVector(
            "sensor",
            [0.0, 0.0, 1.0],
            math.radians(40.0),
            kind="sun_sensor",
            sun_inclusion_half_angle_rad=math.radians(30.0),
        )
    with pytest.raises(InputError, match="sun inclusion half angle must be between"):
        BodyVector("sensor", [0.0, 0.0, 1.0], sun_inclusion_half_angle_rad=math.radians(200.0))


def test_eclipse_png_on_any_orbit_as_the_docs_say(run):
    """A Keplerian orbit (no TLE) gets its eclipse figure, and the docs say so."""
    out = run[1]
    assert (out / "eclipse.png").stat().st_size > 0
    docs = (Path(__file__).parents[1] / "docs" / "scenarios.md").read_text()
    row = next(line for line in docs.splitlines() if line.startswith("| `plots` |"))
    assert "TLE" not in row and "`eclipse.png` with an orbit" in row


def test_the_monte_carlo_metrics_carry_blinded_and_the_sun_sensor(run):
    from attitude.montecarlo.metrics import metric_names, pointing_outcome
    from attitude.outputs.formats import OutputChoice
    from attitude.report.plan import plan_run

    path, _, _, summary = run
    loaded = load_scenario(path)
    plan = plan_run(loaded.scenario, loaded.pointing, OutputChoice(("csv",)), horizon=False)
    metrics = pointing_outcome(plan)
    names = metric_names(loaded.scenario, plan.pointing)
    vectors = summary["pointing"]["body_vectors"]
    for name, kind in (("tracker", "blinded"), ("sun_sensor", "sun_in_view")):
        for total in ("count", "total_s", "longest_s", "fraction_of_span"):
            key = f"{name}_{kind}_{total}"
            assert key in names and metrics[key] == vectors[name][kind][total], key
    assert "sun_sensor_blinded_total_s" not in names
