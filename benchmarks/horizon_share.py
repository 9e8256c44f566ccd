"""Benchmark: the validity horizon's share of a one-day run, in CPU time.

A torque-free run with an orbit computes its validity horizon
(:func:`attitude.trajectory.horizon.validity_horizon`): the averaged kicks' screen in
the run's own process, and the splitting, when the screen cannot answer, in a process
forked beside the report (:class:`attitude.report.beside.Beside`).  This
runs ``attitude run`` in a fresh process (``--repeat`` times, after one untimed warm-up
run: numba's cache, matplotlib's font cache, the ``.pyc`` files) and reports the CPU
of the run's own process and of its children (user + system, ``getrusage``), the
horizon's share (the CPU of its call in the run's process and of the children, over
the whole), and how far the horizon searched (summary.json's
``torques.validity_horizon.searched_s``, which is the span when no crossing comes
first).  The case is ``benchmarks.report_one_day``'s: ``spinner_thruster_pulse.toml``
stretched to one day at a 1 s output step, default outputs.

    python -m benchmarks.horizon_share --repeat 3

Results: stdout and ``benchmarks/results/horizon_share.json``.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from benchmarks.report_one_day import scenario_text
from benchmarks.run_record import conditions, short_commit, started_utc, write_results

ROOT = Path(__file__).parents[1]

# Run in a fresh interpreter: the run, then its own CPU and its children's, and the
# CPU its own process spent in the horizon (the screen by averaged kicks, computed in
# the run's process; the splitting, when needed, in the child forked beside it).
_CHILD = """
import json, resource, sys, time
import attitude.report.plan as plan
spent = [0.0]
beside = plan.horizon_beside
def timed(*args):
    start = time.process_time()
    try:
        return beside(*args)
    finally:
        spent[0] += time.process_time() - start
plan.horizon_beside = timed
from attitude.cli.main import main
sys.argv = ["attitude", "run", sys.argv[1], "--out", sys.argv[2], "--quiet"]
code = main()  # as the command (its own garbage collection), not as a call
own = resource.getrusage(resource.RUSAGE_SELF)
children = resource.getrusage(resource.RUSAGE_CHILDREN)
print(json.dumps({
    "code": code,
    "run_cpu_s": own.ru_utime + own.ru_stime - spent[0],
    "horizon_cpu_s": children.ru_utime + children.ru_stime + spent[0],
    "horizon_in_process_cpu_s": spent[0],
}))
"""


def run_once(scenario: Path, out: Path) -> dict:
    # Compiled modules kept, as an installed package has them (a shell's
    # PYTHONDONTWRITEBYTECODE would make every run compile them again).
    environment = dict(os.environ)
    environment.pop("PYTHONDONTWRITEBYTECODE", None)
    done = subprocess.run(
        [sys.executable, "-c", _CHILD, str(scenario), str(out)],
        cwd=ROOT,
        env=environment,
        capture_output=True,
        text=True,
    )
    if done.returncode != 0:
        raise RuntimeError(done.stderr[-1500:])
    result = json.loads(done.stdout.strip().splitlines()[-1])
    if result["code"] != 0:
        raise RuntimeError(f"attitude run exited {result['code']}: {done.stderr[-1500:]}")
    summary = json.loads((out / "summary.json").read_text())
    horizon = summary["torques"]["validity_horizon"]
    result["searched_s"] = horizon["searched_s"]
    result["horizon_s"] = horizon["horizon_s"]
    total = result["run_cpu_s"] + result["horizon_cpu_s"]
    result["share"] = result["horizon_cpu_s"] / total
    return result


def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--days", type=float, default=1.0)
    args = parser.parse_args(argv)
    commit = short_commit(ROOT)
    loads = [os.getloadavg()[0]]
    started = started_utc()
    runs = []
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        scenario = folder / "spinner_one_day.toml"
        scenario.write_text(scenario_text(args.days))
        run_once(scenario, folder / "warm")
        for repeat in range(args.repeat):
            result = run_once(scenario, folder / f"out-{repeat}")
            runs.append(result)
            loads.append(os.getloadavg()[0])
            print(
                f"run {result['run_cpu_s']:.2f} s CPU, horizon {result['horizon_cpu_s']:.2f} s "
                f"CPU: {100.0 * result['share']:.1f} % of both; searched "
                f"{result['searched_s']:g} s   (load {loads[-1]:.1f})",
                flush=True,
            )
    report = {
        "runs": runs,
        "median_share": statistics.median(r["share"] for r in runs),
        "median_horizon_cpu_s": statistics.median(r["horizon_cpu_s"] for r in runs),
        "median_run_cpu_s": statistics.median(r["run_cpu_s"] for r in runs),
        "case": f"spinner_thruster_pulse.toml over {args.days:g} day(s) at a 1 s step",
        "commit": commit,
        **conditions(started, loads),
    }
    path = write_results("horizon_share", report)
    print(
        f"{commit}: the horizon {100.0 * report['median_share']:.1f} % of the run's CPU "
        f"(median; {report['median_horizon_cpu_s']:.2f} s of "
        f"{report['median_horizon_cpu_s'] + report['median_run_cpu_s']:.2f} s); "
        f"{report['machine']}; started {started}; load (1 min) {min(loads):.1f} to "
        f"{max(loads):.1f}; written: {path}"
    )
    return report


if __name__ == "__main__":
    main()
