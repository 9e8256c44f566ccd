"""The CSV files of a run: the time series of a propagated scenario (its columns,
which the Parquet file shares, and the CSV) and intervals.csv (the JSON summary is
:mod:`attitude.report.summaries`).

The CSV opens with ``#`` lines that state the epoch and time scale, the frames, the
units and the quaternion convention; each column's name carries its frame and
unit (``omega_body_x_rad_s``, ``q_body_to_icrf_w``).  Each number is written as the
shortest text that reads back as the same double (17 significant digits at most:
``0.1``, not ``0.10000000000000001``), so a file read back gives the same doubles.

The CSV is written as it is computed, a chunk of rows at a time (:class:`CsvWriter`),
by Apache Arrow's CSV writer: its C++ number formatting is about three times as fast
as numpy's ``savetxt`` with ``%.17g`` (``benchmarks/report_outputs.py`` measures both).
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from pathlib import Path
from types import TracebackType
from typing import Any

import numpy as np
from numpy.typing import NDArray

from attitude.pointing.intervals import Interval
from attitude.pointing.sampling import PointingSamples, VectorSamples
from attitude.pointing.search import PointingAnalysis
from attitude.pointing.spec import PointingSpec
from attitude.trajectory.trajectory import Trajectory

__all__ = [
    "Column",
    "CsvWriter",
    "Samples",
    "arrow_texts",
    "pointing_column_count",
    "pointing_columns",
    "right_ascension_deg",
    "sample",
    "trajectory_columns",
    "write_csv",
    "write_intervals_csv",
]

QUATERNION_CONVENTION = (
    "quaternion q_body_to_icrf_(w,x,y,z): scalar first; rotates body coordinates into "
    "ICRF coordinates (v_icrf = q ⊗ (0, v_body) ⊗ q*); dq/dt = ½ q ⊗ (0, omega_body)"
)


@dataclass(frozen=True)
class Column:
    """One CSV column: its name (with frame and unit), values and a description."""

    name: str
    values: NDArray[np.float64]
    description: str


def _components(
    name: str, values: NDArray[np.float64], axes: str, description: str
) -> list[Column]:
    """One column per component: ``name`` with ``{}`` replaced by each axis letter."""
    return [Column(name.format(c), values[:, i], description) for i, c in enumerate(axes)]


@dataclass(frozen=True)
class Samples:
    """The trajectory evaluated once on the output grid, for the files and the plots."""

    seconds: NDArray[np.float64]
    quaternion: NDArray[np.float64]  # (w, x, y, z), body -> ICRF
    angular_velocity: NDArray[np.float64]  # body, rad/s
    angular_momentum: NDArray[np.float64]  # body, N m s
    inertial_angular_momentum: NDArray[np.float64]  # ICRF, N m s
    kinetic_energy: NDArray[np.float64]  # J
    segment: NDArray[np.intp]


def sample(trajectory: Trajectory, seconds: NDArray[np.float64]) -> Samples:
    """``trajectory`` at ``seconds`` (TT s since the epoch).

    A single epoch is evaluated as a pair and the first kept: numpy's matrix product
    takes another path for one row (``gemv``), which can differ in the last bit, and a
    stream's chunk of one epoch must write the digits the whole grid writes.
    """
    seconds = np.asarray(seconds, dtype=np.float64)
    if seconds.size == 1:
        pair = sample(trajectory, np.repeat(seconds, 2))
        return Samples(seconds, *(getattr(pair, f.name)[:1] for f in fields(Samples)[1:]))
    return Samples(
        seconds,
        trajectory.attitude_quaternion(seconds),
        trajectory.angular_velocity(seconds),
        trajectory.angular_momentum(seconds),
        trajectory.inertial_angular_momentum(seconds),
        trajectory.kinetic_energy(seconds),
        trajectory.segment_index(seconds),
    )


def trajectory_columns(samples: Samples) -> list[Column]:
    """Attitude, rates, momentum and energy: the columns of the time series."""
    return [
        Column("t_s", samples.seconds, "TT seconds since the scenario epoch"),
        *_components(
            "q_body_to_icrf_{}",
            samples.quaternion,
            "wxyz",
            "attitude quaternion, scalar first, body -> ICRF",
        ),
        *_components(
            "omega_body_{}_rad_s",
            samples.angular_velocity,
            "xyz",
            "angular velocity, body axes, rad/s",
        ),
        *_components(
            "h_body_{}_N_m_s",
            samples.angular_momentum,
            "xyz",
            "angular momentum, body axes, N m s",
        ),
        *_components(
            "h_icrf_{}_N_m_s",
            samples.inertial_angular_momentum,
            "xyz",
            "angular momentum, ICRF axes, N m s",
        ),
        Column("kinetic_energy_J", samples.kinetic_energy, "rotational kinetic energy, J"),
        Column(
            "segment",
            samples.segment.astype(float),
            "index of the motion segment (0 = before the first event)",
        ),
    ]


def arrow_numbers(values: NDArray, kind: Any = None) -> Any:
    """A numeric numpy array as an Arrow array of ``kind`` (float64 when None; any
    integer type, or a timestamp of int64 ``values``).

    Wrapped from the array's own buffer: ``pa.array`` would do the same, but its first
    call imports pandas (0.3 s) to ask whether the array is a pandas object.
    """
    import pyarrow as pa

    kind = pa.float64() if kind is None else kind
    dtype = np.float64 if pa.types.is_floating(kind) else np.dtype(f"int{kind.bit_width}")
    values = np.ascontiguousarray(values, dtype=dtype)
    return pa.Array.from_buffers(kind, values.size, [None, pa.py_buffer(values)])


def arrow_texts(epochs: NDArray) -> Any:
    """ASCII texts (numpy ``S`` or ``U`` arrays) as an Arrow string array; ``S`` arrays
    (:class:`attitude.environment.epoch_texts.EpochTexts`) are wrapped without a copy."""
    import pyarrow as pa

    epochs = np.asarray(epochs)
    if epochs.dtype.kind == "U":
        epochs = np.char.encode(epochs, "ascii")
    epochs = np.ascontiguousarray(epochs)
    width = epochs.dtype.itemsize
    offsets = np.arange(epochs.size + 1, dtype=np.int32) * width
    return pa.Array.from_buffers(
        pa.string(), epochs.size, [None, pa.py_buffer(offsets), pa.py_buffer(epochs)]
    )


class CsvWriter:
    """``timeseries.csv`` written a chunk of rows at a time.

    The ``#`` preamble goes first; the column descriptions and the header row are
    written with the first chunk, whose columns every later chunk must repeat.
    ``time_label`` names the first column (e.g. ``time_utc``), which holds each row's
    ISO 8601 epoch.  A context manager: the file is closed on exit.
    """

    def __init__(self, path: Path, time_label: str, preamble: list[str]) -> None:
        self.path = Path(path)
        self.time_label = time_label
        self._stream = open(self.path, "wb")
        self._stream.write("".join(f"# {line}\n" for line in preamble).encode("utf-8"))
        self._names: list[str] | None = None
        self._writer: Any = None  # a pyarrow.csv.CSVWriter (pyarrow is untyped)

    def write(self, epochs: NDArray, columns: list[Column]) -> None:
        """Append one row per epoch: ``epochs`` (ISO texts), then each column's value."""
        import pyarrow as pa
        import pyarrow.csv as pa_csv

        names = [c.name for c in columns]
        if self._names is None:
            header = ["# columns:"] + [f"#   {c.name}: {c.description}" for c in columns]
            header.append(",".join([self.time_label, *names]))
            self._stream.write(("\n".join(header) + "\n").encode("utf-8"))
            self._names = names
        elif names != self._names:
            raise ValueError(f"{self.path.name}: the columns changed between chunks")
        arrays = [arrow_texts(epochs)]
        arrays += [arrow_numbers(c.values) for c in columns]
        table = pa.Table.from_arrays(arrays, names=[self.time_label, *names])
        if self._writer is None:
            options = pa_csv.WriteOptions(include_header=False, quoting_style="none")
            self._writer = pa_csv.CSVWriter(self._stream, table.schema, write_options=options)
        self._writer.write_table(table)

    def close(self) -> None:
        if self._writer is not None:
            self._writer.close()
            self._writer = None
        self._stream.close()

    def __enter__(self) -> CsvWriter:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.close()


