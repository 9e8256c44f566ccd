"""The envelope's outputs read back by readers that share no code with the writer
(duckdb for the Parquet table, the csv module for the CSV one, json for the summary),
the same table from a cluster of two workers (one failure a task) as from this process
alone, and the output folder's rules.  One Dask cluster for the whole file.
"""

import csv
import json
import math

import duckdb
import numpy as np
import pandas
import pytest
from cli_lines import said
from envelope_scenarios import with_envelope

from attitude import load_scenario
from attitude.cli.main import main
from attitude.envelope.failure import evaluate_batch
from attitude.envelope.plan import make_job, plan_envelope

TABLE = """[envelope]
times = [300.0, 1920.0, 3300.0, 5100.0]
window = 600.0
wheels = { case = "locked", momentum = [0.0, 2.0, 0.0] }
power_threshold = 0.3
"""


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """The command's outputs, on a local cluster of two workers, one failure a task."""
    tmp = tmp_path_factory.mktemp("envelope")
    path = with_envelope(tmp, TABLE)
    out = tmp / "out"
    argv = ["envelope", str(path), "--out", str(out), "--workers", "2", "--batch-size", "1"]
    assert main([*argv, "--quiet"]) == 0
    return path, out


def _alone(path) -> pandas.DataFrame:
    """The table computed in this process, failure after failure, as one worker would."""
    plan = plan_envelope(load_scenario(path))
    job, epochs, modes = make_job(plan)
    rows = evaluate_batch(job, 0, job.count).rows
    for row in rows:
        row["epoch_utc"], row["mode"] = epochs[row["failure"]], modes[row["failure"]]
    return pandas.DataFrame(rows, columns=plan.columns)


def test_parquet_and_csv_read_back_by_duckdb_and_csv_agree_with_one_process(written):
    path, out = written
    alone = _alone(path)
    assert list(alone["tau_s"]) == [300.0, 1920.0, 3300.0, 5100.0]
    assert set(alone["status"]) == {"ok"}
    parquet = duckdb.sql(f"SELECT * FROM read_parquet('{out / 'envelope.parquet'}')").df()
    with open(out / "envelope.csv", newline="") as stream:
        rows = list(csv.DictReader(stream))
    assert list(parquet.columns) == list(alone.columns)
    assert len(rows) == len(alone) == len(parquet)
    metrics = [c for c in alone.columns if c not in ("epoch_utc", "mode", "status", "error")]
    for name in metrics:
        theirs = alone[name].to_numpy(dtype=float)
        # Two workers and this process alone give the same table, to the last bit.
        assert np.array_equal(parquet[name].to_numpy(dtype=float), theirs), name
        from_csv = np.array([float(row[name]) for row in rows])  # "inf" reads as inf
        assert np.allclose(from_csv, theirs, rtol=1e-15, atol=0.0, equal_nan=True), name
    assert list(parquet["epoch_utc"]) == list(alone["epoch_utc"])
    assert list(parquet["mode"]) == list(alone["mode"])
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
