"""Hostile attitude laws, slews and control losses: one clear line from both `check` and
`run`, naming the file and the key, and nothing written.

Parallel directions (given so, and reached during the run), parallel body vectors,
slews that cannot finish before the next event, a tumble too fast to capture, a
control loss with absurd wheel momentum, a law that needs an orbit in a scenario
without one, events out of place (a mode change while control is lost, a resume
under a law, an impulse under a law), and the scenario file's own mistakes.  And two
that must run: a ground site at the pole (regular), and a ground target that never
rises above the horizon in its segment, which the run states (check's notes and
summary.json), not tracked silently through the Earth.
"""

from __future__ import annotations

import json
import math
import re
import warnings

import numpy as np
import pytest
from astropy.time import Time
from cli_lines import said
from eo_orbit import EPOCH, ORBIT

from attitude import InputError, SunLaw
from attitude.cli.main import main
from attitude.files.scenario_reader import load_scenario
from attitude.report.plan import plan_run

BASE = """
[scenario]
name = "guided"
epoch = "2025-05-01T10:00:00"

[spacecraft]
name = "eo"
principal_moments = [820.0, 1040.0, 610.0]

[pointing.keplerian]
semi_major_axis = { value = 7078.137, unit = "km" }
eccentricity = 0.001
inclination = { value = 98.2, unit = "deg" }
raan = { value = 170.0, unit = "deg" }
argument_of_perigee = { value = 0.0, unit = "deg" }
mean_anomaly = { value = 0.0, unit = "deg" }
j2 = true

[[sites]]
name = "kiruna"
latitude = { value = 67.857, unit = "deg" }
longitude = { value = 20.964, unit = "deg" }
height = 400.0

[initial_state.law]
name = "nadir"
yaw_steering = "zero_doppler"

[[events]]
type = "mode_change"
offset = 600.0
law = { name = "sun", axis = "-z", constraint_axis = "+x", constraint = "orbit_normal" }
[events.slew]
max_rate = { value = 1.0, unit = "deg/s" }
max_acceleration = { value = 0.05, unit = "deg/s2" }

[[events]]
type = "control_loss"
offset = 1200.0
wheels = { case = "spinning", momentum = [0.0, 2.0, 0.0] }

[output]
duration = 1800.0
step = 10.0
formats = ["csv"]
"""

SUN_LAW = 'law = { name = "sun", axis = "-z", constraint_axis = "+x", constraint = "orbit_normal" }'


def _replace(old: str, new: str, text: str = BASE) -> str:
    assert old in text, old
    return text.replace(old, new, 1)


def _apparent_sun_at(seconds: float) -> list[float]:
    """The apparent Sun from the spacecraft at ``seconds`` (ICRF unit vector)."""
    bound = SunLaw("+z", "+x").bind(EPOCH, 0.0, 1800.0, ORBIT)
    return bound.state([seconds]).attitude[0].apply([0.0, 0.0, 1.0]).tolist()


