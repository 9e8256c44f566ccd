"""Every example, every output format, read back by readers written apart from ours.

Each scenario of ``scenarios/`` (the Monte Carlo one as a plain ``attitude run``) is run
with ``--formats csv,parquet,aem,plots,report``; then each file is read by another
reader and compared with the run's own attitude, ``Trajectory.attitude`` of the same
scenario (the exact motion, or the splitting under torques), within what the file
declares:

- ``timeseries.csv`` by Python's ``csv`` module: every row's quaternion is the attitude
  at its ``t_s`` to the last bits (the file declares the shortest text of each double),
  and its time text, read by astropy in the scenario's scale, is ``t_s`` to the
  nanosecond it is written to;
- ``timeseries.parquet`` by pyarrow, pandas and DuckDB: the same, at ``tt_ns``, with
  ``timestamp_tt`` uniform and equal to the epoch plus ``tt_ns``;
- ``attitude.aem`` by ccsds-ndm-py (``aem_read_back``), interpolated as it declares at
  every mid-step of its records: within the tolerance its header states; and the file
  is the one whose reading by Orekit is frozen in ``tests/data/orekit`` (the same
  records per segment, from the same first to the same last epoch), so that
  ``test_aem_oem_against_orekit_frozen.py``'s check of Orekit's reading holds for it.
"""

from __future__ import annotations

import csv
import json
import re
from pathlib import Path

import duckdb
import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest
from aem_read_back import interpolate_as_declared, read_back, rotation_angle
from astropy.time import Time
from orekit_frozen import read_frozen

from attitude.cli.main import main
from attitude.environment.timescales import offline_time, tt_seconds
from attitude.files.scenario_reader import load_scenario
from attitude.trajectory.trajectory import propagate

ROOT = Path(__file__).parents[1]
EXAMPLES = sorted((ROOT / "scenarios").glob("*.toml"))
FORMATS = "csv,parquet,aem,plots,report"
FROZEN = Path(__file__).parent / "data" / "orekit" / "aem_read_by_orekit"
# The quaternions of the time series are the doubles computed, written to round trip:
# the same evaluation at the same seconds agrees to a few units of the last place.
SERIES_RAD = 1e-15

_RUNS: dict[str, tuple] = {}


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    return tmp_path_factory.mktemp("examples")


def _run(example: Path, folder: Path):
    """(output folder, scenario, trajectory) of ``example``, run once per process."""
    if example.stem not in _RUNS:
        out = folder / example.stem
        args = ["run", str(example), "--out", str(out), "--formats", FORMATS, "--quiet"]
        assert main(args) == 0
        loaded = load_scenario(example)
        _RUNS[example.stem] = (out, loaded.scenario, propagate(loaded.scenario))
    return _RUNS[example.stem]


def _cases() -> list:
    return [pytest.param(path, id=path.stem) for path in EXAMPLES]


def test_the_examples_cover_every_kind_of_run():
    names = {p.stem for p in EXAMPLES}
    assert {"spinner_dispersions", "tumbler_gravity_gradient_burn"} <= names
    assert len(names) >= 7


@pytest.mark.parametrize("example", _cases())
def test_csv_read_by_pythons_csv(example, folder):
    out, scenario, trajectory = _run(example, folder)
    files = {p.name for p in out.iterdir()}
    assert {"timeseries.csv", "timeseries.parquet", "attitude.aem", "report.html"} <= files
    assert "summary.json" in files and any(name.endswith(".png") for name in files)
    with open(out / "timeseries.csv", newline="", encoding="utf-8") as stream:
        rows = list(csv.reader(line for line in stream if not line.startswith("#")))
    header, rows = rows[0], rows[1:]
    label = f"time_{scenario.time_scale}"
    assert header[0] == label and len(rows) == scenario.output_count()
    column = {name: k for k, name in enumerate(header)}
    t_s = np.array([float(row[column["t_s"]]) for row in rows])
    q = np.array([[float(row[column[f"q_body_to_icrf_{c}"]]) for c in "wxyz"] for row in rows])
    assert np.max(rotation_angle(q, trajectory.attitude_quaternion(t_s))) <= SERIES_RAD
    with offline_time():
        written = Time([row[0] for row in rows], scale=scenario.time_scale, precision=9)
        seconds = np.ravel(tt_seconds(written, scenario.epoch))
    assert np.max(np.abs(seconds - t_s)) <= 0.5e-9 + 4.0 * np.spacing(max(t_s.max(), 1.0))


