"""Benchmark: a one-day scenario at a 1 s step, three body vectors, a TLE orbit, to its report.

The spinner example (scenarios/spinner_thruster_pulse.toml) stretched to one day at a
1 s step (86 401 epochs), run as a user runs it: ``attitude run`` in a fresh Python
process, so the wall time includes imports.  The stage times come from the progress
lines.  Target (issue 4): the full report in under 10 s on this machine.

    python -m benchmarks.report_one_day

Results go to stdout and to benchmarks/results/report_one_day.json.
"""

from __future__ import annotations

import json
import os
import platform
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).parents[1]
RESULTS = Path(__file__).parent / "results"


def main() -> dict:
    text = (ROOT / "scenarios" / "spinner_thruster_pulse.toml").read_text()
    text = re.sub(r"(?m)^duration = .*$", "duration = 86400.0", text)
    text = re.sub(r"(?m)^step = .*$", "step = 1.0", text)
    with tempfile.TemporaryDirectory() as folder:
        scenario = Path(folder) / "one_day.toml"
        scenario.write_text(text)
        start = time.perf_counter()
        run = subprocess.run(
            [sys.executable, "-m", "attitude.cli", "run", str(scenario), "--out", f"{folder}/out"],
            capture_output=True,
            text=True,
            check=True,
        )
        wall = time.perf_counter() - start
        sizes = {p.name: p.stat().st_size for p in Path(folder, "out").iterdir()}
    stages = [
        (float(m.group(1)), m.group(2)) for m in re.finditer(r"\[\s*([\d.]+) s\] (.*)", run.stderr)
    ]
    report = {
        "machine": f"{platform.machine()}, {os.cpu_count()} cores, {platform.system()}",
        "python": platform.python_version(),
        "load_average_1min": os.getloadavg()[0],
        "epochs": 86401,
        "wall_s": wall,
        "stages_s": [{"at_s": at, "stage": stage} for at, stage in stages],
        "output_bytes": sizes,
        "target_s": 10.0,
    }
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "report_one_day.json").write_text(json.dumps(report, indent=2) + "\n")
    print(run.stderr, end="")
    print(
        f"one day at 1 s, 3 body vectors, TLE orbit: {wall:.1f} s wall (target < 10 s), "
        f"load {report['load_average_1min']:.2f}"
    )
    return report


if __name__ == "__main__":
    main()
