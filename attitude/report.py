"""A scenario run, from a loaded scenario file to its output folder.

``produce(scenario_file, out_dir)`` propagates the scenario and writes, atomically
(into a temporary folder renamed into place at the end, so that a failed run leaves
no half-written output):

- ``timeseries.csv``: attitude, rates, momentum and energy on the output grid;
- ``summary.json``: the scenario, its segments and events, flips, precession,
  nutation and conservation checks.
"""

from __future__ import annotations

import os
import shutil
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from attitude.exports import (
    QUATERNION_CONVENTION,
    motion_summary,
    trajectory_columns,
    write_csv,
    write_json,
)
from attitude.motion_analysis import analyze
from attitude.pointing import PointingSpec
from attitude.scenario import Scenario
from attitude.trajectory import propagate
from attitude.version import __version__

__all__ = ["Progress", "produce", "replace_directory"]


class Progress:
    """Stage messages with the elapsed time, to a callable (stderr for the command line)."""

    def __init__(self, write: Callable[[str], None] | None = None) -> None:
        self._write = write
        self._start = time.perf_counter()

    def __call__(self, message: str) -> None:
        if self._write is not None:
            self._write(f"[{time.perf_counter() - self._start:7.1f} s] {message}")


def replace_directory(out_dir: Path, build: Callable[[Path], Any]) -> Any:
    """Run ``build(tmp)`` into a fresh temporary folder next to ``out_dir``, then put it
    in place of ``out_dir``; on any failure nothing is left behind."""
    out_dir = out_dir.resolve()
    out_dir.parent.mkdir(parents=True, exist_ok=True)
    tmp = out_dir.parent / f".{out_dir.name}.partial-{os.getpid()}"
    shutil.rmtree(tmp, ignore_errors=True)
    tmp.mkdir()
    try:
        result = build(tmp)
        if out_dir.exists():
            old = out_dir.parent / f".{out_dir.name}.old-{os.getpid()}"
            out_dir.rename(old)
            tmp.rename(out_dir)
            shutil.rmtree(old, ignore_errors=True)
        else:
            tmp.rename(out_dir)
        return result
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


def _scenario_summary(scenario: Scenario, source: str) -> dict[str, Any]:
    craft = scenario.spacecraft
    return {
        "name": scenario.name,
        "file": source,
        "epoch": scenario.format_epoch(0.0),
        "time_scale": scenario.time_scale.upper(),
        "stop": scenario.format_epoch(scenario.stop_s),
        "duration_s": scenario.stop_s,
        "output": {
            "start": scenario.format_epoch(scenario.start_s),
            "step_s": scenario.step_s,
            "samples": int(scenario.output_seconds().size),
        },
        "spacecraft": {
            "name": craft.name,
            "inertia_tensor_body_kg_m2": craft.inertia_tensor,
            "principal_moments_kg_m2": craft.principal_moments,
        },
        "events": [
            {"type": event.kind, "label": event.label or None, "epoch": scenario.format_epoch(t)}
            for t, event in scenario.events
        ],
    }


def produce(
    scenario: Scenario,
    out_dir: Path,
    pointing: PointingSpec | None = None,
    source: str = "",
    progress: Progress | None = None,
) -> dict[str, Any]:
    """Propagate ``scenario`` and write its outputs into ``out_dir``; returns the summary.

    ``pointing``: the pointing outputs asked for; ``source``: the scenario file's
    name, for the headers.
    """
    progress = progress or Progress()
    pointing = pointing or PointingSpec()

    def build(tmp: Path) -> dict[str, Any]:
        progress(f"propagating {scenario.name!r} over {scenario.stop_s:g} s")
        trajectory = propagate(scenario)
        motion = analyze(trajectory)
        seconds = scenario.output_seconds()
        progress(f"sampling {seconds.size} epochs")
        columns = trajectory_columns(trajectory, seconds)
        epochs_iso = scenario.iso(seconds)
        scale = scenario.time_scale
        progress("writing timeseries.csv")
        write_csv(
            tmp / "timeseries.csv",
            epochs_iso,
            f"time_{scale}",
            columns,
            [
                f"attitude {__version__}: {scenario.name} ({source})",
                f"spacecraft: {scenario.spacecraft.name}",
                f"epoch: {scenario.format_epoch(0.0)}; t_s = TT seconds since the epoch",
                f"time_{scale}: ISO 8601 epochs in {scale.upper()}",
                "frames: body = spacecraft body axes; icrf = ICRF axes (GCRS, geocentric)",
                QUATERNION_CONVENTION,
                "units: SI (s, rad/s, N m s, J)",
            ],
        )
        summary = {
            "attitude_version": __version__,
            "scenario": _scenario_summary(scenario, source),
            "motion": motion_summary(trajectory, motion),
            "extrema": {
                "max_rate_rad_s": float(
                    np.max(
                        np.linalg.norm(np.column_stack([c.values for c in columns[5:8]]), axis=1)
                    )
                ),
            },
        }
        progress("writing summary.json")
        write_json(tmp / "summary.json", summary)
        return summary

    summary = replace_directory(Path(out_dir), build)
    progress(f"done: {Path(out_dir)}")
    return summary
