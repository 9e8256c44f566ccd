"""`attitude check` refuses whatever `attitude run` refuses, with the same one line.

Both go through one path up to the sampling (attitude.report.plan).  Each file below
was accepted by `check` and refused by `run` after computing, or crashed `run` with a
traceback: a bad TLE, an epoch outside the ephemeris (with the margins the pointing
adds), a far TLE epoch, wrong types, absurd magnitudes, outputs that cannot fit on
any disk.  Each now gives exit 2 and the same message from both, naming the file and
the key, before anything is written.  The disk is the one thing `check` can only
check with the folder, `check --out DIR`: those cases are run that way.
"""

import json
import re
from pathlib import Path

import pytest
from cli_lines import said

from attitude.cli.main import main

BASE = """
[scenario]
name = "base"
epoch = "2027-06-21T00:00:00"

[spacecraft]
name = "sat"
principal_moments = [10.0, 20.0, 25.0]

[initial_state]
quaternion = [1.0, 0.0, 0.0, 0.0]
angular_velocity = [0.01, 0.2, 0.01]

[[events]]
type = "angular_impulse"
offset = 5.0
impulse = [0.1, 0.0, 0.0]

[output]
duration = 10.0
step = 1.0
"""

LINE1 = "1 59001U 27042A   27171.50000000  .00000120  00000-0  18000-4 0  9999"
LINE2 = "2 59001  98.2100 175.3000 0012000  95.0000 265.2000 14.57123456    14"

POINTING = """
[pointing]
tle = ["{line1}", "{line2}"]

[[pointing.body_vectors]]
name = "tracker"
vector = [0.0, 0.0, 1.0]
sun_exclusion_half_angle = {{ value = 30, unit = "deg" }}
"""


EARTH_CENTRE = '\n[pointing]\n[[pointing.body_vectors]]\nname = "x"\nvector = [1.0, 0.0, 0.0]\n'


def _checksum(line: str) -> str:
    """A TLE line with its checksum recomputed (digits, and 1 for each minus sign)."""
    body = line[:68]
    total = sum(int(c) for c in body if c.isdigit()) + body.count("-")
    return body + str(total % 10)


def _with_tle(line1: str = LINE1, line2: str = LINE2, text: str = BASE) -> str:
    return text + POINTING.format(line1=line1, line2=line2)


def _replace(old: str, new: str, text: str = BASE) -> str:
    assert old in text, old
    return text.replace(old, new, 1)


def _epoch(epoch: str, duration: float = 10.0) -> str:
    text = _replace('epoch = "2027-06-21T00:00:00"', f'epoch = "{epoch}"\ntime_scale = "tdb"')
    return _replace("duration = 10.0", f"duration = {duration!r}", text)


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

BURN = "[[torques.burns]]\noffset = 1.0\nduration = 2.0\ntorque = [0.0, 0.0, 0.01]\n"


def _torques(table: str, burn: str = "", orbit: bool = True) -> str:
    """BASE with a [torques] table (and a burn), on a Keplerian orbit unless not."""
    return BASE + "\n[torques]\n" + table + "\n" + burn + (KEPLERIAN if orbit else "")


