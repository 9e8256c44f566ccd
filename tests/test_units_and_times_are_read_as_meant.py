"""Units and epochs are read as the user meant them, or refused with one line.

- `unit = "Hz"` was taken as rad/s (astropy's dimensionless_angles makes 1 Hz = 1
  rad/s): a silent factor 2π.  It is refused as ambiguous, in files and at the
  Python edge (`EulerSolver.from_angular_velocity(I, ω * u.Hz)`); `cycle/s` is 2π rad/s.
- A bare angle was radians: `sun_exclusion_half_angle = 3` became 171.9°.  An angle
  now needs its unit, and `check` echoes it in degrees.
- `06:19:60` on an ordinary day and a leap second that never was (2027-03-01
  23:59:60) were read as the next minute with a raw ErfaWarning; a real leap second
  (2016-12-31 23:59:60 UTC) is still accepted.
- None, booleans and strings were read as NaN, 1 and numbers.
"""

import math
import re

import numpy as np
import pytest
from astropy import units as u
from cli_lines import said

from attitude import EulerSolver, InputError
from attitude.cli.main import main

BASE = """
[scenario]
name = "units"
epoch = "2027-03-01T12:00:00"

[spacecraft]
name = "sat"
principal_moments = [10.0, 20.0, 25.0]

[initial_state]
quaternion = [1.0, 0.0, 0.0, 0.0]
angular_velocity = [0.0, 0.0, 0.01]

[output]
duration = 10.0
step = 1.0
"""

VECTOR = """
[pointing]
[[pointing.body_vectors]]
name = "tracker"
vector = [1.0, 0.0, 0.0]
"""


def _file(tmp_path, text):
    path = tmp_path / "s.toml"
    path.write_text(text, encoding="utf-8")
    return path


def _refused(tmp_path, capsys, text, message):
    path = _file(tmp_path, text)
    for argv in (["check", str(path)], ["run", str(path), "--out", str(tmp_path / "o")]):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert len(said(err)) == 1 and "Traceback" not in err, err
        assert re.search(message, err), err
    assert not (tmp_path / "o").exists()


def _first_rate(tmp_path, text) -> np.ndarray:
    path = _file(tmp_path, text)
    assert main(["run", str(path), "--out", str(tmp_path / "o"), "--quiet"]) == 0
    lines = [
        line
        for line in (tmp_path / "o" / "timeseries.csv").read_text().splitlines()
        if not line.startswith("#")
    ]
    header, first = lines[0].split(","), lines[1].split(",")
    return np.array([float(first[header.index(f"omega_body_{c}_rad_s")]) for c in "xyz"])


def test_hz_is_refused_in_a_file(tmp_path, capsys):
    text = BASE.replace("[0.0, 0.0, 0.01]", '{ value = [0.0, 0.0, 0.5], unit = "Hz" }')
    _refused(
        tmp_path, capsys, text, r"initial_state\.angular_velocity: unit 'Hz' is ambiguous.*cycle/s"
    )


def test_cycles_per_second_are_two_pi_radians_per_second(tmp_path):
    text = BASE.replace("[0.0, 0.0, 0.01]", '{ value = [0.0, 0.0, 0.5], unit = "cycle/s" }')
    np.testing.assert_allclose(_first_rate(tmp_path, text), [0.0, 0.0, math.pi], rtol=1e-15)


def test_degrees_per_second(tmp_path):
    text = BASE.replace("[0.0, 0.0, 0.01]", '{ value = [0.0, 0.0, 180.0], unit = "deg/s" }')
    np.testing.assert_allclose(_first_rate(tmp_path, text), [0.0, 0.0, math.pi], rtol=1e-15)


def test_hz_is_refused_at_the_python_edge():
    with pytest.raises(InputError, match=r"unit 'Hz' is ambiguous.*cycle/s"):
        EulerSolver.from_angular_velocity([1.0, 2.0, 3.0], [0.0, 0.0, 1.0] * u.Hz)
    solver = EulerSolver.from_angular_velocity([1.0, 2.0, 3.0], [0.0, 0.0, 1.0] * u.cycle / u.s)
    np.testing.assert_allclose(solver.angular_velocity(0.0), [0.0, 0.0, 2.0 * math.pi])


def test_an_angle_needs_its_unit(tmp_path, capsys):
    text = BASE + VECTOR + "sun_exclusion_half_angle = 3\n"
    _refused(
        tmp_path,
        capsys,
        text,
        r"pointing\.body_vectors\[0\]\.sun_exclusion_half_angle: an angle needs its unit",
    )


def test_a_unit_on_a_pure_number_is_refused(tmp_path, capsys):
    text = BASE.replace("[1.0, 0.0, 0.0, 0.0]", '{ value = [1.0, 0.0, 0.0, 0.0], unit = "deg" }')
    _refused(tmp_path, capsys, text, r"initial_state\.quaternion: takes no unit")


def test_check_echoes_angles_in_degrees(tmp_path, capsys):
    text = BASE + VECTOR + 'sun_exclusion_half_angle = { value = 0.5, unit = "rad" }\n'
    assert main(["check", str(_file(tmp_path, text))]) == 0
    out = capsys.readouterr().out
    assert f"Sun exclusion half angle {math.degrees(0.5):.12g} deg" in out
    assert "rate        [0, 0, 0.572958] deg/s" in out


@pytest.mark.parametrize(
    ("key", "epoch"),
    [
        ("scenario.epoch", "2027-03-02T06:19:60"),
        ("scenario.epoch", "2027-03-01T23:59:60"),
        ("output.stop", "2027-03-01T23:59:60"),
    ],
)
def test_a_second_that_does_not_exist_is_refused(tmp_path, capsys, key, epoch):
    if key == "scenario.epoch":
        text = BASE.replace("2027-03-01T12:00:00", epoch)
    else:
        text = BASE.replace("duration = 10.0", f'stop = "{epoch}"')
    _refused(tmp_path, capsys, text, rf"{re.escape(key)}: '{epoch}' names a second that does not")


def test_a_real_leap_second_is_accepted(tmp_path, capsys):
    path = _file(tmp_path, BASE.replace("2027-03-01T12:00:00", "2016-12-31T23:59:55"))
    assert main(["run", str(path), "--out", str(tmp_path / "o"), "--quiet"]) == 0
    assert capsys.readouterr().err == ""  # no ErfaWarning
    csv = (tmp_path / "o" / "timeseries.csv").read_text()
    assert "\n2016-12-31T23:59:60.000000000," in csv


@pytest.mark.parametrize(
    ("inertia", "message"),
    [
        (None, "inertia is missing"),
        ([True, 2.0, 3.0], "inertia must be numeric, got True"),
        (["1", "2", "3"], "inertia must be numeric, got '1'"),
    ],
)
def test_the_python_edge_names_the_real_problem(inertia, message):
    with pytest.raises(InputError, match=message):
        EulerSolver(inertia, [1.0, 2.0, 3.0])


def test_a_triangle_warning_is_one_line_naming_the_file_and_the_key(tmp_path, capsys):
    path = _file(tmp_path, BASE.replace("[10.0, 20.0, 25.0]", "[1.0, 2.0, 25.0]"))
    assert main(["run", str(path), "--out", str(tmp_path / "o"), "--quiet"]) == 0
    err = capsys.readouterr().err
    assert err.startswith(
        "attitude: warning: s.toml: spacecraft.principal_moments: principal moments "
        "[1.0, 2.0, 25.0] kg m² break the triangle inequality"
    )
    assert len(said(err)) == 1 and ".py" not in err