# Each case: the file, the key that holds the bad value (InputError.key, as data), and
# the reason the line gives.
REFUSED = {
    "parallel body vectors": (
        _replace(
            SUN_LAW,
            'law = { name = "align_constrain", primary_axis = "+x", primary = "sun", '
            'secondary_axis = "-x", secondary = "orbit_normal" }',
        ),
        "events[0].law",
        r"align_constrain: the primary and secondary body vectors are parallel",
    ),
    "the same direction twice": (
        _replace(
            SUN_LAW,
            'law = { name = "align_constrain", primary_axis = "+x", primary = "nadir", '
            'secondary_axis = "+y", secondary = "-nadir" }',
        ),
        "events[0].law",
        r"cannot make a pair: they are opposite",
    ),
    "directions parallel during the run": (
        _replace(
            SUN_LAW,
            'law = { name = "align_constrain", primary_axis = "+x", primary = "sun", '
            f'secondary_axis = "+y", secondary = {_apparent_sun_at(900.0)!r} }}',
        ),
        "events[0].law",
        r"the align_constrain law is undefined at 2025-05-01T10:1[45]:.* UTC \(t = 9\d\d\.\d* s\): "
        r".* come within .* rad of each other",
    ),
    "a slew that cannot end before the next event": (
        _replace("offset = 1200.0", "offset = 650.0"),
        "events[0].slew",
        r"the slew of 1\d\d\.\d deg from .* takes \d+\.?\d* s .* after the next event, "
        r"events\[1\] at 2025-05-01T10:10:50",
    ),
    "a resume onto a law faster than the slew's limit": (
        _replace(
            "[output]",
            '[[events]]\ntype = "control_resume"\noffset = 1500.0\nlaw = { name = "nadir" }\n'
            'slew = { max_rate = { value = 0.01, unit = "deg/s" }, max_acceleration = '
            '{ value = 0.05, unit = "deg/s2" } }\n\n[output]',
        ),
        "events[2].slew.max_rate",
        r"the target law itself turns at up to 0\.06\d* deg/s, beyond max_rate 0\.01 deg/s: "
        r"no slew within it can join the law; give a larger max_rate",
    ),
    "a resume from a tumble too fast to capture": (
        _replace(
            "[output]",
            '[[events]]\ntype = "control_resume"\noffset = 1500.0\nlaw = { name = "nadir" }\n'
            'slew = { max_rate = { value = 0.15, unit = "deg/s" }, max_acceleration = '
            '{ value = 0.05, unit = "deg/s2" } }\n\n[output]',
            _replace(
                'case = "spinning", momentum = [0.0, 2.0, 0.0]',
                'case = "locked", momentum = [0.5, 2.0, 1.0]',
            ),
        ),
        "events[2].slew.max_rate",
        r"the body turns at 0\.1\d* deg/s relative to the target law, which turns at up to "
        r"0\.06\d* deg/s: max_rate 0\.15 deg/s cannot capture it; give a larger max_rate",
    ),
    "absurd wheel momentum": (
        _replace("momentum = [0.0, 2.0, 0.0]", "momentum = [0.0, 2.0e7, 0.0]"),
        "events[1].wheels.momentum",
        r"\[0\.0, 20000000\.0, 0\.0\] N m s would turn the body at 1\.92e\+04 rad/s .*no "
        r"reaction wheel holds that much",
    ),
    "spinning wheels for a century": (
        _replace("duration = 1800.0", "duration = 3.0e9"),
        "events[1].wheels",
        r"the state after the control_loss at .*: choosing the gyrostat's step for 1e-07 rad "
        r"over its 3e\+09 s would start at 408 s, 7\.35e\+06 steps a try \(at most 200000\): "
        r"give \[torques\] step, or a shorter span",
    ),
    "wheel momentum beyond floats": (
        _replace("momentum = [0.0, 2.0, 0.0]", "momentum = [0.0, 1e400, 0.0]"),
        "events[1].wheels.momentum",
        r"expected finite numbers, got \[0\.0, inf, 0\.0\]",
    ),
    "a law that needs an orbit without one": (
        re.sub(r"(?s)\[pointing\.keplerian\].*?j2 = true\n", "", BASE),
        "initial_state.law",
        r"the nadir law \(\+z on geodetic nadir, zero-Doppler yaw steering\) needs an orbit .* "
        r"and the scenario has none",
    ),
    "a mode change while control is lost": (
        _replace(
            "[output]",
            f'[[events]]\ntype = "mode_change"\noffset = 1500.0\n{SUN_LAW}\n\n[output]',
        ),
        "events[2]",
        r"the mode_change at .*: no law holds the attitude there \(since the control_loss at "
        r"2025-05-01T10:20:00\.000000000 UTC\): use control_resume to give the body a law",
    ),
    "a mode change on a body that starts free": (
        _replace(
            '[initial_state.law]\nname = "nadir"\nyaw_steering = "zero_doppler"',
            "[initial_state]\nquaternion = [1.0, 0.0, 0.0, 0.0]\n"
            "angular_velocity = [0.0, 0.001, 0.0]",
        ),
        "events[0]",
        r"the mode_change at .*: no law holds the attitude there \(from the epoch: "
        r"\[initial_state\] gives no law\): use control_resume to give the body a law",
    ),
    "a control loss on a body that starts free": (
        re.sub(
            r"(?s)\[\[events\]\]\ntype = \"mode_change\".*?deg/s2\" \}\n\n",
            "",
            _replace(
                '[initial_state.law]\nname = "nadir"\nyaw_steering = "zero_doppler"',
                "[initial_state]\nquaternion = [1.0, 0.0, 0.0, 0.0]\n"
                "angular_velocity = [0.0, 0.001, 0.0]",
            ),
        ),
        "events[0]",
        r"the control_loss at .*: no law holds the attitude there \(from the epoch: "
        r"\[initial_state\] gives no law\): control is already lost",
    ),
    "a resume under a law": (
        _replace(
            'type = "control_loss"', 'type = "control_resume"\nlaw = { name = "nadir" }'
        ).replace('wheels = { case = "spinning", momentum = [0.0, 2.0, 0.0] }\n', ""),
        "events[1]",
        r"the control_resume at .*: control is not lost there",
    ),
    "an impulse under a law": (
        _replace(
            "[output]",
            '[[events]]\ntype = "angular_impulse"\noffset = 300.0\nimpulse = [0.1, 0.0, 0.0]'
            "\n\n[output]",
        ),
        "events[2]",
        r"the angular_impulse at .*: an angular_impulse needs a free body, and a law holds the "
        r"attitude there",
    ),
    "an unknown law": (
        _replace('name = "nadir"\nyaw', 'name = "nadirr"\nyaw'),
        "initial_state.law.name",
        r"expected one of inertial, orbit_frame, nadir, sun, target, align_constrain, got 'nadirr'",
    ),
    "an unknown site": (
        _replace(SUN_LAW, 'law = { name = "target", target = "kourou" }'),
        "events[0].law.target",
        r"unknown direction 'kourou'",
    ),
    "a key of another law": (
        _replace('yaw_steering = "zero_doppler"', 'yaw_steering = "zero_doppler"\naxis = "+x"'),
        "initial_state.law.axis",
        r"unknown key; expected one of: name, yaw_steering, vertical, phasing_axis",
    ),
    "a law beside an attitude": (
        _replace(
            "[initial_state.law]",
            "[initial_state]\nquaternion = [1.0, 0.0, 0.0, 0.0]\n[initial_state.law]",
        ),
        "initial_state",
        r"give \[initial_state\.law\] alone",
    ),
    "a slew without its acceleration": (
        _replace('max_acceleration = { value = 0.05, unit = "deg/s2" }\n', ""),
        "events[0].slew.max_acceleration",
        r"missing key",
    ),
    "a slew acceleration in deg/s": (
        _replace('unit = "deg/s2"', 'unit = "deg/s"'),
        "events[0].slew.max_acceleration",
        r"unit 'deg / s' cannot be converted",
    ),
    "a negative slew rate": (
        _replace('value = 1.0, unit = "deg/s" }', 'value = -1.0, unit = "deg/s" }'),
        "events[0].slew.max_rate",
        r"must be positive",
    ),
    "wheels of no known case": (
        _replace('case = "spinning"', 'case = "coasting"'),
        "events[1].wheels.case",
        r"expected one of locked, spinning, got 'coasting'",
    ),
    "a site named like a direction": (
        _replace('name = "kiruna"', 'name = "sun"'),
        "sites[0].name",
        r"expected a name that is not a direction's",
    ),
    "a site beyond the pole": (
        _replace("value = 67.857", "value = 97.857"),
        "sites[0].latitude",
        r"must be between -90 and 90 deg, got 97\.857 deg",
    ),
}


