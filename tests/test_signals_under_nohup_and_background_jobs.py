"""A run keeps the signal dispositions its caller set, and a signal that kills the
process beside it stops the run as that signal, not as a bug.

Against the real ways of starting a command: `nohup` (the system's, which ignores
SIGHUP before it executes the command) and a job in the background of a script (the
shell ignores SIGINT in it, POSIX Shell Command Language §2.11: given here
explicitly).  The run has its validity horizon computed in a process beside it
(attitude.report.beside), so each signal reaches two processes, as a terminal's
hangup or Ctrl-C reaches its whole process group.  A run that ignores the signal
ends as if it never came: exit 0, every output, the horizon in summary.json.
"""

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from signal_dispositions import defaults, starting_with

ROOT = Path(__file__).parents[1]
linux_only = pytest.mark.skipif(not Path("/proc/self/task").is_dir(), reason="needs /proc")


def _spinner(folder: Path) -> Path:
    """The spinner on its orbit over 30 000 s with a horizon threshold of 0.1°, which
    the averaged kicks' screen finds half crossed: the splitting runs beside it,
    thousands of steps."""
    text = (ROOT / "scenarios" / "spinner_thruster_pulse.toml").read_text()
    text = text.replace("duration = 3600.0", "duration = 30000.0").replace(
        "step = 0.5", "step = 10.0"
    )
    assert "duration = 30000.0" in text and "step = 10.0" in text
    text += '\n[torques]\nhorizon_threshold = { value = 0.1, unit = "deg" }\n'
    path = folder / "spinner.toml"
    path.write_text(text)
    return path


def _children(pid: int) -> list[int]:
    path = Path(f"/proc/{pid}/task/{pid}/children")
    return [int(p) for p in path.read_text().split()] if path.exists() else []


def _ignored(pid: int, number: int = signal.SIGINT) -> bool | None:
    """Whether process ``pid`` ignores signal ``number`` (its SigIgn mask in /proc), or
    None once it has ended."""
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except FileNotFoundError:
        return None
    mask = next(line.split()[1] for line in status.splitlines() if line.startswith("SigIgn:"))
    return bool(int(mask, 16) >> (number - 1) & 1)


def _start(command: list[str], preexec) -> tuple[subprocess.Popen, int, list[int]]:
    """Start ``command`` in its own process group; once the run streams and its process
    beside has started: (the process, the run's pid, the pids beside it)."""
    process = subprocess.Popen(
        command, stderr=subprocess.PIPE, text=True, start_new_session=True, preexec_fn=preexec
    )
    for line in process.stderr:
        if "sampling" in line:
            break
    children = _children(process.pid)
    while not children and process.poll() is None:  # forked as the stream starts
        time.sleep(0.01)
        children = _children(process.pid)
    assert children, "no process beside the run"
    return process, process.pid, children


def _run(scenario: Path, out: Path) -> list[str]:
    return [sys.executable, "-m", "attitude", "run", str(scenario), "--out", str(out)]


def _finished(process: subprocess.Popen, out: Path) -> None:
    rest = process.stderr.read()
    assert process.wait(timeout=120) == 0, rest
    assert "attitude: error" not in rest and "Traceback" not in rest, rest
    summary = json.loads((out / "summary.json").read_text())
    assert summary["torques"]["validity_horizon"]["searched_s"] > 0.0
    assert (out / "report.html").is_file()


@linux_only
@pytest.mark.skipif(shutil.which("nohup") is None, reason="needs nohup")
def test_a_hangup_does_not_stop_a_run_under_nohup(tmp_path):
    """`nohup attitude run` used to end at a hangup with exit 129: the command put its
    own SIGHUP handler over the SIG_IGN that nohup had set."""
    out = tmp_path / "out"
    command = ["nohup", *_run(_spinner(tmp_path), out)]
    process, _, _ = _start(command, defaults)  # nohup itself sets SIGHUP to SIG_IGN
    os.killpg(process.pid, signal.SIGHUP)  # the terminal hangs up: the whole group
    _finished(process, out)


@linux_only
def test_a_background_job_ignores_the_groups_ctrl_c_and_keeps_its_process_beside(tmp_path):
    """A run started with SIGINT ignored used to lose its process beside to a SIGINT
    sent to the group (the child reset SIGINT to its default action), then end with
    'internal error ... a bug', exit 3."""
    out = tmp_path / "out"
    process, _, children = _start(_run(_spinner(tmp_path), out), starting_with(signal.SIGINT))
    for pid in children:  # ignoring SIGINT as its caller asked (if not already done)
        assert _ignored(pid) in (None, True), pid
    os.killpg(process.pid, signal.SIGINT)
    _finished(process, out)  # exit 0, the horizon beside it computed: not killed


@linux_only
@pytest.mark.parametrize(
    ("number", "code", "said"),
    [(signal.SIGINT, 130, "interrupted"), (signal.SIGKILL, 137, "stopped by SIGKILL")],
    ids=["SIGINT", "SIGKILL (the kernel's, when memory runs out)"],
)
def test_a_signal_that_kills_the_process_beside_stops_the_run_as_that_signal(
    tmp_path, number, code, said
):
    """The process beside the run, killed by a signal the run did not get: the run
    ends with that signal's exit status and one line, and leaves nothing behind."""
    out = tmp_path / "out"
    process, _, children = _start(_run(_spinner(tmp_path), out), defaults)
    for pid in children:
        os.kill(pid, number)
    rest = process.stderr.read()
    assert process.wait(timeout=120) == code, rest
    lines = [line for line in rest.splitlines() if not line.startswith("[")]
    assert lines == [
        f"attitude: error: {said} (the process computing beside the run got "
        f"{signal.Signals(number).name}); nothing of this run was left behind"
    ], rest
    assert not out.exists() or not any(out.iterdir())
