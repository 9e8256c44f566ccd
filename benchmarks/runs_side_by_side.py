"""Benchmark: whole `attitude run`s, this tree beside a peer worktree, in CPU time.

What a user pays for a run is everything, not the solver: the imports, reading the
scenario, the validity horizon (a process forked beside the run), the output stream,
the pointing search, the plots.  This runs ``attitude run`` in a fresh process for
each case, once with this tree and once with the peer's tree and its own Python (its
own venv: the peer's dependencies as it pinned them), alternated, ``--repeat`` times,
after one untimed warm-up run of each (numba's cache, matplotlib's font cache, the
``.pyc`` files, kept for each side in a folder of its own outside both trees), and
reports each run's CPU time (user + system of the run and of the process it forks
beside it, from ``os.wait4``) and the median ratio this / peer per case, with the
peer's own median beside it.  CPU time because the machine is shared:
wall time moves with the load, CPU time much less.

    python -m benchmarks.runs_side_by_side --peer-tree /work/wt/base98 \\
        --peer-python /work/wt/base98/.venv/bin/python                 # the examples
    python -m benchmarks.runs_side_by_side --peer-tree ... --peer-python ... \\
        --one-day --repeat 5                     # the spinner stretched to a day at 1 s

The cases: every ``scenarios/*.toml`` that ``attitude run`` runs (the Monte Carlo
example has its own benchmark, ``benchmarks.montecarlo_fixed_cost``), or, with
``--one-day``, ``spinner_thruster_pulse.toml`` over one day at a 1 s output step
(``benchmarks.report_one_day``'s case).

Results: stdout and ``benchmarks/results/runs_side_by_side[_one_day].json``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from benchmarks.report_one_day import scenario_text
from benchmarks.run_record import conditions, short_commit, started_utc, write_results

ROOT = Path(__file__).parents[1]
# Scenarios that `attitude run` does not run as they are.
_NOT_RUN = {"spinner_dispersions.toml"}


def cases(one_day: bool, folder: Path, peer_tree: Path) -> dict[str, Path]:
    """name → scenario file (the one-day case written into ``folder``).  The examples
    are the peer's files, which both trees read (a later example may use what the
    peer does not have: the nadir pointer's Sun sensor)."""
    if one_day:
        path = folder / "spinner_one_day.toml"
        path.write_text(scenario_text(1.0))
        return {"spinner, 1 day at 1 s": path}
    found = sorted((peer_tree / "scenarios").glob("*.toml"))
    return {p.stem: p for p in found if p.name not in _NOT_RUN}


def run_once(python: str, tree: Path, scenario: Path, out: Path, pycache: Path) -> dict:
    """One ``attitude run`` in a fresh process: CPU (s, the run and its forked child),
    wall (s), peak RSS (MB).

    ``pycache``: where this side's compiled modules are kept (``PYTHONPYCACHEPREFIX``),
    outside both trees: an installed package has its ``.pyc`` files, and a shell with
    ``PYTHONDONTWRITEBYTECODE`` set would otherwise make every run compile the
    package's modules again (0.1 to 0.2 s of either side's CPU)."""
    environment = dict(os.environ, PYTHONPATH=str(tree), PYTHONPYCACHEPREFIX=str(pycache))
    environment.pop("PYTHONDONTWRITEBYTECODE", None)
    command = [python, "-m", "attitude", "run", str(scenario), "--out", str(out)]
    start = time.perf_counter()
    process = subprocess.Popen(
        command, cwd=tree, env=environment, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE
    )
    stderr = process.stderr.read() if process.stderr else b""
    _, status, usage = os.wait4(process.pid, 0)
    wall = time.perf_counter() - start
    if os.waitstatus_to_exitcode(status) != 0:
        raise RuntimeError(f"{tree}: {scenario.name}: {stderr.decode()[-1500:]}")
    return {
        "cpu_s": usage.ru_utime + usage.ru_stime,
        "wall_s": wall,
        "peak_rss_mb": usage.ru_maxrss / 1024.0,
    }


def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--peer-tree", type=Path, required=True, help="the peer's worktree")
    parser.add_argument("--peer-python", required=True, help="the peer venv's python")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--one-day", action="store_true")
    parser.add_argument("--only", nargs="*", help="case names (the examples' file stems)")
    args = parser.parse_args(argv)
    peer_commit = short_commit(args.peer_tree)
    this_commit = short_commit(ROOT)
    sides = {"this": (sys.executable, ROOT), "peer": (args.peer_python, args.peer_tree)}
    loads = [os.getloadavg()[0]]
    started = started_utc()
    report: dict = {"cases": {}}
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        chosen = cases(args.one_day, folder, args.peer_tree)
        if args.only:
            chosen = {k: v for k, v in chosen.items() if k in args.only}
        for name, scenario in chosen.items():
            runs: dict[str, list[dict]] = {"this": [], "peer": []}
            for side, (python, tree) in sides.items():  # warm: caches, .pyc, fonts
                run_once(python, tree, scenario, folder / f"warm-{side}", folder / f"pyc-{side}")
            for repeat in range(args.repeat):
                order = ("this", "peer") if repeat % 2 == 0 else ("peer", "this")
                for side in order:
                    python, tree = sides[side]
                    out = folder / f"out-{side}-{repeat}"
                    runs[side].append(run_once(python, tree, scenario, out, folder / f"pyc-{side}"))
                loads.append(os.getloadavg()[0])
            this = statistics.median(r["cpu_s"] for r in runs["this"])
            peer = statistics.median(r["cpu_s"] for r in runs["peer"])
            report["cases"][name] = {
                "runs": runs,
                "median_cpu_s": {"this": this, "peer": peer},
                "cpu_ratio": this / peer,
            }
            print(
                f"{name:34s} this {this:6.2f} s CPU, peer {peer:6.2f} s CPU: "
                f"ratio {this / peer:.3f}   (load {loads[-1]:.1f})",
                flush=True,
            )
    report.update(
        {
            "this_commit": this_commit,
            "peer_commit": peer_commit,
            **conditions(started, loads),
            "repeat": args.repeat,
        }
    )
    path = write_results(f"runs_side_by_side{'_one_day' if args.one_day else ''}", report)
    print(
        f"this {this_commit} against {peer_commit}; {report['machine']}; started {started}; "
        f"load (1 min) {min(loads):.1f} to {max(loads):.1f}; written: {path}"
    )
    return report


if __name__ == "__main__":
    main()
