"""Benchmark: the one-hour target, each example's CPU above the import floor both trees pay.

The target (issue 27, option (a) of issue 20's one-hour target): an example's run
costs, above the floor that both trees pay, at most half of what 98b74d4's costs above
it.  The floor is what no change of ours can remove while the outputs are the same:
the Python interpreter and the import of the libraries both runs need (numpy, scipy,
astropy, skyfield, matplotlib for the figures, ...).  For each example:

1. ``python -m attitude run`` of the example in each tree, in a fresh process that
   records, as it exits, the third-party modules its main process imported
   (``sys.modules`` in import order, without the standard library and without
   ``attitude`` itself); these are also each side's warm-up run (``.pyc`` files, numba's
   cache, matplotlib's font cache).  The floor's modules are those of this tree's run
   that the peer's run imported too; a library only one side imports is that side's
   own cost.
2. Alternated, ``--repeat`` times (the order reversed every other time), after one
   warm-up of each floor: this tree's run, the peer's run (each as
   ``benchmarks.runs_side_by_side.run_once``), and the floor in each side's own Python
   (a fresh process that imports those modules and nothing else); CPU time (user +
   system, any forked child included, from ``os.wait4``).
3. Per side, the median run less the median floor; the ratio of the two.

The floor process imports with the garbage collector off and frozen before it exits
(no collection at all, none at the exit): the least CPU any process pays for those
imports, less than either run pays for them (the peer collects with Python's
defaults, this tree ten times less often).  A lower floor adds the same to both sides
of the ratio, so it can only bring the ratio closer to 1: the figure is conservative.

    python -m benchmarks.import_floor --peer-tree /tmp/peer-98b74d4 \\
        --peer-python /tmp/peer-98b74d4/.venv/bin/python [--only boom_deployment]

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

from benchmarks.run_record import conditions, short_commit, started_utc, write_results
from benchmarks.runs_side_by_side import ROOT, cases, run_once

TARGET = 0.5

# Run in the child: the command as ``python -m attitude`` runs it (either tree), then
# the third-party modules its main process imported.
_RECORD = """
import json, runpy, sys
record = sys.argv.pop(1)
try:
    runpy.run_module("attitude", run_name="__main__", alter_sys=True)
except SystemExit as exit:
    if exit.code not in (0, None):
        raise
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

# Run in the child: import those modules, in that order, and nothing of ours; no
# garbage collection while importing nor at the exit (see the module docstring).
_IMPORT = """
import gc, importlib, json, sys
gc.disable()
for name in json.load(open(sys.argv[1])):
    if name not in sys.modules:
        try:
            importlib.import_module(name)
        except Exception:
            pass
gc.freeze()
"""


def _environment(tree: Path, pycache: Path) -> dict[str, str]:
    """A side's environment, as ``runs_side_by_side.run_once`` sets it."""
    environment = dict(os.environ, PYTHONPATH=str(tree), PYTHONPYCACHEPREFIX=str(pycache))
    environment.pop("PYTHONDONTWRITEBYTECODE", None)
    return environment


def _cpu(command: list[str], environment: dict[str, str], cwd: Path | None = None) -> float:
    """CPU time (s) of ``command`` and its children, from ``os.wait4``."""
    process = subprocess.Popen(
        command, cwd=cwd, env=environment, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE
    )
    stderr = process.stderr.read() if process.stderr else b""
    _, status, usage = os.wait4(process.pid, 0)
    if os.waitstatus_to_exitcode(status) != 0:
        raise RuntimeError(f"{command}: {stderr.decode()[-1500:]}")
    return usage.ru_utime + usage.ru_stime


def _modules(python: str, tree: Path, scenario: Path, folder: Path, side: str) -> list[str]:
    """The third-party modules a run of ``scenario`` imports in ``tree`` (its warm-up)."""
    record = folder / f"modules-{side}-{scenario.stem}.json"
    out = folder / f"record-{side}-{scenario.stem}"
    command = [python, "-c", _RECORD, str(record), "run", str(scenario), "--out", str(out)]
    _cpu(command, _environment(tree, folder / f"pyc-{side}"), cwd=tree)
    return json.loads(record.read_text())


