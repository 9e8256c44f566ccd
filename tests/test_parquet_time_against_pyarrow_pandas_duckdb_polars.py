"""``timeseries.parquet``'s time, read across the 2016-12-31 leap second by pyarrow,
pandas, DuckDB and polars.

A UTC run from 23:59:50 to 00:00:10 every 0.25 s holds 85 samples, four of them inside
the leap second (``23:59:60.x``).  Each reader must get from the file a time column
that it cannot misread: strictly increasing, uniform at 0.25 s (elapsed seconds, where
UTC's calendar repeats none and POSIX time skips one), and equal, sample by sample, to
the instant astropy gives for the row's own UTC text (the authority: ERFA's leap-second
table), in TT.  The ISO texts are what the file says too; the first test records what
the two lenient readers do with them (``23:59:60.25`` read as ``00:00:00.25`` of the
next day), which is why the docs send pandas and polars users to ``timestamp_tt``.
"""

import duckdb
import numpy as np
import pandas as pd
import polars as pl
import pyarrow.parquet as pq
import pytest
from astropy.time import Time

from attitude.cli.main import main
from attitude.environment.timescales import offline_time

SCENARIO = """
[scenario]
name = "Parquet across the 2016 leap second"
epoch = "2016-12-31T23:59:50"

[spacecraft]
name = "sat"
principal_moments = [10.0, 20.0, 25.0]

[initial_state]
quaternion = [1.0, 0.0, 0.0, 0.0]
angular_velocity = [0.01, 0.2, 0.01]

[output]
duration = 21.0
step = 0.25
"""
STEP_NS = 250_000_000


@pytest.fixture(scope="module")
def parquet(tmp_path_factory):
    folder = tmp_path_factory.mktemp("leap")
    (folder / "leap.toml").write_text(SCENARIO)
    out = folder / "out"
    args = ["run", str(folder / "leap.toml"), "--out", str(out), "--quiet"]
    assert main([*args, "--formats", "parquet"]) == 0
    return out / "timeseries.parquet"


@pytest.fixture(scope="module")
def truth(parquet):
    """Each row's UTC text read by astropy, as TT nanoseconds since 1970-01-01 TT."""
    texts = pq.read_table(parquet, columns=["time_utc"]).column(0).to_pylist()
    assert sum(":59:60." in t for t in texts) == 4
    with offline_time():
        tt = Time(texts, scale="utc", precision=9).tt
        origin = Time("1970-01-01T00:00:00", scale="tt")
        days = (tt.jd1 - origin.jd1) + (tt.jd2 - origin.jd2)
    nanoseconds = np.rint(days * 86400e9).astype(np.int64)  # 2e-7 s of float error
    return texts, nanoseconds


def _check(values_ns: np.ndarray, truth_ns: np.ndarray, reader: str) -> None:
    assert values_ns.size == truth_ns.size == 85, reader
    assert np.all(np.diff(values_ns) == STEP_NS), reader  # uniform, strictly increasing
    assert np.max(np.abs(values_ns - truth_ns)) <= 1000, reader  # 1 µs: astropy's floats


def test_texts_are_utc_and_lenient_readers_misread_them(parquet, truth):
    texts, _ = truth
    assert "2016-12-31T23:59:60.250000000" in texts
    parsed = pd.to_datetime(pd.Series(texts)).to_numpy()
    # The leap second's samples land on the next day's: a second appears twice.
    assert np.unique(parsed).size < len(texts)


def test_pyarrow(parquet, truth):
    table = pq.read_table(parquet)
    field = table.schema.field("timestamp_tt")
    assert str(field.type) == "timestamp[ns]" and field.type.tz is None
    assert b"TT" in field.metadata[b"description"]
    values = table.column("timestamp_tt").cast("int64").to_numpy()
    _check(values, truth[1], "pyarrow")
    # The exact count and the timestamp say the same thing.
    tt_ns = table.column("tt_ns").to_numpy()
    assert np.all(values - tt_ns == values[0])


def test_pandas(parquet, truth):
    frame = pd.read_parquet(parquet)
    assert str(frame["timestamp_tt"].dtype) == "datetime64[ns]"
    _check(frame["timestamp_tt"].to_numpy().astype(np.int64), truth[1], "pandas")
    assert frame["timestamp_tt"].is_monotonic_increasing and frame["timestamp_tt"].is_unique


def test_duckdb(parquet, truth):
    rows = duckdb.sql(
        f"SELECT epoch_ns(timestamp_tt) AS ns, typeof(timestamp_tt) AS kind "
        f"FROM read_parquet('{parquet}') ORDER BY tt_ns"
    ).fetchall()
    assert {kind for _, kind in rows} == {"TIMESTAMP_NS"}
    _check(np.array([ns for ns, _ in rows], dtype=np.int64), truth[1], "duckdb")
    # A span taken as a difference of timestamps is the elapsed time: 21 s.
    span = duckdb.sql(
        f"SELECT epoch_ns(max(timestamp_tt)) - epoch_ns(min(timestamp_tt)) "
        f"FROM read_parquet('{parquet}')"
    ).fetchall()[0][0]
    assert span == 21_000_000_000


def test_polars(parquet, truth):
    frame = pl.read_parquet(parquet)
    assert frame.schema["timestamp_tt"] == pl.Datetime("ns")
    _check(frame["timestamp_tt"].cast(pl.Int64).to_numpy(), truth[1], "polars")
    # polars, like pandas, reads the leap second's text as the next day's.
    parsed = frame["time_utc"].str.to_datetime("%Y-%m-%dT%H:%M:%S%.f", strict=False)
    assert parsed.n_unique() < frame.height or parsed.null_count() > 0


def test_the_timestamp_beyond_int64_nanoseconds_is_in_microseconds(tmp_path):
    text = SCENARIO.replace("2016-12-31T23:59:50", "2300-06-01T00:00:00").replace(
        'epoch = "', 'time_scale = "tt"\nepoch = "'
    )
    (tmp_path / "far.toml").write_text(text)
    out = tmp_path / "out"
    args = ["run", str(tmp_path / "far.toml"), "--out", str(out), "--quiet"]
    assert main([*args, "--formats", "parquet"]) == 0
    table = pq.read_table(out / "timeseries.parquet")
    assert str(table.schema.field("timestamp_tt").type) == "timestamp[us]"
    values = table.column("timestamp_tt").cast("int64").to_numpy()
    assert np.all(np.diff(values) == STEP_NS // 1000)
    first = np.datetime64("2300-06-01T00:00:00", "us").astype(np.int64)
    assert values[0] == first
