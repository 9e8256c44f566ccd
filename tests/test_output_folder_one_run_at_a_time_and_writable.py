"""The output folder: one run at a time, found unwritable before anything is computed,
and a full disk named (issue 27).

- Two jobs into one folder: main at d285687 let both compute; the later wrote its
  outputs and the earlier died at its end blaming files "not attitude's", leaving the
  folder without its manifest.  Now the second (`montecarlo`, `run`, `envelope`) is
  refused at its start, exit 2, one line naming the run that holds the folder (its
  lock), and `check --out` says so; the first finishes with its manifest.  A lock
  left by a dead run (`kill -9`) is taken over.
- A read-only folder: main found it after the whole computation (exit 1, the
  machine's absolute path) and `check --out` said "enough".  Now `check`, `run`,
  `montecarlo` and `envelope` refuse it before computing: exit 2, one line, the
  folder as the user wrote it.  The folder is made read-only for real: its mode where
  the tests run as a user, a read-only bind mount where they run as root (root
  writes through any mode); the test is skipped, saying why, where neither can be had.
- A full disk mid-write (ENOSPC from the writer): main said "No space left on device"
  naming no folder; now the line names the folder as written, and nothing of the run
  is left in it (a job's finished samples stay in its checkpoint, and the line says
  so).
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from cli_lines import progress_lines, said
from envelope_scenarios import with_envelope
from montecarlo_scenarios import write_spinner
from signal_dispositions import defaults

import attitude.montecarlo.report
import attitude.report.run
from attitude.cli.main import main

NOBODY_WRITES = "the folder could not be made read-only here (neither its mode nor a mount)"


def _writable(folder: Path) -> bool:
    probe = folder / ".probe"
    try:
        probe.write_text("x")
    except OSError:
        return False
    probe.unlink()
    return True


@pytest.fixture
def read_only(tmp_path):
    """An empty folder ``ro`` of ``tmp_path`` that cannot be written, for real."""
    folder = tmp_path / "ro"
    folder.mkdir()
    folder.chmod(0o555)
    mounted = False
    if _writable(folder) and os.geteuid() == 0:  # root writes through the mode
        folder.chmod(0o755)
        source = tmp_path / "ro-source"
        source.mkdir()
        bound = subprocess.run(["mount", "--bind", str(source), str(folder)], capture_output=True)
        if bound.returncode == 0:
            mounted = True
            subprocess.run(["mount", "-o", "remount,ro,bind", str(folder)], capture_output=True)
    try:
        if _writable(folder):
            pytest.skip(NOBODY_WRITES)
        yield folder
    finally:
        if mounted:
            subprocess.run(["umount", str(folder)], capture_output=True)
        folder.chmod(0o755)


@pytest.mark.parametrize("command", ["check", "run", "montecarlo", "envelope"])
@pytest.mark.parametrize("where", ["ro", "ro/new"])
def test_a_read_only_folder_is_refused_before_anything_is_computed(
    command, where, read_only, tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(tmp_path)
    if command == "envelope":
        scenario = with_envelope(tmp_path, "[envelope]\nevery = 600.0\nwindow = 300.0")
    else:
        scenario = write_spinner(tmp_path, samples=4)
    argv = [command, scenario.name, "--out", where]
    code = main(argv)
    err = capsys.readouterr().err
    assert code == 2, err
    lines = said(err)
    problem = "cannot be written" if where == "ro" else "cannot create the folder"
    assert len(lines) == 1 and lines[0].startswith(f"attitude: error: --out {where}: {problem}: ")
    assert lines[0].endswith(("Read-only file system", "Permission denied")), lines[0]
    # Nothing computed: no propagation, no sample, no failure time.
    assert not any(
        word in line
        for line in progress_lines(err)
        for word in ("propagating", "nominal", "sampling", "hand-off")
    ), err
    assert os.listdir(read_only) == []


def _until(process: subprocess.Popen, text: str) -> None:
    for line in process.stderr:
        if text in line:
            return
    raise AssertionError(f"ended before {text!r}: {process.wait()}")


def test_a_second_run_into_a_folder_is_refused_at_its_start(tmp_path, capsys):
    scenario = write_spinner(tmp_path, samples=6)
    envelope = with_envelope(tmp_path, "[envelope]\nevery = 600.0\nwindow = 300.0")
    out = tmp_path / "out"
    argv = ["montecarlo", str(scenario), "--out", str(out), "--workers", "1"]
    first = subprocess.Popen(
        [sys.executable, "-m", "attitude", *argv],
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=defaults,
    )
    try:
        _until(first, "nominal run")  # its lock is held from before the nominal run
        first.send_signal(subprocess.signal.SIGSTOP)
        for argv in (
            ["montecarlo", str(scenario), "--out", str(out), "--workers", "1", "--quiet"],
            ["run", str(scenario), "--out", str(out), "--quiet"],
            ["envelope", str(envelope), "--out", str(out), "--workers", "1", "--quiet"],
        ):
            assert main(argv) == 2, argv
            lines = said(capsys.readouterr().err)
            assert len(lines) == 1, lines
            assert lines[0].startswith(
                f"attitude: error: --out {out}: another run, `attitude montecarlo` (PID "
                f"{first.pid} since "
            ), lines[0]
            assert lines[0].endswith(
                "is writing into this folder: wait for it to end, or choose another folder"
            )
        assert main(["check", str(scenario), "--out", str(out), "--quiet"]) == 0
        shown = capsys.readouterr().out
        assert f"  folder      {out}: another run, `attitude montecarlo` (PID {first.pid}" in shown
        first.send_signal(subprocess.signal.SIGCONT)
        rest = first.stderr.read()
        assert first.wait(timeout=300) == 0, rest
    finally:
        first.kill()
        first.stderr.close()
    manifest = json.loads((out / "attitude-manifest.json").read_text())
    assert sorted(manifest["files"]) == sorted(attitude.montecarlo.report.OUTPUT_NAMES)
    assert sorted(os.listdir(out)) == sorted([*manifest["files"], "attitude-manifest.json"])


def test_a_lock_left_by_a_dead_run_is_taken_over(tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    dead = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True
    )
    lock = {"format": "attitude output folder lock", "pid": int(dead.stdout), "command": "run"}
    (out / ".attitude-lock").write_text(json.dumps(lock))
    scenario = write_spinner(tmp_path, samples=4)
    assert main(["run", str(scenario), "--out", str(out), "--quiet", "--formats", "csv"]) == 0
    assert not (out / ".attitude-lock").exists()
    assert (out / "attitude-manifest.json").is_file()


def _errors(capsys) -> list[str]:
    return [line for line in said(capsys.readouterr().err) if line.startswith("attitude: error")]


def _no_space(*args, **kwargs):
    raise OSError(28, "No space left on device")


def test_a_full_disk_names_the_folder_as_written(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    scenario = write_spinner(tmp_path, samples=4)
    monkeypatch.setattr(attitude.report.run, "write_json", _no_space)
    assert main(["run", scenario.name, "--out", "results", "--quiet", "--formats", "csv"]) == 1
    assert _errors(capsys) == [
        "attitude: error: --out results: the outputs could not be written (No space left on "
        "device); nothing of this run was left in the folder"
    ]
    assert not Path("results").exists()

    monkeypatch.setattr(attitude.montecarlo.report, "write_json", _no_space)
    argv = ["montecarlo", scenario.name, "--out", "mc", "--workers", "1", "--quiet"]
    assert main(argv) == 1
    assert _errors(capsys) == [
        "attitude: error: --out mc: the outputs could not be written (No space left on "
        "device); nothing of this run was left in the folder; 4 of 4 samples are kept in "
        "mc/.attitude-checkpoint: the same command with --resume continues the job"
    ]
    assert os.listdir("mc") == [".attitude-checkpoint"]