def _library_error(path, monkeypatch) -> InputError | None:
    """The error the library raises on the path check and run take, with every
    InputError's text unreadable meanwhile: a key parsed out of a message would show."""
    with warnings.catch_warnings(), monkeypatch.context() as patch:
        warnings.simplefilter("ignore")
        patch.setattr(InputError, "__str__", lambda self: "UNREAD")
        try:
            loaded = load_scenario(path)
            plan_run(loaded.scenario, loaded.pointing, loaded.outputs, horizon=False)
        except InputError as exc:
            return exc
    return None


@pytest.mark.parametrize("case", sorted(REFUSED))
def test_refused_in_one_line_by_check_and_run(case, tmp_path, capsys, monkeypatch):
    text, key, reason = REFUSED[case]
    path = tmp_path / "guided.toml"
    path.write_text(text)
    out = tmp_path / "out"
    for command in ("check", "run"):
        argv = [command, str(path)] + (["--out", str(out)] if command == "run" else [])
        assert main(argv) == 2, case
        lines = said(capsys.readouterr().err)
        assert len(lines) == 1, lines
        assert lines[0].startswith(f"attitude: error: guided.toml: {key}: "), lines
        assert re.search(reason, lines[0]), lines
    assert not out.exists()
    error = _library_error(path, monkeypatch)
    assert error is not None and error.key == key, (error and error.key, key)
    assert "UNREAD" not in error.reason, error.reason


