"""Benchmark: ``attitude check`` on scenarios under torques, this tree beside a peer commit.

What issue 23 measured: ``check`` computed instead of checking, and its cost grew as the
square of the number of burns.  The cases, all from the example
``scenarios/tumbler_gravity_gradient_burn.toml``:

- ``burns N``: the example with N one-second inertial burns every 5 s (N = 1, 30, 100,
  300, 1000) in place of its burn;
- ``one day``: the example over 86400 s;
- ``step 0.05 s``: a given step of 0.05 s over 1900 s (38 000 steps).

Each is ``attitude check`` in a fresh Python process (imports included), CPU time of the
child (user + system, ``os.wait4``), this tree and the peer alternately, ``--repeat``
times each, after one warm-up run of each: compare the ratios, not the absolute times
(other work shares the machine; the load is printed).  The peer is another commit of
this repository exported with ``git archive`` (default: ``main``).

    python -m benchmarks.torques_check                 # every case, 2 runs each
    python -m benchmarks.torques_check --no-peer       # this tree only
    python -m benchmarks.torques_check --cases "burns 300" "one day"

A case the peer does not finish within ``--timeout`` seconds is reported as such.
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).parents[1]
EXAMPLE = ROOT / "scenarios" / "tumbler_gravity_gradient_burn.toml"


def _burns(count: int) -> str:
    text = EXAMPLE.read_text()
    head, tail = text.split("[[torques.burns]]")
    tail = "[output]" + tail.split("[output]")[1]
    burns = "".join(
        f"[[torques.burns]]\noffset = {10.0 + 5.0 * k}\nduration = 1.0\n"
        'torque = [-0.0002, -0.0001, -0.0003]\nframe = "inertial"\n\n'
        for k in range(count)
    )
    return head + burns + tail


def cases() -> dict[str, str]:
    text = EXAMPLE.read_text()
    found = {f"burns {n}": _burns(n) for n in (1, 30, 100, 300, 1000)}
    found["one day"] = text.replace("duration = 5828.0", "duration = 86400.0")
    fine = re.sub(r"(?m)^accuracy = .*$", "step = 0.05", text)
    fine = fine.replace("duration = 5828.0", "duration = 1900.0")
    found["step 0.05 s"] = re.sub(r"(?ms)^\[\[events\]\].*?(?=^\[torques\])", "", fine)
    return found


def export_peer(commit: str, folder: Path) -> Path:
    archive = subprocess.run(
        ["git", "-C", str(ROOT), "archive", commit], capture_output=True, check=True
    ).stdout
    subprocess.run(["tar", "-x", "-C", str(folder)], input=archive, check=True)
    return folder


def check_cpu(tree: Path, scenario: Path, timeout: float) -> float | None:
    """CPU seconds of `attitude check scenario` run from ``tree`` (None: timed out)."""
    environment = dict(os.environ, PYTHONPATH=str(tree))
    command = [sys.executable, "-m", "attitude", "check", str(scenario), "--formats", "csv"]
    process = subprocess.Popen(
        command, cwd=tree, env=environment, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE
    )
    started = time.monotonic()
    while True:
        pid, status, usage = os.wait4(process.pid, os.WNOHANG)
        if pid:
            if os.waitstatus_to_exitcode(status) not in (0, 2):
                raise RuntimeError(f"{tree}: check failed: {process.stderr.read().decode()}")
            return usage.ru_utime + usage.ru_stime
        if time.monotonic() - started > timeout:
            process.kill()
            process.wait()
            return None
        time.sleep(0.05)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--peer", default="main", help="peer commit (default main)")
    parser.add_argument("--no-peer", action="store_true")
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--timeout", type=float, default=300.0)
    parser.add_argument("--cases", nargs="*", help="case names (default: all)")
    args = parser.parse_args(argv)
    print(subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip())
    with tempfile.TemporaryDirectory() as folder:
        work = Path(folder)
        trees = {"this tree": ROOT}
        if not args.no_peer:
            (work / "peer").mkdir()
            trees[f"peer {args.peer}"] = export_peer(args.peer, work / "peer")
        chosen = cases()
        names = args.cases or list(chosen)
        print(f"{'case':<14}" + "".join(f"{name:>22}" for name in trees) + "  ratio")
        for name in names:
            path = work / f"{name.replace(' ', '_')}.toml"
            path.write_text(chosen[name])
            times: dict[str, list[float | None]] = {tree: [] for tree in trees}
            for where in trees.values():  # warm-up: the numba cache, the file system
                check_cpu(where, path, args.timeout)
            for _ in range(args.repeat):
                for tree, where in trees.items():
                    times[tree].append(check_cpu(where, path, args.timeout))
            medians = {}
            for tree, values in times.items():
                done = [v for v in values if v is not None]
                medians[tree] = statistics.median(done) if len(done) == len(values) else None
            cells = "".join(
                f"{f'> {args.timeout:g} s' if m is None else f'{m:.2f} s CPU':>22}"
                for m in medians.values()
            )
            values = list(medians.values())
            ratio = (
                f"  {values[1] / values[0]:.1f}x" if len(values) == 2 and None not in values else ""
            )
            print(f"{name:<14}{cells}{ratio}", flush=True)
    print(subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip())


if __name__ == "__main__":
    main()
