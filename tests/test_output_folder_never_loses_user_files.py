"""`attitude run --out DIR` never removes or overwrites a file it did not write.

Each case of the data-loss report, through the real command line: `--out .` in the
user's folder, `--out ~`, the scenario's own folder, a non-empty folder of the user's,
`--out` naming a file, the docs' `--out results/` beside sibling outputs, files of
ours edited or replaced by the user, a forged manifest, a failed rename, a full disk
(a file-size limit), and SIGINT, SIGTERM and SIGKILL in the middle of a run.  After
each: the exit status, one line on stderr (no traceback), every file of the user's
byte for byte as before, and no `.partial-*`/`.old-*` leftovers.
"""

import json
import os
import resource
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from cli_lines import said
from signal_dispositions import defaults

import attitude.outputs.folder
import attitude.report.run
from attitude.cli.main import main

SCENARIO = """
[scenario]
name = "folder test"
epoch = "2027-03-01T12:00:00"

[spacecraft]
name = "sat"
principal_moments = [10.0, 20.0, 25.0]

[initial_state]
quaternion = [1.0, 0.0, 0.0, 0.0]
angular_velocity = [0.01, 0.2, 0.01]

[output]
duration = DURATION
step = 1.0
"""


def _scenario(folder: Path, duration: float = 20.0, name: str = "scenario.toml") -> Path:
    path = folder / name
    path.write_text(SCENARIO.replace("DURATION", repr(duration)))
    return path


def _snapshot(folder: Path) -> dict[str, bytes]:
    """Every file under ``folder`` (relative path -> bytes)."""
    return {
        str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()
    }


def _leftovers(folder: Path) -> list[str]:
    return [str(p) for p in folder.rglob("*") if ".partial-" in p.name or ".old-" in p.name]


def _refused(capsys, argv) -> str:
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert len(said(err)) == 1 and "Traceback" not in err, err
    return said(err)[0]


@pytest.fixture
def user_folder(tmp_path):
    """A user's folder: their scenario, their thesis, a subfolder of their data."""
    folder = tmp_path / "work"
    folder.mkdir()
    scenario = _scenario(folder)
    (folder / "thesis.tex").write_text("\\documentclass{article} % months of work\n")
    (folder / "data").mkdir()
    (folder / "data" / "measurements.csv").write_text("t,x\n0,1\n")
    return folder, scenario


def test_out_dot_in_the_users_folder_is_refused(user_folder, capsys, monkeypatch):
    folder, _ = user_folder
    before = _snapshot(folder)
    monkeypatch.chdir(folder)
    err = _refused(capsys, ["run", "scenario.toml", "--out", ".", "--quiet"])
    assert "did not write" in err and "thesis.tex" in err
    assert _snapshot(folder) == before


def test_the_scenarios_own_folder_is_refused(user_folder, capsys):
    folder, scenario = user_folder
    before = _snapshot(folder)
    _refused(capsys, ["run", str(scenario), "--out", str(folder), "--quiet"])
    assert _snapshot(folder) == before


def test_out_home_is_refused(user_folder, capsys, monkeypatch):
    folder, scenario = user_folder
    monkeypatch.setenv("HOME", str(folder))
    before = _snapshot(folder)
    _refused(capsys, ["run", str(scenario), "--out", "~", "--quiet"])
    _refused(capsys, ["run", str(scenario), "--out", str(Path.home()), "--quiet"])
    assert _snapshot(folder) == before


def test_a_path_that_is_a_file_is_refused(user_folder, capsys):
    folder, scenario = user_folder
    before = _snapshot(folder)
    err = _refused(capsys, ["run", str(scenario), "--out", str(folder / "thesis.tex")])
    assert "is a file" in err
    assert _snapshot(folder) == before
    assert not _leftovers(folder.parent)


def test_results_folder_of_the_docs_keeps_its_siblings(user_folder, capsys):
    folder, scenario = user_folder
    results = folder / "results"
    assert main(["run", str(scenario), "--out", str(results / "a"), "--quiet"]) == 0
    assert main(["run", str(scenario), "--out", str(results / "b"), "--quiet"]) == 0
    before = _snapshot(folder)
    # `--out results/` (the parent of both): not ours, refused, both kept.
    _refused(capsys, ["run", str(scenario), "--out", str(results), "--quiet"])
    assert _snapshot(folder) == before


