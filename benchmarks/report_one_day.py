"""Benchmark: the report of a long scenario, this tree side by side with a peer commit.

The spinner example (scenarios/spinner_thruster_pulse.toml: a TLE orbit, three body
vectors, a thruster pulse) stretched to ``--days`` days at a 1 s step, run as a user
runs it: ``attitude run`` in a fresh Python process, so the wall time includes the
imports.  The peer is another commit of this repository (by default 52ad360, the main
before the reports were streamed), exported with ``git archive`` and run the same way,
alternately with this tree, ``--repeat`` times each, on the same machine and under the
same load: the figures to compare are the ratios, not the absolute times (other work
shares the machine).  Peak RSS is each child's own (``os.wait4``).

    python -m benchmarks.report_one_day                       # 1 day, 3 runs each
    python -m benchmarks.report_one_day --days 30 --repeat 1  # the 30-day case (slow)
    python -m benchmarks.report_one_day --days 30 --no-peer   # this tree only
    python -m benchmarks.report_one_day --formats parquet,aem # passed to this tree's run
    python -m benchmarks.report_one_day --days 30 --no-pointing  # the trajectory alone

A peer that refuses the run (main before streaming refuses 30 days with pointing: its
memory estimate is 19.5 GB) is reported as refused, with its message.

Targets (issue 9): one day in ≤ 45% of the peer's time; peak RSS ≤ 600 MB at 30 days.
Results go to stdout and to benchmarks/results/report_<days>d.json.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).parents[1]
RESULTS = Path(__file__).parent / "results"
PEER_COMMIT = "52ad360"


def scenario_text(days: float, pointing: bool = True) -> str:
    text = (ROOT / "scenarios" / "spinner_thruster_pulse.toml").read_text()
    text = re.sub(r"(?m)^duration = .*$", f"duration = {days * 86400.0!r}", text)
    text = re.sub(r"(?m)^step = .*$", "step = 1.0", text)
    return text if pointing else text.split("[pointing]")[0]


def export_peer(commit: str, folder: Path) -> Path:
    """The peer commit's tree, from ``git archive`` (nothing is checked out here)."""
    archive = subprocess.run(
        ["git", "-C", str(ROOT), "archive", commit], capture_output=True, check=True
    ).stdout
    subprocess.run(["tar", "-x", "-C", str(folder)], input=archive, check=True)
    return folder


def run_once(
    tree: Path, scenario: Path, out: Path, extra: list[str], module: str = "attitude.cli.main"
) -> dict:
    """One ``attitude run`` of ``tree``'s package: wall time, peak RSS, stages, sizes."""
    environment = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tree), str(ROOT)]))
    command = [sys.executable, "-m", module, "run", str(scenario), "--out", str(out)]
    start = time.perf_counter()
    process = subprocess.Popen(
        command + extra, cwd=tree, env=environment, stderr=subprocess.PIPE, text=True
    )
    stderr = process.stderr.read()
    _, status, usage = os.wait4(process.pid, 0)
    wall = time.perf_counter() - start
    process.returncode = os.waitstatus_to_exitcode(status)
    if process.returncode != 0:
        raise RuntimeError(f"{tree}: exit {process.returncode}: {stderr[-2000:]}")
    stages = [
        (float(m.group(1)), m.group(2)) for m in re.finditer(r"\[\s*([\d.]+) s\] (.*)", stderr)
    ]
    return {
        "wall_s": wall,
        "peak_rss_mb": usage.ru_maxrss / 1024.0,  # Linux: kilobytes
        "cpu_s": usage.ru_utime + usage.ru_stime,
        "stages": stages,
        "output_bytes": {p.name: p.stat().st_size for p in sorted(out.iterdir())},
    }


def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--days", type=float, default=1.0)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--peer-commit", default=PEER_COMMIT)
    parser.add_argument("--no-peer", action="store_true")
    parser.add_argument("--formats", help="--formats for this tree's runs")
    parser.add_argument("--no-pointing", action="store_true", help="without [pointing]")
    args = parser.parse_args(argv)
    extra = ["--formats", args.formats] if args.formats else []
    load_before = os.getloadavg()
    runs: dict[str, list[dict]] = {"this": [], "peer": []}
    refused: dict[str, str] = {}
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        scenario = folder / "scenario.toml"
        scenario.write_text(scenario_text(args.days, not args.no_pointing))
        trees = {"this": ROOT}
        if not args.no_peer:
            peer = folder / "peer"
            peer.mkdir()
            trees["peer"] = export_peer(args.peer_commit, peer)
        for repeat in range(args.repeat):
            for name, tree in trees.items():
                if name in refused:
                    continue
                out = folder / f"out-{name}-{repeat}"
                try:
                    runs[name].append(
                        run_once(tree, scenario, out, extra if name == "this" else [])
                    )
                except RuntimeError as exc:
                    refused[name] = str(exc)
                    print(f"{name:4s} refused: {exc}", flush=True)
                    continue
                print(
                    f"{name:4s} run {repeat + 1}: {runs[name][-1]['wall_s']:7.1f} s wall, "
                    f"{runs[name][-1]['peak_rss_mb']:7.0f} MB peak RSS",
                    flush=True,
                )
    load_after = os.getloadavg()

    def median(name, key):
        return statistics.median(run[key] for run in runs[name]) if runs[name] else None

    report = {
        "case": f"spinner_thruster_pulse.toml over {args.days:g} days at 1 s "
        f"({int(args.days * 86400) + 1} epochs)"
        + (", no pointing" if args.no_pointing else ", TLE orbit, 3 body vectors"),
        "refused": refused,
        "machine": f"{platform.machine()}, {os.cpu_count()} cores, {platform.system()} "
        f"{platform.release()}, Python {platform.python_version()}",
        "load_average_1min": {"before": load_before[0], "after": load_after[0]},
        "peer_commit": None if args.no_peer else args.peer_commit,
        "formats": args.formats or "default",
        "runs": runs,
        "median_wall_s": {name: median(name, "wall_s") for name in runs},
        "median_cpu_s": {name: median(name, "cpu_s") for name in runs},
        "peak_rss_mb": {
            name: max((r["peak_rss_mb"] for r in runs[name]), default=None) for name in runs
        },
    }
    if runs["peer"]:
        report["wall_ratio_this_to_peer"] = median("this", "wall_s") / median("peer", "wall_s")
        report["cpu_ratio_this_to_peer"] = median("this", "cpu_s") / median("peer", "cpu_s")
    report["wall_s_per_day"] = median("this", "wall_s") / args.days
    RESULTS.mkdir(exist_ok=True)
    suffix = "_no_pointing" if args.no_pointing else ""
    path = RESULTS / f"report_{args.days:g}d{suffix}.json"
    path.write_text(json.dumps(report, indent=2) + "\n")
    print(f"case: {report['case']}; load {load_before[0]:.2f} -> {load_after[0]:.2f}")
    for name in runs:
        if runs[name]:
            sizes = runs[name][-1]["output_bytes"]
            print(
                f"{name:4s}: median {median(name, 'wall_s'):.2f} s wall, "
                f"{median(name, 'cpu_s'):.2f} s CPU, "
                f"peak RSS {report['peak_rss_mb'][name]:.0f} MB, "
                f"outputs {sum(sizes.values()) / 1e6:.1f} MB"
            )
    if runs["peer"]:
        print(
            f"this / peer: wall {report['wall_ratio_this_to_peer']:.3f}, "
            f"CPU {report['cpu_ratio_this_to_peer']:.3f}"
        )
    print(f"written: {path}")
    return report


if __name__ == "__main__":
    main()
