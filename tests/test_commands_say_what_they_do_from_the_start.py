"""`check` and `run` say on stderr what they are doing from their first second, on a
clock that starts with their process.

`check` used to print nothing until it ended, and `run` nothing until its planning
was done (150 s for a one-day torqued CubeSat on a loaded machine), its clock started
then, so that `done` stated less than the wall time.  Read against the kernel's own
record of when the process started (psutil's create_time): each line's time is that
process's age when it was written, no more (never ahead of the kernel's clock), and
not a planning's length less.  The stages come in the order they are done, the
planning's before the sampling; `--quiet` says nothing.

No margin of wall time: a loaded machine delays when a line is read, not when it was
written, so the age at reading bounds the stated times from above only.  From below
they are bounded by the CPU the process had used (its own, one thread: its wall time
is at least that), read when the line before the last was read: the last line states
at least that, less what Python spends before the command reads its clock and the
exit after the last line (half a second of CPU is far more).  A clock started after
the planning (seconds of CPU here) states less by the planning's CPU.
"""

import os
import re
import subprocess
import sys
import time
from pathlib import Path

import psutil
from signal_dispositions import defaults

ROOT = Path(__file__).parents[1]
SCENARIO = ROOT / "scenarios" / "tumbler_gravity_gradient_burn.toml"  # seconds of planning
LINE = re.compile(r"^\[ *(\d+\.\d) s\] (.*)$")
# One thread of computation, so that the process's CPU time is at most its age.
ONE_THREAD = {name: "1" for name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")}
# The CPU a command spends outside its clock: Python's start before the clock is read
# (about 0.05 s), and the exit after its last line.
OUTSIDE_THE_CLOCK_CPU_S = 0.5


def _command(*args: str) -> tuple[list[tuple[float, float, float, str]], str, int]:
    """Run ``attitude ARGS``: its progress lines as (age of the process when read, CPU
    it had used then, time the line states, text), its stdout, its exit status."""
    process = subprocess.Popen(
        [sys.executable, "-m", "attitude", *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=defaults,
        env=dict(os.environ, **ONE_THREAD),
    )
    watched = psutil.Process(process.pid)
    created = watched.create_time()
    lines = []
    cpu = 0.0
    for line in process.stderr:
        age = time.time() - created
        try:  # its own, not the process it may fork beside it
            cpu = watched.cpu_times().user + watched.cpu_times().system
        except psutil.Error:  # gone (a zombie's times are read): the last reading stands
            pass
        found = LINE.match(line.rstrip("\n"))
        assert found, line  # nothing but progress lines
        lines.append((age, cpu, float(found.group(1)), found.group(2)))
    out = process.stdout.read()
    return lines, out, process.wait(timeout=300)


def _stages(lines) -> list[str]:
    return [text.split(" ")[0] for *_, text in lines]


def _on_the_process_clock(lines) -> None:
    for age, _, stated, text in lines:
        assert stated <= age + 0.15, (stated, age, text)  # 0.1 s rounding, 10 ms ticks
    _, cpu_before, _, _ = lines[-2]
    *_, stated, text = lines[-1]
    # Not a planning's length short.
    assert stated >= cpu_before - OUTSIDE_THE_CLOCK_CPU_S, (stated, cpu_before, text)


def test_check_says_each_stage_as_it_starts():
    lines, out, code = _command("check", str(SCENARIO))
    assert code == 0 and ": OK" in out
    stages = _stages(lines)
    assert stages[0] == "reading" and lines[0][2] < lines[-1][2]
    expected = ["reading", "propagating", "analysing", "checking", "choosing"]
    assert [s for s in stages if s in expected] == expected, stages
    # The step for the accuracy is chosen on the run's error estimate, while propagating.
    propagating = next(text for *_, text in lines if text.startswith("propagating"))
    assert "error estimate" in propagating and "1e-06 rad" in propagating, propagating
    _on_the_process_clock(lines)


def test_run_says_its_planning_before_it_samples_and_done_states_the_wall_time(tmp_path):
    out = tmp_path / "out"
    lines, _, code = _command("run", str(SCENARIO), "--out", str(out), "--formats", "csv")
    assert code == 0 and (out / "timeseries.csv").is_file()
    stages = _stages(lines)
    assert stages[0] == "reading" and stages[-1] == "done:", stages
    assert stages.index("propagating") < stages.index("analysing") < stages.index("sampling")
    _on_the_process_clock(lines)


def test_quiet_says_nothing(tmp_path):
    lines, out, code = _command("check", str(SCENARIO), "--quiet")
    assert code == 0 and ": OK" in out and lines == []
