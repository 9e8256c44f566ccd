"""Bad scenario files: one clear message each, naming the file, the key and the value.

Through the command line: exit status 2, the message on stderr, no traceback, and
no output folder left behind (nor an old one damaged).
"""

import re

import pytest

import attitude.report.run
from attitude.cli.main import main

VALID = """
[scenario]
name = "valid"
epoch = "2027-03-01T12:00:00"

[spacecraft]
name = "sat"
principal_moments = [10.0, 20.0, 25.0]

[initial_state]
quaternion = [1.0, 0.0, 0.0, 0.0]
angular_velocity = [0.01, 0.2, 0.01]

[[events]]
type = "angular_impulse"
offset = 30.0
impulse = [0.0, 0.0, 1.0]

[output]
duration = 100.0
step = 1.0
"""


def _replace(old, new):
    assert old in VALID, old
    return VALID.replace(old, new, 1)


BAD = {
    "missing table": (
        VALID.replace('[spacecraft]\nname = "sat"\nprincipal_moments = [10.0, 20.0, 25.0]\n', ""),
        r"bad\.toml: spacecraft: missing table$",
    ),
    "missing key": (
        _replace('epoch = "2027-03-01T12:00:00"\n', ""),
        r"bad\.toml: scenario\.epoch: missing key",
    ),
    "unknown key": (
        _replace("angular_velocity =", "angualr_velocity ="),
        r"bad\.toml: initial_state\.angualr_velocity: unknown key; expected one of: quaternion",
    ),
    "wrong unit": (
        _replace(
            "angular_velocity = [0.01, 0.2, 0.01]",
            'angular_velocity = { value = [1, 2, 3], unit = "m" }',
        ),
        r"bad\.toml: initial_state\.angular_velocity: unit 'm' cannot be converted to rad / s",
    ),
    "unknown unit": (
        _replace(
            "angular_velocity = [0.01, 0.2, 0.01]",
            'angular_velocity = { value = [1, 2, 3], unit = "rpmm" }',
        ),
        r"bad\.toml: initial_state\.angular_velocity: unit 'rpmm' cannot be converted",
    ),
    "wrong shape": (
        _replace("principal_moments = [10.0, 20.0, 25.0]", "principal_moments = [10.0, 20.0]"),
        r"bad\.toml: spacecraft\.principal_moments: expected 3 numbers, got \[10\.0, 20\.0\]",
    ),
    "not numbers": (
        _replace("impulse = [0.0, 0.0, 1.0]", 'impulse = ["a", 0.0, 1.0]'),
        r"bad\.toml: events\[0\]\.impulse: expected 3 numbers, got \['a', 0\.0, 1\.0\]",
    ),
    "unknown event type": (
        _replace('type = "angular_impulse"', 'type = "torque"'),
        r"bad\.toml: events\[0\]\.type: expected one of angular_impulse, inertia_change, "
        r"attitude_reset, mode_change, control_loss, control_resume, got 'torque'",
    ),
    "non-finite number": (
        _replace("impulse = [0.0, 0.0, 1.0]", "impulse = [nan, 0.0, 1.0]"),
        r"bad\.toml: events\[0\]\.impulse: expected finite numbers, got \[nan, 0\.0, 1\.0\]",
    ),
    "infinite duration": (
        _replace("duration = 100.0", "duration = inf"),
        r"bad\.toml: output\.duration: expected finite numbers, got inf",
    ),
    "event out of span": (
        _replace("offset = 30.0", "offset = 500.0"),
        r"bad\.toml: events\[0\]\.offset: the angular_impulse at 2027-03-01T12:08:20\.000000000 "
        r"UTC is after the end of the propagation span 2027-03-01T12:01:40\.000000000 UTC",
    ),
    "event before the epoch": (
        _replace("offset = 30.0", 'epoch = "2027-03-01T11:00:00"'),
        r"bad\.toml: events\[0\]\.epoch: the angular_impulse at 2027-03-01T11:00:00\.000000000 "
        r"UTC is before the scenario epoch",
    ),
    "bad epoch": (
        _replace('epoch = "2027-03-01T12:00:00"', 'epoch = "2027-13-45T12:00:00"'),
        r"bad\.toml: scenario\.epoch: not an ISO 8601 epoch: '2027-13-45T12:00:00' \(bad month\)",
    ),
    "bad time scale": (
        _replace('name = "valid"', 'name = "valid"\ntime_scale = "gps"'),
        r"bad\.toml: scenario\.time_scale: expected one of utc, tt, tai, tdb, tcg, tcb, got 'gps'",
    ),
    "not a unit quaternion": (
        _replace("quaternion = [1.0, 0.0, 0.0, 0.0]", "quaternion = [1.0, 1.0, 0.0, 0.0]"),
        r"bad\.toml: initial_state\.quaternion: quaternion must have unit norm, "
        r"got \|q\| = 1\.41421356",
    ),
    "asymmetric tensor": (
        _replace(
            "principal_moments = [10.0, 20.0, 25.0]",
            "inertia_tensor = [[10.0, 1.0, 0.0], [0.0, 20.0, 0.0], [0.0, 0.0, 25.0]]",
        ),
        r"bad\.toml: spacecraft\.inertia_tensor: tensor is not symmetric",
    ),
    "negative step": (
        _replace("step = 1.0", "step = -1.0"),
        r"bad\.toml: output\.step: must be positive, got -1\.0",
    ),
    "stop and duration": (
        _replace("duration = 100.0", 'duration = 100.0\nstop = "2027-03-01T13:00:00"'),
        r"bad\.toml: output: give exactly one of stop \(ISO 8601\) and duration \(seconds\)",
    ),
    "rate missing": (
        _replace("angular_velocity = [0.01, 0.2, 0.01]\n", ""),
        r"bad\.toml: initial_state: missing angular_velocity \(rad/s\) "
        r"or angular_momentum \(N m s\)",
    ),
    "not toml": ("this is = = not toml", r"bad\.toml: not valid TOML"),
}


