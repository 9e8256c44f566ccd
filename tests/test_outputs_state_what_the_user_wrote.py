"""The outputs state what the user wrote, in the ranges they promise.

- `offset = 600.0` was echoed as 599.9999999999978 (a round trip through the UTC
  epoch), an exclusion of 30 deg as 29.999999999999996: both come out as written.
- RA columns held 360.0: they lie in [0, 360).
- summary.json events carry their impulse (and frame), new inertia, new state.
- |m| ≈ 2e160 gave `angular_momentum_norm_N_m_s: null` (the squares overflowed).
- A non-ASCII name ("T-handle – flip") failed after all the computing, in the AEM.
- `python -m attitude` and `-V` work; a closed pipe ends `check` quietly.
"""

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from cli_lines import said

from attitude.base.version import __version__
from attitude.cli.main import main
from attitude.outputs.csv import right_ascension_deg

SCENARIO = """
[scenario]
name = "{name}"
epoch = "2027-06-21T00:00:00"

[spacecraft]
name = "sat"
principal_moments = {moments}

[initial_state]
quaternion = [1.0, 0.0, 0.0, 0.0]
{rate}

[[events]]
type = "angular_impulse"
offset = 600.0
impulse = [18.0, 0.0, 0.0]
frame = "inertial"

[[events]]
type = "inertia_change"
offset = 900.0
principal_moments = [900.0, 950.0, 1250.0]

[[events]]
type = "attitude_reset"
offset = 1000.0
angular_velocity = [0.0, 0.0, 0.2]

[output]
duration = 1200.0
step = 10.0

[pointing]
[[pointing.body_vectors]]
name = "axis"
vector = [1.0, -1e-17, 0.0]
sun_exclusion_half_angle = {{ value = 30, unit = "deg" }}
"""


def _run(tmp_path, name="echo", moments="[850.0, 900.0, 1200.0]", rate=None):
    rate = rate or "angular_velocity = [0.0, 0.0, 0.0]"
    path = tmp_path / "echo.toml"
    path.write_text(SCENARIO.format(name=name, moments=moments, rate=rate), encoding="utf-8")
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 0
    return path, out, json.loads((out / "summary.json").read_text())


def test_offsets_and_angles_are_echoed_as_written(tmp_path, capsys):
    path, _, summary = _run(tmp_path)
    events = summary["scenario"]["events"]
    assert [e["offset_s"] for e in events] == [600.0, 900.0, 1000.0]
    assert [s["start_s"] for s in summary["motion"]["segments"]] == [0.0, 600.0, 900.0, 1000.0]
    axis = summary["pointing"]["body_vectors"]["axis"]
    assert axis["sun_exclusion_half_angle_deg"] == 30.0
    capsys.readouterr()
    assert main(["check", str(path)]) == 0
    text = capsys.readouterr().out
    assert "(+600 s)  angular_impulse" in text and "half angle 30 deg" in text


def test_events_say_what_they_change(tmp_path):
    _, _, summary = _run(tmp_path)
    impulse, inertia, reset = summary["scenario"]["events"]
    assert impulse["impulse_N_m_s"] == [18.0, 0.0, 0.0] and impulse["frame"] == "inertial"
    assert inertia["principal_moments_kg_m2"] == [900.0, 950.0, 1250.0]
    assert reset["angular_velocity_body_rad_s"] == [0.0, 0.0, 0.2]


def test_right_ascension_stays_below_360(tmp_path):
    """The body vector [1, -1e-17, 0] of a body at rest points at RA = -1e-17 rad."""
    _, out, _ = _run(tmp_path, rate="angular_velocity = [0.0, 0.0, 0.0]")
    text = (out / "timeseries.csv").read_text().splitlines()
    rows = [line.split(",") for line in text if not line.startswith("#")]
    column = rows[0].index("axis_ra_deg")
    ra = np.array([float(row[column]) for row in rows[1:]])
    assert np.all((ra >= 0.0) & (ra < 360.0))
    two_pi = 2.0 * math.pi
    angles = np.array([two_pi, np.nextafter(two_pi, 0.0), -1e-17, 0.0, math.pi])
    degrees = right_ascension_deg(angles)
    assert np.all((degrees >= 0.0) & (degrees < 360.0))
    assert degrees[-1] == 180.0


def test_a_huge_momentum_has_a_norm(tmp_path):
    text = SCENARIO.format(
        name="huge",
        moments="[1e160, 2e160, 3e160]",
        rate="angular_momentum = [2e160, 1e158, 1e158]",
    )
    path = tmp_path / "huge.toml"
    path.write_text(text[: text.index("[[events]]")] + "[output]\nduration = 100.0\n")
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    first = summary["motion"]["segments"][0]
    assert first["angular_momentum_norm_N_m_s"] == pytest.approx(math.hypot(2e160, 1e158, 1e158))


def test_a_non_ascii_name_reaches_the_aem(tmp_path):
    _, out, summary = _run(tmp_path, name="T-handle – flip")
    assert summary["scenario"]["name"] == "T-handle – flip"
    aem = (out / "attitude.aem").read_text(encoding="ascii")
    assert "COMMENT T-handle flip" in aem


def _module(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "attitude", *args], capture_output=True, text=True, timeout=120
    )


@pytest.mark.parametrize("flag", ["-V", "--version"])
def test_python_dash_m_attitude_and_its_version(flag):
    result = _module(flag)
    assert result.returncode == 0 and result.stdout.strip() == f"attitude {__version__}"


def test_python_dash_m_attitude_checks_a_scenario():
    scenario = Path(__file__).parents[1] / "scenarios" / "dzhanibekov_t_handle.toml"
    result = _module("check", str(scenario))
    assert result.returncode == 0 and ": OK" in result.stdout and said(result.stderr) == []


def test_a_closed_pipe_ends_check_quietly():
    scenario = Path(__file__).parents[1] / "scenarios" / "dzhanibekov_t_handle.toml"
    process = subprocess.Popen(
        [sys.executable, "-m", "attitude", "check", str(scenario)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    process.stdout.close()  # `attitude check x | head -0`
    _, err = process.communicate(timeout=120)
    assert process.returncode == 0 and said(err.decode()) == []


def test_the_aem_names_the_tles_international_designator():
    # The ISS TLE's columns 10-17 ("98067A") are its published COSPAR designator,
    # 1998-067A; a TLE that leaves them blank has none (the AEM then says UNKNOWN).
    from sgp4.io import compute_checksum

    from attitude.environment.orbit import TleOrbit

    line1 = "1 25544U 98067A   14020.93268519  .00009878  00000-0  18200-3 0  5082"
    line2 = "2 25544  51.6498 109.4756 0003572  55.9686 274.8005 15.49815350868473"
    assert TleOrbit(line1, line2).international_designator == "1998-067A"
    blank = line1[:9] + " " * 8 + line1[17:68]
    blank += str(compute_checksum(blank + "0"))
    assert TleOrbit(blank, line2).international_designator is None
