"""The envelope's outputs read back by readers that share no code with the writer
(duckdb for the Parquet table, the csv module for the CSV one, json for the summary),
the same table from one worker and from two, and the output folder's rules.
"""

import csv
import json
import math

import duckdb
import numpy as np
import pytest
from cli_lines import said
from envelope_scenarios import with_envelope

from attitude import loss_of_control_envelope
from attitude.cli.main import main

TABLE = """[envelope]
times = [300.0, 1920.0, 3300.0, 5100.0]
window = 600.0
wheels = { case = "locked", momentum = [0.0, 2.0, 0.0] }
power_threshold = 0.3
"""


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """The command's outputs, with one worker."""
    tmp = tmp_path_factory.mktemp("envelope")
    path = with_envelope(tmp, TABLE)
    out = tmp / "out"
    assert main(["envelope", str(path), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    return path, out


def test_parquet_and_csv_read_back_by_duckdb_and_csv_agree_with_two_workers(written):
    path, out = written
    two = loss_of_control_envelope(path, workers=2, batch_size=1)
    assert list(two["tau_s"]) == [300.0, 1920.0, 3300.0, 5100.0]
    assert set(two["status"]) == {"ok"}
    parquet = duckdb.sql(f"SELECT * FROM read_parquet('{out / 'envelope.parquet'}')").df()
    with open(out / "envelope.csv", newline="") as stream:
        rows = list(csv.DictReader(stream))
    assert list(parquet.columns) == list(two.columns)
    assert len(rows) == len(two) == len(parquet)
    metrics = [c for c in two.columns if c not in ("epoch_utc", "mode", "status", "error")]
    for name in metrics:
        theirs = two[name].to_numpy(dtype=float)
        # One worker and two give the same table, to the last bit.
        assert np.array_equal(parquet[name].to_numpy(dtype=float), theirs), name
        from_csv = np.array([float(row[name]) for row in rows])  # "inf" reads as inf
        assert np.allclose(from_csv, theirs, rtol=1e-15, atol=0.0, equal_nan=True), name
    assert list(parquet["epoch_utc"]) == list(two["epoch_utc"])
    assert parquet["epoch_utc"][0].startswith("2025-05-01T10:05:00")
    assert next(iter(parquet["mode"])) == "nadir"


def test_summary_names_the_worst_failure_time_of_the_table(written):
    _path, out = written
    summary = json.loads((out / "summary.json").read_text())
    table = duckdb.sql(f"SELECT * FROM read_parquet('{out / 'envelope.parquet'}')").df()
    soonest = table["first_violation_s"].min()
    worst = summary["worst"]
    row = table[table["tau_s"] == worst["tau_s"]].iloc[0]
    assert row["first_violation_s"] == soonest
    for name, value in worst["margins"].items():
        if value is None:  # none within the window
            assert math.isinf(row[name]) or math.isnan(row[name])
        else:
            assert value == pytest.approx(row[name], rel=1e-15)
    assert summary["failures"] == 4 and summary["window_s"] == 600.0
    page = (out / "report.html").read_text()
    assert "Loss-of-control envelope" in page and "envelope.png" in page
    assert (out / "envelope.png").read_bytes()[:4] == b"\x89PNG"


def test_a_folder_holding_another_file_is_refused_and_left_as_it_was(written, tmp_path, capsys):
    path, _ = written
    out = tmp_path / "theirs"
    out.mkdir()
    (out / "envelope.csv").write_text("not ours\n")
    code = main(["envelope", str(path), "--out", str(out), "--workers", "1", "--quiet"])
    err = said(capsys.readouterr().err)
    assert code == 2 and len(err) == 1, err
    assert (out / "envelope.csv").read_text() == "not ours\n"
    assert sorted(p.name for p in out.iterdir()) == ["envelope.csv"]
