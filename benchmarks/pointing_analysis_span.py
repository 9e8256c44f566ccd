"""Benchmark: pointing_analysis over growing spans, in bounded memory and linear time.

The spinner example (scenarios/spinner_thruster_pulse.toml: 5 rpm, three body vectors,
a TLE orbit) analysed over 1/4, 1 and 4 days, each in a fresh process: the CPU time
of ``pointing_analysis`` (intervals and extrema on the exact motion, independent of
the output step; the shared surroundings built in it) per simulated day, and the peak
RSS of the process.  The search runs in windows of ``WINDOW_NODES`` nodes
(attitude.pointing.free_search), so the peak should not grow with the span (beyond the
intervals found), and the time per day should not grow either.

    python -m benchmarks.pointing_analysis_span

Reported as ratios to the 1/4-day run of the same invocation, with the load average.
(``search points``: the search's nodes and grid points, ``SearchGrid.count``.)
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).parents[1]
DAYS = (0.25, 1.0, 4.0)

_CHILD = """
import json, re, resource, sys, time
from pathlib import Path
from attitude.files.scenario_reader import load_scenario
from attitude.trajectory.trajectory import propagate
from attitude import pointing_analysis
days = float(sys.argv[1])
text = (Path(sys.argv[2]) / "scenarios" / "spinner_thruster_pulse.toml").read_text()
text = re.sub(r"(?m)^duration = .*$", f"duration = {days * 86400.0}", text)
path = Path(sys.argv[3]) / "span.toml"
path.write_text(text)
loaded = load_scenario(path)
trajectory = propagate(loaded.scenario)
start = time.process_time()
analysis = pointing_analysis(trajectory, loaded.pointing)
wall = time.process_time() - start
intervals = sum(len(v.sun_visible) + len(v.sun_exclusion) for v in analysis.vectors)
peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(json.dumps({"days": days, "cpu_s": wall, "peak_mb": peak_mb,
                  "search_points": analysis.grid.count, "intervals": intervals}))
"""


def main() -> list[dict]:
    import tempfile

    results = []
    with tempfile.TemporaryDirectory() as folder:
        for days in DAYS:
            run = subprocess.run(
                [sys.executable, "-c", _CHILD, str(days), str(ROOT), folder],
                capture_output=True,
                text=True,
                check=True,
            )
            results.append(json.loads(run.stdout.strip().splitlines()[-1]))
    base = results[0]
    for item in results:
        item["cpu_per_day_ratio"] = (item["cpu_s"] / item["days"]) / (base["cpu_s"] / base["days"])
        item["peak_ratio"] = item["peak_mb"] / base["peak_mb"]
        print(
            f"{item['days']:5g} days: {item['search_points']:>9} search points, "
            f"{item['intervals']:>7} intervals, CPU {item['cpu_s']:.3g} s, per day "
            f"×{item['cpu_per_day_ratio']:.2f}, "
            f"peak RSS ×{item['peak_ratio']:.2f} ({item['peak_mb']:.0f} MB)"
        )
    print(f"load average {os.getloadavg()[0]:.1f}")
    return results


if __name__ == "__main__":
    main()