def write_csv(
    path: Path,
    epochs_iso: NDArray,
    time_label: str,
    columns: list[Column],
    preamble: list[str],
) -> None:
    """Write the time series at once: ``#`` preamble, a header row, one row per epoch.

    ``time_label`` names the first column (e.g. ``time_utc``); ``epochs_iso`` are its
    ISO 8601 texts.  A run writes its series in chunks, through :class:`CsvWriter`.
    """
    with CsvWriter(path, time_label, preamble) as writer:
        writer.write(epochs_iso, columns)


def right_ascension_deg(radians: NDArray[np.float64]) -> NDArray[np.float64]:
    """Right ascensions in degrees, in [0, 360): an angle a hair below 2π rounds to
    360.0 in degrees, which is written as 0."""
    degrees = np.mod(np.degrees(radians), 360.0)
    return np.where(degrees >= 360.0, 0.0, degrees)


def _flag(name: str, values, description: str) -> list[Column]:
    return [] if values is None else [Column(name, values.astype(float), description)]


def _degrees(name: str, values, description: str) -> list[Column]:
    return [] if values is None else [Column(name, np.degrees(values), description)]


def pointing_column_count(spec: PointingSpec) -> int:
    """How many columns :func:`pointing_columns` gives for ``spec``, known before
    anything is sampled (for the size estimate of ``attitude.outputs.budget``):
    the Sun's direction; on an orbit the lit fraction, the Earth's angular radius and
    the LVLH quaternion (and Euler angles when asked); per vector its Sun, Moon, RA
    and Dec columns and incidence, on an orbit its nadir and limb angles, and a flag
    per constraint (the Sun inclusion's says the Sun is in view)."""
    columns = 3
    if spec.on_orbit:
        columns += 2 + 4 + (3 if spec.lvlh_euler_sequence is not None else 0)
    for v in spec.body_vectors:
        columns += 5 + (2 if spec.on_orbit else 0)
        columns += sum(
            angle is not None
            for angle in (
                v.sun_exclusion_half_angle_rad,
                v.moon_exclusion_half_angle_rad,
                v.earth_limb_exclusion_angle_rad,
                v.sun_inclusion_half_angle_rad,
            )
        )
    return columns