def test_a_site_at_the_pole_is_tracked(tmp_path, capsys):
    text = _replace("value = 67.857", "value = 90.0")
    text = _replace(SUN_LAW, 'law = { name = "target", target = "kiruna" }', text)
    path = tmp_path / "pole.toml"
    path.write_text(text)
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    target = [s for s in summary["guidance"]["segments"] if s.get("law") == "target"]
    assert target and all(np.isfinite(s["rate_bound_deg_s"]) for s in target)
    assert any(s["ground_site_passes"] for s in target if "ground_site_passes" in s)


def test_a_target_that_never_rises_is_stated(tmp_path, capsys):
    # Kiruna is below the horizon from 10:00 to 10:15 (it rises at about 10:22).
    text = _replace("offset = 600.0", "offset = 120.0")
    text = _replace(SUN_LAW, 'law = { name = "target", target = "kiruna" }', text)
    text = _replace("offset = 1200.0", "offset = 900.0", text)
    path = tmp_path / "below.toml"
    path.write_text(text)
    assert main(["check", str(path)]) == 0
    shown = capsys.readouterr().out
    assert re.search(r"note +events\[0\]\.law: kiruna never rises above the horizon between", shown)
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    notes = summary["guidance"]["notes"]
    assert any("kiruna never rises above the horizon" in note for note in notes), notes
    target = [s for s in summary["guidance"]["segments"] if s.get("law") == "target"]
    assert [s["ground_site_visible"] for s in target if "ground_site_visible" in s] == [False]
    assert math.isfinite(target[-1]["rate_bound_deg_s"])


def test_the_hand_off_refuses_absurd_wheel_momentum_in_python():
    # The functions the envelope calls refuse what a scenario's control_loss refuses:
    # 2e7 N m s about y would turn the body at 1.9e4 rad/s (|I⁻¹h|).
    from scipy.spatial.transform import Rotation

    from attitude import Wheels, hand_off, hand_off_states

    inertia = [820.0, 1040.0, 610.0]
    for case in ("locked", "spinning"):
        wheels = Wheels(case, [0.0, 2.0e7, 0.0])
        with pytest.raises(InputError, match=r"1\.92e\+04 rad/s .*no reaction wheel") as caught:
            hand_off(Rotation.identity(), [0.0, 1e-3, 0.0], inertia, wheels=wheels)
        assert caught.value.key == "wheels.momentum"
        bound = SunLaw("+z", "+x").bind(Time("2025-05-01T10:00:00", scale="utc"), 0.0, 60.0, None)
        with pytest.raises(InputError, match=r"no reaction wheel") as caught:
            hand_off_states(bound.state([0.0, 30.0]), inertia, wheels)
        assert caught.value.key == "wheels.momentum"
