"""Telemetry as the fit takes it: gyro rates and attitude quaternions at their times,
checked, sorted and cleaned, with a model-free estimate of each sensor's noise.

What a user's telemetry does to a fit, and what is done about it here (every action is
a line in ``Telemetry.notes``; every refusal an :class:`InputError` naming the source,
the row and the value):

- rows out of time order are sorted; a row repeated exactly (a logger writing a record
  twice) is kept once; two different readings at the same time (a stuck clock) are
  refused, naming both rows;
- a missing reading (a row of NaN, as a file that merges gyro and star-tracker records
  has) is left out of its kind; a reading with only some of its components is refused;
- a quaternion whose norm is not 1 (to 1e-3) is refused; the others are normalized.
  Sign flips between samples (q and −q are the same attitude) need nothing: the fit
  compares rotations;
- a frozen sensor (the same reading, to the bit, ten or more times in a row: a real
  sensor's noise never repeats) has its repeats dropped, and the note says when;
- gaps are allowed (the largest is noted), and so are sparse attitude fixes.

Outliers are not removed here: the fit's robust loss finds them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.base.quantities import as_si_array

__all__ = ["FROZEN_RUN", "SensorSamples", "Telemetry", "difference_noise", "prepare_telemetry"]

# This many identical readings in a row (bit for bit) is a frozen sensor, not noise.
FROZEN_RUN = 10
# Quaternion norms further than this from 1 are refused, as the AEM reader does.
NORM_TOLERANCE = 1e-3


@dataclass
class SensorSamples:
    """One sensor's samples: times (s from the telemetry's t = 0, ascending, unique),
    values ((N, 3) rad/s or (N, 4) quaternions body → ICRF scalar first), and the row
    of the input each came from (for messages and for the residuals table)."""

    t: NDArray[np.float64]
    values: NDArray[np.float64]
    rows: NDArray[np.intp]

    def __len__(self) -> int:
        return int(self.t.size)


@dataclass
class Telemetry:
    """Checked telemetry: gyro and attitude samples (either may be None), the instant
    that t = 0 stands for (an astropy ``Time``, or None for relative seconds), the
    name of the source for messages, and what was done to it."""

    gyro: SensorSamples | None
    attitude: SensorSamples | None
    epoch: Any = None
    source: str = "telemetry"
    notes: list[str] = field(default_factory=list)
    # The gyro read exactly 0 on every axis at every one of its (two or more) readings.
    gyro_reads_zero: bool = False

    @property
    def span(self) -> tuple[float, float]:
        """First and last time of any sample, s."""
        times = [s.t for s in (self.gyro, self.attitude) if s is not None and len(s)]
        return float(min(t[0] for t in times)), float(max(t[-1] for t in times))


def _times(times: Any, source: str) -> tuple[NDArray[np.float64], Any]:
    """Seconds from the first time, and the epoch (a ``Time``) if ``times`` are ``Time``s."""
    from attitude.environment.timescales import check_year_range, tt_seconds

    if hasattr(times, "jd1") and hasattr(times, "scale"):  # astropy Time
        if times.ndim != 1:
            raise InputError(f"times must be a 1-D array, got shape {times.shape}", file=source)
        if len(times) == 0:
            raise InputError("no samples", file=source)
        check_year_range(times, f"{source}: times")
        seconds = tt_seconds(times, times[0])
        first = int(np.argmin(seconds))
        epoch = times[first]
        return seconds - seconds[first], epoch
    seconds = as_si_array(times, "time", f"{source}: times")
    if seconds.ndim != 1:
        raise InputError(f"times must be a 1-D array, got shape {seconds.shape}", file=source)
    if seconds.size == 0:
        raise InputError("no samples", file=source)
    return np.array(seconds, dtype=np.float64), None


def _readings(
    values: Any, kind: str, width: int, count: int, source: str, name: str
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """(N, width) readings and the mask of the rows that hold one (a row of NaN holds
    none); a partly missing or non-finite reading is refused, naming its row."""
    array = as_si_array(values, kind, f"{source}: {name}", allow_nonfinite=True)
    if array.ndim != 2 or array.shape != (count, width):
        raise InputError(
            f"{name} must have shape ({count}, {width}) to match the times, got {array.shape}",
            file=source,
        )
    missing = np.isnan(array)
    present: NDArray[np.bool_] = ~np.any(missing, axis=1)
    partial = missing.any(axis=1) & ~missing.all(axis=1)
    if np.any(partial):
        row = int(np.flatnonzero(partial)[0])
        raise InputError(
            f"{name} {array[row].tolist()} is partly missing", file=source, key=f"row {row}"
        )
    infinite = present & ~np.isfinite(array).all(axis=1)
    if np.any(infinite):
        row = int(np.flatnonzero(infinite)[0])
        raise InputError(
            f"{name} {array[row].tolist()} is not finite", file=source, key=f"row {row}"
        )
    return array, present


def _sensor(
    t: NDArray[np.float64],
    values: NDArray[np.float64],
    present: NDArray[np.bool_],
    name: str,
    source: str,
    notes: list[str],
) -> SensorSamples | None:
    """One sensor's samples sorted, exact repeats merged, a stuck clock refused and a
    frozen sensor's repeats dropped."""
    rows = np.flatnonzero(present)
    if rows.size == 0:
        return None
    order = rows[np.argsort(t[rows], kind="stable")]
    ts, vs = t[order], values[order]
    same = np.flatnonzero(np.diff(ts) == 0.0)
    if same.size:
        equal = np.all(vs[same] == vs[same + 1], axis=1)
        if not np.all(equal):
            k = int(same[~equal][0])
            raise InputError(
                f"rows {int(order[k])} and {int(order[k + 1])} give {name} at the same "
                f"time ({float(ts[k])!r} s) with different values, {vs[k].tolist()} and "
                f"{vs[k + 1].tolist()}: a stuck clock? Remove one of them",
                file=source,
            )
        keep = np.ones(ts.size, dtype=bool)
        keep[same + 1] = False
        notes.append(f"{name}: {same.size} exactly repeated rows kept once")
        order, ts, vs = order[keep], ts[keep], vs[keep]
    frozen = _frozen(vs)
    if np.any(frozen):
        starts = np.flatnonzero(np.diff(np.concatenate([[0], frozen.astype(np.int8)])) == 1)
        notes.append(
            f"{name}: frozen sensor: {int(frozen.sum())} repeated readings (the same value "
            f"{FROZEN_RUN} or more times in a row) left out, first from t = {ts[starts[0]]:.6g} s"
        )
        order, ts, vs = order[~frozen], ts[~frozen], vs[~frozen]
    return SensorSamples(ts, vs, order)