BAD = {
    # [torques]: every value a hostile user could write.
    "burn: negative duration": (
        _torques("", BURN.replace("duration = 2.0", "duration = -5.0")),
        r"torques\.burns\[0\]\.duration: must be positive, got -5\.0",
    ),
    "burn: NaN duration": (
        _torques("", BURN.replace("duration = 2.0", "duration = nan")),
        r"torques\.burns\[0\]\.duration: expected finite numbers, got nan",
    ),
    "burn: 10**400 s": (
        _torques("", BURN.replace("duration = 2.0", "duration = 1" + "0" * 400)),
        r"torques\.burns\[0\]\.duration: a number is beyond the float range",
    ),
    "burn: a torque whose impulse squared overflows": (
        _torques("", BURN.replace("[0.0, 0.0, 0.01]", "[1e300, 0.0, 0.0]")),
        r"torques\.burns\[0\]\.torque: \[1e\+300, 0\.0, 0\.0\] N m over the span is an "
        r"angular impulse of 2e\+300 N m s, beyond what floats hold",
    ),
    "burn: a torque that spins the body beyond what TT seconds follow": (
        _torques("step = 1.0", BURN.replace("[0.0, 0.0, 0.01]", "[1e150, 0.0, 0.0]")),
        r"torques\.burns\[0\]\.torque: the torques spin the body up to 1e\+149 rad/s or "
        r"more .* faster than float seconds can follow",
    ),
    "burn: the same with the step chosen for an accuracy": (
        _torques("", BURN.replace("[0.0, 0.0, 0.01]", "[1e150, 0.0, 0.0]")),
        r"torques\.burns\[0\]\.torque: the burns spin the body up to 2e\+149 rad/s \(this one "
        r"adds 2e\+150 N m s\): 1e-06 rad over 10 s would need a step below 3\.93e-150 s, "
        r"more than 1e\+07 steps: give a smaller torque",
    ),
    "burn: after the span": (
        _torques("", BURN.replace("offset = 1.0", "offset = 10.0")),
        r"torques\.burns\[0\]\.offset: the burn starts at 2027-06-21T00:00:10\.000000000 UTC, "
        r"outside the span",
    ),
    "burn: a string torque": (
        _torques("", BURN.replace("[0.0, 0.0, 0.01]", '"0.01"')),
        r"torques\.burns\[0\]\.torque: expected 3 numbers, got '0\.01'",
    ),
    "burn: no torque": (
        _torques("", BURN.replace("torque = [0.0, 0.0, 0.01]\n", "")),
        r"torques\.burns\[0\]\.torque: missing key",
    ),
    "burn: unknown frame": (
        _torques("", BURN + 'frame = "lvlh"\n'),
        r"torques\.burns\[0\]\.frame: expected one of body, inertial, got 'lvlh'",
    ),
    "torques: step and accuracy": (
        _torques('step = 1.0\naccuracy = { value = 1e-6, unit = "rad" }', BURN),
        r"torques: give step or accuracy, not both",
    ),
    "torques: unknown key": (
        _torques("gravity_gradiant = true", BURN),
        r"torques\.gravity_gradiant: unknown key; expected one of: gravity_gradient, ",
    ),
    "torques: gravity gradient without an orbit": (
        _torques("gravity_gradient = true", orbit=False),
        r"torques\.gravity_gradient: gravity gradient needs an orbit",
    ),
    "torques: gravity gradient as a string": (
        _torques('gravity_gradient = "yes"'),
        r"torques\.gravity_gradient: expected true or false, got 'yes'",
    ),
    "torques: order 3": (
        _torques("order = 3", BURN),
        r"torques\.order: expected 2, 4 or 6 \(the splitting's order\), got 3",
    ),
    "torques: order 4.0": (
        _torques("order = 4.0", BURN),
        r"torques\.order: expected 2, 4 or 6",
    ),
    "torques: accuracy without its unit": (
        _torques("accuracy = 1e-6", BURN),
        r"torques\.accuracy: an angle needs its unit",
    ),
    "torques: accuracy of 0 rad": (
        _torques('accuracy = { value = 0.0, unit = "rad" }', BURN),
        r"torques\.accuracy: must be between 1e-12 and 0\.1 rad, got 0\.0 rad",
    ),
    "torques: step longer than the span": (
        _torques("step = 1e9", BURN),
        r"torques\.step: 1e\+09 s is longer than the span \(10 s\)",
    ),
    "torques: 1e10 steps": (
        _torques("step = 1e-9", BURN),
        r"torques\.step: 1e-09 s is 1e\+10 steps over the span of 10 s, more than 1e\+07",
    ),
    "torques: an accuracy over 300 years": (
        _torques(
            'accuracy = { value = 1e-6, unit = "rad" }',
            BURN.replace("duration = 2.0", "duration = 1e10"),
        ).replace("duration = 10.0", "duration = 1e10"),
        r"torques\.accuracy: 1e-06 rad over 1e\+10 s would need a step below [\d.e+-]+ s, "
        r"more than 1e\+07 steps: give torques\.step",
    ),
    "torques: an accuracy for a burn that spins the body up to 1e8 rad/s": (
        _torques(
            'accuracy = { value = 1e-6, unit = "rad" }',
            BURN.replace("[0.0, 0.0, 0.01]", "[1e9, 0.0, 0.0]"),
        ),
        r"torques\.burns\[0\]\.torque: the burns spin the body up to 2e\+08 rad/s .*: 1e-06 "
        r"rad over 10 s would need a step below [\d.e+-]+ s, more than 1e\+07 steps: give a "
        r"smaller torque",
    ),
    "torques: negative step": (
        _torques("step = -1.0", BURN),
        r"torques\.step: must be positive, got -1\.0",
    ),
    "torques: horizon threshold of 200 deg": (
        _torques('horizon_threshold = { value = 200, unit = "deg" }'),
        r"torques\.horizon_threshold: must be between 0 and 180 deg, got 200\.0 deg",
    ),
    # The TLE: every error names the file and pointing.tle.
    "TLE checksum": (_with_tle(LINE1[:68] + "0"), r"pointing\.tle: line1: checksum"),
    "TLE short line": (_with_tle(LINE1, LINE2[:60]), r"pointing\.tle: line2 must have 69"),
    "TLE lines swapped": (_with_tle(LINE2, LINE1), r"pointing\.tle: line1 must start with '1 '"),
    "TLE non-numeric field": (
        _with_tle(LINE1, _checksum(LINE2[:52] + "14.5712x456" + LINE2[63:])),
        r"pointing\.tle: line2",
    ),
    "TLE eccentricity near 1": (
        _with_tle(LINE1, _checksum(LINE2[:26] + "9999999" + LINE2[33:])),
        r"pointing\.tle: .*SGP4",
    ),
    "TLE not ASCII": (_with_tle(LINE1[:20] + "é" + LINE1[21:]), r"pointing\.tle: line1 must be"),
    "TLE epoch decades away": (
        _with_tle(text=_replace("2027-06-21T00:00:00", "2047-06-21T00:00:00")),
        r"pointing\.tle: the span reaches \d+ days from the TLE's epoch",
    ),
    # The Sun ephemeris, DE421: 1899-07-29 to 2053-10-09 TDB.
    "epoch 1850": (
        _with_tle(text=_epoch("1850-01-01T00:00:00")),
        r"scenario\.epoch: the span .* outside the span of the DE421 ephemeris",
    ),
    "epoch 2060": (
        _with_tle(text=_epoch("2060-01-01T00:00:00")),
        r"scenario\.epoch: the span .* outside the span of the DE421 ephemeris",
    ),
    "span across 2053-10-09": (
        _with_tle(text=_epoch("2053-10-08T12:00:00", 2 * 86400.0)),
        r"output\.duration: the span .* outside the span of the DE421 ephemeris",
    ),
    # The epoch and the end are inside; the interpolation's nodes 10 min beyond are not.
    "ephemeris start within the margin": (
        _epoch("1899-07-29T00:15:00") + EARTH_CENTRE,
        r"scenario\.epoch: the span with its 600 s margins",
    ),
    "ephemeris end within the margin": (
        _epoch("2053-10-08T23:59:00", 50.0) + EARTH_CENTRE,
        r"output\.duration: the span with its 600 s margins",
    ),
    "year 10000": (
        _replace('epoch = "2027-06-21T00:00:00"', 'epoch = "9999-12-31T23:59:55"'),
        r"output\.duration: epochs must lie in the years 0001-9999",
    ),
    # Types: TOML booleans and strings are not numbers.
    "boolean moment": (
        _replace("[10.0, 20.0, 25.0]", "[true, 20.0, 25.0]"),
        r"spacecraft\.principal_moments: expected 3 numbers, got \[True, 20\.0, 25\.0\]",
    ),
    "string duration": (
        _replace("duration = 10.0", 'duration = "20"'),
        r"output\.duration: expected a number, got '20'",
    ),
    "string vector": (
        _replace("angular_velocity = [0.01, 0.2, 0.01]", 'angular_velocity = ["1", "2", "3"]'),
        r"initial_state\.angular_velocity: expected 3 numbers, got \['1', '2', '3'\]",
    ),
    # Magnitudes.
    "step 5e-324": (
        _replace("step = 1.0", "step = 5e-324"),
        r"output\.step: 4\.94066e-324 s is below what TT seconds resolve",
    ),
    # Streamed, a run holds a chunk whatever its span: only the disk can refuse these
    # (hundreds of terabytes: no disk holds them).
    "1e12 output epochs": (
        _replace("step = 1.0", "step = 1e-3", _replace("duration = 10.0", "duration = 1e9")),
        r"output\.step: 1000000000002 samples would take about [\d.]+ TB \(timeseries\.csv .*\), "
        r"and the disk of .* has",
    ),
    "1e11 output epochs": (
        _replace("step = 1.0", "step = 1e-2", _replace("duration = 10.0", "duration = 1e9")),
        r"output\.step: 100000000001 samples would take about [\d.]+ TB",
    ),
    "1e200 rad/s": (
        _replace("[0.01, 0.2, 0.01]", "[1e200, 1e200, 0]"),
        r"initial_state\.angular_velocity: the body turns in .* too fast for TT seconds",
    ),
    "1e200 rad/s after an event": (
        _replace("impulse = [0.1, 0.0, 0.0]", "impulse = [1e201, 0.0, 0.0]"),
        r"events\[0\]\.impulse: the state after the angular_impulse at .*: the body turns in",
    ),
}

