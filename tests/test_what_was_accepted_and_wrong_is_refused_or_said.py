"""Inputs that were accepted and wrong, or refused in Python's words, against what they
mean.

- A ground site at a longitude of 1000 deg was accepted (a typo for 100?): geodetic
  coordinates out of range are refused, one line naming the file, the key and the value.
- Sun yaw steering near β = 0 turns the yaw by 180° in a few minutes: the law demanded
  2.4 deg/s, silently.  `check` and `run` warn in one line with the peak and when, against
  the slews' limits when given; the peak is checked against the law's rate sampled
  every 0.1 s.
- Dispersing the inertia of a spacecraft guided over the whole span changes no motion:
  said in one line when the job is planned.
- Python's wording reached the user: "invalid literal for int() with base 10" (a TLE
  field), astropy's "Input values did not match the format class isot" (an OEM epoch),
  and an ERFA error reported as a bug of ours for an event 1e30 s after the epoch.
"""

import re
import warnings

import astropy.units as u
import numpy as np
import pytest
from cli_lines import said

from attitude.base.errors import InputError, LawRateWarning
from attitude.cli.main import main
from attitude.files.scenario_reader import ScenarioFileWarning, load_scenario
from attitude.laws.directions import GroundSite
from attitude.montecarlo.plan import plan_montecarlo
from attitude.report.plan import plan_run

KEPLERIAN = """
[pointing.keplerian]
semi_major_axis = { value = 7000.0, unit = "km" }
eccentricity = 0.0
inclination = { value = 0.0, unit = "deg" }
raan = { value = 0.0, unit = "deg" }
argument_of_perigee = { value = 0.0, unit = "deg" }
mean_anomaly = { value = 0.0, unit = "deg" }
"""
# An equatorial orbit four days after the March equinox: the Sun 1.6 deg from the orbit
# plane, and the spacecraft at the subsolar point at the epoch.
YAW = (
    """
[scenario]
name = "Sun yaw steering near beta = 0"
epoch = "2027-03-25T00:00:00"

[spacecraft]
name = "sat"
principal_moments = [10.0, 20.0, 25.0]

[initial_state.law]
name = "nadir"
yaw_steering = "sun"

[output]
duration = 600.0
step = 10.0
"""
    + KEPLERIAN
)
SLEW = (
    '\n[[events]]\ntype = "mode_change"\noffset = 300.0\nlaw = { name = "nadir" }\n'
    'slew = { max_rate = { value = RATE, unit = "deg/s" }, '
    'max_acceleration = { value = 0.5, unit = "deg/s2" } }\n'
)