def _frozen(values: NDArray[np.float64]) -> NDArray[np.bool_]:
    """The repeats (not the first reading) of runs of ``FROZEN_RUN`` or more identical rows."""
    repeat = np.concatenate([[False], np.all(values[1:] == values[:-1], axis=1)])
    # Runs of repeats: [start, stop) where ``repeat`` is True; a run of k repeats is a
    # run of k + 1 identical readings.
    edges = np.diff(np.concatenate([[0], repeat.astype(np.int8), [0]]))
    starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    frozen = np.zeros(len(values), dtype=bool)
    for start, stop in zip(starts, stops, strict=True):
        if stop - start + 1 >= FROZEN_RUN:
            frozen[start:stop] = True
    return frozen


def _rotation_quaternions(attitude: Rotation, count: int, source: str) -> NDArray[np.float64]:
    """N attitudes given as a ``Rotation`` (one per time) as (N, 4) quaternions, scalar
    first."""
    if attitude.single or len(attitude) != count:
        shown = "a single rotation" if attitude.single else f"{len(attitude)} rotations"
        raise InputError(
            f"quaternions as a Rotation must hold one attitude per time ({count}), got {shown}",
            file=source,
        )
    return attitude.as_quat(scalar_first=True)


def prepare_telemetry(
    times: Any,
    angular_velocity: Any = None,
    quaternions: Any = None,
    source: str = "telemetry",
) -> Telemetry:
    """Check and clean telemetry (the module docstring says what is done to it).

    ``times``: an astropy ``Time`` array or seconds; ``angular_velocity``: (N, 3) body
    rates, rad/s (or a ``Quantity``); ``quaternions``: (N, 4) body → ICRF, scalar first
    (w, x, y, z), or a ``scipy.spatial.transform.Rotation`` of N attitudes (body →
    ICRF).  Rows of NaN are missing readings of that kind.
    """
    if angular_velocity is None and quaternions is None:
        raise InputError("give angular_velocity, quaternions or both", file=source)
    t, epoch = _times(times, source)
    if not np.all(np.isfinite(t)):
        row = int(np.flatnonzero(~np.isfinite(t))[0])
        raise InputError(f"time {t[row]!r} is not finite", file=source, key=f"row {row}")
    notes: list[str] = []
    if np.any(np.diff(t) < 0.0):
        notes.append(f"rows not in time order ({int(np.sum(np.diff(t) < 0.0))} steps back): sorted")
    gyro = attitude = None
    if angular_velocity is not None:
        ω, present = _readings(
            angular_velocity, "angular_velocity", 3, t.size, source, "angular_velocity"
        )
        zero = int(np.count_nonzero(present)) >= 2 and not np.any(ω[present])
        gyro = _sensor(t, ω, present, "angular_velocity", source, notes)
    if quaternions is not None:
        if isinstance(quaternions, Rotation):  # what the package returns: an attitude
            quaternions = _rotation_quaternions(quaternions, t.size, source)
        q, present = _readings(quaternions, "dimensionless", 4, t.size, source, "quaternions")
        norm = np.linalg.norm(np.where(present[:, None], q, 1.0), axis=1)
        bad = present & (np.abs(norm - 1.0) > NORM_TOLERANCE)
        if np.any(bad):
            row = int(np.flatnonzero(bad)[0])
            raise InputError(
                f"quaternion {q[row].tolist()} has norm {norm[row]:.9g}, "
                "not 1 (body -> ICRF, scalar first (w, x, y, z))",
                file=source,
                key=f"row {row}",
            )
        q = np.where(present[:, None], q / norm[:, None], q)
        attitude = _sensor(t, q, present, "quaternions", source, notes)
    if gyro is None and attitude is None:
        raise InputError("every reading is missing", file=source)
    telemetry = Telemetry(gyro, attitude, epoch, source, notes)
    telemetry.gyro_reads_zero = angular_velocity is not None and zero
    for sensor, name in ((gyro, "angular_velocity"), (attitude, "quaternions")):
        if sensor is not None and len(sensor) > 2:
            gaps = np.diff(sensor.t)
            median = float(np.median(gaps))
            largest = float(gaps.max())
            if largest > 10.0 * median:
                notes.append(
                    f"{name}: {len(sensor)} samples, typically {median:.4g} s apart; largest "
                    f"gap {largest:.6g} s, from t = {sensor.t[int(np.argmax(gaps))]:.6g} s"
                )
    return telemetry


