"""How much a run writes and holds in memory, and whether that fits: decided before
anything is sampled.

A run holds its whole output grid in memory (the trajectory, the pointing, the CSV
text of each row as it is written) and writes a CSV row and an AEM record per output
epoch.  :func:`estimate` counts that from the scenario alone; :func:`check_fits`
refuses a run whose outputs would not fit in the memory available now or on the disk
that takes them, with one message that states the sizes.  Both live here, and only
here, so that when long runs stream their outputs in chunks, the memory term is what
changes.

The figures per sample are measured on one case each, with a margin of about 1.5:
``attitude run`` of a body with moments (10, 20, 25) kg m² and no pointing, every
1 s over 1e5 and 4e5 s, peaked at 251 and 606 MB (1.2 kB a sample) and wrote 279
bytes of CSV and 187 bytes of AEM a sample; the pointing search grid of a tumbler at
2 rad/s with two body vectors cost 173 bytes a point (peak RSS from
``/usr/bin/time``, on the 2-core development machine).
"""

from __future__ import annotations

import math
import os
import shutil
from dataclasses import dataclass
from pathlib import Path

from attitude.errors import InputError

__all__ = ["OutputBudget", "ResourceError", "available_memory_bytes", "check_fits", "estimate"]

# Memory a run holds per output epoch, per search-grid point, and per body vector on
# each (bytes; measured, with a margin of about 1.5).
_MEMORY_PER_SAMPLE = 1_800
_MEMORY_PER_SAMPLE_PER_VECTOR = 400
_MEMORY_PER_GRID_POINT = 300
_MEMORY_PER_GRID_POINT_PER_VECTOR = 100
# File bytes per output epoch: the time text and each %.17g column of the CSV; a
# record of the AEM.  Plus the plots, page and summary.
_CSV_TIME_BYTES = 32
_CSV_BYTES_PER_COLUMN = 25
_TRAJECTORY_COLUMNS = 16
_AEM_BYTES_PER_SAMPLE = 200
_FIXED_FILE_BYTES = 2_000_000
# The share of the memory available, and of the free disk, that a run may take.
MEMORY_SHARE = 0.8
DISK_SHARE = 0.95


class ResourceError(InputError):
    """A run would not fit in memory or on disk; the message states the sizes."""


@dataclass(frozen=True)
class OutputBudget:
    """What a run will write and hold (bytes), from :func:`estimate`."""

    samples: int
    search_grid_points: int
    memory_bytes: int
    csv_bytes: int
    aem_bytes: int
    other_bytes: int

    @property
    def disk_bytes(self) -> int:
        return self.csv_bytes + self.aem_bytes + self.other_bytes

    def describe(self) -> str:
        return (
            f"{self.samples} samples; writes about {_size(self.disk_bytes)} "
            f"(timeseries.csv {_size(self.csv_bytes)}, attitude.aem {_size(self.aem_bytes)}), "
            f"holds about {_size(self.memory_bytes)} in memory"
        )


def _size(count: float) -> str:
    for unit in ("bytes", "kB", "MB", "GB", "TB", "PB"):
        if count < 1000.0 or unit == "PB":
            return f"{count:.0f} {unit}" if unit == "bytes" else f"{count:.3g} {unit}"
        count /= 1000.0
    raise AssertionError


def estimate(
    samples: int, search_grid_points: int = 0, body_vectors: int = 0, on_orbit: bool = False
) -> OutputBudget:
    """The memory and file sizes of a run with ``samples`` output epochs.

    ``search_grid_points``: the interval search grid of the pointing (0 without one),
    ``body_vectors`` and ``on_orbit``: the pointing columns.  Python ints: a hostile
    span of 1e9 s every 1e-3 s is 1e12 samples, and is counted, not allocated.
    """
    columns = _TRAJECTORY_COLUMNS
    if body_vectors or on_orbit:
        columns += 3 + (2 if on_orbit else 0) + 6 * body_vectors
    memory = samples * (_MEMORY_PER_SAMPLE + _MEMORY_PER_SAMPLE_PER_VECTOR * body_vectors)
    memory += search_grid_points * (
        _MEMORY_PER_GRID_POINT + _MEMORY_PER_GRID_POINT_PER_VECTOR * body_vectors
    )
    return OutputBudget(
        samples=samples,
        search_grid_points=search_grid_points,
        memory_bytes=memory,
        csv_bytes=samples * (_CSV_TIME_BYTES + _CSV_BYTES_PER_COLUMN * columns),
        aem_bytes=samples * _AEM_BYTES_PER_SAMPLE,
        other_bytes=_FIXED_FILE_BYTES,
    )


def available_memory_bytes() -> int:
    """The memory available to a new allocation now: ``MemAvailable`` from
    /proc/meminfo (Linux: free memory plus the caches that can be dropped), else the
    free physical pages; unbounded if the system says neither."""
    try:
        with open("/proc/meminfo", encoding="ascii") as stream:
            for line in stream:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return math.inf


def _existing(path: Path) -> Path:
    """``path`` or its nearest existing ancestor (where its files will be written)."""
    path = path.expanduser().absolute()
    for candidate in (path, *path.parents):
        if candidate.exists():
            return candidate
    return Path(path.anchor)


def check_fits(budget: OutputBudget, out_dir: str | Path | None = None) -> None:
    """Refuse (:class:`ResourceError`) a run that would not fit in :data:`MEMORY_SHARE`
    of the memory available, or in :data:`DISK_SHARE` of the free space of the disk
    that holds ``out_dir`` (not checked when None)."""
    memory = available_memory_bytes()
    if budget.memory_bytes > MEMORY_SHARE * memory:
        grid = budget.search_grid_points
        if grid > budget.samples:  # the pointing search, not the output grid, is the cost
            what = (
                f"the pointing's interval search ({grid} points: 64 a turn of the fastest "
                "rotation over the span)"
            )
            remedy = "a shorter span"
        else:
            what = f"{budget.samples} samples"
            remedy = "a longer output.step or a shorter span"
        raise ResourceError(
            f"output: {what} would need about {_size(budget.memory_bytes)} of memory, and "
            f"{_size(memory)} is available: use {remedy}"
        )
    if out_dir is None:
        return
    free = shutil.disk_usage(_existing(Path(out_dir))).free
    if budget.disk_bytes > DISK_SHARE * free:
        raise ResourceError(
            f"output: the outputs would take about {_size(budget.disk_bytes)}, and the disk "
            f"of {out_dir} has {_size(free)} free: use a longer output.step, a shorter span "
            "or another disk"
        )
