"""A job on an external cluster (`dask scheduler` and `dask worker` processes on
loopback, as a user starts them) survives what a shared cluster does to it, or
fails as a job, never as rows (issue 27).

- A worker killed (`kill -9`) mid-job: its nanny starts another, the scheduler runs
  the lost task again, and the job's table is the same, byte for byte, as a run in
  this process (main at d285687 scattered the job to the workers: it died with the
  one worker, and every sample after it was `failed`).
- A worker that runs edited code under the same version (a copy of the package with
  one file changed, first on its PYTHONPATH): refused before the job, one line naming
  what differs.  Main at d285687 compared the version strings, and let it compute.
- The scheduler killed (`kill -9`) mid-job: main exited 0, said `done` and replaced
  the previous outputs with a report of `failed` samples (FutureCancelledError ...
  scheduler-connection-lost), and two Dask tracebacks reached stderr.  Now exit 1,
  one line naming the scheduler and what the checkpoint kept, the previous outputs
  untouched; `--resume` then finishes the job in this process, to the same bytes.
  The envelope's lost scheduler too (marked slow: the same attitude.jobs path).

To stop a job mid-way without a race, the worker is frozen (SIGSTOP) as soon as the
job has reported a finished sample: no other sample can finish before the kill.
"""

import io
import json
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import psutil
import pytest
from cli_lines import said
from envelope_scenarios import with_envelope
from montecarlo_scenarios import write_spinner
from signal_dispositions import defaults

from attitude import run_montecarlo
from attitude.cli.main import main

PACKAGE = Path(__file__).resolve().parents[1] / "attitude"
DASK = str(Path(sys.executable).parent / "dask")
# Files of a job's folder that state how it ran (the page's execution note, and the
# manifest that lists the page): not compared.  statistics.json and summary.json are
# compared without their "execution".
RUN_DEPENDENT = {"report.html", "attitude-manifest.json"}


def _start(*argv, env=None) -> subprocess.Popen:
    return subprocess.Popen(
        [DASK, *argv],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        env=env,
        preexec_fn=defaults,
    )


class Cluster:
    """A `dask scheduler` and `dask worker` processes on 127.0.0.1."""

    def __init__(self, folder: Path) -> None:
        file = folder / "scheduler.json"
        self.scheduler = _start(
            "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
            "--scheduler-file", str(file),
        )  # fmt: skip
        self.workers: list[subprocess.Popen] = []
        deadline = time.monotonic() + 60
        while not file.exists() or not file.read_text().strip():
            assert time.monotonic() < deadline and self.scheduler.poll() is None
            time.sleep(0.05)
        time.sleep(0.1)  # written whole
        self.address = json.loads(file.read_text())["address"]

    def add_worker(self, env=None) -> subprocess.Popen:
        worker = _start(
            "worker", self.address, "--nworkers", "1", "--nthreads", "1", "--no-dashboard",
            env=env,
        )  # fmt: skip
        self.workers.append(worker)
        return worker

    def wait_for_workers(self, count: int) -> None:
        from distributed import Client

        with Client(self.address, timeout=30) as client:
            client.wait_for_workers(count, timeout=120)

    def close(self) -> None:
        for process in [*self.workers, self.scheduler]:
            for child in _children(process):
                child.kill()
            process.kill()
            process.wait(timeout=30)


def _children(process: subprocess.Popen) -> list[psutil.Process]:
    try:
        return psutil.Process(process.pid).children(recursive=True)
    except psutil.NoSuchProcess:
        return []


def _worker_process(nanny: subprocess.Popen) -> psutil.Process:
    """The process a `dask worker` runs its tasks in (its nanny's child)."""
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        found = [
            p for p in _children(nanny) if "spawn_main" in " ".join(p.cmdline()) and p.is_running()
        ]
        if found:
            return found[0]
        time.sleep(0.05)
    raise AssertionError("the worker's process did not start")


@pytest.fixture
def cluster(tmp_path):
    made = Cluster(tmp_path)
    try:
        yield made
    finally:
        made.close()


def _job(command: str, scenario: Path, out: Path, *options: str) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-m", "attitude", command, str(scenario), "--out", str(out), *options],
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=defaults,
    )


_BAR = re.compile(r"^\[[#.]+\] (\d+)/\d+ ")


def _until_one_finished(job: subprocess.Popen) -> list[str]:
    """Read the job's stderr until its bar shows a finished item; the lines read."""
    lines = []
    for line in job.stderr:
        lines.append(line)
        found = _BAR.match(line)
        if found and int(found.group(1)) > 0:
            return lines
    raise AssertionError(f"the job ended before a finished item: {''.join(lines)}")


def _outputs(folder: Path) -> dict[str, object]:
    """A job folder's outputs, for comparison: bytes, and JSON without "execution"."""
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


def _edited_copy(folder: Path) -> Path:
    """A copy of the package with one file edited (a comment added): the same version,
    other code."""
    root = folder / "edited"
    shutil.copytree(PACKAGE, root / "attitude", ignore=shutil.ignore_patterns("__pycache__"))
    solver = root / "attitude" / "solver" / "euler_solver.py"
    solver.write_text(solver.read_text() + "\n# a fix tried on one machine\n")
    return root


