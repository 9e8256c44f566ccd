"""How much a run writes and holds in memory, and whether that fits: decided before
anything is sampled.

A run streams its outputs (``attitude.report.run``): it holds one chunk of the output
grid at a time, whatever the span, so its memory is a constant (the libraries, the
Sun and orbit nodes of the pointing, a chunk) and only the disk grows with the span.
:func:`estimate` counts both from the scenario and the chosen formats;
:func:`check_fits` refuses a run that would not fit in the memory available now or
on the disk that takes its outputs, with one message that states the sizes.

The work of the pointing's interval search (64 samples a turn of the fastest
rotation, over the whole span, and an interval per turn) is bounded where the search
is planned (:data:`attitude.pointing.search.MAX_SEARCH_POINTS`); here it sizes
intervals.csv.

The figures are measured (``benchmarks/report_one_day.py`` and
``report_outputs.py``, docs/benchmarks.md, on the 2-core development machine, with
margins of 1.3 to 1.5): peak RSS 195–215 MB for one day or 30 at 1 s (the time series;
with a TLE the orbit's nodes and the intervals add to it); 651 bytes a row of CSV for
41 columns (15 a shortest round-trip number, 30 the epoch), 6.2 bytes a column of
Parquet (zstd), 187 bytes an AEM record.
"""

from __future__ import annotations

import math
import os
import shutil
from dataclasses import dataclass, field
from pathlib import Path

from attitude.base.errors import InputError

__all__ = [
    "JobFolderSize",
    "OutputBudget",
    "ResourceError",
    "about_text",
    "available_memory_bytes",
    "check_fits",
    "check_table_fits",
    "estimate",
    "free_disk_bytes",
    "size_text",
    "table_size_text",
]

# Memory of a run: the libraries and the pointing's nodes, plus one chunk of samples
# (bytes; measured, with a margin).
_BASE_MEMORY = 300_000_000
_MEMORY_PER_CHUNK_SAMPLE = 2_500
_MEMORY_PER_CHUNK_SAMPLE_PER_VECTOR = 500
# File bytes per output epoch: the time text and each number of the CSV; each column
# of the Parquet file (zstd; the text, tt_ns and timestamp_tt included); a record of
# the AEM.
_CSV_TIME_BYTES = 31
_CSV_BYTES_PER_COLUMN = 20
_PARQUET_BYTES_PER_COLUMN = 8
_AEM_BYTES_PER_RECORD = 190
_PLOT_BYTES = 250_000
_SUMMARY_BYTES = 50_000
_TRAJECTORY_COLUMNS = 16
# The share of the memory available, and of the free disk, that a run may take.
MEMORY_SHARE = 0.8
DISK_SHARE = 0.95


class ResourceError(InputError):
    """A run would not fit in memory or on disk; the message states the sizes."""


@dataclass(frozen=True)
class OutputBudget:
    """What a run will write (bytes per file) and hold, from :func:`estimate`."""

    samples: int
    search_grid_points: int
    memory_bytes: int
    files: dict[str, int] = field(default_factory=dict)

    @property
    def disk_bytes(self) -> int:
        return sum(self.files.values())

    def describe(self) -> str:
        shown = ", ".join(f"{name} {_size(size)}" for name, size in self.files.items())
        return (
            f"{self.samples} samples; writes about {_size(self.disk_bytes)} ({shown}), "
            f"holds about {_size(self.memory_bytes)} in memory"
        )


def _size(count: float) -> str:
    for unit in ("bytes", "kB", "MB", "GB", "TB", "PB"):
        if count < 1000.0 or unit == "PB":
            return f"{count:.0f} {unit}" if unit == "bytes" else f"{count:.3g} {unit}"
        count /= 1000.0
    raise AssertionError


