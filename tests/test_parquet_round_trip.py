"""``timeseries.parquet`` read back by pyarrow: the CSV's numbers, exact times, metadata.

A run with ``--formats csv,parquet`` over a UTC leap second (2016-12-31T23:59:60) writes
both; pyarrow reads the Parquet file back.  The authority for the numbers is the CSV of
the same run (itself the exact solution, tested elsewhere); for the times, astropy:
``tt_ns`` added to the epoch in TT gives the ISO texts of the file, the leap second
included.  The schema states the frames, units, time scale and quaternion convention.
"""

import json

import numpy as np
import pyarrow.parquet as pq
import pytest
from astropy.time import Time, TimeDelta

from attitude.cli.main import main
from attitude.environment.timescales import iso_texts, offline_time

SCENARIO = """
[scenario]
name = "Parquet over a leap second"
epoch = "2016-12-31T23:59:00"

[spacecraft]
name = "sat"
principal_moments = [10.0, 20.0, 25.0]

[initial_state]
quaternion = [1.0, 0.0, 0.0, 0.0]
angular_velocity = [0.01, 0.2, 0.01]

[[events]]
type = "angular_impulse"
offset = 30.5
impulse = [0.1, 0.0, 0.0]

[output]
duration = 120.0
step = 0.25

[pointing]
[[pointing.body_vectors]]
name = "tracker"
vector = [0.0, 0.0, 1.0]
sun_exclusion_half_angle = { value = 30, unit = "deg" }
"""


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("parquet")
    (folder / "leap.toml").write_text(SCENARIO)
    out = folder / "out"
    args = ["run", str(folder / "leap.toml"), "--out", str(out), "--quiet"]
    assert main([*args, "--formats", "csv,parquet"]) == 0
    return out


def _csv(path):
    text = path.read_text()
    preamble = sum(1 for line in text.splitlines() if line.startswith("#"))
    return np.genfromtxt(
        path, delimiter=",", skip_header=preamble, names=True, dtype=None, encoding="utf-8"
    )


def test_the_numbers_are_the_csvs(run):
    table = pq.read_table(run / "timeseries.parquet")
    data = _csv(run / "timeseries.csv")
    assert table.num_rows == len(data) == 481
    names = [n for n in data.dtype.names if n != "time_utc"]
    assert table.column_names == ["time_utc", "tt_ns", "timestamp_tt", *names]
    for name in names:
        column = table.column(name).to_numpy()
        assert np.array_equal(column, data[name]), name  # the same doubles, bit for bit
    assert table.schema.field("segment").type == "int32"
    assert list(table.column("time_utc").to_pylist()) == list(data["time_utc"])


def test_the_time_columns_are_exact_across_the_leap_second(run):
    table = pq.read_table(run / "timeseries.parquet")
    meta = {k.decode(): v.decode() for k, v in table.schema.metadata.items()}
    texts = table.column("time_utc").to_pylist()
    assert "2016-12-31T23:59:60.250000000" in texts
    tt_ns = table.column("tt_ns").to_numpy()
    assert np.all(np.diff(tt_ns) == 250_000_000)  # uniform, though UTC repeats no second
    with offline_time():
        epoch = Time(meta["attitude.epoch_tt"].removesuffix(" TT"), scale="tt", precision=9)
        times = epoch + TimeDelta(tt_ns // 10**9, tt_ns % 10**9 * 1e-9, format="sec")
        times = times.utc
        times.precision = 9
        assert list(iso_texts(times)) == texts
    np.testing.assert_array_equal(table.column("t_s").to_numpy() * 1e9, tt_ns.astype(float))


def test_the_schema_states_frames_units_scale_and_convention(run):
    schema = pq.read_schema(run / "timeseries.parquet")
    meta = {k.decode(): v.decode() for k, v in schema.metadata.items()}
    assert meta["attitude.time_scale"] == "UTC"
    assert meta["attitude.epoch"] == "2016-12-31T23:59:00.000000000 UTC"
    assert "scalar first" in meta["attitude.quaternion_convention"]
    assert "ICRF" in meta["attitude.frames"] and "body" in meta["attitude.frames"]
    assert "23:59:60" in meta["attitude.time_columns"]
    units = {f.name: f.metadata[b"unit"].decode() for f in schema}
    assert units["omega_body_x_rad_s"] == "rad/s"
    assert units["h_icrf_z_N_m_s"] == "N m s"
    assert units["tracker_sun_angle_deg"] == "deg"
    assert units["q_body_to_icrf_w"] == "1" and units["tt_ns"] == "ns"
    assert b"body -> ICRF" in schema.field("q_body_to_icrf_x").metadata[b"description"]


def test_a_row_group_per_chunk(tmp_path):
    (tmp_path / "s.toml").write_text(SCENARIO.split("[pointing]")[0])
    from attitude.files.scenario_reader import load_scenario
    from attitude.outputs.formats import OutputChoice
    from attitude.report.plan import plan_run
    from attitude.report.run import write_report

    loaded = load_scenario(tmp_path / "s.toml")
    plan = plan_run(loaded.scenario, loaded.pointing, OutputChoice(("parquet",)))
    write_report(loaded.scenario, tmp_path / "out", plan=plan, chunk_samples=100)
    metadata = pq.ParquetFile(tmp_path / "out" / "timeseries.parquet").metadata
    assert metadata.num_row_groups == 5 and metadata.num_rows == 481
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["outputs"]["formats"] == ["parquet"]
