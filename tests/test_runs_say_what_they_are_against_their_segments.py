"""What `check`, summary.json and the report's head say a run is, against the run's own
segments: guided by attitude laws, exact torque-free motion, a gyrostat or torques by
splitting with its estimated error.

- A guided scenario on a Keplerian orbit said "no orbit: the gravity gradient ... is not
  known" (it has an orbit: the laws' controller holds the attitude, nothing is
  neglected).
- The report's head said "exact torque-free motion, no integration" for runs under
  laws, and for a gyrostat by splitting.
- `check` said "torques none: the exact torque-free solver" for a gyrostat by
  splitting, and its AEM "within 1e-06 rad of the exact attitude".
"""

import json

import pytest
from cli_lines import said

from attitude.cli.main import main
from attitude.files.scenario_reader import load_scenario
from attitude.report.plan import plan_run
from attitude.report.torques import propagation_text, torques_lines, torques_summary

BASE = """
[scenario]
name = "what the run is"
epoch = "2025-05-01T10:00:00"

[spacecraft]
name = "sat"
principal_moments = [820.0, 1040.0, 610.0]

[pointing.keplerian]
semi_major_axis = { value = 7078.137, unit = "km" }
eccentricity = 0.001
inclination = { value = 98.2, unit = "deg" }
raan = { value = 170.0, unit = "deg" }
argument_of_perigee = { value = 0.0, unit = "deg" }
mean_anomaly = { value = 0.0, unit = "deg" }

[initial_state.law]
name = "nadir"

[output]
duration = 600.0
step = 10.0
"""
LOSS = '\n[[events]]\ntype = "control_loss"\noffset = 300.0\n'
SPINNING = LOSS + 'wheels = { case = "spinning", momentum = [0.0, 2.0, 0.0] }\n'
GUIDED = "guided by attitude laws (closed form)"
EXACT = "exact torque-free motion (closed form, no integration)"
GYROSTAT = "a gyrostat by splitting with the exact gyroscopic flow, estimated error "
TORQUED = "under gravity gradient (point-mass Earth): splitting with the exact free flow, "

CASES = {
    "guided": (BASE, [GUIDED]),
    "guided, then free": (BASE + LOSS, [GUIDED, EXACT]),
    "guided, then a gyrostat": (BASE + SPINNING, [GUIDED, GYROSTAT]),
    "guided, then torqued": (
        BASE + LOSS + "\n[torques]\ngravity_gradient = true\nstep = 10.0\n",
        [GUIDED, TORQUED],
    ),
}


def _plan(tmp_path, text):
    path = tmp_path / "s.toml"
    path.write_text(text, encoding="utf-8")
    loaded = load_scenario(path)
    return path, plan_run(loaded.scenario, loaded.pointing, loaded.outputs, check=True)


@pytest.mark.parametrize("case", list(CASES))
def test_each_run_says_its_segments_kinds(case, tmp_path):
    text, kinds = CASES[case]
    _, plan = _plan(tmp_path, text)
    parts = propagation_text(plan).split(", then ")
    assert len(parts) == len(kinds)
    assert all(p.startswith(k) for p, k in zip(parts, kinds, strict=True)), parts
    torques = torques_summary(plan)
    assert torques["propagation"] == propagation_text(plan)
    note = torques["validity_horizon_note"] or ""
    assert "no orbit" not in note  # every case has one
    if case == "guided":
        assert note.startswith("guided by attitude laws over the whole span")
    if not torques["modelled"]:  # check's line
        assert torques_lines(plan)[0] == f"torques     none: {propagation_text(plan)}"


def test_check_and_the_page_say_a_gyrostat_is_split(tmp_path, capsys):
    path, _ = _plan(tmp_path, BASE + SPINNING)
    assert main(["check", str(path)]) == 0
    out = capsys.readouterr().out
    assert "the exact torque-free solver" not in out
    assert f"torques     none: {GUIDED}, then {GYROSTAT}" in out
    assert "of the propagated attitude" in out  # the AEM's tolerance: not "of the exact"
    out_dir = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out_dir), "--formats", "report"]) == 0
    assert not [line for line in said(capsys.readouterr().err) if "error" in line]
    page = (out_dir / "report.html").read_text()
    summary = json.loads((out_dir / "summary.json").read_text())
    head = page[page.index("computed by attitude") :].split("</p>")[0]
    assert f"({GUIDED}, then {GYROSTAT}" in head and "no integration" not in head
    assert summary["torques"]["propagation"].startswith(f"{GUIDED}, then {GYROSTAT}")