# Refused by the disk: `check --out DIR` names DIR's, `check` alone the current folder's
# (where a relative --out goes), which it used to leave unchecked and say OK.
DISK = {"1e12 output epochs", "1e11 output epochs"}

BIG = "1" + "0" * 400  # 10**400, a valid TOML integer
BIG_KEYS = {
    "duration": ("duration = 10.0", f"duration = {BIG}"),
    "step": ("step = 1.0", f"step = {BIG}"),
    "offset": ("offset = 5.0", f"offset = {BIG}"),
    "principal_moments": ("[10.0, 20.0, 25.0]", f"[{BIG}, 20.0, 25.0]"),
    "angular_velocity": ("[0.01, 0.2, 0.01]", f"[0.01, {BIG}, 0.01]"),
    "impulse": ("[0.1, 0.0, 0.0]", f"[0.1, 0.0, -{BIG}]"),
    "quaternion": ("[1.0, 0.0, 0.0, 0.0]", f"[{BIG}, 0.0, 0.0, 0.0]"),
}
for _key, (_old, _new) in BIG_KEYS.items():
    BAD[f"10**400 as {_key}"] = (
        _replace(_old, _new),
        rf"[\w.\[\]]*\b{_key}: a number is beyond the float range",
    )


def _lines(capsys) -> list[str]:
    err = capsys.readouterr().err
    assert "Traceback" not in err
    return said(err)


