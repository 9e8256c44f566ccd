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


BURNS = "".join(
    f"\n[[torques.burns]]\noffset = {300.0 + 150.0 * k}\nduration = 5.0\n"
    "torque = [0.001, -0.001, 0.0005]\n"
    for k in range(30)
)


def test_the_aem_records_past_checks_budget_are_predicted(monkeypatch, tmp_path, capsys):
    """Under a thousand burns a day of gravity gradient is 2001 AEM segments, whose
    planning took check 27 s of CPU: it has check's budget now, and predicts the
    segments past it from their rate bounds and the planned ones' steps.  Here, with a
    budget of zero, every segment but the first is predicted; the run plans them all,
    within a factor 2 of the prediction (measured: 7 % over, on the thousand burns)."""
    import attitude.report.plan as plan_module

    text = re.sub(r"(?m)^accuracy = .*$", "step = 20.0", EXAMPLE.read_text())
    text = re.sub(r"(?ms)^\[\[torques\.burns\]\].*?(?=^\[output\])", BURNS + "\n", text)
    path = tmp_path / "burns.toml"
    path.write_text(text)
    loaded = load_scenario(path)
    run = plan_run(loaded.scenario, loaded.pointing, loaded.outputs, horizon=False)
    monkeypatch.setattr(plan_module, "CHECK_BUDGET_S", 0.0)
    check = plan_run(loaded.scenario, loaded.pointing, loaded.outputs, check=True)
    assert run.aem is not None and check.aem is not None
    assert run.aem.predicted == 0 and len(run.aem.segments) == 61
    assert check.aem.predicted == 60 and len(check.aem.segments) == 61
    assert [(s.start_s, s.end_s) for s in check.aem.segments] == [
        (s.start_s, s.end_s) for s in run.aem.segments
    ]
    assert 0.5 <= check.aem.records / run.aem.records <= 2.0
    assert main(["check", str(path)]) == 0
    out = capsys.readouterr().out
    assert re.search(r"aem +about \d+ records .*; 1 of its 61 segments planned within check's", out)
