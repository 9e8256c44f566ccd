"""A refused value is echoed as the file writes it, in the unit the user gave; a slew's
limits, like angles, need their unit.

- `slew = { max_rate = 1.0, ... }` was read as 1 rad/s (57.3 deg/s), the acceleration
  as rad/s²: a slew limit is written in deg/s on a data sheet, so a bare number is
  refused, as a bare angle is (tests/hostile/bare_angle.toml).
- `max_rate = { value = -1, unit = "deg/s" }` was refused as "got -0.017453292519943295";
  `duration = { value = -5, unit = "min" }` as "got -300.0"; an inclination of 4 rad as
  229.183 deg.  Each line below says the value as written: checked in the reader
  where the reader checks it, and added after a builder's own SI wording otherwise
  ("(given as 30 deg)").
"""

import re

import pytest
from cli_lines import said

from attitude.base.errors import InputError
from attitude.cli.main import main
from attitude.envelope.settings import read_envelope
from attitude.files.scenario_reader import load_scenario
from attitude.montecarlo.dispersions import read_dispersions

BASE = """
[scenario]
name = "echo"
epoch = "2027-06-21T00:00:00"

[spacecraft]
name = "sat"
principal_moments = [10.0, 20.0, 25.0]

[initial_state]
quaternion = [1.0, 0.0, 0.0, 0.0]
angular_velocity = [0.01, 0.2, 0.01]

[output]
duration = 600.0
step = 1.0
"""
KEPLERIAN = """
[pointing]
[pointing.keplerian]
semi_major_axis = { value = 7000.0, unit = "km" }
eccentricity = 0.0
inclination = { value = 51.6, unit = "deg" }
raan = { value = 0.0, unit = "deg" }
argument_of_perigee = { value = 0.0, unit = "deg" }
mean_anomaly = { value = 0.0, unit = "deg" }
"""
GUIDED = BASE.replace(
    "[initial_state]\nquaternion = [1.0, 0.0, 0.0, 0.0]\nangular_velocity = [0.01, 0.2, 0.01]\n",
    '[initial_state.law]\nname = "nadir"\n',
)
DEG_S = '{ value = 1.0, unit = "deg/s" }'
DEG_S2 = '{ value = 0.05, unit = "deg/s2" }'


def _slew(rate: str = DEG_S, acceleration: str = DEG_S2) -> str:
    return (
        GUIDED
        + '\n[[events]]\ntype = "mode_change"\noffset = 100.0\n'
        + 'law = { name = "sun", axis = "+z" }\n'
        + f"slew = {{ max_rate = {rate}, max_acceleration = {acceleration} }}\n"
        + KEPLERIAN
    )


def _site(latitude: str, longitude: str, height: str = "0.0") -> str:
    site = f'\n[[sites]]\nname = "k"\nlatitude = {latitude}\nlongitude = {longitude}\n'
    return GUIDED + site + f"height = {height}\n" + KEPLERIAN


def _in(text: str, table: str, line: str) -> str:
    assert table in text, table
    return text.replace(table, f"{table}{line}\n", 1)


def _sub(old: str, new: str, text: str = BASE) -> str:
    assert old in text, old
    return text.replace(old, new, 1)


TORQUES = BASE + KEPLERIAN + "\n[torques]\ngravity_gradient = true\n"
VECTOR = '[[pointing.body_vectors]]\nname = "x"\nvector = [1.0, 0.0, 0.0]\n'