def test_a_killed_worker_is_recovered_a_worker_of_other_code_refused_a_lost_scheduler_resumed(
    tmp_path, cluster, capsys
):
    scenario = write_spinner(tmp_path, samples=10)
    reference = tmp_path / "reference"
    assert main(["montecarlo", str(scenario), "--out", str(reference), "--workers", "1"]) == 0
    capsys.readouterr()
    expected = _outputs(reference)
    nanny = cluster.add_worker()
    cluster.wait_for_workers(1)
    where = ["--scheduler", cluster.address, "--batch-size", "1"]

    # 1. A worker killed mid-job (as its first sample is in): recovered, the same table.
    killed = []

    def kill_the_worker(done, total, failed):
        if done and not killed:
            killed.append(_worker_process(nanny))
            killed[0].kill()

    table = run_montecarlo(
        scenario, scheduler=cluster.address, batch_size=1, progress=kill_the_worker
    )
    assert killed and not killed[0].is_running()
    written = io.BytesIO()
    table.to_parquet(written, index=False)
    assert written.getvalue() == expected["samples.parquet"]

    # 2. A worker of other code under the same version: refused, one line.
    env = dict(os.environ, PYTHONPATH=str(_edited_copy(tmp_path)))
    cluster.add_worker(env=env)
    cluster.wait_for_workers(2)
    code = main(["montecarlo", str(scenario), "--out", str(tmp_path / "other"), *where, "--quiet"])
    lines = said(capsys.readouterr().err)
    assert code == 2, lines
    assert len(lines) == 1, lines
    assert lines[0].startswith(
        "attitude: error: spinner.toml: --scheduler: worker tcp://127.0.0.1:"
    )
    assert "runs other code under the same version" in lines[0], lines[0]
    assert lines[0].endswith("install this very code and these versions on every worker")
    assert not (tmp_path / "other").exists()
    bad = cluster.workers.pop()
    for child in _children(bad):
        child.kill()
    bad.kill()
    bad.wait(timeout=30)

    # 3. The scheduler killed mid-job: the job fails, the previous outputs stay.
    out = tmp_path / "out"
    shutil.copytree(reference, out)
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    job = _job("montecarlo", scenario, out, *where)
    try:
        lines = _until_one_finished(job)
        worker = _worker_process(cluster.workers[0])
        worker.suspend()  # no other sample finishes now
        cluster.scheduler.kill()
        cluster.scheduler.wait(timeout=30)
        worker.resume()
        rest = job.stderr.read()
        code = job.wait(timeout=300)
    finally:
        job.kill()
    errors = [line for line in rest.splitlines() if not line.startswith("[")]
    assert code == 1, "".join(lines) + rest
    assert "Traceback" not in "".join(lines) + rest
    assert len(errors) == 1, rest
    assert errors[0].startswith(
        f"attitude: error: --scheduler {cluster.address}: the connection to the Dask "
        "scheduler was lost; "
    ), errors[0]
    assert errors[0].endswith(
        f"of 10 samples are kept in {out}/.attitude-checkpoint: the same command with "
        "--resume continues the job"
    ), errors[0]
    assert {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()} == before

    # --resume, here in this process: the uninterrupted run's outputs.
    assert main(["montecarlo", str(scenario), "--out", str(out), "--workers", "1", "--resume"]) == 0
    err = capsys.readouterr().err
    assert " samples from " in err and "resumed: " in err, err
    assert _outputs(out) == expected
    assert not (out / ".attitude-checkpoint").exists()


@pytest.mark.slow  # the Monte Carlo's test above goes through the same attitude.jobs
def test_the_envelope_on_a_lost_scheduler_fails_and_resumes(tmp_path, cluster, capsys):
    table = (
        "[envelope]\ntimes = [600.0, 2400.0, 3300.0, 4200.0]\nwindow = 600.0\n"
        'wheels = { case = "locked", momentum = [0.0, 2.0, 0.0] }'
    )
    scenario = with_envelope(tmp_path, table)
    reference = tmp_path / "reference"
    assert main(["envelope", str(scenario), "--out", str(reference), "--workers", "1"]) == 0
    capsys.readouterr()
    cluster.add_worker()
    cluster.wait_for_workers(1)
    out = tmp_path / "out"
    job = _job("envelope", scenario, out, "--scheduler", cluster.address, "--batch-size", "1")
    try:
        lines = _until_one_finished(job)
        worker = _worker_process(cluster.workers[0])
        worker.suspend()
        cluster.scheduler.kill()
        cluster.scheduler.wait(timeout=30)
        worker.resume()
        rest = job.stderr.read()
        code = job.wait(timeout=300)
    finally:
        job.kill()
    errors = [line for line in rest.splitlines() if not line.startswith("[")]
    assert code == 1, "".join(lines) + rest
    assert "Traceback" not in "".join(lines) + rest
    assert len(errors) == 1 and "the connection to the Dask scheduler was lost" in errors[0], rest
    assert "of 4 failures are kept in" in errors[0], errors[0]
    assert sorted(p.name for p in out.iterdir()) == [".attitude-checkpoint"]
    assert main(["envelope", str(scenario), "--out", str(out), "--workers", "1", "--resume"]) == 0
    assert _outputs(out) == _outputs(reference)
