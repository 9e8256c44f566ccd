"""The largest body rate is found on the motion, not on the output grid.

``summary.json`` states ``max_rate_deg_s`` and when it is reached.  Torque-free, it is
the closed-form extremum of |ω| on the polhode (``attitude.trajectory.rates``); under
torques, a search on the dense output.  Compared here with |ω| of the exact solver
sampled densely (a million samples over the span, the largest refined by bounded
scalar maximization, scipy), and shown not to depend on the output step: the same
scenario written every 0.25 s and every 7 s states the same figure and instant.
"""

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from attitude.cli.main import main
from attitude.files.scenario_reader import load_scenario
from attitude.trajectory.motion import analyze, largest_rate_of
from attitude.trajectory.trajectory import propagate

ROOT = Path(__file__).parents[1]
CASES = [
    "scenarios/dzhanibekov_t_handle.toml",
    "scenarios/boom_deployment.toml",
    "scenarios/spinner_thruster_pulse.toml",
    "scenarios/tumbling_defunct_satellite.toml",
    "tests/hostile/separatrix.toml",
    "tests/hostile/sphere.toml",
]


def _sampled(trajectory, start_s, stop_s, count=1_000_000):
    """|ω| sampled densely over the span, its largest refined on the exact solver."""
    t = np.linspace(start_s, stop_s, count)
    rate = np.linalg.norm(trajectory.angular_velocity(t), axis=1)
    k = int(np.argmax(rate))
    low, high = t[max(k - 1, 0)], t[min(k + 1, count - 1)]

    def negative(τ):
        return -float(np.linalg.norm(trajectory.angular_velocity(np.array([τ]))[0]))

    refined = minimize_scalar(
        negative,
        bounds=(low, high),
        method="bounded",
        options={"xatol": 1e-12 * max(abs(high), 1.0)},
    )
    return float(rate[k]), max(float(rate[k]), -refined.fun)


@pytest.mark.parametrize("case", CASES)
def test_the_largest_rate_against_dense_sampling(case):
    scenario = load_scenario(ROOT / case).scenario
    trajectory = propagate(scenario)
    found = largest_rate_of(analyze(trajectory))
    assert found is not None
    rate, at = found
    sampled, refined = _sampled(trajectory, scenario.start_s, scenario.stop_s)
    # Never below what any sample shows, and no more than the refined peak.
    assert rate >= sampled * (1.0 - 1e-13), (rate, sampled)
    assert rate <= refined * (1.0 + 1e-12), (rate, refined)
    # And reached where it is said to be.
    there = float(np.linalg.norm(trajectory.angular_velocity(np.array([at]))[0]))
    assert there == pytest.approx(rate, rel=1e-12, abs=1e-300)


def test_the_largest_rate_does_not_depend_on_the_output_step(tmp_path):
    text = (ROOT / "scenarios/boom_deployment.toml").read_text()
    stated = []
    for step in ("0.25", "7.0"):
        path = tmp_path / f"boom-{step}.toml"
        changed, count = re.subn(r"(?m)^step = .*$", f"step = {step}", text, count=1)
        assert count == 1
        path.write_text(changed)
        out = tmp_path / f"out-{step}"
        assert main(["run", str(path), "--out", str(out), "--formats", "csv", "--quiet"]) == 0
        stated.append(json.loads((out / "summary.json").read_text())["extrema"])
    assert stated[0] == stated[1]
    assert math.isfinite(stated[0]["max_rate_deg_s"])
