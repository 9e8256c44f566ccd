"""The AEM of a run under torques, read back by an independent parser, holds what it states.

Two runs with ``--formats aem``: ``scenarios/tumbler_gravity_gradient_burn.toml``
(gravity gradient, a 5-minute inertial burn across an inertia change), and the 5 rpm
spinner of ``scenarios/spinner_thruster_pulse.toml`` with a body-fixed spin-up burn
across its thruster pulse.  ``attitude.aem`` is parsed by ccsds-ndm-py
(``aem_read_back``) and every segment is interpolated the way its metadata declares
(LAGRANGE of its INTERPOLATION_DEGREE, Neville's recurrence written in the test) at 16
points inside every interval.  The authority is the propagated attitude of the same
scenario (each segment's own solver, as the file's segments end at an event with the
pre-event state).

What is checked:

- the error read back stays within the file's tolerance (main was 8.5e-5 rad off just
  after the burn starts, for 1e-6), and within the largest error that ``summary.json``
  states for each segment (a figure measured on the file, not an estimate), at the
  default tolerance and at 1e-8 rad;
- each burn's start and stop, and each event, are boundaries of AEM segments (the
  rate's derivative jumps at a burn's edge: no polynomial may cross it).
"""

import json
from pathlib import Path

import numpy as np
import pytest
from aem_read_back import interpolate_as_declared, read_back, rotation_angle

from attitude.cli.main import main
from attitude.environment.timescales import tt_seconds
from attitude.files.scenario_reader import load_scenario
from attitude.trajectory.trajectory import propagate

ROOT = Path(__file__).parents[1]
SPIN_UP = """
[torques]
step = 2.0

[[torques.burns]]
offset = 450.0
duration = 300.0
torque = [0.0, 0.0, 0.5]
frame = "body"
"""
# name: (scenario file, text changes, the boundaries the AEM must have, TT s)
CASES = {
    "tumbler, gravity gradient and an inertial burn": (
        "scenarios/tumbler_gravity_gradient_burn.toml",
        {},
        (1800.0, 1950.0, 2100.0),
    ),
    "spinner, a body burn across a pulse": (
        "scenarios/spinner_thruster_pulse.toml",
        {"duration = 3600.0": "duration = 1000.0", "[pointing]": SPIN_UP + "\n[pointing]"},
        (450.0, 600.0, 750.0),
    ),
}
RUNS = [(case, None) for case in CASES] + [(next(iter(CASES)), "1e-8 rad")]


def _scenario(tmp_path: Path, case: str) -> Path:
    source, changes, _ = CASES[case]
    text = (ROOT / source).read_text()
    for old, new in changes.items():
        assert old in text, (case, old)
        text = text.replace(old, new, 1)
    path = tmp_path / "scenario.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize(("case", "tolerance"), RUNS)
def test_the_file_read_back_holds_its_stated_error(case, tolerance, tmp_path):
    path = _scenario(tmp_path, case)
    scenario = load_scenario(path).scenario
    motion = propagate(scenario)
    out = tmp_path / "out"
    argv = ["run", str(path), "--out", str(out), "--formats", "aem", "--quiet"]
    if tolerance is not None:
        argv += ["--aem-tolerance", tolerance]
    assert main(argv) == 0
    summary = json.loads((out / "summary.json").read_text())
    aem = summary["outputs"]["aem"]
    stated = aem["segments"]
    segments, _ = read_back(out / "attitude.aem")
    assert len(segments) == len(stated)

    worst = 0.0
    fractions = np.linspace(0.0, 1.0, 18)[1:-1]
    for segment, entry in zip(segments, stated, strict=True):
        x = tt_seconds(segment.times, scenario.epoch)
        t = (x[:-1, None] + fractions[None, :] * np.diff(x)[:, None]).ravel()
        solver = motion.segments[entry["segment"]].solver
        error = rotation_angle(
            interpolate_as_declared(segment, t, scenario.epoch), solver.attitude_quaternion(t)
        )
        assert np.max(error) <= aem["tolerance_rad"], (x[0], float(np.max(error)))
        # The stated figure is a bound of what a reader gets, measured on the file.
        assert np.max(error) <= entry["largest_error_rad"], (entry, float(np.max(error)))
        worst = max(worst, float(np.max(error)))
    assert worst <= aem["largest_error_rad"] <= aem["tolerance_rad"]
    # Measured, not a loose bound: within a few percent of what the reader sees.
    assert aem["largest_error_rad"] <= 1.2 * worst

    # Every breakpoint of the motion, and the event, is a boundary of AEM segments.
    starts = [float(tt_seconds(s.times[:1], scenario.epoch)[0]) for s in segments]
    ends = [float(tt_seconds(s.times[-1:], scenario.epoch)[0]) for s in segments]
    for boundary in CASES[case][2]:
        assert min(abs(np.array(starts) - boundary)) < 1e-6, (boundary, starts)
        assert min(abs(np.array(ends) - boundary)) < 1e-6, (boundary, ends)
