"""Benchmark: the CPU a run spends importing the libraries its outputs need, beside a peer.

Issue 20 asks a one-hour example to cost at most half of what it cost at 98b74d4.  A
run pays a floor no change of ours can remove while it writes the same outputs: the
Python interpreter and the import of the libraries its work needs (numpy, scipy,
astropy with its Earth-orientation tables, skyfield, matplotlib for the figures,
pyarrow for the CSV writer).  This measures that floor for each example and sets it
beside the peer's whole run and the target:

1. ``attitude run`` of the example in this tree, in a fresh process that records, as it
   exits, the third-party modules its main process imported (``sys.modules``, in
   import order, without the standard library and without ``attitude`` itself);
2. alternated, ``--repeat`` times, after one warm-up of each: a fresh process of this
   tree's Python that imports exactly those modules and nothing else (the floor), and
   the peer's whole run (``benchmarks.runs_side_by_side.run_once``); CPU time (user +
   system, the run's forked child included, from ``os.wait4``).

The floor is what this tree's run would cost if everything of ours (reading the
scenario, the propagation, the search, the files, drawing the figures, the validity
horizon) cost nothing: when it exceeds half the peer's run, the target cannot be met
with the same outputs.

    python -m benchmarks.import_floor --peer-tree /work/wt/base98 \\
        --peer-python /work/wt/base98/.venv/bin/python

Results: stdout and ``benchmarks/results/import_floor.json``.
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

from benchmarks.run_record import conditions, started_utc, write_results
from benchmarks.runs_side_by_side import ROOT, cases, run_once

# Run in the child: the example's run, then the third-party modules it imported.
_RECORD = """
import sys, json
record = sys.argv.pop(1)
try:
    from attitude.cli.main import main
    main()
except SystemExit:
    pass
finally:
    names = [
        name for name in list(sys.modules)
        if name.partition(".")[0] not in sys.stdlib_module_names
        and name.partition(".")[0] not in ("attitude", "__main__", "_virtualenv")
        and not name.startswith("__editable__")
    ]
    with open(record, "w") as handle:
        json.dump(names, handle)
"""

# Run in the child: import those modules, in that order, and nothing of ours.
_IMPORT = """
import importlib, json, sys
for name in json.load(open(sys.argv[1])):
    if name not in sys.modules:
        try:
            importlib.import_module(name)
        except Exception:
            pass
"""


def _cpu(command: list[str], environment: dict[str, str]) -> float:
    """CPU time (s) of ``command`` and its children, from ``os.wait4``."""
    process = subprocess.Popen(
        command, env=environment, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE
    )
    stderr = process.stderr.read() if process.stderr else b""
    _, status, usage = os.wait4(process.pid, 0)
    if os.waitstatus_to_exitcode(status) != 0:
        raise RuntimeError(f"{command}: {stderr.decode()[-1500:]}")
    return usage.ru_utime + usage.ru_stime


def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--peer-tree", type=Path, required=True, help="the peer's worktree")
    parser.add_argument("--peer-python", required=True, help="the peer venv's python")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)
    started = started_utc()
    loads = [os.getloadavg()[0]]
    report: dict = {"cases": {}}
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        # The .pyc files of either side kept outside both trees, as runs_side_by_side does.
        environment = dict(
            os.environ, PYTHONPATH=str(ROOT), PYTHONPYCACHEPREFIX=str(folder / "pyc-this")
        )
        environment.pop("PYTHONDONTWRITEBYTECODE", None)
        peer_pycache = folder / "pyc-peer"
        for name, scenario in cases(False, folder, args.peer_tree).items():
            record = folder / f"{name}.json"
            out = folder / f"record-{name}"
            command = [sys.executable, "-c", _RECORD, str(record), "run", str(scenario)]
            _cpu([*command, "--out", str(out)], environment)
            floor_command = [sys.executable, "-c", _IMPORT, str(record)]
            _cpu(floor_command, environment)  # warm: .pyc files, font cache
            run_once(
                args.peer_python, args.peer_tree, scenario, folder / f"warm-{name}", peer_pycache
            )
            floors, peers = [], []
            for repeat in range(args.repeat):
                order = ("floor", "peer") if repeat % 2 == 0 else ("peer", "floor")
                for side in order:
                    if side == "floor":
                        floors.append(_cpu(floor_command, environment))
                    else:
                        peer_out = folder / f"peer-{name}-{repeat}"
                        run = run_once(
                            args.peer_python, args.peer_tree, scenario, peer_out, peer_pycache
                        )
                        peers.append(run["cpu_s"])
                loads.append(os.getloadavg()[0])
            floor, peer = statistics.median(floors), statistics.median(peers)
            modules = json.loads(record.read_text())
            tops = sorted({m.partition(".")[0] for m in modules})
            report["cases"][name] = {
                "floor_cpu_s": floors,
                "peer_cpu_s": peers,
                "median": {"floor": floor, "peer": peer},
                "floor_over_peer": floor / peer,
                "target_cpu_s": 0.5 * peer,
                "libraries": tops,
            }
            print(
                f"{name:30s} floor {floor:5.2f} s CPU; peer's whole run {peer:5.2f} s CPU "
                f"(target 0.5x: {0.5 * peer:5.2f} s); floor / peer {floor / peer:.2f}   "
                f"(load {loads[-1]:.1f})",
                flush=True,
            )
    report.update(
        {
            **conditions(started, loads),
            "repeat": args.repeat,
        }
    )
    path = write_results("import_floor", report)
    print(
        f"{report['machine']}; started {started}; load (1 min) {min(loads):.1f} to "
        f"{max(loads):.1f}; written: {path}"
    )
    return report


if __name__ == "__main__":
    main()
