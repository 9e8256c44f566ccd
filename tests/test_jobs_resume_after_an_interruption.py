"""An interrupted job continues with `--resume` from its checkpoint, to the same outputs,
byte for byte, as an uninterrupted run (issue 27; main at d285687 discarded every
finished sample).

Compared: every file of the job's folder, bytes for bytes, but the two that state how
the job ran (report.html's execution note: workers, wall time; the manifest, which
lists report.html's digest); statistics.json and summary.json compared as JSON
without their ``execution`` (wall time, CPU, batches, how many items were resumed).

The interruptions: Ctrl-C and SIGTERM at the moment the bar reports a finished batch
(raised from the bar itself: the instant is the test's, not a race), and `kill -9` of
a job as soon as a sample is in (whenever it lands, the resumed job's outputs are the
same).  Around them: the previous
outputs of the folder stay untouched; `check --out` says a checkpoint is there; a
checkpoint is refused for another job (another seed) with one line; a run without
`--resume` discards it, saying so; the checkpoint is gone once the job completes.
"""

import json
import math
import os
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas
import pytest
from cli_lines import said
from envelope_scenarios import with_envelope
from montecarlo_scenarios import write_spinner
from signal_dispositions import defaults

import attitude.cli.montecarlo
from attitude import EnvelopeSettings, Wheels, load_scenario, loss_of_control_envelope
from attitude.base.signals import Stopped
from attitude.cli.main import main
from attitude.envelope.engine import simulate as envelope_simulate
from attitude.envelope.job import envelope_job
from attitude.envelope.plan import plan_envelope
from attitude.jobs.checkpoint import batch_table, canonical_rows

RUN_DEPENDENT = {"report.html", "attitude-manifest.json"}
CHECKPOINT = ".attitude-checkpoint"


def _outputs(folder: Path) -> dict[str, object]:
    found: dict[str, object] = {}
    for path in sorted(folder.iterdir()):
        if not path.is_file() or path.name in RUN_DEPENDENT:
            continue
        if path.suffix == ".json":
            data = json.loads(path.read_text())
            data.pop("execution", None)
            found[path.name] = data
        else:
            found[path.name] = path.read_bytes()
    return found


def _files(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in folder.iterdir() if p.is_file()}


