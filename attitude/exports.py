"""Time series (CSV) and summary (JSON) files of a propagated scenario.

The CSV opens with ``#`` lines that state the epoch and time scale, the frames,
the units and the quaternion convention; each column's name carries its frame and
unit (``omega_body_x_rad_s``, ``q_body_to_icrf_w``).  Each number is written as the
shortest text that reads back as the same double (17 significant digits at most:
``0.1``, not ``0.10000000000000001``), so a file read back gives the same doubles.

The CSV is written as it is computed, a chunk of rows at a time (:class:`CsvWriter`),
by Apache Arrow's CSV writer: its C++ number formatting is about three times as fast
as numpy's ``savetxt`` with ``%.17g`` (``benchmarks/report_outputs.py`` measures both).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, fields
from pathlib import Path
from types import TracebackType
from typing import Any

import numpy as np
from numpy.typing import NDArray

from attitude.intervals import Interval, total_duration
from attitude.motion_analysis import LISTED_FLIPS, SegmentMotion
from attitude.pointing import PointingAnalysis, PointingSamples
from attitude.trajectory import Trajectory

__all__ = [
    "Column",
    "CsvWriter",
    "Samples",
    "arrow_texts",
    "motion_summary",
    "pointing_columns",
    "pointing_summary",
    "right_ascension_deg",
    "sample",
    "to_json",
    "trajectory_columns",
    "write_csv",
    "write_intervals_csv",
    "write_json",
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


def arrow_texts(epochs: NDArray) -> Any:
    """ASCII texts (numpy ``S`` or ``U`` arrays) as an Arrow string array; ``S`` arrays
    (:class:`attitude.epoch_texts.EpochTexts`) are wrapped without a copy."""
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
        self._writer = None

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
        arrays += [pa.array(np.asarray(c.values, dtype=np.float64)) for c in columns]
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


def to_json(value: Any) -> Any:
    """``value`` with numpy arrays and scalars made JSON-serializable (inf/nan as None)."""
    if isinstance(value, dict):
        return {str(k): to_json(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [to_json(v) for v in value]
    if isinstance(value, np.ndarray):
        return to_json(value.tolist())
    if isinstance(value, np.generic):
        return to_json(value.item())
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def write_json(path: Path, data: dict[str, Any]) -> None:
    path.write_text(
        json.dumps(to_json(data), indent=2, ensure_ascii=False) + "\n", encoding="utf-8"
    )


_MOTION_TEXT = {
    "periodic": "periodic: m(t) repeats every body period",
    "steady spin": "steady spin: m is fixed in the body and the body turns about it; "
    "no period of m, no flips, no nutation",
    "separatrix": "separatrix: no period; m leaves the intermediate axis and returns to it "
    "asymptotically, so the body turns over at most once",
    "rest": "at rest: no motion",
}


def _flips_summary(scenario, motion: list[SegmentMotion]) -> dict[str, Any]:
    """All flips: their count, and their times up to LISTED_FLIPS (an event's epoch can
    end one segment and start the next with the same flip: it counts once)."""
    listed = np.concatenate([item.flip_times_s for item in motion]) if motion else np.empty(0)
    listed, repeated = np.unique(listed, return_counts=True)
    count = sum(item.flip_count for item in motion) - int(np.sum(repeated - 1))
    listed = listed[:LISTED_FLIPS]
    complete = listed.size == count
    return {
        "count": count,
        "times_s": listed,
        "times": [scenario.format_epoch(t) for t in listed[:1000]],
        "note": None
        if complete
        else f"times_s lists the first {listed.size} of {count} flips (closed form)",
    }


def motion_summary(trajectory: Trajectory, motion: list[SegmentMotion]) -> dict[str, Any]:
    """The JSON summary of the motion: segments, events, flips, precession, nutation."""
    scenario = trajectory.scenario
    segments = []
    for k, (segment, item) in enumerate(zip(trajectory.segments, motion, strict=True)):
        event = segment.event
        segments.append(
            {
                "index": k,
                "start": scenario.format_epoch(item.start_s),
                "start_s": item.start_s,
                "end_s": item.end_s,
                "started_by": None
                if event is None
                else {"type": event.kind, "label": event.label or None},
                "formula": item.formula,
                "motion": item.motion,
                "motion_description": _MOTION_TEXT[item.motion],
                "body_period_s": item.period_s,
                "flip_period_s": item.flip_period_s,
                "flip_count": item.flip_count,
                "spin_axis_body": item.spin_axis_body,
                "nutation_angle_min_deg": None
                if item.nutation_min_rad is None
                else math.degrees(item.nutation_min_rad),
                "nutation_angle_max_deg": None
                if item.nutation_max_rad is None
                else math.degrees(item.nutation_max_rad),
                "nutation_period_s": item.nutation_period_s,
                "spin_period_s": item.spin_period_s,
                "precession_period_s": item.precession_period_s,
                "kinetic_energy_J": item.kinetic_energy_J,
                "angular_momentum_icrf_N_m_s": item.inertial_angular_momentum_N_m_s,
                "angular_momentum_norm_N_m_s": item.angular_momentum_norm_N_m_s,
            }
        )
    return {"segments": segments, "flips": _flips_summary(scenario, motion)}


def right_ascension_deg(radians: NDArray[np.float64]) -> NDArray[np.float64]:
    """Right ascensions in degrees, in [0, 360): an angle a hair below 2π rounds to
    360.0 in degrees, which is written as 0."""
    degrees = np.mod(np.degrees(radians), 360.0)
    return np.where(degrees >= 360.0, 0.0, degrees)


def _flag(name: str, values, description: str) -> list[Column]:
    return [] if values is None else [Column(name, values.astype(float), description)]


def _degrees(name: str, values, description: str) -> list[Column]:
    return [] if values is None else [Column(name, np.degrees(values), description)]


def pointing_columns(samples: PointingSamples) -> list[Column]:
    """The pointing columns of the time series, at the samples' times (any chunk of
    the output grid: the columns of consecutive chunks follow on)."""
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
    if samples.q_body_to_lvlh is not None:
        columns += _components(
            "q_body_to_lvlh_{}",
            samples.q_body_to_lvlh,
            "wxyz",
            "attitude in the orbit's LVLH frame (z nadir, y -orbit normal), quaternion, "
            "scalar first (w >= 0), body -> LVLH",
        )
    if samples.lvlh_euler_deg is not None:
        sequence = samples.lvlh_euler_sequence
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
    for item in samples.vectors:
        name = item.vector.name
        columns += _degrees(f"{name}_sun_angle_deg", item.sun_angle_rad, f"angle {name}-Sun, deg")
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
    return columns


# The kinds of interval in intervals.csv: (kind, the VectorAnalysis field), per vector.
_VECTOR_INTERVALS = ("sun_exclusion", "moon_exclusion", "earth_limb_exclusion", "sun_visible")


def _interval_rows(analysis: PointingAnalysis) -> list[tuple[str, str, Interval]]:
    rows = [("eclipse", "", i) for i in analysis.shadow]
    rows += [("umbra", "", i) for i in analysis.umbra]
    rows += [("moon_behind_earth", "", i) for i in analysis.moon_hidden]
    for item in analysis.vectors:
        for kind in _VECTOR_INTERVALS:
            rows += [(kind, item.vector.name, i) for i in getattr(item, kind)]
    return sorted(rows, key=lambda row: (row[0], row[1], row[2].start_s))


def write_intervals_csv(
    path: Path, analysis: PointingAnalysis, iso, preamble: list[str]
) -> None:
    """One row per interval: kind, body vector, start and end (ISO and TT s), duration.

    ``iso``: a function from TT seconds to ISO texts in the scenario's time scale.
    """
    rows = _interval_rows(analysis)
    starts = iso(np.array([r[2].start_s for r in rows])) if rows else []
    ends = iso(np.array([r[2].end_s for r in rows])) if rows else []
    with open(path, "w", encoding="utf-8", newline="") as stream:
        for line in preamble:
            stream.write(f"# {line}\n")
        stream.write(
            "kind,body_vector,start,end,start_s,end_s,duration_s,starts_before_span,ends_after_span\n"
        )
        for (kind, name, i), start, end in zip(rows, starts, ends, strict=True):
            stream.write(
                f"{kind},{name},{start},{end},{i.start_s:.9f},{i.end_s:.9f},{i.duration_s:.9f},"
                f"{int(i.starts_before)},{int(i.ends_after)}\n"
            )


def _interval_totals(intervals: list[Interval], format_epoch=None) -> dict[str, Any]:
    totals: dict[str, Any] = {
        "count": len(intervals),
        "total_s": total_duration(intervals),
        "longest_s": max((i.duration_s for i in intervals), default=0.0),
    }
    if format_epoch is not None:
        totals["first"] = [
            {
                "start": format_epoch(i.start_s),
                "end": format_epoch(i.end_s),
                "duration_s": i.duration_s,
            }
            for i in intervals[:20]
        ]
    return totals


# The extrema in the summary: (key in VectorAnalysis.extrema, summary name, in degrees).
_EXTREMA = (
    ("sun_angle", "sun_angle", True),
    ("moon_angle", "moon_angle", True),
    ("nadir_angle", "nadir_angle", True),
    ("earth_limb_angle", "earth_limb_angle", True),
    ("cos_incidence", "cos_incidence", False),
)


def pointing_summary(analysis: PointingAnalysis, format_epoch) -> dict[str, Any]:
    """Extrema with their times, constraint and visibility totals, eclipses: all found
    on the exact motion over the analysed span (``attitude.pointing.pointing_analysis``),
    none from the output grid."""
    vectors = {}
    for item in analysis.vectors:
        v = item.vector
        entry: dict[str, Any] = {"kind": v.kind, "vector_body": v.vector}
        for key, name, degrees in _EXTREMA:
            if key not in item.extrema:
                continue
            low, high = item.extrema[key]
            unit = "_deg" if degrees else ""
            convert = math.degrees if degrees else float
            entry[f"{name}_min{unit}"] = convert(low.value)
            entry[f"{name}_min_at"] = format_epoch(low.time_s)
            entry[f"{name}_max{unit}"] = convert(high.value)
            entry[f"{name}_max_at"] = format_epoch(high.time_s)
        entry["mean_cos_incidence"] = item.mean_cos_incidence
        entry["sun_visible"] = _interval_totals(item.sun_visible)
        for constraint, angle in (
            ("sun_exclusion", "sun_exclusion_half_angle_deg"),
            ("moon_exclusion", "moon_exclusion_half_angle_deg"),
            ("earth_limb_exclusion", "earth_limb_exclusion_angle_deg"),
        ):
            if getattr(v, angle) is not None:
                entry[angle] = getattr(v, angle)
                entry[constraint] = _interval_totals(getattr(item, constraint), format_epoch)
        vectors[v.name] = entry
    summary: dict[str, Any] = {
        "position": analysis.orbit,
        "span": {"start": format_epoch(analysis.start_s), "stop": format_epoch(analysis.stop_s)},
        "interval_precision_s": analysis.precision_s,
        "search_step_s": analysis.grid.step_s,
        "body_vectors": vectors,
    }
    if analysis.on_orbit:
        summary["eclipses"] = {
            "shadow": _interval_totals(analysis.shadow),
            "umbra": _interval_totals(analysis.umbra),
            "sunlit_fraction_of_span": analysis.sunlit_fraction_mean,
        }
        summary["moon_behind_earth"] = _interval_totals(analysis.moon_hidden)
    return summary
