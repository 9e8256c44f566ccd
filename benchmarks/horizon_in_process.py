"""Benchmark: the validity horizon alone, in process, in CPU time.

``benchmarks.horizon_share`` measures the horizon's forked process beside a whole run;
this times :func:`attitude.trajectory.horizon.validity_horizon` by itself
(``time.process_time``), after the same planning as a run (``plan_run`` with the horizon
left out), on the one-day case of ``benchmarks.report_one_day`` and on the one-hour
example it stretches (``scenarios/spinner_thruster_pulse.toml``), ``--repeat`` times each
after one untimed call; and says whether the call imported numba.

    python -m benchmarks.horizon_in_process --repeat 3
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

from benchmarks.report_one_day import scenario_text


def time_case(text: str, repeat: int) -> tuple[list[float], object]:
    from attitude.files.scenario_reader import load_scenario
    from attitude.report.plan import plan_run
    from attitude.trajectory.horizon import validity_horizon

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "case.toml"
        path.write_text(text)
        loaded = load_scenario(path)
    plan = plan_run(loaded.scenario, loaded.pointing, horizon=False)
    found = validity_horizon(plan.trajectory, plan.pointing.orbit)  # untimed: warm
    times = []
    for _ in range(repeat):
        start = time.process_time()
        found = validity_horizon(plan.trajectory, plan.pointing.orbit)
        times.append(time.process_time() - start)
    return times, found


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)
    had_numba = "numba" in sys.modules
    for name, days in (("one day", 1.0), ("one hour", 1.0 / 24.0)):
        times, found = time_case(scenario_text(days), args.repeat)
        print(
            f"{name}: the horizon {statistics.median(times):.3f} s CPU (median of "
            f"{', '.join(f'{t:.3f}' for t in times)}); searched {found.searched_s:g} s, "
            f"horizon {found.horizon_s:g} s, method {found.method}, largest step "
            f"{found.step_s:.4g} s; load {os.getloadavg()[0]:.1f}"
        )
    print(f"numba imported: {'numba' in sys.modules} (before: {had_numba})")


if __name__ == "__main__":
    main()