def test_a_rerun_replaces_only_our_files(user_folder):
    folder, scenario = user_folder
    out = folder / "out"
    assert main(["run", str(scenario), "--out", str(out), "--quiet"]) == 0
    (out / "notes.txt").write_text("my notes on this run\n")
    first = json.loads((out / "attitude-manifest.json").read_text())
    scenario.write_text(SCENARIO.replace("DURATION", "30.0"))
    assert main(["run", str(scenario), "--out", str(out), "--quiet"]) == 0
    assert (out / "notes.txt").read_text() == "my notes on this run\n"
    manifest = json.loads((out / "attitude-manifest.json").read_text())
    assert "notes.txt" not in manifest["files"] and "previous" not in manifest
    assert manifest["files"]["timeseries.csv"] != first["files"]["timeseries.csv"]
    assert set(manifest["files"]) | {"notes.txt", "attitude-manifest.json"} == {
        p.name for p in out.iterdir()
    }
    assert not _leftovers(folder)


def test_an_empty_folder_of_the_user_is_used_and_left_as_it_was_on_failure(
    user_folder, capsys, monkeypatch
):
    folder, scenario = user_folder
    empty = folder / "empty"
    empty.mkdir()

    def fail(*args, **kwargs):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(attitude.report.run, "write_json", fail)
    assert main(["run", str(scenario), "--out", str(empty), "--quiet"]) == 1
    assert len(capsys.readouterr().err.splitlines()) == 1
    assert empty.is_dir() and list(empty.iterdir()) == []
    monkeypatch.undo()
    assert main(["run", str(scenario), "--out", str(empty), "--quiet"]) == 0
    assert (empty / "attitude-manifest.json").is_file()


@pytest.mark.parametrize("change", ["edited", "symlink", "foreign name", "forged manifest"])
def test_files_that_are_not_ours_inside_our_folder_are_never_replaced(user_folder, capsys, change):
    folder, scenario = user_folder
    out = folder / "out"
    assert main(["run", str(scenario), "--out", str(out), "--quiet"]) == 0
    if change == "edited":
        (out / "summary.json").write_text('{"my": "annotations"}\n')
    elif change == "symlink":
        (out / "timeseries.csv").unlink()
        (out / "timeseries.csv").symlink_to(folder / "thesis.tex")
    elif change == "foreign name":
        (out / "eclipse.png").write_bytes(b"my own picture")
    else:
        manifest = json.loads((out / "attitude-manifest.json").read_text())
        manifest["files"]["../thesis.tex"] = {"bytes": 1, "sha256": "0" * 64}
        (out / "attitude-manifest.json").write_text(json.dumps(manifest))
    before = _snapshot(folder)
    _refused(capsys, ["run", str(scenario), "--out", str(out), "--quiet"])
    assert _snapshot(folder) == before


def test_a_failed_rename_leaves_a_folder_the_next_run_recognizes(user_folder, capsys, monkeypatch):
    folder, scenario = user_folder
    out = folder / "out"
    assert main(["run", str(scenario), "--out", str(out), "--quiet"]) == 0
    (out / "notes.txt").write_text("mine\n")
    real_replace = os.replace
    moved = []

    def replace(src, dst):
        # Fail on the second output file to move: the first is already the new one.
        if Path(dst).name != "attitude-manifest.json":
            moved.append(dst)
            if len(moved) == 2:
                raise PermissionError(13, "Permission denied", str(dst))
        return real_replace(src, dst)

    monkeypatch.setattr(attitude.outputs.folder.os, "replace", replace)
    scenario.write_text(SCENARIO.replace("DURATION", "30.0"))
    assert main(["run", str(scenario), "--out", str(out), "--quiet"]) == 1
    assert len(capsys.readouterr().err.splitlines()) == 1
    assert not _leftovers(folder)
    assert (out / "notes.txt").read_text() == "mine\n"
    monkeypatch.undo()
    # Whatever mix of old and new files is there, it is ours: the next run replaces it.
    assert main(["run", str(scenario), "--out", str(out), "--quiet"]) == 0
    assert (out / "notes.txt").read_text() == "mine\n"