# What the file writes, and the key and the line (a regular expression) it is refused with.
CASES = {
    "slew rate, bare": (
        _slew(rate="1.0"),
        "events[0].slew.max_rate",
        r'a rate needs its unit, e\.g\. \{ value = 1\.0, unit = "deg/s" \} \(a bare number '
        r"would be read as rad/s\)",
    ),
    "slew acceleration, bare": (
        _slew(acceleration="0.05"),
        "events[0].slew.max_acceleration",
        r"an angular acceleration needs its unit, e\.g\. \{ value = 0\.05, unit = \"deg/s2\" \}",
    ),
    "slew rate, -1 deg/s": (
        _slew(rate='{ value = -1, unit = "deg/s" }'),
        "events[0].slew.max_rate",
        r"must be positive, got -1 deg/s$",
    ),
    "slew acceleration, -1 deg/s2": (
        _slew(acceleration='{ value = -1, unit = "deg/s2" }'),
        "events[0].slew.max_acceleration",
        r"must be positive, got -1 deg/s2$",
    ),
    "slew rate, 1e9 deg/s": (
        _slew(rate='{ value = 1e9, unit = "deg/s" }'),
        "events[0].slew.max_rate",
        r"rad/s is beyond any spacecraft \(at most 1000\) \(given as 1e\+09 deg/s\)$",
    ),
    "duration, -5 min": (
        _sub("duration = 600.0", 'duration = { value = -5, unit = "min" }'),
        "output.duration",
        r"must be positive, got -5 min$",
    ),
    "step, -1 ms": (
        _sub("step = 1.0", 'step = { value = -1, unit = "ms" }'),
        "output.step",
        r"must be positive, got -1 ms$",
    ),
    "aem tolerance, 10 deg": (
        _in(BASE, "step = 1.0\n", 'aem_tolerance = { value = 10, unit = "deg" }'),
        "output.aem_tolerance",
        r"\(given as 10 deg\)$",
    ),
    "accuracy, 30 deg": (
        _in(TORQUES, "[torques]\n", 'accuracy = { value = 30.0, unit = "deg" }'),
        "torques.accuracy",
        r"must be between 1e-12 and 0\.1 rad, got .* \(given as 30\.0 deg\)$",
    ),
    "horizon threshold, 4 rad": (
        _in(BASE + KEPLERIAN, "[pointing]\n", "")
        + '\n[torques]\nhorizon_threshold = { value = 4, unit = "rad" }\n',
        "torques.horizon_threshold",
        r"must be between 0 and 180 deg, got .* \(given as 4 rad\)$",
    ),
    "torque step, -1 min": (
        _in(TORQUES, "[torques]\n", 'step = { value = -1, unit = "min" }'),
        "torques.step",
        r"must be positive, got -1 min$",
    ),
    "semi-major axis, -1 km": (
        BASE + _sub('{ value = 7000.0, unit = "km" }', '{ value = -1, unit = "km" }', KEPLERIAN),
        "pointing.keplerian.semi_major_axis",
        r"must be positive, got -1 km$",
    ),
    "inclination, 4 rad": (
        BASE + _sub('{ value = 51.6, unit = "deg" }', '{ value = 4, unit = "rad" }', KEPLERIAN),
        "pointing.keplerian.inclination",
        r"must be between 0 and 180 deg, got .* \(given as 4 rad\)$",
    ),
    "limb height, -1 km": (
        _in(
            BASE + KEPLERIAN,
            "[pointing]\n",
            'earth_limb_atmosphere_height = { value = -1, unit = "km" }',
        ),
        "pointing.earth_limb_atmosphere_height",
        r"\(given as -1 km\)$",
    ),
    "interval precision, -1 ms": (
        _in(BASE + KEPLERIAN, "[pointing]\n", 'interval_precision = { value = -1, unit = "ms" }'),
        "pointing.interval_precision",
        r"must be positive, got -1 ms$",
    ),
    "exclusion angle, 4 rad": (
        BASE + KEPLERIAN + VECTOR + 'sun_exclusion_half_angle = { value = 4, unit = "rad" }\n',
        "pointing.body_vectors[0].sun_exclusion_half_angle",
        r"must be between 0 and 180 deg, got 4 rad$",
    ),
    "moments, g m2": (
        _sub(
            "principal_moments = [10.0, 20.0, 25.0]",
            'principal_moments = { value = [-1, 2, 2], unit = "g m2" }',
        ),
        "spacecraft.principal_moments",
        r"\(given as \[-1, 2, 2\] g m2\)$",
    ),
    "event offset, 1 h": (
        BASE + '\n[[events]]\ntype = "angular_impulse"\noffset = { value = 1, unit = "h" }\n'
        "impulse = [0.1, 0.0, 0.0]\n",
        "events[0].offset",
        r"is after the end of the propagation span .* \(given as 1 h\)$",
    ),
    "burn duration, -1 min": (
        BASE
        + '\n[torques]\n[[torques.burns]]\noffset = 1.0\nduration = { value = -1, unit = "min" }\n'
        "torque = [0.0, 0.0, 0.01]\n",
        "torques.burns[0].duration",
        r"must be positive, got -1 min$",
    ),
    "site latitude, 2 rad": (
        _site('{ value = 2, unit = "rad" }', '{ value = 0, unit = "deg" }'),
        "sites[0].latitude",
        r"must be between -90 and 90 deg, got 2 rad$",
    ),
    "site height, 1000 km": (
        _site(
            '{ value = 2, unit = "deg" }',
            '{ value = 0, unit = "deg" }',
            '{ value = 1000, unit = "km" }',
        ),
        "sites[0].height",
        r"got 1000 km$",
    ),
    "site height, bare": (
        _site('{ value = 2, unit = "deg" }', '{ value = 0, unit = "deg" }', "1e6"),
        "sites[0].height",
        r"got 1000000\.0 m$",
    ),
}


