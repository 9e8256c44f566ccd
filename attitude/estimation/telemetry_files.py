"""Telemetry files for ``attitude fit``: CSV, Parquet and CCSDS AEM, read into times,
body rates and attitude quaternions, with every problem named by file, column, row
and value.

**CSV and Parquet** (the columns of ``attitude run``'s ``timeseries.csv`` and
``timeseries.parquet``, so that a run's output can be fitted as it is):

- time, one of: ``time_utc`` (or ``time_tt``, ``time_tai``, ``time_tdb``...: ISO 8601
  epochs in that scale), ``time`` or ``epoch`` (ISO 8601 in ``--time-scale``, UTC by
  default), ``t_s`` (seconds; the epoch they count from is read from the
  ``# epoch: ... UTC`` line that ``attitude run`` writes, from the Parquet metadata,
  or from ``--epoch``; without one, relative seconds);
- rates: ``omega_body_x_rad_s``, ``omega_body_y_rad_s``, ``omega_body_z_rad_s`` (or
  ``_deg_s``), body axes;
- attitude: ``q_body_to_icrf_w`` … ``_z`` (scalar first, body → ICRF), or
  ``q_icrf_to_body_w`` … ``_z`` (its inverse).

Other columns are ignored; an empty cell (or NaN) is a missing reading.  Lines that
start with ``#`` before the header are comments.

**CCSDS AEM 2.0** (KVN, parsed by ccsds-ndm-py, as ``attitude.files.aem_reader``
reads it): ``QUATERNION``, ``QUATERNION/DERIVATIVE`` or ``QUATERNION/ANGVEL`` segments
between ICRF, GCRF or EME2000 and a body frame, in either direction, with the
conventions of annex F of CCSDS 504.0-B-2 (documented in that module); ANGVEL rates,
when present, are read as the gyro.
"""

from __future__ import annotations

import csv
import re
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.environment.timescales import SCALES, as_time, offline_time

__all__ = ["MAX_ROWS", "TelemetryFile", "read_telemetry"]

# A day at 1 kHz; beyond, a file is more than one arc of telemetry.
MAX_ROWS = 100_000_000
_AXES = "xyz"
_QUATERNION = "wxyz"
_TIME_NAMES = {"time", "epoch", *(f"time_{scale}" for scale in SCALES)}
_EPOCH_LINE = re.compile(r"^#\s*epoch:\s*(\S+)\s+([A-Za-z]+)")
_ERROR_CELL = re.compile(r"In CSV column #(\d+): Row #(\d+): .*?invalid value '([^']*)'")
_ERROR_WIDTH = re.compile(r"Expected (\d+) columns, got (\d+): (.*)")
_BOM = b"\xef\xbb\xbf"


@dataclass
class TelemetryFile:
    """What a telemetry file holds: times (an astropy ``Time`` array, or relative
    seconds), body rates (N, 3) rad/s and quaternions (N, 4) body → ICRF scalar first
    (NaN rows where missing; either may be None)."""

    path: Path
    times: Any
    angular_velocity: NDArray[np.float64] | None
    quaternions: NDArray[np.float64] | None
    notes: list[str] = field(default_factory=list)


def read_telemetry(
    path: str | Path, time_scale: str | None = None, epoch: Any = None
) -> TelemetryFile:
    """Read a CSV, Parquet or CCSDS AEM telemetry file (the module docstring).

    ``time_scale``: the scale of a ``time``/``epoch`` column of ISO texts (UTC by
    default); ``epoch``: the instant that a ``t_s`` column counts from, when the file
    does not say (ISO text in ``time_scale``, or a ``Time``).
    """
    path = Path(path)
    name = path.name
    try:
        if not path.is_file():
            raise InputError("no such file" if not path.exists() else "not a file", file=str(path))
        with open(path, "rb") as stream:
            head = stream.read(1 << 16)
    except OSError as exc:
        raise InputError(f"cannot read: {exc.strerror or exc}", file=str(path)) from None
    if head.startswith(b"PAR1"):
        return _parquet(path, time_scale, epoch)
    marked = head.startswith(_BOM)  # a UTF-8 byte-order mark, as Excel writes
    if head[len(_BOM) if marked else 0 :].lstrip().startswith(b"CCSDS_AEM_VERS"):
        if marked:
            raise InputError(
                "begins with a UTF-8 byte-order mark: a CCSDS AEM in KVN is ASCII text "
                "(CCSDS 504.0-B-2); save it without the mark",
                file=name,
            )
        return _aem(path)
    if b"\x00" in head:
        raise InputError("a binary file, not telemetry (CSV, Parquet or CCSDS AEM)", file=name)
    try:
        head.decode("utf-8")
    except UnicodeDecodeError as exc:
        if exc.start < len(head) - 4:  # not just a character cut by the 64 KiB window
            raise InputError(
                f"not UTF-8 text (byte {exc.start}): not telemetry (CSV, Parquet or CCSDS AEM)",
                file=name,
            ) from None
    return _csv(path, head, time_scale, epoch)