def _write(tmp_path, text, name="s.toml"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def _site(longitude: str, latitude: str = "0.0") -> str:
    return YAW + (
        f'\n[[sites]]\nname = "k"\nlatitude = {{ value = {latitude}, unit = "deg" }}\n'
        f'longitude = {{ value = {longitude}, unit = "deg" }}\n'
    )


@pytest.mark.parametrize(
    ("longitude", "latitude", "key", "message"),
    [
        ("1000", "0.0", "longitude", r"must be between -180 and 360 deg \(east\), got 1000 deg$"),
        ("-200", "0.0", "longitude", r"must be between -180 and 360 deg \(east\), got -200 deg$"),
        ("10", "90.5", "latitude", r"must be between -90 and 90 deg, got 90\.5 deg$"),
    ],
)
def test_a_ground_site_out_of_range_is_refused(tmp_path, capsys, longitude, latitude, key, message):
    path = _write(tmp_path, _site(longitude, latitude))
    assert main(["check", str(path)]) == 2
    (line,) = said(capsys.readouterr().err)
    assert line.startswith(f"attitude: error: s.toml: sites[0].{key}: "), line
    assert re.search(message, line), line


def test_a_ground_site_out_of_range_is_refused_at_the_python_edge():
    with pytest.raises(InputError, match=r"longitude must be between -180 and 360 deg"):
        GroundSite(10 * u.deg, 1000 * u.deg)
    GroundSite(10 * u.deg, 350 * u.deg)  # east of Greenwich the other way round: accepted
    GroundSite(10 * u.deg, -179 * u.deg)


def _law_warnings(tmp_path, text):
    loaded = load_scenario(_write(tmp_path, text))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        plan = plan_run(loaded.scenario, loaded.pointing, loaded.outputs, check=True)
    return plan, [w.message for w in caught if isinstance(w.message, LawRateWarning)]


def test_sun_yaw_steering_near_beta_zero_is_warned_of_with_its_peak(tmp_path):
    plan, found = _law_warnings(tmp_path, YAW)
    (warning,) = found
    assert warning.key == "initial_state.law"
    peak, at = re.search(r"up to ([\d.]+) deg/s, at .* \(t = ([\d.]+) s\)", warning.reason).groups()
    assert "more than 1 deg/s (no slew limits are given" in warning.reason
    # Against the law's own rate, every 0.1 s over the segment.
    solver = plan.trajectory.segments[0].solver
    t = np.arange(0.0, 600.0, 0.1)
    rates = np.degrees(np.linalg.norm(solver.angular_velocity(t), axis=-1))
    assert float(peak) == pytest.approx(rates.max(), rel=2e-3)  # 3 digits stated
    assert abs(float(at) - t[np.argmax(rates)]) < 0.2


@pytest.mark.parametrize(("limit", "warned"), [("1.0", True), ("5.0", False)])
def test_the_peak_is_compared_with_the_slews_limits(tmp_path, limit, warned):
    _, found = _law_warnings(tmp_path, YAW + SLEW.replace("RATE", limit))
    assert len(found) == int(warned)
    if warned:
        assert "beyond the slews' max_rate of 1 deg/s" in found[0].reason


def test_check_and_run_say_it_in_one_line(tmp_path, capsys):
    path = _write(tmp_path, YAW)
    lines = []
    for argv in (["check", str(path)], ["run", str(path), "--out", str(tmp_path / "o")]):
        assert main([*argv, "--formats", "csv"]) == 0
        lines.append([line for line in said(capsys.readouterr().err) if "warning" in line])
    assert lines[0] == lines[1] and len(lines[0]) == 1, lines
    assert lines[0][0].startswith("attitude: warning: s.toml: initial_state.law: the nadir law")


GUIDED_ONLY = (
    YAW.replace('yaw_steering = "sun"', "")
    + "\n[dispersions]\nseed = 1\nsamples = 10\n[dispersions.spacecraft]\n"
    + 'principal_moments = { distribution = "normal", relative_sigma = 0.05 }\n'
)


def test_dispersing_the_inertia_of_a_guided_spacecraft_is_said_to_change_no_motion(tmp_path):
    loaded = load_scenario(_write(tmp_path, GUIDED_ONLY))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        plan_montecarlo(loaded)
    said_ = [str(w.message) for w in caught if issubclass(w.category, ScenarioFileWarning)]
    assert len(said_) == 1, said_
    assert said_[0].startswith("s.toml: dispersions.spacecraft.principal_moments: the spacecraft ")
    assert "changes no motion" in said_[0]
    # With a control loss the inertia matters: nothing said.
    lost = GUIDED_ONLY + '\n[[events]]\ntype = "control_loss"\noffset = 300.0\n'
    loaded = load_scenario(_write(tmp_path, lost))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        plan_montecarlo(loaded)
    assert not [w for w in caught if issubclass(w.category, ScenarioFileWarning)]


LINE1 = "1 59001U 27042A   27171.50000000  .00000120  00000-0  18000-4 0  9999"
LINE2 = "2 59001  98.2100 175.3000 0012000  95.0000 265.2000 14.57123456    14"
PYTHON = re.compile(r"invalid literal|could not convert|int\(\)|float\(\)|Input values|ERFA|Erfa")


def _checksum(line: str) -> str:
    body = line[:68]
    return body + str((sum(int(c) for c in body if c.isdigit()) + body.count("-")) % 10)


def _tle(column: int, text: str, line: int) -> tuple[str, str]:
    base = LINE1 if line == 1 else LINE2
    bad = _checksum(base[: column - 1] + text + base[column - 1 + len(text) :])
    return (bad, LINE2) if line == 1 else (LINE1, bad)


@pytest.mark.parametrize(
    ("column", "text", "line", "field"),
    [
        (19, "2x", 1, "columns 19-20 (epoch year) hold '2x'"),
        (45, " 0000x-0", 1, "columns 45-52 (second derivative of the mean motion)"),
        (54, " 18000-x", 1, "columns 54-61 (BSTAR drag term) hold ' 18000-x'"),
        (27, "0012x00", 2, "columns 27-33 (eccentricity) hold '0012x00'"),
        (53, "14.5712x456", 2, "columns 53-63 (mean motion) hold '14.5712x456'"),
    ],
)
def test_a_tle_field_that_is_not_a_number_is_named_in_our_words(column, text, line, field):
    from attitude.environment.orbit import TleOrbit

    with pytest.raises(InputError) as caught:
        TleOrbit(*_tle(column, text, line))
    reason = caught.value.reason
    assert reason.startswith(f"line{line}: {field}"), reason
    assert not PYTHON.search(reason), reason


def test_an_oem_epoch_that_is_no_date_is_named_in_our_words(tmp_path, capsys):
    oem = (
        "CCSDS_OEM_VERS = 2.0\nCREATION_DATE = 2027-06-20T00:00:00\nORIGINATOR = ME\n\n"
        "META_START\nOBJECT_NAME = SAT\nOBJECT_ID = 2027-001A\nCENTER_NAME = EARTH\n"
        "REF_FRAME = ICRF\nTIME_SYSTEM = UTC\nSTART_TIME = 2027-06-21T00:00:00\n"
        "STOP_TIME = 2027-13-21T00:02:00\nMETA_STOP\n\n"
        "2027-06-21T00:00:00 7000 0 0 0 7.5 0\n2027-06-21T00:01:00 6998 450 0 -0.5 7.5 0\n"
        "2027-13-21T00:02:00 6992 900 0 -1.0 7.4 0\n"
    )
    (tmp_path / "bad.oem").write_text(oem)
    text = YAW.replace(KEPLERIAN, '\n[pointing]\noem = "bad.oem"\n')
    assert main(["check", str(_write(tmp_path, text))]) == 2
    (line,) = said(capsys.readouterr().err)
    assert line.endswith("bad.oem: segment 0: epoch '2027-13-21T00:02:00': bad month"), line
    assert not PYTHON.search(line), line


def test_an_event_beyond_any_date_is_refused_not_a_bug_of_ours(tmp_path, capsys):
    text = YAW + '\n[[events]]\ntype = "control_loss"\noffset = 1e30\n'
    assert main(["check", str(_write(tmp_path, text))]) == 2
    (line,) = said(capsys.readouterr().err)
    assert line.startswith("attitude: error: s.toml: events[0].offset: the control_loss at 1e+30 s")
    assert "internal error" not in line and not PYTHON.search(line), line
