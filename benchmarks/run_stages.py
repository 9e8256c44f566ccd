"""Benchmark: where one `attitude run`'s CPU goes, stage by stage.

A fresh process runs the command as a user does (``attitude.cli.main.main()`` with the
command line's own arguments, so with the command's process settings), with each stage
of ``attitude.report.run`` wrapped to count its CPU time (``time.process_time``, the
main process's own): the imports before the scenario is read, reading it, planning,
the output stream (CSV, pointing samples, the figures' envelopes), the pointing search
with ``intervals.csv``, the AEM, the figures (matplotlib's import, drawing, PNG), the
summary and the page.  The process that computes the validity horizon beside the run
is counted apart (its CPU from ``os.wait4``, with the main process's exit, which is
what the parent sees beyond the main's last reading).  ``--repeat`` runs, the median
of each stage.

    python -m benchmarks.run_stages                       # the one-hour spinner
    python -m benchmarks.run_stages --one-day --repeat 3  # the spinner over a day at 1 s
    python -m benchmarks.run_stages --scenario scenarios/boom_deployment.toml

Results: stdout and ``benchmarks/results/run_stages[_one_day].json``.
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

# Run in the child: the stages wrapped, then the command; the CPU of each stage (s)
# written as JSON to the path in argv[1].
_DRIVER = r"""
import json, sys, time
started = time.process_time()
record = sys.argv.pop(1)
stages = {}
def timed(module, name, stage):
    function = getattr(module, name)
    def wrapper(*args, **kwargs):
        begin = time.process_time()
        try:
            return function(*args, **kwargs)
        finally:
            stages[stage] = stages.get(stage, 0.0) + time.process_time() - begin
    setattr(module, name, wrapper)
begin = time.process_time()
import attitude.files.scenario_reader as reader
import attitude.report.plan as plan
import attitude.report.run as run
import attitude.cli.main as cli
stages["imports before the scenario is read"] = time.process_time() - begin
timed(reader, "load_scenario", "reading the scenario")
timed(plan, "plan_run", "planning")
timed(run, "_stream_output_grid", "the output stream")
timed(run, "_search_pointing", "the pointing search and intervals.csv")
timed(run, "_write_aem", "the AEM")
timed(run, "_plots", "the figures")
timed(run, "write_json", "summary.json and the page")
timed(run, "render_page", "summary.json and the page")
try:
    cli.main()
finally:
    stages["main process, all"] = time.process_time() - started
    with open(record, "w") as stream:
        json.dump(stages, stream)
"""


def run_once(scenario: Path, folder: Path, repeat: int) -> dict[str, float]:
    """One run in a fresh process: each stage's CPU (s), the main process's, and the
    rest (the horizon's process and the main's exit) from ``os.wait4``."""
    record = folder / f"stages-{repeat}.json"
    out = folder / f"out-{repeat}"
    command = [sys.executable, "-c", _DRIVER, str(record), "run", str(scenario), "--out", str(out)]
    environment = dict(os.environ, PYTHONPATH=str(ROOT), PYTHONPYCACHEPREFIX=str(folder / "pyc"))
    environment.pop("PYTHONDONTWRITEBYTECODE", None)  # as an installed copy: .pyc kept
    process = subprocess.Popen(
        command, cwd=ROOT, env=environment, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE
    )
    stderr = process.stderr.read() if process.stderr else b""
    _, status, usage = os.wait4(process.pid, 0)
    if os.waitstatus_to_exitcode(status) != 0:
        raise RuntimeError(f"{scenario.name}: {stderr.decode()[-1500:]}")
    stages = json.loads(record.read_text())
    total = usage.ru_utime + usage.ru_stime
    stages["the horizon's process and the exit"] = total - stages["main process, all"]
    stages["all"] = total
    return stages


def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--scenario", type=Path, default=ROOT / "scenarios/spinner_thruster_pulse.toml"
    )
    parser.add_argument("--one-day", action="store_true", help="the spinner over a day at 1 s")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)
    commit = short_commit(ROOT)
    started = started_utc()
    loads = [os.getloadavg()[0]]
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        scenario = args.scenario.resolve()
        if args.one_day:
            scenario = folder / "spinner_one_day.toml"
            scenario.write_text(scenario_text(1.0))
        run_once(scenario, folder, -1)  # warm: .pyc files, numba's cache, fonts
        runs = []
        for repeat in range(args.repeat):
            runs.append(run_once(scenario, folder, repeat))
            loads.append(os.getloadavg()[0])
    names = list(dict.fromkeys(name for run in runs for name in run))
    medians = {name: statistics.median(run.get(name, 0.0) for run in runs) for name in names}
    for name, value in medians.items():
        print(f"{name:45s} {value:6.3f} s CPU")
    report = {
        "scenario": "spinner, 1 day at 1 s" if args.one_day else args.scenario.name,
        "commit": commit,
        "median_cpu_s": medians,
        "runs": runs,
        **conditions(started, loads),
        "repeat": args.repeat,
    }
    path = write_results(f"run_stages{'_one_day' if args.one_day else ''}", report)
    print(
        f"{report['scenario']} at {commit}; started {started}; load (1 min) "
        f"{min(loads):.1f} to {max(loads):.1f}; written: {path}"
    )
    return report


if __name__ == "__main__":
    main()