# ----------------------------------------------------------------- columns


def _columns(names: list[str], file: str) -> dict[str, Any]:
    """Which columns hold the time, the rates (and their unit) and the quaternions."""
    lower = {n.strip().lower(): n for n in names}
    found: dict[str, Any] = {"time": None, "rates": None, "rate_unit": None, "q": None}
    for scale in SCALES:
        if f"time_{scale}" in lower:
            found["time"] = ("iso", lower[f"time_{scale}"], scale)
            break
    else:
        for key in ("time", "epoch"):
            if key in lower:
                found["time"] = ("iso", lower[key], None)
                break
        else:
            if "t_s" in lower:
                found["time"] = ("seconds", lower["t_s"], None)
    for unit in ("rad_s", "deg_s"):
        columns = [f"omega_body_{a}_{unit}" for a in _AXES]
        present = [c in lower for c in columns]
        if any(present):
            if not all(present):
                missing = columns[present.index(False)]
                raise InputError(f"column {missing} is missing (the rates need x, y, z)", file=file)
            found["rates"] = [lower[c] for c in columns]
            found["rate_unit"] = unit
            break
    for prefix, inverse in (("q_body_to_icrf_", False), ("q_icrf_to_body_", True)):
        columns = [prefix + c for c in _QUATERNION]
        present = [c in lower for c in columns]
        if any(present):
            if not all(present):
                missing = columns[present.index(False)]
                raise InputError(
                    f"column {missing} is missing (the quaternion needs w, x, y, z)", file=file
                )
            found["q"] = ([lower[c] for c in columns], inverse)
            break
    shown = ", ".join(names[:12]) + (", ..." if len(names) > 12 else "")
    if found["time"] is None:
        raise InputError(
            f"no time column (time_utc, time_tt, ..., time, epoch or t_s); columns: {shown}",
            file=file,
        )
    if found["rates"] is None and found["q"] is None:
        raise InputError(
            f"no rate columns (omega_body_x_rad_s, ...) and no quaternion columns "
            f"(q_body_to_icrf_w, ...); columns: {shown}",
            file=file,
        )
    return found


def _numbers(table, column: str, file: str) -> NDArray[np.float64]:
    """A column as float64, nulls as NaN; a cell that is not a decimal number is
    refused, naming its row (a CSV's cells are read as texts: Arrow's own inference
    takes '0x10' for 16)."""
    import pyarrow as pa
    import pyarrow.compute as pc

    values = table.column(column)
    if not (pa.types.is_floating(values.type) or pa.types.is_integer(values.type)):
        if pa.types.is_null(values.type):
            return np.full(len(values), np.nan)
        texts = pc.utf8_trim_whitespace(values.cast(pa.string()))
        texts = pc.if_else(pc.equal(texts, ""), pa.scalar(None, pa.string()), texts)
        try:
            values = pc.cast(texts, pa.float64())
        except pa.ArrowInvalid:
            for row, text in enumerate(texts.to_pylist()):
                try:
                    pc.cast(pa.array([text], pa.string()), pa.float64())
                except pa.ArrowInvalid:
                    raise InputError(
                        f"{text!r} is not a number", file=file, key=f"row {row}, column {column}"
                    ) from None
            raise  # pragma: no cover (the column failed and no cell does)
    array = values.to_numpy(zero_copy_only=False).astype(np.float64)
    return np.where(np.isnan(array), np.nan, array)