def test_a_folder_that_cannot_be_written_leaves_nothing(user_folder, capsys, monkeypatch):
    folder, scenario = user_folder

    def refuse(self, *args, **kwargs):
        raise OSError(30, "Read-only file system", str(self))

    monkeypatch.setattr(attitude.outputs.folder.Path, "mkdir", refuse)
    before = _snapshot(folder)
    # Found before anything is computed: exit 2, the folder as written (issue 27).
    assert main(["run", str(scenario), "--out", str(folder / "new"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.splitlines() == [
        f"attitude: error: --out {folder / 'new'}: cannot create the folder: Read-only file system"
    ]
    assert _snapshot(folder) == before and not (folder / "new").exists()


def _cli(*args, cwd=None, **kwargs) -> subprocess.Popen:
    """The installed `attitude` command (or `python -m attitude` where there is none)."""
    script = Path(sys.executable).parent / "attitude"
    command = [str(script)] if script.is_file() else [sys.executable, "-m", "attitude"]
    kwargs.setdefault("preexec_fn", defaults)  # not the ignored SIGINT of a `pytest &`
    return subprocess.Popen(
        [*command, *args],
        cwd=cwd,
        stderr=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
        **kwargs,
    )


@pytest.mark.parametrize("formats", ["csv,aem,plots,report", "parquet", "aem"])
def test_a_full_disk_leaves_nothing(user_folder, formats):
    """A file-size limit (RLIMIT_FSIZE) makes the writes fail as a full disk does (Python
    ignores SIGXFSZ, so the write raises EFBIG instead of killing the process), in the
    middle of the stream of each format."""
    folder, scenario = user_folder
    scenario = _scenario(folder, duration=200000.0, name="long.toml")
    before = _snapshot(folder)

    def limit():
        defaults()
        resource.setrlimit(resource.RLIMIT_FSIZE, (200_000, 200_000))

    process = _cli(
        "run",
        str(scenario),
        "--out",
        str(folder / "out"),
        "--quiet",
        "--formats",
        formats,
        preexec_fn=limit,
    )
    _, err = process.communicate(timeout=120)
    assert process.returncode == 1, err
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    assert _snapshot(folder) == before and not (folder / "out").exists()


def _run_until(folder: Path, scenario: Path, out: Path, stage: str) -> subprocess.Popen:
    """Start a long run and return once it reports ``stage`` on stderr."""
    process = _cli("run", str(scenario), "--out", str(out))
    for line in process.stderr:
        if stage in line:
            return process
    raise AssertionError(f"the run ended before {stage!r}: {process.wait()}")


@pytest.mark.parametrize(
    ("number", "code", "stage"),
    [
        (signal.SIGINT, 130, "sampling"),
        (signal.SIGTERM, 143, "sampling"),
        (signal.SIGINT, 130, "% ("),  # in the middle of the stream: a chunk was written
        (signal.SIGTERM, 143, "writing attitude.aem"),
        (signal.SIGINT, 130, "plotting"),
    ],
    ids=["SIGINT start", "SIGTERM start", "SIGINT mid-stream", "SIGTERM aem", "SIGINT plots"],
)
def test_a_signal_stops_the_run_with_one_line_and_no_leftovers(user_folder, number, code, stage):
    folder, _ = user_folder
    # Long enough for several chunks (the stream reports after its first).
    scenario = _scenario(folder, duration=150000.0, name="long.toml")
    out = folder / "out"
    # A previous run of ours, which must survive the interrupted one untouched.
    assert main(["run", str(folder / "scenario.toml"), "--out", str(out), "--quiet"]) == 0
    (out / "notes.txt").write_text("mine\n")
    before = _snapshot(folder)
    process = _run_until(folder, scenario, out, stage)
    process.send_signal(number)
    rest = process.stderr.read()
    assert process.wait(timeout=60) == code, rest
    errors = [line for line in rest.splitlines() if line.startswith("attitude: error:")]
    others = [line for line in rest.splitlines() if not line.startswith("[")]
    assert errors == others and len(errors) == 1, rest
    assert "Traceback" not in rest
    assert _snapshot(folder) == before
    assert not _leftovers(folder)


def test_kill_9_leaves_only_what_the_next_run_cleans(user_folder):
    folder, _ = user_folder
    scenario = _scenario(folder, duration=150000.0, name="long.toml")
    out = folder / "out"
    process = _run_until(folder, scenario, out, "sampling")
    process.kill()
    process.wait(timeout=60)
    # Nothing beside the user's files: the partial outputs are inside our folder.
    assert sorted(p.name for p in folder.iterdir()) == [
        "data",
        "long.toml",
        "out",
        "scenario.toml",
        "thesis.tex",
    ]
    assert (out / "attitude-manifest.json").is_file()
    before = _snapshot(folder)
    del before["out/attitude-manifest.json"]
    assert main(["run", str(folder / "scenario.toml"), "--out", str(out), "--quiet"]) == 0
    assert not _leftovers(folder)
    after = _snapshot(folder)
    assert all(after[name] == data for name, data in before.items() if not name.startswith("out"))
