"""Stage messages for a user who waits: what is being done, and since when.

:class:`Progress` writes ``[   12.3 s] message`` lines (the command line writes them
to stderr), its clock counted from ``start``.  The command line counts from the
start of its own process (:func:`process_started_at`), so that the first line comes
within the first second and the last one, ``done``, states the whole wall time the
user waited, imports and checks included.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from pathlib import Path

__all__ = ["Progress", "process_started_at"]

_IMPORTED = time.perf_counter()


class Progress:
    """Stage messages with the time since ``start`` (a ``time.perf_counter()`` value;
    default: now), to ``write`` (nothing when None)."""

    def __init__(self, write: Callable[[str], None] | None = None, start: float | None = None):
        self._write = write
        self._start = time.perf_counter() if start is None else start

    @property
    def elapsed_s(self) -> float:
        return time.perf_counter() - self._start

    def __call__(self, message: str) -> None:
        if self._write is not None:
            self._write(f"[{self.elapsed_s:7.1f} s] {message}")


def process_started_at() -> float:
    """The ``time.perf_counter()`` reading at which this process started: on Linux from
    ``/proc`` (its start time in clock ticks since boot, against the time since boot,
    both to 10 ms), elsewhere when this module was first imported."""
    try:
        stat = Path("/proc/self/stat").read_text()
        # Field 22, starttime, counted from field 3, after the command's "(name)".
        start_ticks = int(stat.rsplit(")", 1)[1].split()[19])
        since_boot = float(Path("/proc/uptime").read_text().split()[0])
        age = since_boot - start_ticks / os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError, IndexError, AttributeError):
        return _IMPORTED
    now = time.perf_counter()
    since_import = now - _IMPORTED
    # The process began before this import, and not much before it: /proc counts from
    # the fork, and a shell that runs its last command by exec (``sh -c "pip install .
    # && attitude run ..."``) forked this process before everything it ran first, while
    # it slept waiting for them.  Python's start, before the import here, runs: its
    # time is the time this process has been on a CPU or waiting for one (however
    # loaded the machine), and a little reading of files.  Otherwise (that, or clocks
    # that disagree: a container's /proc/uptime, say) the import is close.
    plausible = since_import + _running_s() + 0.5
    return now - age if since_import - 0.1 <= age <= plausible else _IMPORTED


def _running_s() -> float:
    """The time this process has spent on a CPU or runnable, waiting for one, since its
    fork (Linux's /proc/self/schedstat, ns); where that is not kept, five times its
    CPU time (Python's start on a machine under some load)."""
    try:
        on_cpu, waiting = Path("/proc/self/schedstat").read_text().split()[:2]
        return (int(on_cpu) + int(waiting)) * 1e-9
    except (OSError, ValueError):
        return 5.0 * time.process_time()