def _assemble(
    table, columns: dict, file: str, time_scale, epoch, notes: list[str]
) -> TelemetryFile:
    """Times, rates and quaternions from a table with the ``columns`` found."""
    count = table.num_rows
    if count == 0:
        raise InputError("no rows", file=file)
    if count > MAX_ROWS:
        raise InputError(f"{count} rows, more than {MAX_ROWS}: split the telemetry", file=file)
    kind, column, scale = columns["time"]
    if kind == "iso":
        texts = table.column(column).cast("string").to_numpy(zero_copy_only=False)
        times = _iso_times(texts, scale or time_scale or "utc", file, column)
    else:
        seconds = _numbers(table, column, file)
        bad = ~np.isfinite(seconds)
        if np.any(bad):
            row = int(np.flatnonzero(bad)[0])
            raise InputError(
                f"time {seconds[row]!r} is not finite", file=file, key=f"row {row}, column {column}"
            )
        if epoch is not None:
            from attitude.environment.timescales import time_from_tt_seconds

            times = time_from_tt_seconds(as_time(epoch, time_scale, "--epoch"), seconds)
        else:
            times = seconds
            notes.append(f"{column}: relative seconds (no epoch in the file, none given)")
    rates = quaternions = None
    if columns["rates"] is not None:
        rates = np.stack([_numbers(table, c, file) for c in columns["rates"]], axis=1)
        if columns["rate_unit"] == "deg_s":
            rates = np.radians(rates)
    if columns["q"] is not None:
        names, inverse = columns["q"]
        quaternions = np.stack([_numbers(table, c, file) for c in names], axis=1)
        if inverse:
            quaternions = quaternions * np.array([1.0, -1.0, -1.0, -1.0])
    return TelemetryFile(Path(file), times, rates, quaternions, notes)


def _iso_times(texts: NDArray, scale: str, file: str, column: str):
    """ISO 8601 texts as one ``Time`` (vectorized; the first bad text is named)."""
    from astropy.time import Time

    if scale not in SCALES:
        raise InputError(
            f"expected one of {', '.join(SCALES)}, got {scale!r}", key="--time-scale", value=scale
        )
    missing = np.array([t is None or str(t).strip() == "" for t in texts])
    if np.any(missing):
        row = int(np.flatnonzero(missing)[0])
        raise InputError("no time", file=file, key=f"row {row}, column {column}")
    cleaned = np.char.rstrip(np.char.strip(texts.astype(str)), "Z")
    from erfa import ErfaWarning

    try:
        # ERFA only warns of a second 61 of a minute that has no leap second: refused.
        with offline_time(), warnings.catch_warnings():
            warnings.simplefilter("error", ErfaWarning)
            return Time(cleaned, format="isot", scale=scale, precision=9)
    except (ValueError, TypeError, ErfaWarning):
        for row, text in enumerate(cleaned):
            try:
                with offline_time(), warnings.catch_warnings():
                    warnings.simplefilter("error", ErfaWarning)
                    Time(text, format="isot", scale=scale)
            except ErfaWarning:
                raise InputError(
                    f"{str(text)!r} is not an instant of {scale.upper()}: its seconds run "
                    "past the end of the minute (only a leap second has a 60th)",
                    file=file,
                    key=f"row {row}, column {column}",
                ) from None
            except (ValueError, TypeError):
                raise InputError(
                    f"{str(text)!r} is not an ISO 8601 epoch",
                    file=file,
                    key=f"row {row}, column {column}",
                ) from None
        raise  # pragma: no cover (the vector failed and no element does)


# ----------------------------------------------------------------- formats


def _csv(path: Path, head: bytes, time_scale, epoch) -> TelemetryFile:
    import pyarrow as pa
    from pyarrow import csv as pa_csv

    file = path.name
    # "utf-8-sig": a byte-order mark (Excel's "CSV UTF-8") is not part of the header.
    lines = head.decode("utf-8-sig", errors="replace").splitlines()
    comments = 0
    notes: list[str] = []
    for line in lines:
        if not line.startswith("#"):
            break
        comments += 1
        found = _EPOCH_LINE.match(line)
        if found and epoch is None:
            try:
                epoch = as_time(found.group(1), found.group(2).lower(), "# epoch")
            except InputError as exc:
                raise exc.located(file=file) from None
    first = lines[comments] if comments < len(lines) else ""
    # A semicolon-separated table (what a spreadsheet in a locale with decimal commas
    # writes as "CSV") when its header has semicolons and no comma.
    delimiter = ";" if ";" in first and "," not in first else ","
    header = next(csv.reader([first], delimiter=delimiter)) if first else []
    # Every cell is read as text: epochs (Arrow would parse them as POSIX timestamps,
    # which have no leap second) and numbers (its inference reads '0x10' as 16), each
    # column then converted and checked (_numbers, _iso_times).
    texts = {name: pa.string() for name in header}
    try:
        table = pa_csv.read_csv(
            path,
            read_options=pa_csv.ReadOptions(skip_rows=comments),
            parse_options=pa_csv.ParseOptions(delimiter=delimiter),
            convert_options=pa_csv.ConvertOptions(
                column_types=texts,
                strings_can_be_null=True,
                null_values=["", "NaN", "nan", "NA"],
            ),
        )
    except pa.ArrowInvalid as exc:
        raise _csv_error(str(exc), path, comments, delimiter) from None
    except OSError as exc:
        raise InputError(f"cannot read: {exc}", file=str(path)) from None
    columns = _columns(table.column_names, file)
    return _assemble(table, columns, file, time_scale, epoch, notes)


