"""What every whole-run benchmark records beside its figures: the commit, the machine,
when it started, and where its results go (``benchmarks/results/NAME.json``)."""

from __future__ import annotations

import json
import os
import platform
import subprocess
import time
from pathlib import Path

RESULTS = Path(__file__).parent / "results"


def short_commit(tree: Path) -> str:
    """The short hash of ``tree``'s checked-out commit."""
    return subprocess.run(
        ["git", "-C", str(tree), "rev-parse", "--short", "HEAD"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.strip()


def cpu_model() -> str:
    """The processor's model name (``/proc/cpuinfo``), or the architecture."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def machine_line() -> str:
    """The machine, its cores, the kernel and the Python that ran the benchmark."""
    return (
        f"{cpu_model()} ({platform.machine()}), {os.cpu_count()} cores, {platform.system()} "
        f"{platform.release()}, Python {platform.python_version()}"
    )


def started_utc() -> str:
    return time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())


def conditions(started: str, loads: list[float]) -> dict:
    """The keys every result file holds on how it was measured: the machine, the start,
    the 1-minute load average sampled during the run."""
    return {
        "machine": machine_line(),
        "started": started,
        "load_1min": {"min": min(loads), "max": max(loads), "samples": loads},
    }


def write_results(name: str, report: dict) -> Path:
    """``report`` as ``benchmarks/results/{name}.json``; its path."""
    RESULTS.mkdir(exist_ok=True)
    path = RESULTS / f"{name}.json"
    path.write_text(json.dumps(report, indent=2) + "\n")
    return path
