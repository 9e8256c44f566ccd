"""Benchmark: the CPU time of one Monte Carlo sample, this tree against a reference commit.

A sample, as a Monte Carlo worker evaluates it (``attitude.montecarlo``): its
scenario read from its drawn document and planned (no validity horizon), |ω| and the
Sun angles on the output grid (the envelopes), and the pointing metrics of
summary.json (the exact search).  Measured in a warm process (the worker's case: its
first sample pays the imports and, here, the shared surroundings), on samples 2 to
``--samples`` of ``scenarios/spinner_dispersions.toml`` (one hour, a 5 rpm spinner
with a thruster pulse, a TLE orbit, three body vectors), CPU time per sample
(``time.process_time``), median over the samples.

The reference tree (``--reference``: a worktree of an earlier commit with its own
venv, e.g. ``git worktree add /work/wt/base98 98b74d4``) runs the same measurement in
its own interpreter; the two alternate, ``--rounds`` times, so that they share the
machine's load, and each round's ratio is printed beside both costs.

``--one-day``: the case of ``benchmarks.montecarlo_throughput`` instead (the spinner
with its thruster pulse over one day at a 10 s output step, dispersed; its file
written once, read by both trees).

    python -m benchmarks.montecarlo_sample_cost --reference /work/wt/base98
    python -m benchmarks.montecarlo_sample_cost --reference /work/wt/base98 --one-day --samples 4

Results: stdout and benchmarks/results/montecarlo_sample_cost.json (``_one_day.json``).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).parent
RESULTS = HERE / "results"
SCENARIO = "scenarios/spinner_dispersions.toml"

# Run in the tree measured: its own modules, whatever their layout.
_CHILD = r"""
import json, sys, time
from pathlib import Path
import numpy as np

def names():
    try:
        from attitude.files.scenario_reader import load_scenario, scenario_from_document
        from attitude.montecarlo.dispersions import draw_sample
        from attitude.montecarlo.metrics import METRICS_ONLY, sample_metrics
        from attitude.montecarlo.plan import plan_montecarlo
        from attitude.report.plan import plan_run
    except ImportError:  # the flat layout before the re-filing
        from attitude.scenario_file import load_scenario, scenario_from_document
        from attitude.dispersions import draw_sample
        from attitude.montecarlo import METRICS_ONLY, plan_montecarlo, sample_metrics
        from attitude.run_plan import plan_run
    return (load_scenario, scenario_from_document, draw_sample, METRICS_ONLY,
            sample_metrics, plan_montecarlo, plan_run)

(load_scenario, scenario_from_document, draw_sample, METRICS_ONLY, sample_metrics,
 plan_montecarlo, plan_run) = names()
path = Path(sys.argv[1])
count = int(sys.argv[2])
loaded = load_scenario(path)
mc = plan_montecarlo(loaded)
stages = {"plan_s": [], "metrics_s": [], "sample_s": []}
metrics = {}
for k in range(count):
    sample = draw_sample(mc.dispersions, loaded.document, k)
    t0 = time.process_time()
    read = scenario_from_document(path, sample.document)
    plan = plan_run(read.scenario, read.pointing, METRICS_ONLY, horizon=False)
    t1 = time.process_time()
    values, _ = sample_metrics(plan)  # what a worker computes for its row
    t2 = time.process_time()
    metrics[k] = {key: v for key, v in values.items() if isinstance(v, float)}
    if k == 0:
        continue  # the worker's first sample: imports, caches
    for key, value in zip(stages, (t1 - t0, t2 - t1, t2 - t0)):
        stages[key].append(value)
print(json.dumps({
    "median": {key: float(np.median(v)) for key, v in stages.items()},
    "all": stages,
    "metrics": {str(k): v for k, v in metrics.items()},
}))
"""


def _run(python: str, tree: Path, samples: int, scenario: Path | None = None) -> dict:
    path = scenario if scenario is not None else tree / SCENARIO
    result = subprocess.run(
        [python, "-c", _CHILD, str(path), str(samples)],
        capture_output=True,
        text=True,
        check=True,
        cwd=tree,
        env={**os.environ, "PYTHONPATH": str(tree)},
    )
    return json.loads(result.stdout.strip().splitlines()[-1])


def _uptime() -> str:
    return subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()


def _python(tree: Path) -> str:
    venv = tree / ".venv" / "bin" / "python"
    return str(venv) if venv.exists() else sys.executable


def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reference", type=Path, required=True, help="the reference tree")
    parser.add_argument("--samples", type=int, default=12)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--one-day", action="store_true", help="the one-day throughput case")
    args = parser.parse_args(argv)
    here = HERE.parent
    scenario = None
    if args.one_day:
        from benchmarks.montecarlo_throughput import scenario_text

        folder = Path(tempfile.mkdtemp(prefix="montecarlo_sample_cost_"))
        scenario = folder / "spinner_one_day_dispersions.toml"
        scenario.write_text(scenario_text(args.samples))
    report: dict = {
        "case": "one day" if args.one_day else SCENARIO,
        "uptime_at_start": _uptime(),
        "rounds": [],
    }
    for _ in range(args.rounds):
        ours = _run(_python(here), here, args.samples, scenario)
        theirs = _run(_python(args.reference), args.reference, args.samples, scenario)
        report["rounds"].append(
            {
                "this_tree": ours["median"],
                "reference": theirs["median"],
                "ratio_sample": ours["median"]["sample_s"] / theirs["median"]["sample_s"],
                "ratio_metrics": ours["median"]["metrics_s"] / theirs["median"]["metrics_s"],
            }
        )
        report["metrics_this_tree"] = ours["metrics"]
        report["metrics_reference"] = theirs["metrics"]
        print(json.dumps(report["rounds"][-1]))
    report["uptime_at_end"] = _uptime()
    RESULTS.mkdir(exist_ok=True)
    name = "montecarlo_sample_cost_one_day" if args.one_day else "montecarlo_sample_cost"
    (RESULTS / f"{name}.json").write_text(json.dumps(report, indent=2) + "\n")
    return report


if __name__ == "__main__":
    main()