@pytest.mark.parametrize("case", list(BAD))
def test_check_and_run_refuse_with_the_same_line(case, tmp_path, capsys):
    text, message = BAD[case]
    path = tmp_path / "bad.toml"
    path.write_text(text, encoding="utf-8")
    out = tmp_path / "out"
    for check in (["check", str(path)], ["check", str(path), "--out", str(out)]):
        assert main(check) == 2
        checked = _lines(capsys)
        assert len(checked) == 1, checked
        assert re.search(rf"^attitude: error: bad\.toml: {message}", checked[0]), checked[0]
        assert checked[0].count("bad.toml") == 1  # the file named once, not `x: x: key`
        if case in DISK:
            where = f"{out}" if "--out" in check else f"the current folder ({Path.cwd()})"
            assert f"and the disk of {where} has " in checked[0], checked[0]
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 2
    assert _lines(capsys) == checked
    assert not out.exists() and [p.name for p in tmp_path.iterdir()] == ["bad.toml"]


@pytest.mark.parametrize(
    ("data", "message"),
    [
        (b"\x00\x01\x02\xff\xfe binary \x89PNG", r"bad\.toml: not a TOML file: .* not UTF-8"),
        ("[scenario]\nname = 'x'\n".encode("utf-16"), r"bad\.toml: not a TOML file: .*UTF-16"),
        (b"a = " + b"[" * 100_000 + b"]" * 100_000, r"bad\.toml: not valid TOML"),
        (b"# " + b"x" * (2 << 20), r"bad\.toml: larger than 1024 KiB"),
    ],
    ids=["binary", "UTF-16", "nested 100000 deep", "2 MiB"],
)
def test_files_that_are_not_scenarios_are_refused_in_one_line(tmp_path, capsys, data, message):
    path = tmp_path / "bad.toml"
    path.write_bytes(data)
    for argv in (["check", str(path)], ["run", str(path), "--out", str(tmp_path / "o")]):
        assert main(argv) == 2
        lines = _lines(capsys)
        assert len(lines) == 1 and re.search(message, lines[0]), lines


def test_year_0001_runs_and_is_written_with_four_digits(tmp_path, capsys):
    path = tmp_path / "old.toml"
    path.write_text(_replace('epoch = "2027-06-21T00:00:00"', 'epoch = "0001-03-01T12:00:00"'))
    assert main(["check", str(path)]) == 0
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    aem = (tmp_path / "out" / "attitude.aem").read_text()
    assert "START_TIME = 0001-03-01T12:00:00.000000000" in aem
    csv = (tmp_path / "out" / "timeseries.csv").read_text()
    assert "\n0001-03-01T12:00:01.000000000," in csv


def test_a_precision_finer_than_time_resolves_is_clamped_and_said(tmp_path, capsys):
    """interval_precision = 1e-13 s: the bisection cannot get below an ulp, so the
    precision is clamped to what time resolves, and said."""
    text = _with_tle().replace("[pointing]\n", "[pointing]\ninterval_precision = 1e-13\n")
    path = tmp_path / "fine.toml"
    path.write_text(_replace("duration = 10.0", "duration = 600.0", text))
    assert main(["check", str(path)]) == 0
    out = capsys.readouterr().out
    assert re.search(r"note .*interval_precision 1e-13 s is finer than TT seconds resolve", out)
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    err = capsys.readouterr().err
    assert len(said(err)) == 1 and "attitude: note: fine.toml: pointing." in err
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["pointing"]["interval_precision_s"] == pytest.approx(2 * 1.1368683772161603e-13)


