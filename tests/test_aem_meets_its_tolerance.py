"""The AEM of a run, interpolated as its metadata declares, stays within the tolerance.

Each scenario is run through ``attitude run --formats aem``; the file is read back by
the independent parser ccsds-ndm-py (``aem_read_back``), and every segment is
interpolated the way it declares (LAGRANGE of its INTERPOLATION_DEGREE over the
records centred on the interval, Neville's recurrence written in the test, apart
from the package's own reading) at every mid-step and at the quarter steps of the
first and last intervals, where the window is off-centre.  The authority is the exact
attitude of the propagated scenario at those instants.  The records themselves must
be the exact attitude at their epochs, to what a time tag rounded to 1 ns allows
(|ω| × 0.5 ns, and the 1e-12 s class of TT seconds computed from texts).
"""

import json
import re
from pathlib import Path

import numpy as np
import pytest
from aem_read_back import interpolate_as_declared, read_back, rotation_angle
from cli_lines import said

from attitude.cli.main import main
from attitude.environment.timescales import tt_seconds
from attitude.files.scenario_reader import load_scenario
from attitude.trajectory.trajectory import propagate

ROOT = Path(__file__).parents[1]

# (file, text substitutions): short spans of the examples, every kind of motion.
CASES = {
    "spinner with its pulse": (
        "scenarios/spinner_thruster_pulse.toml",
        {r"(?m)^duration = .*$": "duration = 1800.0", r"(?m)^step = .*$": "step = 10.0"},
    ),
    "T-handle flips": ("scenarios/dzhanibekov_t_handle.toml", {}),
    "boom deployment": ("scenarios/boom_deployment.toml", {}),
    "Envisat-like tumble": (
        "scenarios/tumbling_defunct_satellite.toml",
        {r"(?m)^duration = .*$": "duration = 20000.0"},
    ),
    "separatrix": ("tests/hostile/separatrix.toml", {}),
    "separatrix after a reset": ("tests/hostile/separatrix_after_reset.toml", {}),
    "sphere": ("tests/hostile/sphere.toml", {}),
    "rest": ("tests/hostile/rest.toml", {}),
    "across a leap second, UTC": (
        "scenarios/dzhanibekov_t_handle.toml",
        {r'(?m)^epoch = ".*"$': 'epoch = "2016-12-31T23:59:50"'},
    ),
    "TDB": ("scenarios/boom_deployment.toml", {r'(?m)^time_scale = "tt"$': 'time_scale = "tdb"'}),
}


def _scenario(tmp_path: Path, case: str) -> Path:
    source, changes = CASES[case]
    text = (ROOT / source).read_text()
    for pattern, replacement in changes.items():
        text, count = re.subn(pattern, replacement, text, count=1)
        assert count == 1, (case, pattern)
    path = tmp_path / "scenario.toml"
    path.write_text(text)
    return path


def _errors(out: Path, path: Path):
    """(largest error at the mid-steps, at the end quarter steps, and of the records
    beyond what their 1 ns time tags explain), rad."""
    loaded = load_scenario(path)
    trajectory = propagate(loaded.scenario)
    epoch = loaded.scenario.epoch
    segments, _ = read_back(out / "attitude.aem")
    mid = ends = records = 0.0
    for segment in segments:
        x = tt_seconds(segment.times, epoch)
        exact = trajectory.attitude_quaternion(np.clip(x, 0.0, loaded.scenario.stop_s))
        # A record at an event's epoch is the segment's own (pre-event) state there.
        inside = (x > x[0]) & (x < x[-1])
        rate = np.linalg.norm(segment.angular_velocity_body_rad_s[inside], axis=1)
        off = rotation_angle(
            segment.quaternion_body_to_inertial_scalar_first[inside], exact[inside]
        )
        records = max(records, float(np.max(off - rate * 0.52e-9, initial=0.0)))
        if len(x) < 2:
            continue
        t_mid = 0.5 * (x[1:] + x[:-1])
        step = np.diff(x)
        t_ends = np.concatenate(
            [x[0] + step[0] * np.array([0.25, 0.75]), x[-2] + step[-1] * np.array([0.25, 0.75])]
        )
        for t, name in ((t_mid, "mid"), (t_ends, "ends")):
            error = float(
                np.max(
                    rotation_angle(
                        interpolate_as_declared(segment, t, epoch),
                        trajectory.attitude_quaternion(t),
                    )
                )
            )
            if name == "mid":
                mid = max(mid, error)
            else:
                ends = max(ends, error)
    return mid, ends, records