# ----------------------------------------------------------------- noise from the data


def _uniform_runs(t: NDArray[np.float64], tolerance: float = 0.01) -> list[slice]:
    """Slices of ``t`` over which the spacing is constant (to ``tolerance`` of it)."""
    if t.size < 2:
        return []
    dt = np.diff(t)
    runs, start = [], 0
    for k in range(1, dt.size + 1):
        if k == dt.size or abs(dt[k] - dt[start]) > tolerance * dt[start]:
            runs.append(slice(start, k + 1))
            start = k
    return runs


def difference_noise(
    t: NDArray[np.float64], values: NDArray[np.float64], order: int = 6
) -> NDArray[np.float64] | None:
    """The white-noise σ of each column of ``values``, from its ``order``-th differences
    over uniformly spaced runs, with no model: the noise of a k-th difference has
    variance C(2k, k) σ², while a smooth signal's k-th difference falls as (ω Δt)^k.
    A median absolute deviation (× 1.4826), so that outliers do not count.  None when
    fewer than 20 differences exist (sparse data: the fit's residuals say it then)."""
    pieces = []
    for run in _uniform_runs(t):
        block = values[run]
        if len(block) > order:
            pieces.append(np.diff(block, n=order, axis=0))
    if not pieces:
        return None
    d = np.concatenate(pieces)
    if len(d) < 20:
        return None
    mad = np.median(np.abs(d - np.median(d, axis=0)), axis=0)
    return 1.4826 * mad / math.sqrt(math.comb(2 * order, order))