def pointing_columns(samples: PointingSamples) -> list[Column]:
    """The pointing columns of the time series, at the samples' times (any chunk of
    the output grid: the columns of consecutive chunks follow on): the Sun and, on an
    orbit, the Earth; the attitude in LVLH; then each body vector's columns."""
    columns = _sun_and_earth_columns(samples) + _lvlh_columns(samples)
    for item in samples.vectors:
        columns += _vector_columns(item)
    return columns


def _sun_and_earth_columns(samples: PointingSamples) -> list[Column]:
    """The Sun's direction; on an orbit, its visible fraction and the Earth's angular radius."""
    columns = _components(
        "sun_icrf_{}",
        samples.sun_direction_icrf,
        "xyz",
        "apparent Sun direction from the spacecraft (unit), ICRF axes",
    )
    if samples.on_orbit:
        columns.append(
            Column("sunlit_fraction", samples.sunlit_fraction, "visible fraction of the Sun's disc")
        )
        columns += _degrees(
            "earth_angular_radius_deg",
            samples.earth_angular_radius_rad,
            "angular radius of the Earth (equatorial sphere) seen from the spacecraft, deg",
        )
    return columns


def _lvlh_columns(samples: PointingSamples) -> list[Column]:
    """The attitude in the orbit's LVLH frame: its quaternion, its Euler angles if asked."""
    columns: list[Column] = []
    if samples.q_body_to_lvlh is not None:
        columns += _components(
            "q_body_to_lvlh_{}",
            samples.q_body_to_lvlh,
            "wxyz",
            "attitude in the orbit's LVLH frame (z nadir, y -orbit normal), quaternion, "
            "scalar first (w >= 0), body -> LVLH",
        )
    sequence = samples.lvlh_euler_sequence
    if samples.lvlh_euler_deg is not None and sequence is not None:
        kind = "intrinsic" if sequence.isupper() else "extrinsic"
        columns += [
            Column(
                f"lvlh_euler_{sequence}_{k + 1}_deg",
                samples.lvlh_euler_deg[:, k],
                f"Euler angle {k + 1} of body -> LVLH, {kind} sequence {sequence} "
                f"(about {sequence[k]}), deg",
            )
            for k in range(3)
        ]
    return columns


