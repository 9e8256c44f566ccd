"""What a run and ``attitude check`` state is what they computed, as they computed it.

- Flips under torques are located on the propagated motion, so ``summary.json``
  gives their count beside their times, the Monte Carlo column carries the same count,
  and a count that was not computed is null with its reason, never 0.
- The report shows what ``summary.json`` holds: no ``inf`` where the file has null.
- ``attitude check`` prints numbers rounded to what they mean (a rate of 30 deg/s, not
  29.999999999999996) and its nouns in the right number (1 flip, 1 body vector).

The flips' times themselves are compared with DOP853 in
``test_scenario_torques_against_numerical_integration.py``.
"""

import json
import re
from pathlib import Path

import numpy as np

from attitude.cli.main import main
from attitude.files.scenario_reader import load_scenario
from attitude.montecarlo.metrics import METRICS_ONLY, sample_metrics
from attitude.report.plan import plan_run
from attitude.report.summaries import motion_summary
from attitude.trajectory.motion import NOT_LOCATED

ROOT = Path(__file__).parents[1]
EXAMPLE = ROOT / "scenarios" / "tumbler_gravity_gradient_burn.toml"


def _short_example(tmp_path: Path) -> Path:
    """The example over its first 2500 s (the burn and the event), for speed."""
    text = EXAMPLE.read_text().replace("duration = 5828.0", "duration = 2500.0")
    path = tmp_path / "tumbler.toml"
    path.write_text(text)
    return path


def test_torqued_flips_are_counted_where_they_are_located(tmp_path):
    path = _short_example(tmp_path)
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--formats", "report,plots", "--quiet"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    flips = summary["motion"]["flips"]
    segments = summary["motion"]["segments"]
    assert all(s["motion"] == "torqued" for s in segments)
    assert flips["count"] == len(flips["times_s"]) == sum(s["flip_count"] for s in segments) > 0
    assert all(s["flips_note"] is None for s in segments)
    assert "not located" not in json.dumps(summary)
    # The page says what the file says: no period is null in both, never "inf".
    assert all(s["body_period_s"] is None for s in segments)
    page = (out / "report.html").read_text()
    assert not re.search(r">\s*-?inf\s*<", page)
    assert not re.search(r"\binf\b", page)

    # The Monte Carlo metrics of the same scenario carry the same count.
    loaded = load_scenario(path)
    plan = plan_run(loaded.scenario, loaded.pointing, METRICS_ONLY, horizon=False)
    metrics, _ = sample_metrics(plan)
    assert metrics["flip_count"] == flips["count"]
    assert metrics["segment0_flip_count"] == segments[0]["flip_count"]
    assert np.isclose(metrics["max_rate_deg_s"], summary["extrema"]["max_rate_deg_s"], rtol=1e-12)


def test_a_count_not_computed_is_null_with_its_reason(tmp_path):
    """`attitude check` leaves the flips under torques to the run: its plan says so."""
    loaded = load_scenario(_short_example(tmp_path))
    plan = plan_run(loaded.scenario, loaded.pointing, METRICS_ONLY, horizon=False, check=True)
    summary = motion_summary(plan.trajectory, plan.motion)
    assert summary["flips"]["count"] is None
    assert NOT_LOCATED in summary["flips"]["note"]
    assert all(s["flip_count"] is None and s["flips_note"] for s in summary["segments"])
    metrics, _ = sample_metrics(plan)
    assert np.isnan(metrics["flip_count"])  # not 0


def test_check_prints_numbers_as_they_mean(tmp_path, capsys):
    text = (ROOT / "scenarios" / "dzhanibekov_t_handle.toml").read_text()
    text = re.sub(
        r"(?m)^angular_velocity = .*$",
        'angular_velocity = { value = [0.72, 30.0, 0.72], unit = "deg/s" }',
        text,
    )
    path = tmp_path / "handle.toml"
    for duration, flips in (("30.0", "1 flip)"), ("100.0", "3 flips)")):
        path.write_text(re.sub(r"(?m)^duration = .*$", f"duration = {duration}", text, count=1))
        assert main(["check", str(path)]) == 0
        out = capsys.readouterr().out
        assert "[0.72, 30, 0.72] deg/s" in out, out
        numbers = [line for line in out.splitlines() if line.startswith(("  rate", "  spacecraft"))]
        assert numbers and not re.search(r"\d\.\d{9,}", "".join(numbers)), numbers
        assert flips in out, out
        assert "1 flips" not in out


def test_check_says_one_body_vector(tmp_path, capsys):
    assert main(["check", str(_short_example(tmp_path))]) == 0
    out = capsys.readouterr().out
    assert "1 body vector," in out and "1 body vectors" not in out
    assert re.search(r"run cost +about [\d.]+ (s|min|h) of CPU", out), out


def test_a_survey_read_in_chunks_finds_the_same_flips_and_rate(tmp_path, monkeypatch):
    """A survey too long to keep is read a chunk at a time, in bounded memory: the same
    flips and the same largest rate as the survey read whole."""
    import attitude.trajectory.torqued as torqued
    from attitude.trajectory.motion import analyze, largest_rate_of
    from attitude.trajectory.trajectory import propagate

    scenario = load_scenario(_short_example(tmp_path)).scenario
    whole = analyze(propagate(scenario))
    monkeypatch.setattr(torqued, "_SURVEY_CHUNK", 97)
    monkeypatch.setattr(torqued, "_SURVEY_KEPT", 10)
    chunked = analyze(propagate(scenario))
    for a, b in zip(whole, chunked, strict=True):
        assert a.flip_count == b.flip_count and a.flip_count
        np.testing.assert_array_equal(a.flip_times_s, b.flip_times_s)
    assert largest_rate_of(whole) == largest_rate_of(chunked)
