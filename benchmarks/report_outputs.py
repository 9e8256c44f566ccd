"""Benchmark: the report's writers against the peers they replace, side by side.

On the one-day spinner's time series (86 401 rows, 41 columns: trajectory and
pointing), in one process, alternately, best of ``--repeat``:

- the CSV: ``attitude.outputs.csv.CsvWriter`` (Arrow's C++ formatter, shortest round-trip
  text) against numpy's fastest text path, ``np.savetxt`` with ``%.17g`` on the same
  numbers (without the epoch column, which savetxt cannot mix in: the peer has less
  to write);
- the epoch texts: ``attitude.environment.epoch_texts.EpochTexts`` against astropy's ``isot``
  (``Scenario.iso``), UTC;
- the AEM records: ``AemWriter.write_records`` with those texts against
  ``write_aem`` with astropy times (its per-segment path);
- Parquet (zstd) against the CSV: time and bytes per row.

    python -m benchmarks.report_outputs [--repeat 3]

Results go to stdout and to benchmarks/results/report_outputs.json.
"""

from __future__ import annotations

import argparse
import io
import json
import os
import platform
import re
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).parents[1]
RESULTS = Path(__file__).parent / "results"


def _best(function, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return min(times)


def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)

    from attitude.environment.epoch_texts import EpochTexts
    from attitude.files.scenario_reader import load_scenario
    from attitude.outputs.aem_writer import AemSegment, AemWriter, write_aem
    from attitude.outputs.csv import CsvWriter, pointing_columns, sample, trajectory_columns
    from attitude.outputs.parquet import ParquetWriter
    from attitude.pointing.sampling import pointing_samples
    from attitude.trajectory.trajectory import propagate

    text = (ROOT / "scenarios" / "spinner_thruster_pulse.toml").read_text()
    text = re.sub(r"(?m)^duration = .*$", "duration = 86400.0", text)
    text = re.sub(r"(?m)^step = .*$", "step = 1.0", text)
    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        (folder / "s.toml").write_text(text)
        loaded = load_scenario(folder / "s.toml")
        scenario = loaded.scenario
        trajectory = propagate(scenario)
        seconds = scenario.output_seconds()
        columns = trajectory_columns(sample(trajectory, seconds))
        columns += pointing_columns(pointing_samples(trajectory, loaded.pointing, seconds))
        rows = seconds.size
        data = np.column_stack([c.values for c in columns])
        texts = EpochTexts(scenario.epoch)
        epochs = texts(seconds)

        def ours_csv():
            with CsvWriter(folder / "a.csv", "time_utc", ["preamble"]) as writer:
                writer.write(epochs, columns)

        def numpy_csv():
            np.savetxt(folder / "b.csv", data, fmt="%.17g", delimiter=",")

        def ours_parquet():
            with ParquetWriter(folder / "c.parquet", "time_utc", {}, "ISO") as writer:
                writer.write(epochs, seconds, columns)

        timings = {}
        for name, function in (
            ("csv: CsvWriter", ours_csv),
            ("csv: np.savetxt %.17g", numpy_csv),
            ("parquet: ParquetWriter", ours_parquet),
            ("epochs: EpochTexts", lambda: texts(seconds)),
            ("epochs: astropy isot", lambda: scenario.iso(seconds)),
        ):
            timings[name] = _best(function, args.repeat)
        sizes = {
            "csv": (folder / "a.csv").stat().st_size,
            "numpy csv": (folder / "b.csv").stat().st_size,
            "parquet": (folder / "c.parquet").stat().st_size,
        }

        solver = trajectory.segments[1].solver
        τ = seconds[seconds > 600.0]
        q, ω = solver.attitude_quaternion(τ), solver.angular_velocity(τ)

        def ours_aem():
            writer = AemWriter(
                io.BytesIO(),
                object_name="S",
                object_id="X",
                time_scale="utc",
                creation_date="2027-01-01T00:00:00",
            )
            ends = texts(τ[[0, -1]])
            writer.begin_segment(ends[0].decode(), ends[1].decode())
            writer.write_records(texts(τ), q, ω)
            writer.end_segment()

        def astropy_aem():
            write_aem(
                folder / "d.aem",
                [AemSegment(scenario.times(τ), q, ω)],
                object_name="S",
                object_id="X",
                time_scale="utc",
                creation_date="2027-01-01T00:00:00",
            )

        timings["aem: AemWriter + EpochTexts"] = _best(ours_aem, args.repeat)
        timings["aem: write_aem, astropy times"] = _best(astropy_aem, args.repeat)
        records = τ.size
    report = {
        "case": f"one-day spinner time series: {rows} rows x {len(columns) + 1} columns; "
        f"AEM: {records} records",
        "machine": f"{platform.machine()}, {os.cpu_count()} cores, Python "
        f"{platform.python_version()}",
        "load_average_1min": {"before": load, "after": os.getloadavg()[0]},
        "best_s": timings,
        "per_row_us": {
            k: v / (records if k.startswith("aem") else rows) * 1e6 for k, v in timings.items()
        },
        "ratios": {
            "CsvWriter / np.savetxt": timings["csv: CsvWriter"] / timings["csv: np.savetxt %.17g"],
            "EpochTexts / astropy": timings["epochs: EpochTexts"] / timings["epochs: astropy isot"],
            "AemWriter / write_aem": timings["aem: AemWriter + EpochTexts"]
            / timings["aem: write_aem, astropy times"],
            "Parquet / CsvWriter": timings["parquet: ParquetWriter"] / timings["csv: CsvWriter"],
        },
        "bytes_per_row": {k: v / rows for k, v in sizes.items()},
    }
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "report_outputs.json").write_text(json.dumps(report, indent=2) + "\n")
    print(f"{report['case']}; load {load:.2f}")
    for name, value in timings.items():
        print(f"  {name:34s} {value:7.3f} s  {report['per_row_us'][name]:7.2f} µs a row")
    for name, value in report["ratios"].items():
        print(f"  {name:34s} {value:7.3f}")
    for name, value in report["bytes_per_row"].items():
        print(f"  {name:34s} {value:7.1f} bytes a row")
    return report


if __name__ == "__main__":
    main()