@pytest.mark.parametrize("case", list(BAD))
def test_bad_file_gives_one_clear_message(case, tmp_path, capsys):
    text, message = BAD[case]
    path = tmp_path / "bad.toml"
    path.write_text(text)
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if line.startswith("attitude: error:")]
    assert len(lines) == 1, err
    assert "Traceback" not in err
    assert re.search(message, lines[0]), lines[0]
    assert not out.exists()
    assert list(tmp_path.iterdir()) == [path]
    # `attitude check` says the same.
    assert main(["check", str(path)]) == 2
    assert lines[0] in capsys.readouterr().err


def test_missing_file(tmp_path, capsys):
    assert main(["check", str(tmp_path / "nowhere.toml")]) == 2
    assert "nowhere.toml: cannot read: No such file or directory" in capsys.readouterr().err


def test_the_valid_base_file_runs(tmp_path):
    path = tmp_path / "valid.toml"
    path.write_text(VALID)
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    assert (tmp_path / "out" / "timeseries.csv").exists()


def test_a_failed_run_leaves_no_output_and_keeps_the_old_one(tmp_path, monkeypatch, capsys):
    path = tmp_path / "valid.toml"
    path.write_text(VALID)
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}

    def fail(*args, **kwargs):
        raise OSError("disk full")

    monkeypatch.setattr(attitude.report.run, "write_json", fail)
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 1
    assert (
        f"attitude: error: --out {out}: the outputs could not be written (disk full)"
        in capsys.readouterr().err
    )
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out", "valid.toml"]
    # And into a new folder: nothing at all.
    assert main(["run", str(path), "--out", str(tmp_path / "new"), "--quiet"]) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out", "valid.toml"]


@pytest.mark.parametrize(
    ("old", "new", "key", "value"),
    [
        ("duration = 100.0", "duration = -5.0", "output.duration", -5.0),
        ('name = "sat"', 'name = " "', "spacecraft.name", " "),
        ("impulse = [0.0, 0.0, 1.0]", 'impulse = "1"', "events[0].impulse", "1"),
        ('epoch = "2027-03-01T12:00:00"', 'epoch = "2027-03-01T12:00:60"', "scenario.epoch", None),
    ],
    ids=["duration", "name", "impulse", "epoch"],
)
def test_the_error_carries_its_key_file_and_value_as_data(tmp_path, old, new, key, value):
    """The line a user reads is the data joined, ``file: key: reason``; the data is kept
    across pickling, as Dask and the process beside a run send an error."""
    import pickle

    from attitude.files.scenario_reader import ScenarioFileError, load_scenario

    path = tmp_path / "bad.toml"
    path.write_text(_replace(old, new))
    with pytest.raises(ScenarioFileError) as caught:
        load_scenario(path)
    error = caught.value
    assert (error.file, error.key) == ("bad.toml", key)
    if value is not None:
        assert error.value == value
    assert str(error) == f"bad.toml: {key}: {error.reason}"
    again = pickle.loads(pickle.dumps(error))
    assert type(again) is ScenarioFileError and str(again) == str(error)
    assert (again.file, again.key, again.reason) == (error.file, error.key, error.reason)
