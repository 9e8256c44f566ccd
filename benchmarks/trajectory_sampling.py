"""Benchmark: a trajectory sampled at a million astropy epochs, against the solver alone.

Issue 3 asks that sampling 1e6 epochs cost little more than the solver itself.  In
one run: ``Trajectory.attitude(times)`` with ``times`` a UTC ``Time`` array of 1e6
epochs (the time-scale conversion, the segment lookup and the solver), the same with
TT seconds, and ``EulerSolver.attitude`` on the same seconds; the ratios.

    python -m benchmarks.trajectory_sampling
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np

from attitude.files.scenario_reader import load_scenario
from attitude.trajectory.trajectory import propagate

RESULTS = Path(__file__).parent / "results"
SCENARIO = Path(__file__).parents[1] / "scenarios" / "spinner_thruster_pulse.toml"


def _best(function, repeats=3):
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        best = min(best, time.perf_counter() - start)
    return best


def main() -> dict:
    loaded = load_scenario(SCENARIO)
    trajectory = propagate(loaded.scenario)
    seconds = np.linspace(0.0, loaded.scenario.stop_s, 1_000_000)
    times = loaded.scenario.times(seconds)  # UTC Time array (built once: not timed)
    solver = trajectory.segments[-1].solver
    report = {
        "samples": seconds.size,
        "trajectory_time_s": _best(lambda: trajectory.attitude(times)),
        "trajectory_seconds_s": _best(lambda: trajectory.attitude(seconds)),
        "solver_s": _best(lambda: solver.attitude(seconds)),
    }
    report["ratio_time_over_solver"] = report["trajectory_time_s"] / report["solver_s"]
    report["ratio_seconds_over_solver"] = report["trajectory_seconds_s"] / report["solver_s"]
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "trajectory_sampling.json").write_text(json.dumps(report, indent=2) + "\n")
    for key, value in report.items():
        print(f"{key:28s} {value:.4g}")
    return report


if __name__ == "__main__":
    main()