def estimate(
    samples: int,
    search_grid_points: int = 0,
    body_vectors: int = 0,
    on_orbit: bool = False,
    formats: tuple[str, ...] = ("csv", "aem", "plots", "report"),
    aem_records: int | None = None,
    chunk_samples: int = 16384,
    pointing_columns: int | None = None,
) -> OutputBudget:
    """The memory and file sizes of a run with ``samples`` output epochs.

    ``search_grid_points``: the interval search grid of the pointing (0 without one),
    ``body_vectors`` and ``on_orbit``: the pointing columns; ``formats``: the chosen
    outputs; ``aem_records``: the AEM's records (``attitude.outputs.aem_sampling``; the
    output epochs when None); ``pointing_columns``: the time series' pointing columns
    (``attitude.outputs.csv.pointing_column_count``; without it, the fewest a pointing
    with these vectors can have: 3, and 5 a vector).  Python ints: a hostile span of
    1e9 s every 1e-3 s is 1e12 samples, and is counted, not allocated.
    """
    columns = _TRAJECTORY_COLUMNS
    pointing = bool(body_vectors or on_orbit)
    if pointing_columns is not None:
        columns += pointing_columns
    elif pointing:
        columns += 3 + 5 * body_vectors
    chunk = min(samples, chunk_samples)
    memory = _BASE_MEMORY + chunk * (
        _MEMORY_PER_CHUNK_SAMPLE + _MEMORY_PER_CHUNK_SAMPLE_PER_VECTOR * body_vectors
    )
    files: dict[str, int] = {}
    if "csv" in formats:
        files["timeseries.csv"] = samples * (_CSV_TIME_BYTES + _CSV_BYTES_PER_COLUMN * columns)
    if "parquet" in formats:
        # The text, tt_ns and timestamp_tt beside the CSV's number columns.
        files["timeseries.parquet"] = samples * _PARQUET_BYTES_PER_COLUMN * (columns + 3)
    if "aem" in formats:
        records = samples if aem_records is None else aem_records
        files["attitude.aem"] = records * _AEM_BYTES_PER_RECORD
    if "plots" in formats:
        files["plots"] = 4 * _PLOT_BYTES
    if pointing:
        # A Sun-visibility window a turn per vector at most, ~100 bytes a line.
        files["intervals.csv"] = min(search_grid_points // 32, 10**15) * 100 * body_vectors
    files["summary.json"] = _SUMMARY_BYTES
    return OutputBudget(samples, search_grid_points, memory, files)


def available_memory_bytes() -> float:
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


def free_disk_bytes(out_dir: str | Path) -> int:
    """The free space of the disk that will hold ``out_dir`` (it need not exist yet)."""
    return shutil.disk_usage(_existing(Path(out_dir))).free


# A job's folder (a Monte Carlo job's samples, an envelope's failures), measured on
# the writers (tests/test_job_size_estimate_against_the_writers.py holds the estimate
# to between 1 and 2 times what they write; 1.09 to 1.42 measured, 3 to 1000 rows).
# A cell of the table is 11 to 19 bytes of CSV (the envelope's many "inf", the Monte
# Carlo's 17 digits) and up to 8 of Parquet (full-entropy floats): each job says its
# own (JobFolderSize.cell); each column costs its Parquet metadata and its entries in
# the job's JSON and page (.per_column), the figures a fixed size (.fixed).  While
# the job runs its checkpoint holds the table too (attitude.jobs.checkpoint): a few
# bytes a cell (.checkpoint_cell), its own columns (.checkpoint_row), and a part's
# metadata (290 bytes a column) for each of at most about a hundred parts; it is
# removed once the outputs are written, and both are counted, at their peak.
_CHECKPOINT_PART_COLUMN_BYTES = 290
_CHECKPOINT_PARTS = 100


@dataclass(frozen=True)
class JobFolderSize:
    """What a job's folder takes (bytes): a cell of its table in the outputs
    (``cell``: CSV and Parquet) and in the checkpoint (``checkpoint_cell``); each
    column (``per_column``: its Parquet metadata, its statistics, its line of the
    page); the figures and the rest (``fixed``), and what a figure of a point a row
    grows by (``figure_per_row``, up to ``figure_growth_at_most``: its lines fill the
    image, which compresses less until it is filled); and each row of the checkpoint
    beyond its cells (``checkpoint_row``: the Monte Carlo's Sun-angle extremes)."""

    cell: int
    per_column: int
    fixed: int
    checkpoint_cell: int
    checkpoint_row: int = 0
    figure_per_row: int = 0
    figure_growth_at_most: int = 0

    def outputs_bytes(self, rows: int, columns: int) -> int:
        figure = min(rows * self.figure_per_row, self.figure_growth_at_most)
        return rows * columns * self.cell + columns * self.per_column + self.fixed + figure

    def checkpoint_bytes(self, rows: int, columns: int) -> int:
        cells = rows * (columns * self.checkpoint_cell + self.checkpoint_row)
        parts = min(rows, _CHECKPOINT_PARTS) * columns * _CHECKPOINT_PART_COLUMN_BYTES
        return cells + parts


def check_table_fits(
    out_dir: str | Path,
    rows: int,
    columns: int,
    noun: str,
    size: JobFolderSize,
    advice: str = "",
) -> None:
    """Refuse (:class:`ResourceError`, key ``--out``) a job of ``rows`` ``noun`` in
    ``columns`` whose outputs and checkpoint (``size``) would take more than
    :data:`DISK_SHARE` of the free space of the disk that holds ``out_dir``;
    ``advice`` ends the message."""
    outputs = size.outputs_bytes(rows, columns)
    need = outputs + size.checkpoint_bytes(rows, columns)
    free = free_disk_bytes(out_dir)
    if need > DISK_SHARE * free:
        raise ResourceError(
            f"{out_dir}: the job's {rows:,} {noun} would take about {_size(need)} (the "
            f"outputs {_size(outputs)}, and its checkpoint while it runs), and its disk "
            f"has {_size(free)} free{advice}",
            key="--out",
            value=str(out_dir),
        )


# The CPU seconds a job's table takes to write as CSV and Parquet, a cell (pandas and
# pyarrow; 3.7 s for 200 000 rows of 21 columns on the development machine, idle).
_TABLE_WRITE_S_PER_CELL = 0.9e-6


def table_size_text(table) -> str:
    """A table's size as a stage line says it: "1,234 rows of 40 columns", and the
    time its writing takes when that is more than a few seconds."""
    rows, columns = table.shape
    return (
        f"{rows:,} rows of {columns} columns{about_text(rows * columns * _TABLE_WRITE_S_PER_CELL)}"
    )


def about_text(seconds: float) -> str:
    """ ", about 12 s" for a stage that takes a while (nothing under 3 s)."""
    if seconds < 3.0:
        return ""
    return f", about {seconds:.0f} s" if seconds < 120 else f", about {seconds / 60:.0f} min"


def size_text(count: float) -> str:
    """A byte count as people read it: 35.2 GB."""
    return _size(count)


def check_fits(
    budget: OutputBudget, out_dir: str | Path | None = None, shown: str | None = None
) -> None:
    """Refuse (:class:`ResourceError`) a run that would not fit in :data:`MEMORY_SHARE`
    of the memory available, or in :data:`DISK_SHARE` of the free space of the disk that
    holds ``out_dir`` (not checked when None; named ``shown`` in the error if given)."""
    memory = available_memory_bytes()
    if budget.memory_bytes > MEMORY_SHARE * memory:
        raise ResourceError(
            f"a run holds about {_size(budget.memory_bytes)} of memory whatever its "
            f"span, and {_size(memory)} is available: free some memory",
            key="output",
        )
    if out_dir is None:
        return
    free = free_disk_bytes(out_dir)
    if budget.disk_bytes > DISK_SHARE * free:
        largest = max(budget.files, key=budget.files.__getitem__)
        raise ResourceError(
            f"{budget.samples} samples would take about {_size(budget.disk_bytes)} "
            f"({largest} {_size(budget.files[largest])}), and the disk of "
            f"{shown or out_dir} has "
            f"{_size(free)} free: use a longer output.step, a shorter span, fewer --formats "
            "(parquet is smaller than csv) or another disk",
            key="output.step",
        )