class _StoppedBar:
    """A progress bar that stops the job (as a signal would, at that instant) once
    ``after`` items are done."""

    def __init__(self, stop: BaseException, after: int) -> None:
        self.stop, self.after = stop, after

    def __call__(self, stream=None, width=30, noun="samples"):
        def progress(done: int, total: int, failed: int) -> None:
            if done >= self.after:
                raise self.stop

        return progress


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The spinner's 8 samples, uninterrupted, in this process: (scenario, its folder)."""
    folder = tmp_path_factory.mktemp("reference")
    scenario = write_spinner(folder, samples=8)
    out = folder / "reference"
    assert main(["montecarlo", str(scenario), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    return scenario, out


def _stopped_run(argv, stop: BaseException, after: int, monkeypatch) -> int:
    monkeypatch.setattr(attitude.cli.montecarlo, "ProgressBar", _StoppedBar(stop, after))
    try:
        return main(argv)
    finally:
        monkeypatch.undo()


def test_ctrl_c_then_resume_gives_the_uninterrupted_outputs(
    reference, tmp_path, capsys, monkeypatch
):
    scenario, done = reference
    out = tmp_path / "out"
    shutil.copytree(done, out)  # the previous outputs of this folder
    before = _files(out)
    argv = ["montecarlo", str(scenario), "--out", str(out), "--workers", "1", "--batch-size", "2"]
    capsys.readouterr()
    assert _stopped_run(argv, KeyboardInterrupt(), 4, monkeypatch) == 130
    lines = said(capsys.readouterr().err)
    assert lines == [
        f"attitude: error: interrupted; 4 of 8 samples are kept in {out}/{CHECKPOINT}: the "
        "same command with --resume continues the job"
    ], lines
    assert _files(out) == before

    # check says so; another job's --resume is refused; this one's resumes.
    assert main(["check", str(scenario), "--out", str(out), "--quiet"]) == 0
    shown = capsys.readouterr().out
    assert f"  checkpoint  {out}/{CHECKPOINT} holds 4 of 8 samples of an interrupted" in shown
    assert main([*argv, "--quiet", "--resume", "--seed", "9"]) == 2
    lines = said(capsys.readouterr().err)
    assert len(lines) == 1 and lines[0].startswith(
        f"attitude: error: spinner.toml: --resume: the checkpoint {out}/{CHECKPOINT} belongs "
        "to another job (spinner.toml, 8 samples, seed 7; this job: spinner.toml, 8 samples, "
        "seed 9)"
    ), lines
    assert _files(out) == before
    assert main([*argv, "--quiet", "--resume"]) == 0
    assert _outputs(out) == _outputs(done)
    assert not (out / CHECKPOINT).exists()


def test_sigterm_keeps_the_finished_batches_and_says_so(tmp_path, capsys, monkeypatch):
    scenario = write_spinner(tmp_path, samples=4)
    out = tmp_path / "out"
    argv = ["montecarlo", str(scenario), "--out", str(out), "--workers", "1", "--batch-size", "1"]
    assert _stopped_run(argv, Stopped(signal.SIGTERM), 3, monkeypatch) == 143
    assert said(capsys.readouterr().err) == [
        f"attitude: error: terminated; 3 of 4 samples are kept in {out}/{CHECKPOINT}: the "
        "same command with --resume continues the job"
    ]
    assert sorted(os.listdir(out)) == [CHECKPOINT]


def test_a_fresh_run_discards_a_checkpoint_saying_so(tmp_path, capsys, monkeypatch):
    scenario = write_spinner(tmp_path, samples=4)
    out = tmp_path / "out"
    argv = ["montecarlo", str(scenario), "--out", str(out), "--workers", "1", "--batch-size", "2"]
    assert _stopped_run(argv, KeyboardInterrupt(), 2, monkeypatch) == 130
    capsys.readouterr()
    assert _stopped_run([*argv, "--seed", "8"], KeyboardInterrupt(), 2, monkeypatch) == 130
    lines = said(capsys.readouterr().err)
    assert lines[0] == (
        f"attitude: note: spinner.toml: the checkpoint of an earlier job in {out}/{CHECKPOINT} "
        "(2 of 4 samples: spinner.toml, 4 samples, seed 7) was discarded: this job starts "
        "afresh (--resume continues a job)"
    ), lines
    assert json.loads((out / CHECKPOINT / "checkpoint.json").read_text())["describe"] == (
        "spinner.toml, 4 samples, seed 8"
    )


def test_the_envelope_from_python_resumes_to_the_uninterrupted_table(tmp_path):
    loaded = load_scenario(with_envelope(tmp_path, "[envelope]\nevery = 600.0\nwindow = 300.0"))
    settings = EnvelopeSettings(
        window=300.0, times=(600.0, 1500.0, 2400.0, 3300.0), wheels=Wheels("locked", [0, 2, 0])
    )
    plan = plan_envelope(loaded, settings=settings)
    out = tmp_path / "out"
    table = envelope_simulate(plan, workers=1).table

    def interrupt(done, total, failed):
        if done >= 3:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt) as caught:
        envelope_job(plan, out, loaded, workers=1, batch_size=1, progress=interrupt)
    assert caught.value.__notes__ == [
        f"3 of 4 failures are kept in {out}/{CHECKPOINT}: the same command with --resume "
        "continues the job"
    ]
    resumed = loss_of_control_envelope(loaded, settings=settings, workers=1, out=out, resume=True)
    pandas.testing.assert_frame_equal(resumed, table, check_exact=True)
    assert pandas.read_parquet(out / "envelope.parquet").equals(table)


def test_kill_9_then_resume(reference, tmp_path, capsys):
    """`kill -9` as soon as a sample is in: whenever it lands (a sample, a part being
    written, the report), what it leaves is the checkpoint's parts written whole, a
    stale lock and perhaps a partial folder; the resumed job cleans them all."""
    scenario, done = reference
    out = tmp_path / "out"
    options = ["--out", str(out), "--workers", "1", "--batch-size", "1"]
    job = subprocess.Popen(
        [sys.executable, "-m", "attitude", "montecarlo", str(scenario), *options],
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=defaults,
    )
    try:
        for line in job.stderr:
            if line.startswith("[#"):  # a finished sample
                break
        else:
            raise AssertionError(f"the job ended first: {job.wait()}")
        job.kill()
        assert job.wait(timeout=60) == -signal.SIGKILL
    finally:
        job.kill()
        job.stderr.close()
    # Its parts (or, had it just finished, its outputs), and its lock, stale now.
    assert (out / CHECKPOINT / "checkpoint.json").is_file() or (out / "report.html").is_file()
    assert (out / ".attitude-lock").is_file()
    assert main(["montecarlo", str(scenario), *options, "--resume", "--quiet"]) == 0
    assert _outputs(out) == _outputs(done)
    assert sorted(os.listdir(out)) == sorted(os.listdir(done))


def test_a_batch_reads_back_from_its_parquet_form_to_the_same_rows(tmp_path):
    """The values a row can hold, through the checkpoint's Parquet file and back: the
    rows the table is built from are the same whether computed now or resumed."""
    from attitude.jobs.checkpoint import Checkpoint

    rows = [
        {"sample": 0, "status": "ok", "error": "", "x": -0.0, "y": math.inf, "kind": "périodique"},
        {"sample": 1, "status": "failed", "error": "a: b: ✗ refused", "x": math.nan},
        {"sample": 2, "status": "ok", "error": "", "x": 5e-324, "y": -math.inf, "kind": ""},
        {"sample": 3, "status": "ok", "error": "", "x": 1.7976931348623157e308, "big": 2**62},
    ]
    columns = ["sample", "status", "error", "x", "y", "kind", "big", "never"]
    table = batch_table(pandas.DataFrame(rows, columns=columns))
    checkpoint = Checkpoint.open(
        tmp_path, "montecarlo", {"a": 1}, 4, "samples", "sample", "test", False, print
    )
    checkpoint.add(table, {"compute_s": 1.5, "bins": 7})
    checkpoint.flush()
    [(back, meta)] = list(checkpoint.parts())
    assert meta == {"compute_s": 1.5, "bins": 7}
    now, again = canonical_rows(table), canonical_rows(back)
    assert len(now) == len(again) == 4
    for a, b in zip(now, again, strict=True):
        assert a.keys() == b.keys()
        for key in a:
            same = a[key] == b[key] or (np.isnan(a[key]) and np.isnan(b[key]))
            assert same and type(a[key]) is type(b[key]), (key, a[key], b[key])
            if isinstance(a[key], float):
                assert math.copysign(1.0, a[key]) == math.copysign(1.0, b[key])
    assert pandas.DataFrame(now, columns=columns).equals(pandas.DataFrame(again, columns=columns))