def _csv_error(text: str, path: Path, comments: int, delimiter: str) -> InputError:
    """Arrow's complaint about a table, in the words of this module: which row, and
    what is wrong with it."""
    found = _ERROR_WIDTH.search(text)
    if found:
        expected, got, line = int(found.group(1)), int(found.group(2)), found.group(3)
        row = None
        with open(path, encoding="utf-8-sig", errors="replace") as stream:
            for number, content in enumerate(stream):
                if content.rstrip("\r\n") == line:
                    row = number - comments - 1  # the data rows' numbering, from 0
                    break
        where = f"row {row}" if row is not None and row >= 0 else None
        return InputError(
            f"{got} cell{'s' if got != 1 else ''} where the header has {expected} "
            f"(cells separated by {delimiter!r}): {line[:120]!r}",
            file=path.name,
            key=where,
        )
    first = text.splitlines()[0] if text else "unreadable"
    return InputError(f"not a CSV table: {first[:200]}", file=path.name)


def _parquet(path: Path, time_scale, epoch) -> TelemetryFile:
    import pyarrow as pa
    import pyarrow.parquet as pq

    file = path.name
    try:
        table = pq.read_table(path)
    except (pa.ArrowInvalid, OSError) as exc:
        text = str(exc).splitlines()[0] if str(exc) else ""
        reason = (
            "no Parquet footer (the file is cut short, or not Parquet)"
            if "magic bytes" in text
            else text[:200]
        )
        raise InputError(f"not a readable Parquet file: {reason}", file=file) from None
    metadata = table.schema.metadata or {}
    stated = metadata.get(b"attitude.epoch")
    if epoch is None and stated:
        text = stated.decode()
        parts = text.split()
        if len(parts) == 2:
            try:
                epoch = as_time(parts[0], parts[1].lower(), "attitude.epoch")
            except InputError as exc:
                raise exc.located(file=file) from None
    columns = _columns(table.column_names, file)
    return _assemble(table, columns, file, time_scale, epoch, [])


