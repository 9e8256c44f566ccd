"""The command's clock (attitude.base.progress.process_started_at) against the process's
real start: the time since Python started, not since a shell forked the process that
later became Python (``sh -c "...; exec attitude ..."``, as a shell runs its last
command)."""

import subprocess
import sys
from pathlib import Path

import pytest

linux_only = pytest.mark.skipif(not Path("/proc/self/stat").is_file(), reason="needs /proc")

_AGE = (
    "import time; from attitude.base.progress import process_started_at; "
    "print(time.perf_counter() - process_started_at())"
)


@linux_only
def test_a_python_started_by_exec_after_a_wait_counts_from_its_own_start():
    done = subprocess.run(
        ["sh", "-c", f'sleep 2; exec "{sys.executable}" -c "{_AGE}"'],
        capture_output=True,
        text=True,
        check=True,
    )
    age = float(done.stdout)
    assert 0.0 <= age < 1.5, age  # the shell's 2 s wait is not the command's


@linux_only
def test_a_python_started_directly_counts_its_start_up():
    done = subprocess.run([sys.executable, "-c", _AGE], capture_output=True, text=True, check=True)
    age = float(done.stdout)
    assert 0.0 <= age < 5.0, age