def _vector_columns(item: VectorSamples) -> list[Column]:
    """A body vector's Sun and Moon angles, incidence, right ascension and declination,
    on an orbit its nadir and limb angles, and a flag per constraint."""
    name = item.vector.name
    columns = _degrees(f"{name}_sun_angle_deg", item.sun_angle_rad, f"angle {name}-Sun, deg")
    columns.append(
        Column(
            f"{name}_cos_incidence",
            item.cos_incidence,
            f"cosine of Sun incidence on {name} (0 if behind or in umbra, × visible fraction)",
        )
    )
    columns += _flag(
        f"{name}_sun_exclusion_violated",
        item.sun_violated,
        f"1 if the Sun is inside {name}'s exclusion cone (and not in umbra)",
    )
    columns += _degrees(
        f"{name}_moon_angle_deg", item.moon_angle_rad, f"angle {name}-Moon (apparent), deg"
    )
    columns += _flag(
        f"{name}_moon_exclusion_violated",
        item.moon_violated,
        f"1 if the Moon is inside {name}'s exclusion cone (and not behind the Earth)",
    )
    columns.append(
        Column(
            f"{name}_ra_deg",
            right_ascension_deg(item.right_ascension_rad),
            f"{name} right ascension, deg",
        )
    )
    columns += _degrees(f"{name}_dec_deg", item.declination_rad, f"{name} declination, deg")
    columns += _degrees(
        f"{name}_nadir_angle_deg",
        item.nadir_angle_rad,
        f"angle between {name} and nadir (the Earth's centre), deg",
    )
    columns += _degrees(
        f"{name}_earth_limb_angle_deg",
        item.earth_limb_angle_rad,
        f"angle of {name} above the Earth's limb (negative: towards the Earth), deg",
    )
    columns += _flag(
        f"{name}_earth_limb_exclusion_violated",
        item.earth_limb_violated,
        f"1 if {name} is less than its exclusion angle above the Earth's limb",
    )
    columns += _flag(
        f"{name}_sun_in_view",
        item.sun_in_view,
        f"1 if the Sun is inside {name}'s inclusion cone (its field of view) and not in umbra",
    )
    return columns


# The kinds of interval in intervals.csv, per vector (each a VectorAnalysis field):
# ``blinded`` is the union of the vector's exclusions, ``sun_in_view`` its Sun
# inclusion cone holding the Sun.
_VECTOR_INTERVALS = (
    "sun_exclusion",
    "moon_exclusion",
    "earth_limb_exclusion",
    "blinded",
    "sun_visible",
    "sun_in_view",
)


def _interval_kinds(analysis: PointingAnalysis) -> list[tuple[str, str, list[Interval]]]:
    """Each kind of interval with its body vector and its intervals (in time order), in
    the file's order: by kind, then by body vector name."""
    kinds = [
        ("eclipse", "", analysis.shadow),
        ("umbra", "", analysis.umbra),
        ("moon_behind_earth", "", analysis.moon_hidden),
    ]
    for item in analysis.vectors:
        kinds += [(kind, item.vector.name, getattr(item, kind)) for kind in _VECTOR_INTERVALS]
    return sorted(kinds, key=lambda entry: entry[:2])


# intervals.csv is written this many rows at a time: its epoch texts are made in bulk,
# and a month of a spinner's windows (a million rows) is never held as text at once.
_INTERVAL_ROWS_AT_A_TIME = 16384


def write_intervals_csv(path: Path, analysis: PointingAnalysis, iso, preamble: list[str]) -> None:
    """One row per interval: kind, body vector, start and end (ISO and TT s), duration;
    sorted by kind, body vector and start.

    ``iso``: a function from TT seconds to ISO texts in the scenario's time scale.
    """
    with open(path, "w", encoding="utf-8", newline="") as stream:
        for line in preamble:
            stream.write(f"# {line}\n")
        stream.write(
            "kind,body_vector,start,end,start_s,end_s,duration_s,starts_before_span,ends_after_span\n"
        )
        for kind, name, intervals in _interval_kinds(analysis):
            # Each list is in time order already (the search finds them so).
            # One % operation per block: C formats each field, no Python code runs per
            # row (the name is the user's: a % in it is escaped).
            row = f"{kind},{name}".replace("%", "%%") + ",%s,%s,%.9f,%.9f,%.9f,%d,%d\n"
            for first in range(0, len(intervals), _INTERVAL_ROWS_AT_A_TIME):
                block = intervals[first : first + _INTERVAL_ROWS_AT_A_TIME]
                start_s = [i.start_s for i in block]
                end_s = [i.end_s for i in block]
                fields = [
                    iso(np.array(start_s)).tolist(),
                    iso(np.array(end_s)).tolist(),
                    start_s,
                    end_s,
                    [i.duration_s for i in block],
                    [i.starts_before for i in block],
                    [i.ends_after for i in block],
                ]
                rows = zip(*fields, strict=True)
                stream.write(row * len(block) % tuple(x for r in rows for x in r))