@pytest.mark.parametrize("case", list(CASES))
def test_refused_with_the_value_as_written(case, tmp_path):
    text, key, message = CASES[case]
    path = tmp_path / "echo.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(InputError) as caught:
        load_scenario(path)
    assert caught.value.key == key, str(caught.value)
    assert re.search(message, caught.value.reason), caught.value.reason


DISPERSIONS = "\n[dispersions]\nseed = 1\nsamples = 10\n[dispersions.initial_state]\n"


@pytest.mark.parametrize(
    ("line", "key", "message"),
    [
        (
            'attitude = { distribution = "normal", sigma = { value = -1, unit = "deg" } }',
            "dispersions.initial_state.attitude.sigma",
            r"must be positive .*, got -1 deg$",
        ),
        (
            'attitude = { distribution = "normal", sigma = { value = 4, unit = "rad" } }',
            "dispersions.initial_state.attitude.sigma",
            r"must be at most 180 deg \(a small rotation\), got 4 rad$",
        ),
    ],
    ids=["sigma -1 deg", "sigma 4 rad"],
)
def test_a_dispersion_is_refused_with_its_value_as_written(tmp_path, line, key, message):
    path = tmp_path / "echo.toml"
    path.write_text(BASE + DISPERSIONS + line + "\n", encoding="utf-8")
    with pytest.raises(InputError) as caught:
        read_dispersions(load_scenario(path))
    assert caught.value.key == key and re.search(message, caught.value.reason), caught.value


def test_an_envelope_window_is_refused_with_its_value_as_written(tmp_path):
    path = tmp_path / "echo.toml"
    envelope = '\n[envelope]\nevery = 60.0\nwindow = { value = 30, unit = "day" }\n'
    path.write_text(GUIDED + KEPLERIAN + envelope, encoding="utf-8")
    with pytest.raises(InputError) as caught:
        read_envelope(load_scenario(path))
    assert caught.value.key == "envelope.window", str(caught.value)
    assert caught.value.reason.endswith("(given as 30 day)"), caught.value.reason
    assert caught.value.file == "echo.toml"


def test_check_and_run_refuse_a_bare_slew_limit_with_the_same_line(tmp_path, capsys):
    path = tmp_path / "slew.toml"
    path.write_text(_slew(rate="1.0"), encoding="utf-8")
    lines = []
    for argv in (["check", str(path)], ["run", str(path), "--out", str(tmp_path / "o"), "--quiet"]):
        assert main(argv) == 2
        lines.append(said(capsys.readouterr().err))
    assert lines[0] == lines[1] and len(lines[0]) == 1, lines
    assert lines[0][0].startswith("attitude: error: slew.toml: events[0].slew.max_rate: a rate ")
    assert not (tmp_path / "o").exists()
