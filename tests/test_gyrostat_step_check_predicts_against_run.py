"""``attitude check`` predicts a gyrostat's step search instead of running it, and the
run's own search agrees with the prediction.

After a control loss with the wheels still spinning and no torque acting, the
gyrostat's step is searched for its accuracy (1e-7 rad by default) over the segment:
each try runs the whole segment at the step and at twice it.  ``check`` cuts that
search at its CPU budget (``attitude.trajectory.steps.CHECK_BUDGET_S``) and predicts
the rest (``TorquedSolver.predict_step``).  Here the budget is set to zero, so that
check stops after the first comparison of its first try whatever the machine's load
(nothing is timed): it must say so, give the step the run will be near and what the
search will cost.  On a segment small enough to run, the run's search ends within a
stated factor of the predicted step; what the prediction refuses, the run refuses too.
The time check takes is not asserted here.
"""

from __future__ import annotations

import json
import re

import pytest

import attitude.torques.solver as torqued_solver
import attitude.trajectory.trajectory as trajectory_module
from attitude.cli.main import main

# A control loss with 520 N m s in the wheels (|I⁻¹h| = 0.5 rad/s), then an impulse
# that sets the body tumbling at about 0.6 rad/s: a fast gyrostat, 1e-7 rad by default.
SCENARIO = """
[scenario]
name = "fast gyrostat"
epoch = "2025-05-01T10:00:00"

[spacecraft]
name = "eo"
principal_moments = [820.0, 1040.0, 610.0]

[pointing.keplerian]
semi_major_axis = {{ value = 7078.137, unit = "km" }}
eccentricity = 0.001
inclination = {{ value = 98.2, unit = "deg" }}
raan = {{ value = 170.0, unit = "deg" }}
argument_of_perigee = {{ value = 0.0, unit = "deg" }}
mean_anomaly = {{ value = 0.0, unit = "deg" }}

[initial_state.law]
name = "nadir"

[[events]]
type = "control_loss"
offset = 600.0
wheels = {{ case = "spinning", momentum = [0.0, 520.0, 0.0] }}

[[events]]
type = "angular_impulse"
offset = 660.0
impulse = [300.0, 0.0, 300.0]

[output]
duration = {duration}
step = {step}
formats = ["csv"]
"""

PREDICTED = re.compile(
    r"segment 2 gyrostat, \w+: the step search for 1e-07 rad stopped at check's budget "
    r"after 1 try; the run finishes it over the segment\n"
    r" +at a step of [\d.]+ s the error is predicted at [\d.e+-]+ rad \(from its first "
    r"[\d.]+ s, growing as t\^[\d.]+\): the step will be near ([\d.e+-]+) s, [\d.e+]+ steps\n"
    r" +run cost +about [\d.]+ (s|min|h) of CPU for its step search"
)


@pytest.fixture
def no_budget(monkeypatch):
    monkeypatch.setattr(trajectory_module, "CHECK_BUDGET_S", 0.0)


def _write(tmp_path, duration: float, step: float):
    path = tmp_path / "gyrostat.toml"
    path.write_text(SCENARIO.format(duration=duration, step=step))
    return path


def test_check_predicts_a_day_of_a_fast_gyrostat(no_budget, tmp_path, capsys):
    """The case of the issue: a day of it took check 2 min of CPU (the search's step
    ends near 0.15 s); check now states a prediction and what the run will cost."""
    assert main(["check", str(_write(tmp_path, 87000.0, 600.0))]) == 0
    out = capsys.readouterr().out
    found = PREDICTED.search(out)
    assert found, out
    assert float(found.group(1)) < 1.0  # a step the search has not tried yet
    assert "the motion below was propagated at" in out


def test_run_ends_near_the_step_check_predicted(no_budget, tmp_path, capsys):
    """540 s of the gyrostat: check predicts from the first 17 s of its first try; the
    run's search, over the whole segment, adopts a step between 0.8 and 3 times that
    (measured: 0.217 s against 0.112 s predicted; the model C h^p is conservative for
    this near-integrable splitting, whose error falls faster than h^4)."""
    path = _write(tmp_path, 1200.0, 10.0)
    assert main(["check", str(path)]) == 0
    found = PREDICTED.search(capsys.readouterr().out)
    assert found
    predicted = float(found.group(1))
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 0
    segment = json.loads((out / "summary.json").read_text())["guidance"]["segments"][2]
    assert 0.8 <= segment["step_s"] / predicted <= 3.0, (segment["step_s"], predicted)
    assert segment["estimated_error_rad"] <= 1e-7
    assert segment["step_search_cpu_s"] > 0.0


def test_what_the_prediction_refuses_the_run_refuses(no_budget, tmp_path, monkeypatch, capsys):
    """With the search's cap on steps lowered to 2000 (from 1e7, so that the case is
    quick), the 540 s segment needs more: check refuses from its prediction, and the
    run from its search, both naming torques.accuracy."""
    monkeypatch.setattr(torqued_solver, "MAX_STEPS", 2e3)
    path = _write(tmp_path, 1200.0, 10.0)
    for command in (["check", str(path)], ["run", str(path), "--out", str(tmp_path / "o")]):
        assert main(command) == 2
        err = capsys.readouterr().err
        assert "torques.accuracy" in err and "more than 2000 steps" in err, err
    assert not (tmp_path / "o").exists()
