"""Benchmark: Monte Carlo throughput on Dask, 1 and 2 workers, against one `attitude run`.

The one-day spinner with pointing (scenarios/spinner_thruster_pulse.toml: 5 rpm, a
thruster pulse, a TLE orbit, three body vectors) at a 10 s output step (8 641
epochs), dispersed: moments 2 %, principal axes 0.5°, attitude 1°, rate, the pulse's
time, magnitude and direction.  In one run, so that the ratios share the machine's
load:

1. ``attitude run`` of the nominal scenario in a fresh process (what one sample costs
   a user who runs samples one by one), and the cost of one sample in this process,
   stage by stage (which part a vectorized free flow would speed up, which part is the
   same for every sample);
2. the Monte Carlo job on a local cluster of 1 worker (``--one-worker`` samples) and of
   2 workers (``--samples``, the first samples of the same seed: their rows must agree);
3. the throughput (samples a second, once the samples run), the share of the workers'
   time spent outside the samples (Dask: scheduling, transfers, idle at the end), the
   scheduler's cost per task, and the bytes each task moves.

    python -m benchmarks.montecarlo_throughput                     # 10,000 and 1,000
    python -m benchmarks.montecarlo_throughput --samples 40 --one-worker 20

A sample of this case costs about 6 to 14 s here (the exact pointing search of a day
of a 5 rpm spinner: 560,000 search points), so the default 10,000 samples would take
a day on this machine; docs/benchmarks.md ("Monte Carlo") was measured with the
second line (run A) and with `--samples 24 --one-worker 12` (run B), and extrapolates.

Results: stdout and benchmarks/results/montecarlo_throughput.json.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import re
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

from benchmarks.trajectory_sampling import _best  # best of 3, warm

ROOT = Path(__file__).parents[1]
RESULTS = Path(__file__).parent / "results"

DISPERSIONS = """
[dispersions]
seed = 2027
samples = {samples}

[dispersions.spacecraft]
principal_moments = { distribution = "normal", relative_sigma = 0.02 }
principal_axes = { distribution = "normal", sigma = { value = 0.5, unit = "deg" } }

[dispersions.initial_state]
attitude = { distribution = "normal", sigma = { value = 1.0, unit = "deg" } }
angular_velocity = { distribution = "normal", sigma = { value = 0.2, unit = "deg/s" } }

[[dispersions.events]]
event = 0
time = { distribution = "uniform", half_width = 0.5 }
impulse_magnitude = { distribution = "normal", relative_sigma = 0.1 }
impulse_direction = { distribution = "normal", sigma = { value = 2.0, unit = "deg" } }
"""


def scenario_text(samples: int) -> str:
    text = (ROOT / "scenarios" / "spinner_thruster_pulse.toml").read_text()
    text = re.sub(r"(?m)^duration = .*$", "duration = 86400.0", text)
    text = re.sub(r"(?m)^step = .*$", "step = 10.0", text)
    return text + DISPERSIONS.replace("{samples}", str(samples))


class LoadSampler:
    """The 1-minute load average every 10 s while the benchmark runs."""

    def __init__(self) -> None:
        self.values = [os.getloadavg()[0]]
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.wait(10.0):
            self.values.append(os.getloadavg()[0])

    def stop(self) -> dict:
        self._stop.set()
        values = [*self.values, os.getloadavg()[0]]
        return {"min": min(values), "mean": float(np.mean(values)), "max": max(values)}


def _uptime() -> str:
    return subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()


def sample_stages(path: Path) -> dict:
    """One sample's cost in this process, stage by stage (best of 3, warm)."""
    from attitude.files.scenario_reader import load_scenario, scenario_from_document
    from attitude.montecarlo.dispersions import draw_sample
    from attitude.montecarlo.metrics import (
        METRICS_ONLY,
        pointing_outcome,
        sun_angles_deg,
    )
    from attitude.montecarlo.plan import plan_montecarlo
    from attitude.report.plan import plan_run

    loaded = load_scenario(path)
    mc = plan_montecarlo(loaded)
    d, document = mc.dispersions, loaded.document
    sample = draw_sample(d, document, 0)
    sample_loaded = scenario_from_document(path, sample.document)
    # As the job plans a sample (attitude.montecarlo.job): no validity horizon.
    plan = plan_run(sample_loaded.scenario, sample_loaded.pointing, METRICS_ONLY, horizon=False)
    seconds = plan.scenario.output_seconds()
    pointing_outcome(plan)  # warm: the ephemeris

    def read_and_plan():
        again = scenario_from_document(path, sample.document)
        plan_run(again.scenario, again.pointing, METRICS_ONLY, horizon=False)

    stages = {
        "draw_s": _best(lambda: draw_sample(d, document, 0)),
        "read_and_plan_s": _best(read_and_plan),
        "sun_angles_on_grid_s": _best(lambda: sun_angles_deg(plan, seconds)),
        "pointing_analysis_s": _best(lambda: pointing_outcome(plan)),
    }
    stages["total_s"] = sum(stages.values())
    stages["search_grid_points"] = plan.search.count
    stages["search_step_s"] = plan.search.step_s
    return stages