def _aem(path: Path) -> TelemetryFile:
    """Every record of every segment of an AEM, in time order, as body → ICRF
    quaternions (and ANGVEL rates when the segments have them)."""
    from attitude.environment.ccsds import parse_epochs, read_message, scale_of
    from attitude.environment.frames import eme2000_to_icrf
    from attitude.files.aem_reader import INERTIAL, TYPES

    file = path.name
    try:
        message, _ = read_message(path, "Aem")
    except InputError as exc:  # its reason starts with the file's name: said once
        reason = exc.reason.removeprefix(f"{file}: ").removeprefix(f"{path}: ")
        raise InputError(reason, file=file) from None
    if str(message.version).strip() not in ("2.0", "2"):
        raise InputError(f"CCSDS_AEM_VERS = {message.version}: only AEM 2.0 is read", file=file)
    times, quats, rates = [], [], []
    for number, segment in enumerate(message.segments):
        where = f"segment {number}"
        meta = segment.metadata
        scale, offset_s = scale_of(meta.time_system, where)
        frame_a = (meta.ref_frame_a or "").strip().upper()
        frame_b = (meta.ref_frame_b or "").strip().upper()
        if frame_a in INERTIAL and frame_b.startswith("SC_BODY"):
            inertial, body_first = frame_a, False
        elif frame_b in INERTIAL and frame_a.startswith("SC_BODY"):
            inertial, body_first = frame_b, True
        else:
            raise InputError(
                f"REF_FRAME_A = {meta.ref_frame_a!r}, REF_FRAME_B = {meta.ref_frame_b!r}: "
                f"expected one of {', '.join(INERTIAL)} and a body frame (SC_BODY_1)",
                file=file,
                key=where,
            )
        kind = (meta.attitude_type or "").strip().upper()
        if kind not in TYPES:
            raise InputError(
                f"ATTITUDE_TYPE = {meta.attitude_type!r}: expected one of {', '.join(TYPES)}",
                file=file,
                key=where,
            )
        states = np.asarray(segment.data.attitude_states_numpy, dtype=np.float64)
        width = 4 if kind == "QUATERNION" else 7 if kind.endswith("ANGVEL") else 8
        if states.ndim != 2 or states.shape[1] != width:
            raise InputError(f"expected {width} numbers a record for {kind}", file=file, key=where)
        if not np.all(np.isfinite(states)):
            row = int(np.argwhere(~np.isfinite(states))[0, 0])
            raise InputError(
                f"record {row} is not finite: {states[row].tolist()}", file=file, key=where
            )
        epochs = _aem_epochs(
            segment.data.attitude_states_epochs, scale, offset_s, where, parse_epochs
        )
        q = states[:, [3, 0, 1, 2]]
        norm = np.linalg.norm(q, axis=1)
        if np.any(np.abs(norm - 1.0) > 1e-3):
            row = int(np.argmax(np.abs(norm - 1.0)))
            raise InputError(f"quaternion norm {norm[row]:.9g}, not 1", file=file, key=where)
        q = q / norm[:, None]
        if body_first:
            q = q * np.array([1.0, -1.0, -1.0, -1.0])
        R = Rotation.from_quat(q, scalar_first=True)
        if inertial == "EME2000":
            R = eme2000_to_icrf() * R
        ω = np.full((len(q), 3), np.nan)
        if kind.endswith("ANGVEL"):
            ω = np.radians(states[:, 4:7])
            frame = (meta.angvel_frame or frame_b).strip().upper()
            if frame in INERTIAL:
                ω = Rotation.from_quat(q, scalar_first=True).apply(ω, inverse=True)
            elif not frame.startswith("SC_BODY"):
                raise InputError(
                    f"ANGVEL_FRAME = {meta.angvel_frame!r}: not understood", file=file, key=where
                )
        times.append(epochs)
        quats.append(R.as_quat(scalar_first=True))
        rates.append(ω)
    from astropy.time import Time

    from attitude.environment.timescales import SAME_INSTANT_S, tt_seconds

    notes = []
    for k in range(len(times) - 1):  # segments that meet: the later one is in force
        if (
            len(times[k])
            and abs(float(tt_seconds(times[k + 1][0], times[k][-1]))) <= SAME_INSTANT_S
        ):
            times[k], quats[k], rates[k] = times[k][:-1], quats[k][:-1], rates[k][:-1]
            notes.append(
                f"segments {k} and {k + 1} meet: the record of segment {k + 1} is used there"
            )
    with offline_time():  # the segments' epochs as one Time, exactly (two-part TT dates)
        tt = [t.tt for t in times]
        all_times = Time(
            np.concatenate([t.jd1 for t in tt]),
            np.concatenate([t.jd2 for t in tt]),
            format="jd",
            scale="tt",
        )
    ω_all = np.concatenate(rates)
    notes.insert(0, f"{len(message.segments)} AEM segment(s), {len(ω_all)} records")
    has_rates = bool(np.any(np.isfinite(ω_all[:, 0])))
    return TelemetryFile(
        path, all_times, ω_all if has_rates else None, np.concatenate(quats), notes
    )


def _aem_epochs(texts: list[str], scale: str, offset_s: float, where: str, fallback):
    """The record epochs as one ``Time``: calendar texts parsed together (fast), the
    rest one by one as ``attitude.environment.ccsds.parse_epochs`` does."""
    from astropy.time import Time, TimeDelta

    cleaned = np.char.rstrip(np.char.strip(np.asarray(texts, dtype=str)), "Z")
    if cleaned.size and all(
        re.match(r"^\d{4}-\d{2}-\d{2}T", t) for t in cleaned[:: max(1, cleaned.size // 50)]
    ):
        try:
            with offline_time():
                times = Time(cleaned, format="isot", scale=scale, precision=9)
                return times + TimeDelta(offset_s, format="sec") if offset_s else times
        except (ValueError, TypeError):
            pass
    return fallback(list(texts), scale, offset_s, where)
