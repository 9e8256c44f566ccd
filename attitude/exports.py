"""Time series (CSV) and summary (JSON) files of a propagated scenario.

The CSV opens with ``#`` lines that state the epoch and time scale, the frames,
the units and the quaternion convention; each column's name carries its frame and
unit (``omega_body_x_rad_s``, ``q_body_to_icrf_w``).  Numbers are written with 17
significant digits, so a file read back gives the same doubles.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from attitude.motion_analysis import SegmentMotion
from attitude.trajectory import Trajectory

__all__ = ["Column", "to_json", "trajectory_columns", "write_csv", "write_json"]

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


def trajectory_columns(trajectory: Trajectory, seconds: NDArray[np.float64]) -> list[Column]:
    """Attitude, rates, momentum and energy at ``seconds`` (TT s since the epoch)."""
    q = trajectory.attitude_quaternion(seconds)
    ω = trajectory.angular_velocity(seconds)
    m = trajectory.angular_momentum(seconds)
    H = trajectory.inertial_angular_momentum(seconds)
    columns = [Column("t_s", seconds, "TT seconds since the scenario epoch")]
    columns += [
        Column(f"q_body_to_icrf_{c}", q[:, i], "attitude quaternion, scalar first, body -> ICRF")
        for i, c in enumerate("wxyz")
    ]
    columns += [
        Column(f"omega_body_{c}_rad_s", ω[:, i], "angular velocity, body axes, rad/s")
        for i, c in enumerate("xyz")
    ]
    columns += [
        Column(f"h_body_{c}_N_m_s", m[:, i], "angular momentum, body axes, N m s")
        for i, c in enumerate("xyz")
    ]
    columns += [
        Column(f"h_icrf_{c}_N_m_s", H[:, i], "angular momentum, ICRF axes, N m s")
        for i, c in enumerate("xyz")
    ]
    columns.append(
        Column(
            "kinetic_energy_J", trajectory.kinetic_energy(seconds), "rotational kinetic energy, J"
        )
    )
    columns.append(
        Column(
            "segment",
            trajectory.segment_index(seconds).astype(float),
            "index of the motion segment (0 = before the first event)",
        )
    )
    return columns


def write_csv(
    path: Path,
    epochs_iso: NDArray[np.str_],
    time_label: str,
    columns: list[Column],
    preamble: list[str],
) -> None:
    """Write the time series: ``#`` preamble, a header row, then one row per epoch.

    ``time_label`` names the first column (e.g. ``time_utc``); ``epochs_iso`` are its
    ISO 8601 texts.
    """
    names = [time_label] + [c.name for c in columns]
    descriptions = [f"#   {c.name}: {c.description}" for c in columns]
    data = np.column_stack([c.values for c in columns])
    integer_columns = {i for i, c in enumerate(columns) if c.name == "segment"}
    formats = ["%d" if i in integer_columns else "%.17g" for i in range(len(columns))]
    row_format = "%s," + ",".join(formats) + "\n"
    with open(path, "w", encoding="utf-8", newline="") as stream:
        for line in preamble:
            stream.write(f"# {line}\n")
        stream.write("# columns:\n")
        for line in descriptions:
            stream.write(line + "\n")
        stream.write(",".join(names) + "\n")
        for epoch, row in zip(epochs_iso, data, strict=True):
            stream.write(row_format % (epoch, *row))


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
                "body_period_s": item.period_s,
                "flip_period_s": item.flip_period_s,
                "flip_count": int(item.flip_times_s.size),
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
                "angular_momentum_norm_N_m_s": float(
                    np.linalg.norm(item.inertial_angular_momentum_N_m_s)
                ),
            }
        )
    flips = trajectory.flip_times()
    return {
        "segments": segments,
        "flips": {
            "count": int(flips.size),
            "times_s": flips,
            "times": [scenario.format_epoch(t) for t in flips[:1000]],
        },
    }