def attitude_run(path: Path, folder: Path) -> float:
    """Wall time of `attitude run` on the nominal scenario, in a fresh process."""
    start = time.perf_counter()
    subprocess.run(
        [
            sys.executable,
            "-m",
            "attitude",
            "run",
            str(path),
            "--out",
            str(folder / "run"),
            "--quiet",
        ],
        check=True,
    )
    return time.perf_counter() - start


def montecarlo(path: Path, samples: int, workers: int) -> tuple[dict, object]:
    from attitude.files.scenario_reader import load_scenario
    from attitude.montecarlo.plan import plan_montecarlo
    from attitude.montecarlo.simulation import simulate

    marks: dict[str, float] = {}

    def progress(done: int, total: int, failed: int) -> None:
        marks.setdefault("first", time.perf_counter())
        marks["last"] = time.perf_counter()

    start = time.perf_counter()
    mc = plan_montecarlo(load_scenario(path), samples=samples)
    result = simulate(mc, workers=workers, progress=progress)
    wall = time.perf_counter() - start
    running = marks["last"] - marks["first"]
    execution = result.execution
    report = {
        "samples": samples,
        "workers": workers,
        "failed": int((result.table["status"] != "ok").sum()),
        "wall_s": wall,
        "samples_wall_s": running,
        "samples_per_s": samples / running,
        "worker_time_in_samples": execution["compute_s"] / (running * workers),
        **{
            k: execution[k]
            for k in (
                "batch_size",
                "tasks",
                "task_overhead_s",
                "job_bytes",
                "result_bytes_per_task",
                "nominal_sample_s",
            )
        },
    }
    return report, result


def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=10_000, help="samples on 2 workers")
    parser.add_argument("--one-worker", type=int, default=1_000, help="samples on 1 worker")
    args = parser.parse_args(argv)
    load = LoadSampler()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        path = folder / "spinner_one_day.toml"
        path.write_text(scenario_text(args.samples))
        report: dict = {
            "machine": f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores",
            "python": platform.python_version(),
            "case": "spinner_thruster_pulse.toml over 86400 s every 10 s (8641 epochs), "
            "TLE orbit, 3 body vectors; 7 dispersed quantities",
            "uptime_at_start": _uptime(),
        }
        report["attitude_run_s"] = attitude_run(path, folder)
        report["sample_in_process"] = sample_stages(path)
        one, one_result = montecarlo(path, args.one_worker, 1)
        two, two_result = montecarlo(path, args.samples, 2)
        report["one_worker"], report["two_workers"] = one, two
        first = two_result.table.iloc[: args.one_worker].reset_index(drop=True)
        report["same_rows_on_1_and_2_workers"] = bool(first.equals(one_result.table))
        per_sample_2 = 1.0 / two["samples_per_s"]
        report["ratios"] = {
            "two_over_one_worker_throughput": two["samples_per_s"] / one["samples_per_s"],
            "attitude_run_over_mc_sample_on_2_workers": report["attitude_run_s"] / per_sample_2,
            "mc_sample_on_1_worker_over_in_process_sample": (1.0 / one["samples_per_s"])
            / report["sample_in_process"]["total_s"],
        }
        from attitude.montecarlo.report import write_montecarlo_report

        start = time.perf_counter()
        write_montecarlo_report(two_result, folder / "mc")
        report["report_s"] = time.perf_counter() - start
        report["report_bytes"] = {p.name: p.stat().st_size for p in (folder / "mc").iterdir()}
    report["load_average_1min"] = load.stop()
    report["uptime_at_end"] = _uptime()
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "montecarlo_throughput.json").write_text(json.dumps(report, indent=2) + "\n")
    print(json.dumps(report, indent=2))
    return report


if __name__ == "__main__":
    main()