def measure_case(
    scenario: Path, sides: dict[str, tuple[str, Path]], folder: Path, repeat: int, loads: list
) -> dict:
    """Each side's runs and floors (CPU s), alternated; the medians and the ratio."""
    modules = {side: _modules(*sides[side], scenario, folder, side) for side in sides}
    peer_set = set(modules["peer"])
    floor_modules = [m for m in modules["this"] if m in peer_set]
    floor_list = folder / f"floor-{scenario.stem}.json"
    floor_list.write_text(json.dumps(floor_modules))

    def floor(side: str) -> float:
        python, tree = sides[side]
        environment = _environment(tree, folder / f"pyc-{side}")
        return _cpu([python, "-c", _IMPORT, str(floor_list)], environment)

    def run(side: str, k: int) -> float:
        python, tree = sides[side]
        out = folder / f"out-{side}-{scenario.stem}-{k}"
        return run_once(python, tree, scenario, out, folder / f"pyc-{side}")["cpu_s"]

    for side in sides:
        floor(side)  # warm
    runs: dict[str, list[float]] = {"this": [], "peer": []}
    floors: dict[str, list[float]] = {"this": [], "peer": []}
    for k in range(repeat):
        order = ["this", "peer"] if k % 2 == 0 else ["peer", "this"]
        for side in order:
            runs[side].append(run(side, k))
        for side in order:
            floors[side].append(floor(side))
        loads.append(os.getloadavg()[0])
    median = {
        side: {"run": statistics.median(runs[side]), "floor": statistics.median(floors[side])}
        for side in sides
    }
    above = {side: median[side]["run"] - median[side]["floor"] for side in sides}
    tops = {side: {m.partition(".")[0] for m in modules[side]} for side in sides}
    return {
        "run_cpu_s": runs,
        "floor_cpu_s": floors,
        "median_cpu_s": median,
        "above_floor_cpu_s": above,
        "ratio_above_floor": above["this"] / above["peer"],
        "floor_libraries": sorted({m.partition(".")[0] for m in floor_modules}),
        "libraries_only_this": sorted(tops["this"] - tops["peer"]),
        "libraries_only_peer": sorted(tops["peer"] - tops["this"]),
    }


def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--peer-tree", type=Path, required=True, help="the peer's worktree")
    parser.add_argument("--peer-python", required=True, help="the peer venv's python")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--only", nargs="*", help="case names (the examples' file stems)")
    args = parser.parse_args(argv)
    started = started_utc()
    loads = [os.getloadavg()[0]]
    sides = {"this": (sys.executable, ROOT), "peer": (args.peer_python, args.peer_tree)}
    report: dict = {"cases": {}}
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        chosen = cases(False, folder, args.peer_tree)
        if args.only:
            chosen = {k: v for k, v in chosen.items() if k in args.only}
        for name, scenario in chosen.items():
            case = measure_case(scenario, sides, folder, args.repeat, loads)
            report["cases"][name] = case
            m, above = case["median_cpu_s"], case["above_floor_cpu_s"]
            ratio = case["ratio_above_floor"]
            print(
                f"{name:30s} this {m['this']['run']:5.2f} s CPU - floor {m['this']['floor']:4.2f}"
                f" = {above['this']:5.2f} s | peer {m['peer']['run']:5.2f} s - floor "
                f"{m['peer']['floor']:4.2f} = {above['peer']:5.2f} s | ratio {ratio:.3f} "
                f"({'met' if ratio <= TARGET else 'not met'}: <= {TARGET})   "
                f"(load {loads[-1]:.1f})",
                flush=True,
            )
    report.update(
        {
            "this_commit": short_commit(ROOT),
            "peer_commit": short_commit(args.peer_tree),
            "target_ratio": TARGET,
            **conditions(started, loads),
            "repeat": args.repeat,
        }
    )
    path = write_results("import_floor", report)
    print(
        f"this {report['this_commit']} against {report['peer_commit']}; {report['machine']}; "
        f"started {started}; load (1 min) {min(loads):.1f} to {max(loads):.1f}; written: {path}"
    )
    return report


if __name__ == "__main__":
    main()