def test_a_far_tle_epoch_is_said(tmp_path, capsys):
    path = tmp_path / "far.toml"
    path.write_text(_with_tle(text=_replace("2027-06-21T00:00:00", "2027-09-21T00:00:00")))
    assert main(["check", str(path)]) == 0
    out = capsys.readouterr().out
    assert re.search(r"note +pointing\.tle: the span reaches 9\d days from the TLE's epoch", out)


def test_check_states_the_samples_and_the_sizes(tmp_path, capsys):
    path = tmp_path / "ok.toml"
    path.write_text(_with_tle(text=_replace("duration = 10.0", "duration = 3600.0")))
    assert main(["check", str(path)]) == 0
    out = capsys.readouterr().out
    assert re.search(r"outputs +3601 samples; writes about [\d.]+ MB \(timeseries\.csv", out)
    assert "holds about" in out
    assert "Sun exclusion half angle 30 deg" in out  # angles echoed in degrees
    # Without --out, the disk a run writes to without a path: said, and checked.
    assert re.search(r"disk +[\d.]+ [kMGT]?B free on the current folder's disk", out), out


def test_check_with_out_refuses_what_run_would(tmp_path, capsys):
    path = tmp_path / "ok.toml"
    path.write_text(BASE)
    assert main(["check", str(path), "--out", str(tmp_path)]) == 2
    assert "did not write" in capsys.readouterr().err
    assert main(["check", str(path), "--out", str(tmp_path / "new")]) == 0
    assert not (tmp_path / "new").exists()  # check creates nothing


def test_every_run_error_names_the_file_and_the_key(tmp_path, capsys):
    """Errors raised after loading (the TLE, the solver, the budget) name both too."""
    for case in ("TLE lines swapped", "1e200 rad/s", "1e11 output epochs", "epoch 2060"):
        path = tmp_path / "bad.toml"
        path.write_text(BAD[case][0], encoding="utf-8")
        assert main(["run", str(path), "--out", str(tmp_path / "o"), "--quiet"]) == 2
        line = capsys.readouterr().err
        assert re.match(
            r"attitude: error: bad\.toml: "
            r"(pointing\.tle|initial_state\.angular_velocity|output\.step|scenario\.epoch): ",
            line,
        )


def test_run_refuses_a_runaway_burn_as_check_does_before_propagating_it(
    tmp_path, capsys, monkeypatch
):
    """A burn that spins the body up to 1.5e5 rad/s, with an accuracy and the AEM: check
    refuses it from its motion within its budget (1 ns time tags cannot hold that
    rate); run searched the step over the whole span first (41 s of CPU on this 10 s
    span, minutes over a longer one), then refused with the same line.  Run takes check's path as
    far as check's budget goes, and refuses there: the full propagation never starts."""
    import attitude.report.plan as plan_module
    import attitude.trajectory.trajectory as trajectory_module

    monkeypatch.setattr(trajectory_module, "CHECK_BUDGET_S", 0.5)  # check's, shorter: faster
    text = BASE + (
        '\n[torques]\naccuracy = { value = 1e-6, unit = "rad" }\n'
        "\n[[torques.burns]]\noffset = 1.0\nduration = 5.0\ntorque = [0.0, 0.0, 1e5]\n"
    )
    path = tmp_path / "bad.toml"
    path.write_text(text, encoding="utf-8")
    asked = []
    propagate = plan_module.propagate

    def recorded(scenario, *args, check=False, **kwargs):
        asked.append(check)
        return propagate(scenario, *args, check=check, **kwargs)

    monkeypatch.setattr(plan_module, "propagate", recorded)
    lines = []
    for command in ("check", "run"):
        argv = [command, str(path), "--formats", "csv,aem"]
        code = main(
            argv + (["--out", str(tmp_path / "out"), "--quiet"] if command == "run" else [])
        )
        assert code == 2
        lines.append(_lines(capsys))
    assert lines[0] == lines[1] and len(lines[0]) == 1, lines
    assert "1 ns time tag" in lines[0][0] and "torques.burns[0].torque" in lines[0][0]
    assert asked == [True, True]  # check's path, twice; never the run's whole propagation
