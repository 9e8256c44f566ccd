"""Pointing through the command line: what `check` and `run` say, and what they write.

- An output step longer than a tenth of the motion's shortest period is said, in one
  note naming output.step and the period, by both `check` and `run`.
- The example scenario `nadir_cubesat_star_tracker.toml` (a 3U CubeSat put on nadir by
  `frame = "lvlh"`): its camera stays on nadir, its star tracker's Sun exclusion
  intervals hold the least Sun angle, the LVLH columns are the identity.
- An attitude reset given in LVLH puts the body on the LVLH axes at the reset's epoch.
"""

import json
import math
import re
from pathlib import Path

import numpy as np
from csv_read_back import read_csv

from attitude.cli.main import main

ROOT = Path(__file__).parents[1]
SPINNER = """
[scenario]
name = "spinner"
epoch = "2027-06-21T00:00:00"

[spacecraft]
name = "sat"
principal_moments = [850.0, 900.0, 1200.0]

[initial_state]
quaternion = [1.0, 0.0, 0.0, 0.0]
angular_velocity = {{ value = [0.0, 0.0, 30.0], unit = "deg/s" }}   # 12 s a turn

[output]
duration = 120.0
step = {step}
"""


def test_an_undersampling_step_is_said_by_check_and_run(tmp_path, capsys):
    path = tmp_path / "coarse.toml"
    path.write_text(SPINNER.format(step=2.0))
    assert main(["check", str(path)]) == 0
    out = capsys.readouterr().out
    note = r"output\.step: 2 s is more than a tenth of the 12 s spin period of segment 0"
    assert re.search(rf"note +{note}", out), out
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and re.match(rf"attitude: note: coarse\.toml: {note}", err[0]), err
    # A step of a tenth of the period or less is not undersampling.
    path.write_text(SPINNER.format(step=1.2))
    assert main(["check", str(path)]) == 0
    assert "undersamples" not in capsys.readouterr().out


def test_the_nadir_pointing_example(tmp_path, capsys):
    scenario = ROOT / "scenarios" / "nadir_cubesat_star_tracker.toml"
    assert main(["check", str(scenario)]) == 0
    out = capsys.readouterr().out
    assert "Moon exclusion half angle 20 deg, Earth limb exclusion angle 25 deg" in out
    assert "Keplerian elements (two-body, ICRF)" in out
    out_dir = tmp_path / "nadir"
    assert main(["run", str(scenario), "--out", str(out_dir), "--quiet"]) == 0
    data = read_csv(out_dir / "timeseries.csv")
    assert np.abs(data["camera_nadir_angle_deg"]).max() < 1e-6
    np.testing.assert_allclose(data["q_body_to_lvlh_w"], 1.0, atol=1e-12)
    for k in (1, 2, 3):
        assert np.abs(data[f"lvlh_euler_ZYX_{k}_deg"]).max() < 1e-6
    summary = json.loads((out_dir / "summary.json").read_text())
    tracker = summary["pointing"]["body_vectors"]["star_tracker"]
    assert tracker["sun_angle_min_deg"] < 40.0 and tracker["sun_exclusion"]["count"] >= 1
    assert tracker["earth_limb_exclusion"]["count"] == 0
    # The least Sun angle falls inside one of the exclusion intervals.
    intervals = read_csv(out_dir / "intervals.csv")
    exclusions = intervals[intervals["kind"] == "sun_exclusion"]
    times = [i for i in exclusions if i["body_vector"] == "star_tracker"]
    least_at = tracker["sun_angle_min_at"]
    assert any(str(i["start"]) <= least_at.removesuffix(" UTC") <= str(i["end"]) for i in times)


def test_an_attitude_reset_in_lvlh(tmp_path, capsys):
    text = (ROOT / "scenarios" / "nadir_cubesat_star_tracker.toml").read_text()
    text = text.replace(
        "angular_velocity = [0.0, -0.0011067834463349404, 0.0]",
        "angular_velocity = [0.01, 0.02, -0.03]",  # tumbling at first
    )
    text = re.sub(r"(?m)^duration = .*$", "duration = 1200.0", text)
    text += (
        '\n[[events]]\ntype = "attitude_reset"\noffset = 600.0\nframe = "lvlh"\n'
        "quaternion = [1.0, 0.0, 0.0, 0.0]\n"
        f"angular_velocity = [0.0, {-math.sqrt(3.986004418e14 / 6878137.0**3)!r}, 0.0]\n"
    )
    path = tmp_path / "reset.toml"
    path.write_text(text)
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    data = read_csv(tmp_path / "out" / "timeseries.csv")
    after = data["t_s"] >= 600.0
    assert np.abs(data["camera_nadir_angle_deg"][after]).max() < 1e-6
    assert data["camera_nadir_angle_deg"][~after].max() > 1.0
