"""A sample that fails is reported with its parameters and its error; the job goes on.

The thruster pulse at 60 s is dispersed uniformly over ±70 s: the samples whose shift
is below −60 s would fire it before the epoch, which the scenario refuses.  Those
samples (and only those) are rows with status "failed", their drawn parameters, and
the scenario's own one-line error; every other sample runs.  The command line says how
many failed, in one note line, and exits 0; statistics.json lists the failures.  A job
in which every sample fails exits 2 with one line, and writes nothing.
"""

import json

import pandas
from montecarlo_scenarios import write_spinner

from attitude.cli.main import main


def test_failed_samples_are_rows_with_parameters_and_error(tmp_path, capsys):
    scenario = write_spinner(tmp_path, samples=40, time_half_width=70.0)
    out = tmp_path / "mc"
    code = main(["montecarlo", str(scenario), "--out", str(out), "--workers", "2", "--quiet"])
    err = capsys.readouterr().err.splitlines()
    assert code == 0
    assert len(err) == 1 and err[0].startswith("attitude: note: spinner.toml: 5 of 40 samples"), err

    table = pandas.read_parquet(out / "samples.parquet")
    shift = table["events[0].time_shift_s"]
    failed = table["status"] == "failed"
    assert failed.sum() == 5
    assert (failed == (shift < -60.0)).all()  # exactly the samples that fire before the epoch
    assert table.loc[~failed, "error"].eq("").all()
    for error in table.loc[failed, "error"]:
        assert error.startswith("spinner.toml: events[0].offset: the angular_impulse at 2027-06-20")
        assert error.endswith("is before the scenario epoch 2027-06-21T00:00:00.000000000 UTC")
    # Their parameters are drawn and recorded; their metrics are empty.
    assert table.loc[failed, "initial_state.attitude_error_deg"].notna().all()
    assert table.loc[failed, "star_tracker_sun_angle_min_deg"].isna().all()
    assert table.loc[~failed, "star_tracker_sun_angle_min_deg"].notna().all()

    statistics = json.loads((out / "statistics.json").read_text())
    assert statistics["samples"] == {"total": 40, "ok": 35, "failed": 5}
    listed = {f["sample"]: f for f in statistics["failures"]}
    assert sorted(listed) == table.loc[failed, "sample"].tolist()
    for k, entry in listed.items():
        assert entry["parameters"]["events[0].time_shift_s"] == shift[k]
    assert statistics["metrics"]["star_tracker_sun_angle_min_deg"]["n"] == 35


def test_a_job_where_every_sample_fails_exits_2_and_writes_nothing(tmp_path, capsys):
    # The pulse at 0.5 s, dispersed over ±2 s: a shift below −0.5 s fires it before the
    # epoch, and with seed 98 all three samples draw one.
    scenario = write_spinner(tmp_path, samples=3, seed=98, time_half_width=2.0)
    scenario.write_text(
        scenario.read_text().replace('epoch = "2027-06-21T00:01:00"', "offset = 0.5")
    )
    out = tmp_path / "mc"
    code = main(["montecarlo", str(scenario), "--out", str(out), "--workers", "1", "--quiet"])
    err = capsys.readouterr().err.splitlines()
    assert code == 2, err
    assert len(err) == 1, err
    assert err[0].startswith("attitude: error: spinner.toml: every sample failed; sample 0: ")
    assert not out.exists()