@pytest.mark.parametrize("case", list(CASES))
def test_interpolating_the_file_as_declared_stays_within_the_tolerance(case, tmp_path, capsys):
    path = _scenario(tmp_path, case)
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--formats", "aem", "--quiet"]) == 0
    assert {p.name for p in out.iterdir()} == {
        "attitude.aem",
        "summary.json",
        "attitude-manifest.json",
    } | ({"intervals.csv"} if "[pointing]" in path.read_text() else set())
    summary = json.loads((out / "summary.json").read_text())
    tolerance = summary["outputs"]["aem"]["tolerance_rad"]
    assert tolerance == 1e-6
    mid, ends, records = _errors(out, path)
    assert mid <= tolerance and ends <= tolerance, (mid, ends)
    # The figure the summary states is measured on the file: what a reader gets.
    stated = summary["outputs"]["aem"]["largest_error_rad"]
    assert max(mid, ends) <= stated <= tolerance, (mid, ends, stated)
    assert records <= 1e-12, records
    text = (out / "attitude.aem").read_text()
    assert "within 1e-06 rad of the exact attitude" in text


def test_a_tolerance_from_the_command_line_and_from_the_file(tmp_path):
    """The step follows the tolerance: 1e-3 rad takes fewer records than 1e-6, and still
    holds; the file's ``aem_tolerance`` is read with its unit, and the option wins."""
    path = _scenario(tmp_path, "Envisat-like tumble")
    records = {}
    for tolerance, arguments in (
        ("1e-06", []),
        ("0.001", ["--aem-tolerance", "1e-3 rad"]),
        ("4.84814e-06", ["--aem-tolerance", "1 arcsec"]),
    ):
        out = tmp_path / f"out-{tolerance}"
        assert (
            main(["run", str(path), "--out", str(out), "--formats", "aem", "--quiet", *arguments])
            == 0
        )
        aem = json.loads((out / "summary.json").read_text())["outputs"]["aem"]
        assert f"{aem['tolerance_rad']:g}" == tolerance
        records[tolerance] = aem["records"]
        mid, ends, _ = _errors(out, path)
        assert max(mid, ends) <= aem["tolerance_rad"]
    assert records["0.001"] < records["4.84814e-06"] < records["1e-06"]
    text = path.read_text().replace(
        "[output]", '[output]\naem_tolerance = { value = 2, unit = "arcsec" }'
    )
    path.write_text(text)
    out = tmp_path / "from-file"
    assert main(["run", str(path), "--out", str(out), "--formats", "aem", "--quiet"]) == 0
    tolerance = json.loads((out / "summary.json").read_text())["outputs"]["aem"]["tolerance_rad"]
    assert tolerance == pytest.approx(np.radians(2.0 / 3600.0), rel=1e-15)


@pytest.mark.parametrize(
    ("option", "message"),
    [
        ("1e-6", r"--aem-tolerance: '1e-6' needs an angle with its unit"),
        ("1e-6 m", r"--aem-tolerance: unit 'm' cannot be converted to rad"),
        ("0 rad", r"--aem-tolerance: 0 rad is outside \[1e-12, 0\.1\] rad"),
        ("10 deg", r"--aem-tolerance: 0\.174533 rad is outside"),
        ("1e-11 rad", r"--aem-tolerance: 1e-11 rad is finer than 1 ns time tags allow"),
        ("nan rad", r"--aem-tolerance: 'nan rad' needs an angle"),
    ],
)
def test_a_bad_tolerance_is_refused_in_one_line(tmp_path, capsys, option, message):
    path = _scenario(tmp_path, "T-handle flips")
    for command in ("check", "run"):
        argv = [command, str(path), "--aem-tolerance", option]
        if command == "run":
            argv += ["--out", str(tmp_path / "out")]
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert len(said(err)) == 1 and re.search(message, err), err
    assert not (tmp_path / "out").exists()
