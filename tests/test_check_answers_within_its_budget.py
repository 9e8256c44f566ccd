"""``attitude check`` checks instead of computing: what it says beyond its budget is a
prediction, and it says so, with what the run will cost.

Check's step search is the run's, stopped at a budget of CPU time
(``attitude.trajectory.steps.CHECK_BUDGET_S``, 3 s).  Here the budget is set to zero, as
if the run were a day of a fast tumbler: check must then stop after its first
comparison of the two runs, predict the estimate from the span covered, and say how
long the run will take;
``run`` of the same file meets the accuracy over the whole span.  The time check takes
is measured in ``benchmarks/torques_check.py``, not asserted here.
"""

import json
import re
from pathlib import Path

import pytest

import attitude.trajectory.trajectory as trajectory_module
from attitude.cli.main import main
from attitude.files.scenario_reader import load_scenario
from attitude.report.plan import plan_run

ROOT = Path(__file__).parents[1]
EXAMPLE = ROOT / "scenarios" / "tumbler_gravity_gradient_burn.toml"


@pytest.fixture
def no_budget(monkeypatch):
    monkeypatch.setattr(trajectory_module, "CHECK_BUDGET_S", 0.0)


def test_check_predicts_past_its_budget_and_the_run_measures(no_budget, tmp_path, capsys):
    assert main(["check", str(EXAMPLE)]) == 0
    out = capsys.readouterr().out
    assert re.search(r"the search stopped at check's [\d.]+ s budget after 1 try", out), out
    assert re.search(r"the run's error is predicted at [\d.e+-]+ rad \(from its first", out)
    assert re.search(r"run cost +about [\d.]+ (s|min|h) of CPU", out)

    loaded = load_scenario(EXAMPLE)
    plan = plan_run(loaded.scenario, loaded.pointing, check=True)
    steps = plan.trajectory.steps
    assert steps is not None and not steps.settled and len(steps.tried) == 1
    assert steps.measurement is not None and not steps.measurement.complete

    out_dir = tmp_path / "out"
    assert main(["run", str(EXAMPLE), "--out", str(out_dir), "--formats", "csv", "--quiet"]) == 0
    torques = json.loads((out_dir / "summary.json").read_text())["torques"]
    assert torques["accuracy_met"] is True
    assert torques["estimated_error_predicted"] is False
    assert torques["estimated_error_rad"] <= torques["accuracy_rad"]


def test_a_given_step_too_long_to_measure_in_check_is_predicted(no_budget, tmp_path, capsys):
    text = EXAMPLE.read_text()
    text = re.sub(r"(?m)^accuracy = .*$", "step = 0.05", text)
    text = text.replace("duration = 5828.0", "duration = 1900.0")
    text = re.sub(r"(?ms)^\[\[events\]\].*?(?=^\[torques\])", "", text)
    path = tmp_path / "fine_step.toml"
    path.write_text(text)
    assert main(["check", str(path)]) == 0
    out = capsys.readouterr().out
    assert "step        0.05 s in every segment under torques" in out, out
    assert re.search(r"estimated error of the run: [\d.e+-]+ rad, predicted from its first", out)
    assert re.search(r"run cost +about [\d.]+ (s|min|h) of CPU .*38\d\d\d steps at 0\.05 s", out)
