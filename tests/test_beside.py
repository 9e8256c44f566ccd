"""The validity horizon computed in a process beside the run (attitude.report.beside).

Against the same computation in the process itself: the same value (bit for bit)
and the same exception; a child still running when the block is left (an error, a
signal) is killed and reaped.  Through the real command line: SIGINT and SIGTERM
while the horizon's process runs give one line and exit codes 130 and 143, leave the
output folder as it was, and leave no process behind; `run` writes the same
summary.json as the horizon computed in the run's own process.  A span the averaged
kicks' screen finds clear is answered without a process; a horizon within the span is
the splitting's, computed beside.
"""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from signal_dispositions import defaults

import attitude.report.beside
from attitude.files.scenario_reader import load_scenario
from attitude.outputs.formats import OutputChoice
from attitude.report.beside import Beside
from attitude.report.plan import horizon_beside, plan_run
from attitude.report.run import write_report
from attitude.trajectory.horizon import validity_horizon

ROOT = Path(__file__).parents[1]
linux_only = pytest.mark.skipif(not Path("/proc/self/task").is_dir(), reason="needs /proc")


def _spinner(folder: Path, duration: float, step: float, threshold_deg: float = 1.0) -> Path:
    """The spinner example over ``duration`` at ``step``; below a threshold of about
    0.1° its horizon falls within a day and needs the splitting beside the run."""
    text = (ROOT / "scenarios" / "spinner_thruster_pulse.toml").read_text()
    text = text.replace("duration = 3600.0", f"duration = {duration!r}")
    text = text.replace("step = 0.5", f"step = {step!r}")
    assert f"duration = {duration!r}" in text and f"step = {step!r}" in text
    text += f'\n[torques]\nhorizon_threshold = {{ value = {threshold_deg!r}, unit = "deg" }}\n'
    path = folder / "spinner.toml"
    path.write_text(text)
    return path


def _fail(message):
    raise ValueError(message)


def _alive(pid: int) -> bool:
    """True while ``pid`` exists and is not a zombie."""
    try:
        status = Path(f"/proc/{pid}/stat").read_text()
    except FileNotFoundError:
        return False
    return status.rsplit(")", 1)[1].split()[0] != "Z"


def test_the_value_is_the_one_computed_here(tmp_path):
    loaded = load_scenario(_spinner(tmp_path, 600.0, 10.0))
    plan = plan_run(loaded.scenario, loaded.pointing, horizon=False)
    assert plan.horizon is None and plan.horizon_deferred
    here = validity_horizon(plan.trajectory, loaded.pointing.orbit)
    with Beside(validity_horizon, plan.trajectory, loaded.pointing.orbit) as beside:
        assert beside.result() == here
        assert beside.result() == here  # asked twice: the same, the child reaped once


def test_a_span_the_screen_finds_clear_is_answered_without_a_process(tmp_path):
    """The hour of the spinner: its averaged kicks stay below half of 1°, so the run's
    horizon is the screen's, computed in the run's own process (no fork: cheaper)."""
    loaded = load_scenario(_spinner(tmp_path, 3600.0, 10.0))
    plan = plan_run(loaded.scenario, loaded.pointing, horizon=False)
    with horizon_beside(plan) as beside:
        assert _children(os.getpid()) == []
        found = beside.result()
    assert found == validity_horizon(plan.trajectory, loaded.pointing.orbit)
    assert found.method == "averaged kicks" and not found.within_span


def test_a_horizon_within_the_span_is_the_splittings_beside(tmp_path):
    loaded = load_scenario(_spinner(tmp_path, 3600.0, 10.0, threshold_deg=0.01))
    plan = plan_run(loaded.scenario, loaded.pointing, horizon=False)
    with horizon_beside(plan) as beside:
        found = beside.result()
    assert found == validity_horizon(plan.trajectory, loaded.pointing.orbit)
    assert found.method == "splitting" and found.within_span


def test_an_exception_is_raised_in_the_parent():
    with Beside(_fail, "no orbit here") as beside, pytest.raises(ValueError, match="no orbit"):
        beside.result()


def test_without_fork_it_computes_in_the_parent(monkeypatch):
    monkeypatch.delattr(attitude.report.beside.os, "fork")
    with Beside(os.getpid) as beside:
        assert beside.result() == os.getpid()


@linux_only
def test_leaving_the_block_kills_and_reaps_a_running_child():
    with Beside(time.sleep, 600.0) as beside:
        pid = beside._pid
        assert pid is not None and _alive(pid)
    assert not _alive(pid)
    with pytest.raises(ChildProcessError):
        os.waitpid(pid, os.WNOHANG)  # reaped: no zombie of ours


def test_run_writes_the_summary_of_the_horizon_computed_in_process(tmp_path):
    loaded = load_scenario(_spinner(tmp_path, 1200.0, 10.0))
    formats = OutputChoice(("csv",))
    inline = plan_run(loaded.scenario, loaded.pointing, formats)
    assert inline.horizon is not None and not inline.horizon_deferred
    write_report(loaded.scenario, tmp_path / "inline", loaded.pointing, "spinner.toml", plan=inline)
    beside = plan_run(loaded.scenario, loaded.pointing, formats, horizon=False)
    write_report(loaded.scenario, tmp_path / "beside", loaded.pointing, "spinner.toml", plan=beside)
    first = (tmp_path / "inline" / "summary.json").read_bytes()
    assert first == (tmp_path / "beside" / "summary.json").read_bytes()
    assert json.loads(first)["torques"]["validity_horizon"]["searched_s"] == 1200.0


def _children(pid: int) -> list[int]:
    path = Path(f"/proc/{pid}/task/{pid}/children")
    return [int(p) for p in path.read_text().split()] if path.exists() else []


@linux_only
@pytest.mark.parametrize(("number", "code"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
@pytest.mark.parametrize("group", [False, True], ids=["to the run", "to its group (a terminal)"])
def test_a_signal_while_the_horizon_runs_leaves_one_line_and_no_process(
    tmp_path, number, code, group
):
    # At 0.1° the averaged kicks' screen finds half of it crossed: the splitting runs
    # beside, thousands of steps (seconds).
    scenario = _spinner(tmp_path, 30000.0, 10.0, threshold_deg=0.1)
    out = tmp_path / "out"
    process = subprocess.Popen(
        [sys.executable, "-m", "attitude", "run", str(scenario), "--out", str(out)],
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        preexec_fn=defaults,  # not the ignored SIGINT of a `pytest &`
    )
    for line in process.stderr:
        if "sampling" in line:
            break
    children = _children(process.pid)
    while not children and process.poll() is None:  # forked as the stream starts
        time.sleep(0.01)
        children = _children(process.pid)
    assert children, "no process beside the run"
    if group:  # the run and the process beside it get the signal, as from a Ctrl-C
        os.killpg(process.pid, number)
    else:
        process.send_signal(number)
    rest = process.stderr.read()
    assert process.wait(timeout=60) == code, rest
    lines = [line for line in rest.splitlines() if not line.startswith("[")]
    assert len(lines) == 1 and lines[0].startswith("attitude: error:"), rest
    assert "Traceback" not in rest
    assert not out.exists() or not any(out.iterdir())
    # Killed by the run (or, if it left one, by its own signal): gone before the hang
    # guard, however loaded the machine.
    hang_guard = time.monotonic() + 120.0
    while any(_alive(pid) for pid in children) and time.monotonic() < hang_guard:
        time.sleep(0.05)
    assert not any(_alive(pid) for pid in children)
