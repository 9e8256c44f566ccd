"""The command's clock (attitude.base.progress.process_started_at) against the process's
real start: the time since Python started, not since a shell forked the process that
later became Python (``sh -c "...; exec attitude ..."``, as a shell runs its last
command).

Read against the kernel's own accounts of the process, not against a wall-clock
margin: the time it has spent on a CPU or waiting for one since its fork
(/proc/self/schedstat), which a loaded machine lengthens as it lengthens the start
itself, and which a shell's wait for its other commands (asleep) does not.
"""

import os
import subprocess
import sys
from pathlib import Path

import pytest

linux_only = pytest.mark.skipif(
    not Path("/proc/self/schedstat").is_file(), reason="needs /proc/self/schedstat"
)

# The time the process has run or waited to run (s), the clock's age of the process,
# and that time again: it goes on as the process reads its clock.
_AGE = (
    "import time; from attitude.base.progress import process_started_at; "
    "running = lambda: sum(map(int, open('/proc/self/schedstat').read().split()[:2])) * 1e-9; "
    "before = running(); age = time.perf_counter() - process_started_at(); "
    "print(before, age, running())"
)
# /proc's start and uptime are in 10 ms ticks.
_TICKS_S = 0.02


def _ages(command: list[str], preexec_fn=None) -> tuple[float, float, float]:
    done = subprocess.run(
        command, capture_output=True, text=True, check=True, preexec_fn=preexec_fn
    )
    before, age, after = (float(word) for word in done.stdout.split())
    return before, age, after


@linux_only
def test_a_python_started_by_exec_after_a_wait_counts_from_its_own_start():
    _, age, running = _ages(["sh", "-c", f'sleep 2; exec "{sys.executable}" -c "{_AGE}"'])
    # The shell's 2 s asleep are not the command's: no more than what it ran.
    assert 0.0 <= age <= running + _TICKS_S, (age, running)


@linux_only
def test_a_python_started_directly_counts_its_start_up():
    # numpy first: a start-up of a tenth of a second or more, all before the clock.
    running, age, _ = _ages([sys.executable, "-c", f"import numpy; {_AGE}"])
    assert running > 0.05
    assert age >= running - _TICKS_S, (age, running)  # the whole start-up counted


@linux_only
@pytest.mark.skipif(not hasattr(os, "sched_setaffinity"), reason="needs CPU affinity")
def test_a_python_started_on_a_busy_cpu_counts_its_start_up():
    """A loaded machine: the command shares its CPU with a busy loop, at a lower
    priority, so that its start-up (some 50 ms of CPU) waits seconds for
    the CPU.  The clock used to take that for a shell's wait (a start before the
    import more than five times its CPU time, plus 0.5 s) and count from the import."""
    cpu = min(os.sched_getaffinity(0))

    def on_that_cpu(niceness: int = 0):
        os.sched_setaffinity(0, {cpu})
        os.nice(niceness)

    busy = subprocess.Popen([sys.executable, "-c", "while True: pass"], preexec_fn=on_that_cpu)
    try:
        start_up = "sum(range(1_000_000)); "  # before the clock is read
        command = [sys.executable, "-c", start_up + _AGE]
        running, age, _ = _ages(command, preexec_fn=lambda: on_that_cpu(15))
    finally:
        busy.kill()
        busy.wait()
    assert age >= running - _TICKS_S, (age, running)
