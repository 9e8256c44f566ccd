"""Benchmark: a Monte Carlo job's fixed cost in CPU, this tree beside a peer worktree.

A job pays, besides its samples, for the plan, the nominal run on the client, the
local Dask cluster (its scheduler, and worker processes that import Dask and the
package before their first sample), the report, and the closing.  This measures the
CPU of the whole process tree of ``attitude montecarlo`` (the client, the cluster's
processes, whatever they start: this process is made their subreaper, so that every
one of them is reaped here and counted in ``RUSAGE_CHILDREN``), for two sample
counts, ``--small`` and ``--large``, on ``--workers`` workers:

    fixed = C(small) − small × (C(large) − C(small)) / (large − small)

(C the tree's CPU, the slope the CPU a sample costs in the job), for this tree and
for the peer's tree with its own Python, alternated, ``--repeat`` times, after one
untimed warm-up job of each.  The case is the Monte Carlo example,
``scenarios/spinner_dispersions.toml`` (one hour of a dispersed 5 rpm spinner at a 5 s
output step, with pointing), read from the peer's tree, with its report (``--out``).

    python -m benchmarks.montecarlo_fixed_cost --peer-tree /work/wt/base98 \\
        --peer-python /work/wt/base98/.venv/bin/python

Results: stdout and ``benchmarks/results/montecarlo_fixed_cost.json``.
"""

from __future__ import annotations

import argparse
import ctypes
import json
import os
import platform
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).parents[1]
RESULTS = Path(__file__).parent / "results"
_PR_SET_CHILD_SUBREAPER = 36  # linux/prctl.h


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def job_cpu(python: str, tree: Path, scenario: Path, workers: int, out: Path) -> float:
    """The CPU (s) of one ``attitude montecarlo`` job's whole process tree."""
    before = _children_cpu()
    environment = dict(os.environ, PYTHONPATH=str(tree))
    command = [python, "-m", "attitude", "montecarlo", str(scenario), "--quiet"]
    command += ["--workers", str(workers), "--out", str(out)]
    done = subprocess.run(command, cwd=tree, env=environment, capture_output=True, text=True)
    while True:  # the orphans the job left to this subreaper (a fork server, say)
        try:
            os.waitpid(-1, 0)
        except ChildProcessError:
            break
    if done.returncode != 0:
        raise RuntimeError(f"{tree}: exit {done.returncode}: {done.stderr[-1500:]}")
    return _children_cpu() - before


def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--peer-tree", type=Path, required=True)
    parser.add_argument("--peer-python", required=True)
    parser.add_argument("--small", type=int, default=2)
    parser.add_argument("--large", type=int, default=12)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--repeat", type=int, default=2)
    args = parser.parse_args(argv)
    if not sys.platform.startswith("linux"):
        raise SystemExit("needs Linux (a subreaper counts every process of the job)")
    ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_CHILD_SUBREAPER, 1)
    commits = {
        name: subprocess.run(
            ["git", "-C", str(tree), "rev-parse", "--short", "HEAD"],
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
        for name, tree in (("this", ROOT), ("peer", args.peer_tree))
    }
    sides = {"this": (sys.executable, ROOT), "peer": (args.peer_python, args.peer_tree)}
    text = (args.peer_tree / "scenarios" / "spinner_dispersions.toml").read_text()
    loads = [os.getloadavg()[0]]
    started = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    runs: dict[str, dict[int, list[float]]] = {s: {args.small: [], args.large: []} for s in sides}
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        scenarios = {}
        for count in (args.small, args.large):
            path = folder / f"spinner_dispersions_{count}.toml"
            path.write_text(re.sub(r"(?m)^samples = .*$", f"samples = {count}", text))
            scenarios[count] = path
        for side, (python, tree) in sides.items():  # warm: caches, .pyc, fonts
            job_cpu(python, tree, scenarios[args.small], args.workers, folder / f"warm-{side}")
        k = 0
        for repeat in range(args.repeat):
            for count in (args.small, args.large):
                order = ("this", "peer") if k % 2 == 0 else ("peer", "this")
                k += 1
                for side in order:
                    python, tree = sides[side]
                    out = folder / f"out-{side}-{count}-{repeat}"
                    cpu = job_cpu(python, tree, scenarios[count], args.workers, out)
                    runs[side][count].append(cpu)
                    loads.append(os.getloadavg()[0])
                    print(f"{side} {count:3d} samples: {cpu:6.2f} s CPU", flush=True)
    report: dict = {"runs": runs}
    for side in sides:
        small = statistics.median(runs[side][args.small])
        large = statistics.median(runs[side][args.large])
        per_sample = (large - small) / (args.large - args.small)
        report[side] = {
            "job_cpu_s": {args.small: small, args.large: large},
            "cpu_per_sample_s": per_sample,
            "fixed_cpu_s": small - args.small * per_sample,
        }
    report.update(
        {
            "commits": commits,
            "case": f"spinner_dispersions.toml ({args.small} and {args.large} samples, "
            f"{args.workers} workers, with --out)",
            "machine": f"{platform.machine()}, {os.cpu_count()} cores, {platform.system()} "
            f"{platform.release()}, Python {platform.python_version()}",
            "started": started,
            "load_1min": {"min": min(loads), "max": max(loads), "samples": loads},
        }
    )
    RESULTS.mkdir(exist_ok=True)
    path = RESULTS / "montecarlo_fixed_cost.json"
    path.write_text(json.dumps(report, indent=2) + "\n")
    for side in sides:
        r = report[side]
        print(
            f"{side} ({commits[side]}): fixed {r['fixed_cpu_s']:.2f} s CPU, "
            f"{r['cpu_per_sample_s']:.3f} s CPU a sample"
        )
    ratio = report["this"]["fixed_cpu_s"] / report["peer"]["fixed_cpu_s"]
    print(
        f"fixed cost, this / peer: {ratio:.3f}; {report['machine']}; started {started}; "
        f"load (1 min) {min(loads):.1f} to {max(loads):.1f}; written: {path}"
    )
    return report


if __name__ == "__main__":
    main()
