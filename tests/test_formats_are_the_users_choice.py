"""``--formats`` (and ``[output] formats``): the run writes what the user chose, ``check``
states the size of each, and anything else is refused in one line before any work.

Also: a stream that fails half-way (the disk fills while a chunk is written, in each
format) leaves nothing behind, as the output folder promises.
"""

import errno
import json
import re
from pathlib import Path

import pytest
from cli_lines import said

import attitude.outputs.csv
import attitude.outputs.parquet
from attitude.cli.main import main

SCENARIO = """
[scenario]
name = "formats"
epoch = "2027-03-01T12:00:00"

[spacecraft]
name = "sat"
principal_moments = [10.0, 20.0, 25.0]

[initial_state]
quaternion = [1.0, 0.0, 0.0, 0.0]
angular_velocity = [0.01, 0.2, 0.01]

[output]
duration = 600.0
step = 0.5
"""

EVERY = {
    "timeseries.csv",
    "timeseries.parquet",
    "attitude.aem",
    "summary.json",
    "report.html",
    "angular_velocity.png",
    "polhode.png",
}


def _scenario(tmp_path: Path, extra: str = "") -> Path:
    path = tmp_path / "s.toml"
    path.write_text(SCENARIO.replace("step = 0.5", "step = 0.5\n" + extra))
    return path


def _files(out: Path) -> set[str]:
    return {p.name for p in out.iterdir()} - {"attitude-manifest.json"}


def test_the_default_is_csv_aem_plots_report(tmp_path):
    out = tmp_path / "out"
    assert main(["run", str(_scenario(tmp_path)), "--out", str(out), "--quiet"]) == 0
    assert _files(out) == EVERY - {"timeseries.parquet"}


@pytest.mark.parametrize(
    ("formats", "written"),
    [
        ("parquet", {"timeseries.parquet", "summary.json"}),
        ("aem,csv", {"timeseries.csv", "attitude.aem", "summary.json"}),
        ("PLOTS, report", {"report.html", "angular_velocity.png", "polhode.png", "summary.json"}),
        ("csv,parquet,aem,plots,report", EVERY),
        ("csv,csv,", {"timeseries.csv", "summary.json"}),
    ],
)
def test_the_run_writes_what_was_chosen_and_check_sizes_it(tmp_path, capsys, formats, written):
    path = _scenario(tmp_path)
    assert main(["check", str(path), "--formats", formats]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if "writes about" in x)
    for name in ("timeseries.csv", "timeseries.parquet", "attitude.aem"):
        assert (f"{name} " in line) == (name in written), (name, line)
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--formats", formats, "--quiet"]) == 0
    assert _files(out) == written
    summary = json.loads((out / "summary.json").read_text())
    assert set(summary["outputs"]["formats"]) == {
        f.strip().lower() for f in formats.split(",") if f
    }
    if "report.html" in written:
        page = (out / "report.html").read_text()
        assert all(f"'{name}'" in page for name in written - {"report.html"})


def test_a_rerun_with_other_formats_replaces_our_previous_files_only(tmp_path):
    path = _scenario(tmp_path)
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--formats", "csv,aem", "--quiet"]) == 0
    (out / "notes.txt").write_text("mine\n")
    assert main(["run", str(path), "--out", str(out), "--formats", "parquet", "--quiet"]) == 0
    assert _files(out) == {"timeseries.parquet", "summary.json", "notes.txt"}
    manifest = json.loads((out / "attitude-manifest.json").read_text())
    assert set(manifest["files"]) == {"timeseries.parquet", "summary.json"}


def test_the_files_formats_and_the_option_that_overrides_them(tmp_path):
    path = _scenario(tmp_path, 'formats = ["aem"]')
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 0
    assert _files(out) == {"attitude.aem", "summary.json"}
    assert main(["run", str(path), "--out", str(out), "--formats", "csv", "--quiet"]) == 0
    assert _files(out) == {"timeseries.csv", "summary.json"}


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--formats", "xml"], r"^attitude: error: --formats: unknown format 'xml': choose from"),
        (["--formats", "csv;aem"], r"--formats: unknown format 'csv;aem'"),
        (["--formats", ""], r"^attitude: error: --formats: give one or more of csv, parquet"),
        (["--formats", " , ,"], r"--formats: give one or more of"),
        (["--formats", "\x00\xff" * 50], r"--formats: unknown format '.{1,45}'"),
        (["--formats", "../../etc/passwd"], r"--formats: unknown format '\.\./\.\./etc/passwd'"),
    ],
    ids=["xml", "semicolon", "empty", "blanks", "binary", "a path"],
)
def test_garbage_formats_are_refused_in_one_line(tmp_path, capsys, argv, message):
    path = _scenario(tmp_path)
    out = tmp_path / "out"
    for command in (["check", str(path)], ["run", str(path), "--out", str(out), "--quiet"]):
        assert main(command + argv) == 2
        err = capsys.readouterr().err
        assert len(said(err)) == 1 and re.search(message, said(err)[0]), err
    assert not out.exists()


@pytest.mark.parametrize(
    ("value", "message"),
    [
        ('"csv"', r"output\.formats: expected a list of format names, got 'csv'"),
        ('["csv", 3]', r"output\.formats: expected format names"),
        ('["excel"]', r"output\.formats: unknown format 'excel'"),
        ("[]", r"output\.formats: give one or more of"),
    ],
)
def test_bad_formats_in_the_file_name_the_key(tmp_path, capsys, value, message):
    path = _scenario(tmp_path, f"formats = {value}")
    for command in (["check", str(path)], ["run", str(path), "--out", str(tmp_path / "o")]):
        assert main(command) == 2
        err = capsys.readouterr().err
        assert len(said(err)) == 1 and re.search(rf"s\.toml: {message}", err), err


@pytest.mark.parametrize("failing", ["csv", "parquet"])
def test_a_disk_full_in_the_middle_of_the_stream_leaves_nothing(
    tmp_path, capsys, monkeypatch, failing
):
    """The third chunk's write fails as a full disk does: exit 1, one line, and the
    folder (here, one with the user's notes and a previous run of ours) as it was."""
    path = _scenario(tmp_path)
    path.write_text(path.read_text().replace("duration = 600.0", "duration = 40000.0"))
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--formats", "aem", "--quiet"]) == 0
    (out / "notes.txt").write_text("mine\n")
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    target = {
        "csv": attitude.outputs.csv.CsvWriter,
        "parquet": attitude.outputs.parquet.ParquetWriter,
    }[failing]
    write = target.write
    calls = []

    def full(self, *args):
        calls.append(1)
        if len(calls) == 3:
            raise OSError(errno.ENOSPC, "No space left on device")
        return write(self, *args)

    monkeypatch.setattr(target, "write", full)
    argv = ["run", str(path), "--out", str(out), "--formats", failing, "--quiet"]
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert said(err) == [
        f"attitude: error: --out {out}: the outputs could not be written (No space left on "
        "device); nothing of this run was left in the folder"
    ], err
    assert len(calls) == 3
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