@pytest.mark.parametrize("example", _cases())
def test_parquet_read_by_pyarrow_pandas_and_duckdb(example, folder):
    out, _, trajectory = _run(example, folder)
    path = out / "timeseries.parquet"
    quaternion = [f"q_body_to_icrf_{c}" for c in "wxyz"]
    table = pq.read_table(path)
    frame = pd.read_parquet(path)
    rows = duckdb.sql(
        f"SELECT tt_ns, epoch_ns(timestamp_tt), {', '.join(quaternion)} "
        f"FROM read_parquet('{path}') ORDER BY tt_ns"
    ).fetchall()
    by_duckdb = np.array([row[2:] for row in rows])
    tt_ns = table.column("tt_ns").to_numpy()
    assert np.array_equal(frame["tt_ns"].to_numpy(), tt_ns)
    assert np.array_equal(np.array([row[0] for row in rows]), tt_ns)
    exact = trajectory.attitude_quaternion(tt_ns / 1e9)
    for reader, q in (
        ("pyarrow", np.column_stack([table.column(c).to_numpy() for c in quaternion])),
        ("pandas", frame[quaternion].to_numpy()),
        ("duckdb", by_duckdb),
    ):
        # tt_ns is t_s rounded to 1 ns: the attitude moves |ω| × 0.5 ns at most there.
        rate = np.max(np.linalg.norm(trajectory.angular_velocity(tt_ns / 1e9), axis=1))
        assert np.max(rotation_angle(q, exact)) <= SERIES_RAD + rate * 0.5e-9, reader
    # timestamp_tt: the epoch in TT plus tt_ns, for every reader.
    stamps = table.column("timestamp_tt").cast("int64").to_numpy()
    assert np.all(stamps - tt_ns == stamps[0] - tt_ns[0])
    assert np.array_equal(frame["timestamp_tt"].to_numpy().astype(np.int64), stamps)
    assert np.array_equal(np.array([row[1] for row in rows]), stamps)


def _declared_tolerance(text: str) -> float:
    joined = text.replace("\nCOMMENT ", " ")
    found = re.search(r"stays within ([0-9.eE+-]+) rad of the exact attitude", joined)
    assert found, "the AEM states no tolerance"
    return float(found.group(1))


@pytest.mark.parametrize("example", _cases())
def test_aem_read_by_ccsds_ndm_py_within_its_declared_tolerance(example, folder):
    out, scenario, trajectory = _run(example, folder)
    path = out / "attitude.aem"
    tolerance = _declared_tolerance(path.read_text())
    summary = json.loads((out / "summary.json").read_text())
    assert tolerance == summary["outputs"]["aem"]["tolerance_rad"]
    segments, _ = read_back(path)
    worst = (0.0, 0.0)
    records = []
    for segment in segments:
        x = tt_seconds(segment.times, scenario.epoch)
        records.append(x)
        mid = 0.5 * (x[1:] + x[:-1])
        error = rotation_angle(
            interpolate_as_declared(segment, mid, scenario.epoch),
            trajectory.attitude_quaternion(mid),
        )
        k = int(np.argmax(error))
        worst = max(worst, (float(error[k]), float(mid[k])))
    assert worst[0] <= tolerance, (
        f"{example.name}: {worst[0]:.3g} rad at t = {worst[1]:.6f} s, {tolerance:g} declared"
    )
    # This run's file is the one Orekit read (tests/data/orekit; rerun
    # tests/freeze_orekit_ccsds.py if the AEM's sampling has changed).
    header, _ = read_frozen(FROZEN / f"{example.stem}.csv")
    assert json.loads(header["records_per_segment"]) == [int(x.size) for x in records]
    ends = json.loads(header["first_and_last_record_s"])
    np.testing.assert_allclose(ends, [[x[0], x[-1]] for x in records], rtol=0.0, atol=1e-9)
