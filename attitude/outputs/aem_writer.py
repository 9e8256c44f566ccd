"""CCSDS Attitude Ephemeris Messages (AEM 2.0, KVN): the writer.

The standard is CCSDS 504.0-B-2 (Attitude Data Messages, January 2024), section 4 (AEM
content), section 6 (KVN syntax) and annex F (conventions).  Section numbers below refer
to it.

What is written
---------------
One message: the header (table 4-2), then one segment per :class:`AemSegment`, each a
``META_START`` … ``META_STOP`` block (table 4-3) and a ``DATA_START`` … ``DATA_STOP``
block (table 4-4).  Our scenarios start a new segment at each event: the attitude is
continuous there but the rate jumps, and a new metadata block is how an AEM says
"do not interpolate across this" (§4.2.4.8.3).

- ``ATTITUDE_TYPE = QUATERNION/ANGVEL``: each data line is
  ``EPOCH Q1 Q2 Q3 QC ANGVEL_X ANGVEL_Y ANGVEL_Z``.
- ``REF_FRAME_A`` = ICRF (or GCRF), ``REF_FRAME_B`` = ``SC_BODY_1``, and
  ``ANGVEL_FRAME = SC_BODY_1``: the rates are in body axes.  The keyword is optional in
  table 4-3, but it is the only place where a file says which axes the rates use, so it
  is always written.
- ``TIME_SYSTEM``: the scenario's astropy scale, as named in the SANA time-systems
  registry (annex B2): utc → UTC, tt → TT, tai → TAI, tdb → TDB, tcg → TCG, tcb → TCB.
  Epochs are written in that scale, as ``YYYY-MM-DDThh:mm:ss.fffffffff`` (§6.8.9, 1 ns).
  A UTC epoch inside a leap second is written ``…T23:59:60…`` (§4.2.4.7.3), which
  astropy's ``isot`` does by itself.
- ``START_TIME``/``STOP_TIME`` are the first and last epochs of the segment.
  ``USEABLE_START_TIME``/``USEABLE_STOP_TIME`` are the same: each record carries the
  exact attitude and rate, so the interpolation below needs no margin at the ends.
- ``INTERPOLATION_METHOD``/``INTERPOLATION_DEGREE``: what the segment recommends to
  its readers.  A report's AEM is sampled for a stated accuracy and declares
  ``LAGRANGE``, degree 7 (``attitude.outputs.aem_sampling``, which chooses the records).
  :func:`write_aem`, given records it did not choose, recommends ``HERMITE``, degree
  3, for segments of at least four records, unless the segment says otherwise.  Why
  Hermite there: each record gives the attitude and, through its angular velocity,
  the attitude's derivative (annex F kinematics, Q̇ = ½ Q ⊗ (ω_B, 0)), and with a
  value and a first derivative at two neighbouring records the polynomial is a
  cubic.  On a rotation at rate ω with step h, its error is at most (ωh/2)⁴/384 per
  component; choosing h is then the caller's responsibility.  Why at least four
  records: the standard does not say what "degree" counts, and Orekit, for one, reads
  degree d as d + 1 records.  §4.2.4.8.4 asks that every block hold enough records
  for the recommended method, so shorter segments get no recommendation.
- ``CREATION_DATE`` is the current UTC time, unless one is given (for reproducible
  files).  The values of ``OBJECT_NAME``, ``OBJECT_ID``, ``CENTER_NAME`` and
  ``ORIGINATOR`` come from the caller.

Quaternion convention: how ours maps onto Q1 Q2 Q3 QC
-----------------------------------------------------
Ours: ``q = (w, x, y, z)``, scalar first, is the rotation that takes **body coordinates to
inertial coordinates**: ``v_I = R(q) v_B``, with R(q) the usual (active) rotation matrix
of q, ``scipy.spatial.transform.Rotation.from_quat(q, scalar_first=True).as_matrix()``.
The columns of R(q) are therefore the body axes written in inertial coordinates: q is the
rotation that carries the inertial basis vectors onto the body basis vectors.

AEM (annex F2.1): the quaternion "from A to B" (here A = inertial, B = body) is "the
rotation that transforms the basis vectors of frame A into the basis vectors of frame B",
with Q1, Q2, Q3 = e·sin(φ/2) and QC = cos(φ/2), scalar **last** (annex J: the
``QUATERNION_TYPE`` keyword of version 1 is gone).  The annex gives the coordinate transform
``X_B = M_BA X_A``, where the first row of M_BA is
``[Q1²−Q2²−Q3²+QC², 2(Q1Q2+Q3QC), 2(Q1Q3−Q2QC)]``.  This M_BA is exactly the transpose of
the active rotation matrix of (Q1, Q2, Q3, QC).

Both definitions name the same rotation, A's axes onto B's, so M_BA = R(q)ᵀ and the
components are equal: **Q1 = x, Q2 = y, Q3 = z, QC = w**.  This is a reordering; there is
no conjugation.

The 90° example, which is annex F2.2's own.  A body whose x axis points along inertial +y
is turned +90° about z: ``q = (cos 45°, 0, 0, sin 45°)``, so ``Q1 = Q2 = 0`` and
``Q3 = QC = √½``.  This gives
``M_BA = [[0, 1, 0], [−1, 0, 0], [0, 0, 1]]``.  The inertial +y axis, ``X_A = (0, 1, 0)``,
has body coordinates ``X_B = (1, 0, 0)``: it is the body's x axis, as stated.

Signs.  q and −q are the same attitude, but an interpolating reader needs neighbouring
records in the same hemisphere.  The writer therefore writes the first record of the file
with QC ≥ 0, and flips each later record whose dot product with the record before it is
negative, across segment boundaries too.  The attitudes are unchanged.

Angular velocity (annex F4): "from A to B" is the angular velocity of B with respect to
A.  Here that is the body's angular velocity relative to inertial space, with
``ANGVEL_FRAME = SC_BODY_1`` giving its components in body axes.  That is our
``angular_velocity_body_rad_s``, converted to deg/s (§4.2.4.6).

Numbers
-------
Values are written in floating-point notation with 16 significant digits, for example
``7.071067811865476E-01``.  §6.8.4 allows at most 16 digits, in the mantissa of either
notation.  17 digits would be needed to reproduce every double bit for bit; with 16, a
quaternion component comes back within 5e-17 (half a unit in its 16th digit).  ``-0`` is
written as 0 (§6.8.5 excludes it).  Data lines stay under the 254-character limit of
§6.6.1.

Text values (§6.8.6) must be all upper case or all lower case.  A mixed-case name is
refused rather than changed: it identifies something.  Comments may use any case
(§6.10.1.4).

Two ways to write.  :class:`AemWriter` streams a message into an open file: the
header, then each segment's metadata (its first and last epochs are known before its
records) and its records a chunk at a time, every check made per chunk and across
chunks; a long run's AEM never sits in memory, and the output folder
(``attitude.outputs.folder``) makes the file appear whole or not at all.
:func:`write_aem` writes segments held in memory atomically: everything is validated
and formatted first, the bytes go to a temporary file in the target's directory, and
``os.replace`` puts it in place, so a failed call leaves no file behind and never a
half-written one.  Bad input raises :class:`~attitude.base.errors.InputError` naming the
field and the value.  Epochs given as texts (the streaming writer's) are written as
given; :func:`write_aem` writes astropy times through astropy.

There is no reader here: nothing in the package reads an AEM.  The tests read our files
back with an independent parser, ccsds-ndm-py, and check what it does not (unit norms,
increasing epochs, START/STOP_TIME against the data) themselves.
"""

from __future__ import annotations

import io
import os
import re
import secrets
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, BinaryIO

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.environment.timescales import as_time, iso_texts, offline_time, tt_seconds

if TYPE_CHECKING:
    from astropy.time import Time

__all__ = [
    "BODY_FRAME",
    "QUATERNION_COMMENT",
    "REFERENCE_FRAMES",
    "TIME_SYSTEMS",
    "AemSegment",
    "AemWriter",
    "write_aem",
]

AEM_VERSION = "2.0"
ATTITUDE_TYPE = "QUATERNION/ANGVEL"
BODY_FRAME = "SC_BODY_1"
# Every message says how to read its quaternions (docs/conventions.md): AEM v2 has no
# QUATERNION_TYPE keyword (annex J), the order is fixed scalar last.
QUATERNION_COMMENT = (
    "quaternion Q1 Q2 Q3 QC: scalar last (QC = cos(angle/2)), from REF_FRAME_A to "
    "REF_FRAME_B as in annex F: the rotation taking body coordinates into REF_FRAME_A "
    "coordinates"
)
# Our inertial axes are the ICRS axes.  The GCRS axes are the same axes; only the origin
# differs, and an attitude does not depend on the origin.  Other frames (EME2000, ...)
# would need a rotation, so they are refused rather than mislabelled.
REFERENCE_FRAMES = ("ICRF", "GCRF")
# astropy scale -> TIME_SYSTEM value (SANA time-systems registry, annex B2).
TIME_SYSTEMS = {"utc": "UTC", "tt": "TT", "tai": "TAI", "tdb": "TDB", "tcg": "TCG", "tcb": "TCB"}
_SCALES = {value: key for key, value in TIME_SYSTEMS.items()}

# scipy's Rotation normalizes to a few ulp; anything further from 1 is a bug upstream
# (a matrix row, a wrong array), not rounding.
UNIT_NORM_TOLERANCE = 1e-12
# §6.8.4: at most 16 digits (see the module docstring for why not 17).
SIGNIFICANT_DIGITS = 16
EPOCH_DECIMALS = 9  # 1 ns, astropy's finest isot precision
MAX_LINE_CHARS = 254  # §6.6.1
HERMITE_DEGREE = 3
HERMITE_MIN_RECORDS = 4

_NUMBER_FORMAT = f"%.{SIGNIFICANT_DIGITS - 1}E"
_RECORD_FORMAT = "%s" + f" {_NUMBER_FORMAT}" * 7
# Written epochs; a 4-digit year also keeps string order equal to time order.
_EPOCH_CHARS = 20 + EPOCH_DECIMALS
_EPOCH_WRITTEN = re.compile(rf"\d{{4}}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{{{EPOCH_DECIMALS}}}")


@dataclass(frozen=True, eq=False)
class AemSegment:
    """One AEM segment: epochs, attitudes (our convention) and body rates, validated.

    - ``times``: 1-D ``astropy.time.Time``, strictly increasing (compared in TT), any scale.
    - ``quaternion_body_to_inertial_scalar_first``: (N, 4), unit quaternions (w, x, y, z)
      taking body coordinates to inertial ones, or a ``Rotation`` of N attitudes (body →
      inertial).
    - ``angular_velocity_body_rad_s``: (N, 3), the body's angular velocity with respect
      to inertial space, in body axes, rad/s.
    - ``comments``: optional lines written at the start of the segment's metadata.

    Bad values raise :class:`InputError` on construction.  The times are stored as a
    copy and the arrays as read-only float64 copies.
    """

    times: Time
    quaternion_body_to_inertial_scalar_first: NDArray[np.float64]
    angular_velocity_body_rad_s: NDArray[np.float64]
    comments: tuple[str, ...] = ()
    interpolation: tuple[str, int] | None = None

    def __post_init__(self) -> None:
        times = _checked_times(self.times)
        n = len(times)
        attitude = self.quaternion_body_to_inertial_scalar_first
        if isinstance(attitude, Rotation):  # an attitude, as the package returns them
            attitude = attitude.as_quat(scalar_first=True)
            object.__setattr__(self, "quaternion_body_to_inertial_scalar_first", attitude)
        quaternions = _checked_array(
            "quaternion_body_to_inertial_scalar_first",
            self.quaternion_body_to_inertial_scalar_first,
            n,
            4,
        )
        _check_unit_norm("quaternion_body_to_inertial_scalar_first", quaternions)
        rates = _checked_array(
            "angular_velocity_body_rad_s", self.angular_velocity_body_rad_s, n, 3
        )
        object.__setattr__(self, "times", times)
        object.__setattr__(self, "quaternion_body_to_inertial_scalar_first", quaternions)
        object.__setattr__(self, "angular_velocity_body_rad_s", rates)
        object.__setattr__(self, "comments", _checked_comments("comments", self.comments))


def write_aem(
    path: str | os.PathLike[str],
    segments: Sequence[AemSegment],
    *,
    object_name: str,
    object_id: str,
    time_scale: str,
    reference_frame: str = "ICRF",
    center_name: str | None = "EARTH",
    originator: str = "attitude",
    creation_date: Time | str | None = None,
    comments: Iterable[str] = (),
) -> Path:
    """Write ``segments`` to ``path`` as a CCSDS AEM 2.0 KVN file, atomically.  Returns the path.

    - ``object_name``/``object_id``: ``OBJECT_NAME``/``OBJECT_ID`` (table 4-3), e.g.
      ``"TESTSAT"``/``"2027-001A"``.  Text must be all upper or all lower case (§6.8.6).
    - ``time_scale``: the scenario's astropy scale (utc, tt, tai, tdb, tcg, tcb); epochs are
      converted to it and ``TIME_SYSTEM`` names it (annex B2).
    - ``reference_frame``: ``REF_FRAME_A``, ``"ICRF"`` or ``"GCRF"``.
    - ``center_name``: ``CENTER_NAME`` (the body orbited), or None to leave it out.
    - ``originator``: ``ORIGINATOR`` (table 4-2).
    - ``creation_date``: ``CREATION_DATE`` (a ``Time``, or an ISO string read as UTC); the
      current UTC time when None.
    - ``comments``: header ``COMMENT`` lines, one per item.

    Consecutive segments may share their boundary epoch (an event) but must not overlap,
    since ``USEABLE_START_TIME`` of a block must not precede ``USEABLE_STOP_TIME`` of the
    one before (table 4-3).  A segment of four records or more recommends cubic
    ``HERMITE`` interpolation (see the module docstring), unless it says otherwise.
    Nothing is written if anything is wrong.
    """
    segments = _checked_segments(segments)
    buffer = io.BytesIO()
    writer = AemWriter(
        buffer,
        object_name=object_name,
        object_id=object_id,
        time_scale=time_scale,
        reference_frame=reference_frame,
        center_name=center_name,
        originator=originator,
        creation_date=creation_date,
        comments=comments,
    )
    for index, segment in enumerate(segments):
        name = f"segments[{index}]"
        epochs = _epoch_strings(segment.times, writer.time_system, name)
        interpolation = segment.interpolation
        if interpolation is None and len(epochs) >= HERMITE_MIN_RECORDS:
            interpolation = ("HERMITE", HERMITE_DEGREE)
        writer.begin_segment(
            str(epochs[0]), str(epochs[-1]), interpolation=interpolation, comments=segment.comments
        )
        writer.write_records(
            np.char.encode(epochs, "ascii"),
            segment.quaternion_body_to_inertial_scalar_first,
            segment.angular_velocity_body_rad_s,
        )
        writer.end_segment()
    writer.close()
    return _write_atomically(Path(path), buffer.getvalue())


def aem_text(value: str, upper: bool = True, width: int = 60) -> str:
    """A free text (a spacecraft's or a scenario's name) made a value the AEM accepts:
    printable ASCII (any other character, such as the en dash of "T-handle – flip",
    becomes a blank), single blanks, at most ``width`` characters, in upper case for a
    keyword value; "UNKNOWN" when nothing is left."""
    text = "".join(c if c.isascii() and c.isprintable() else " " for c in value)
    text = " ".join(text.split())[:width].rstrip()
    return (text.upper() if upper else text) or "UNKNOWN"


class AemWriter:
    """An AEM 2.0 KVN message written as it is produced, into a binary ``stream``.

    The header is checked and written on construction (the keywords of
    :func:`write_aem`).  Then, for each segment: :meth:`begin_segment` with its first
    and last epochs (known before its records are: ``START_TIME`` comes first in the
    file), :meth:`write_records` as many times as there are chunks of records, and
    :meth:`end_segment`; finally :meth:`close`.  Every check of :func:`write_aem`
    is made on each chunk, and across chunks (epochs increasing, signs continuous),
    raising :class:`InputError`; the caller owns the stream, and a file left by a
    failure is the caller's to remove (:mod:`attitude.outputs.folder` does).
    """

    def __init__(
        self,
        stream: BinaryIO,
        *,
        object_name: str,
        object_id: str,
        time_scale: str,
        reference_frame: str = "ICRF",
        center_name: str | None = "EARTH",
        originator: str = "attitude",
        creation_date: Time | str | None = None,
        comments: Iterable[str] = (),
    ) -> None:
        self.time_system = _time_system(time_scale)
        frame = _reference_frame(reference_frame)
        names = [
            f"OBJECT_NAME = {_text_value('object_name', object_name)}",
            f"OBJECT_ID = {_text_value('object_id', object_id)}",
        ]
        if center_name is not None:
            names.append(f"CENTER_NAME = {_text_value('center_name', center_name)}")
        self._frames = [
            *names,
            f"REF_FRAME_A = {frame}",
            f"REF_FRAME_B = {BODY_FRAME}",
            f"TIME_SYSTEM = {self.time_system}",
        ]
        lines = [f"CCSDS_AEM_VERS = {AEM_VERSION}"]
        lines += _comment_lines([*_checked_comments("comments", comments), QUATERNION_COMMENT])
        lines.append(f"CREATION_DATE = {_creation_date(creation_date)}")
        lines.append(f"ORIGINATOR = {_text_value('originator', originator)}")
        _check_line_lengths(lines + self._frames)
        self._stream = stream
        self._count = 0  # segments begun
        self._open: tuple[str, str] | None = None  # (start, stop) of the open segment
        self._last_epoch = ""  # last epoch written in the open segment
        self._previous_stop = ""
        self._previous_record: NDArray[np.float64] | None = None  # AEM order, for signs
        self._write(lines)

    def _write(self, lines: list[str]) -> None:
        self._stream.write(("\n".join(lines) + "\n").encode("ascii"))

    def begin_segment(
        self,
        start: str,
        stop: str,
        *,
        interpolation: tuple[str, int] | None = None,
        comments: Iterable[str] = (),
    ) -> None:
        """Start a segment whose records run from ``start`` to ``stop`` (epoch texts in
        the time system, both included).  ``interpolation``: (``INTERPOLATION_METHOD``,
        ``INTERPOLATION_DEGREE``) recommended to its readers, or None."""
        if self._open is not None:
            raise InputError("begin_segment: the previous segment was not ended")
        name = f"segments[{self._count}]"
        for epoch in (start, stop):
            if not _EPOCH_WRITTEN.fullmatch(epoch):
                raise InputError(
                    f"{name}.times: {epoch} {self.time_system} is outside the years 0000-9999 "
                    "(§6.8.9)"
                )
        if start < self._previous_stop:  # same format and scale: string order is time order
            raise InputError(
                f"{name} starts at {start} {self.time_system}, before segments[{self._count - 1}] "
                f"stops ({self._previous_stop}); segments must not overlap (table 4-3)"
            )
        if stop < start:
            raise InputError(f"{name} stops at {stop}, before it starts ({start})")
        lines = ["", "META_START"]
        lines += _comment_lines(_checked_comments(f"{name}.comments", comments))
        lines += self._frames
        lines += [
            f"START_TIME = {start}",
            f"USEABLE_START_TIME = {start}",
            f"USEABLE_STOP_TIME = {stop}",
            f"STOP_TIME = {stop}",
            f"ATTITUDE_TYPE = {ATTITUDE_TYPE}",
            f"ANGVEL_FRAME = {BODY_FRAME}",
        ]
        if interpolation is not None:
            method, degree = interpolation
            lines += [
                f"INTERPOLATION_METHOD = {_text_value('interpolation method', method)}",
                f"INTERPOLATION_DEGREE = {int(degree)}",
            ]
        lines += ["META_STOP", "", "DATA_START"]
        _check_line_lengths(lines)
        self._write(lines)
        self._count += 1
        self._open = (start, stop)
        self._last_epoch = ""

    def write_records(
        self,
        epochs: NDArray[np.bytes_],
        quaternion_body_to_inertial_scalar_first: ArrayLike,
        angular_velocity_body_rad_s: ArrayLike,
    ) -> None:
        """Append records to the open segment.

        ``epochs``: ASCII epoch texts (numpy ``S29``, as
        :class:`attitude.environment.epoch_texts.EpochTexts` writes them) in the time system,
        increasing, within the segment's start and stop; the quaternions and rates as
        in :class:`AemSegment`.
        """
        if self._open is None:
            raise InputError("write_records: no segment is open (begin_segment first)")
        name = f"segments[{self._count - 1}]"
        epochs = np.asarray(epochs)
        n = epochs.size
        if n == 0:
            return
        quaternions = _checked_array(
            "quaternion_body_to_inertial_scalar_first",
            quaternion_body_to_inertial_scalar_first,
            n,
            4,
        )
        _check_unit_norm("quaternion_body_to_inertial_scalar_first", quaternions)
        rates = _checked_array("angular_velocity_body_rad_s", angular_velocity_body_rad_s, n, 3)
        texts = epochs.astype(f"S{_EPOCH_CHARS}")
        first, last = texts[0].decode("ascii"), texts[-1].decode("ascii")
        start, stop = self._open
        if first <= self._last_epoch or first < start or last > stop:
            raise InputError(
                f"{name}: records from {first} to {last} {self.time_system} are not after the "
                f"last one written ({self._last_epoch or 'none'}) and within the segment "
                f"({start} to {stop})"
            )
        repeated = np.flatnonzero(texts[1:] <= texts[:-1])
        if repeated.size:
            i = int(repeated[0]) + 1
            raise InputError(
                f"{name}.times[{i - 1}] and [{i}] are both written {texts[i].decode()} "
                f"{self.time_system}: epochs closer than 1 ns would repeat a time tag "
                "(§4.2.4.8.1)"
            )
        aem = _aem_quaternions(quaternions, self._previous_record)
        self._previous_record = aem[-1]
        # rad/s -> deg/s (§4.2.4.6); "+ 0.0" turns -0 into 0, which §6.8.5 excludes.
        values = np.hstack([aem, np.degrees(rates)]) + 0.0
        self._stream.write(_records(texts, values))
        self._last_epoch = last

    def end_segment(self) -> None:
        """Close the open segment; its last record must be at its stop epoch."""
        if self._open is None:
            raise InputError("end_segment: no segment is open")
        stop = self._open[1]
        if self._last_epoch != stop:
            raise InputError(
                f"segments[{self._count - 1}]: STOP_TIME is {stop} but the last record is at "
                f"{self._last_epoch or 'none'}"
            )
        self._write(["DATA_STOP"])
        self._previous_stop = stop
        self._open = None

    def close(self) -> None:
        """Check that the message is complete (at least one segment, none open)."""
        if self._open is not None:
            raise InputError("close: the last segment was not ended")
        if self._count == 0:
            raise InputError("segments: an AEM needs at least one segment (table 4-1), got none")


# --- writing -------------------------------------------------------------------------


def _comment_lines(comments: Iterable[str]) -> list[str]:
    return [f"COMMENT {line}" if line else "COMMENT" for line in comments]


def _check_line_lengths(lines: list[str]) -> None:
    longest = max(lines, key=len)
    if len(longest) > MAX_LINE_CHARS:  # only text values can get here; data lines are ~190
        raise InputError(
            f"line {longest[:40]!r}... has {len(longest)} characters, more than the "
            f"{MAX_LINE_CHARS} of §6.6.1"
        )


def _records(epochs: NDArray[np.bytes_], values: NDArray[np.float64]) -> bytes:
    """Data lines: each epoch, then its 7 numbers in ``%.15E``, one line each.

    One ``%`` operation on the whole chunk: the per-value formatting is C's, and no
    Python loop runs per record.
    """
    rows = np.empty((len(epochs), 8), dtype=object)
    rows[:, 0] = epochs.astype(f"U{_EPOCH_CHARS}")
    rows[:, 1:] = values
    return ((_RECORD_FORMAT + "\n") * len(epochs) % tuple(rows.ravel().tolist())).encode("ascii")


def _write_atomically(path: Path, data: bytes) -> Path:
    """Write ``data`` to a temporary file beside ``path``, then ``os.replace`` it into place.

    The temporary file is created with ``O_EXCL`` and mode 0o666, so the umask applies
    as for any new file.  ``tempfile`` would make it 0o600, and the AEM would keep that.
    """
    temporary = path.with_name(f".{path.name}.{secrets.token_hex(8)}.tmp")
    descriptor = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
    try:
        with os.fdopen(descriptor, "wb") as stream:
            stream.write(data)
            stream.flush()
            os.fsync(stream.fileno())
        os.replace(temporary, path)
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise
    return path


def _checked_segments(segments: Sequence[AemSegment]) -> list[AemSegment]:
    if isinstance(segments, AemSegment):
        raise InputError("segments must be a sequence of AemSegment, got a single AemSegment")
    try:
        segments = list(segments)
    except TypeError:
        raise InputError(
            f"segments must be a sequence of AemSegment, got {type(segments).__name__}"
        ) from None
    if not segments:
        raise InputError("segments: an AEM needs at least one segment (table 4-1), got none")
    for index, segment in enumerate(segments):
        if not isinstance(segment, AemSegment):
            raise InputError(
                f"segments[{index}] must be an AemSegment, got {type(segment).__name__}"
            )
    return segments


def _time_system(time_scale: str) -> str:
    scale = str(time_scale).lower()
    if scale not in TIME_SYSTEMS:
        raise InputError(f"time_scale must be one of {', '.join(TIME_SYSTEMS)}, got {time_scale!r}")
    return TIME_SYSTEMS[scale]


def _reference_frame(reference_frame: str) -> str:
    frame = str(reference_frame).upper()
    if frame not in REFERENCE_FRAMES:
        raise InputError(
            f"reference_frame must be one of {', '.join(REFERENCE_FRAMES)} (the axes our "
            f"attitudes are given in), got {reference_frame!r}"
        )
    return frame


def _text_value(name: str, value: Any) -> str:
    """A KVN text value (§6.8.6–6.8.8): printable ASCII, single blanks, one case."""
    if not isinstance(value, str):
        raise InputError(f"{name} must be a string, got {value!r}")
    problem = None
    if not value:
        problem = "it is empty (§6.8.7)"
    elif not (value.isascii() and value.isprintable()):
        problem = "only printable ASCII is allowed (§6.6.3)"
    elif value != value.strip() or "  " in value:
        problem = "leading, trailing or repeated blanks are not significant in KVN (§6.8.8)"
    elif value != value.upper() and value != value.lower():
        problem = "text values must be all upper case or all lower case (§6.8.6)"
    elif len(value) > MAX_LINE_CHARS - len("USEABLE_START_TIME = "):
        problem = f"it is longer than a {MAX_LINE_CHARS}-character line allows (§6.6.1)"
    if problem:
        raise InputError(f"{name}: {value!r} cannot be written: {problem}")
    return value


def _checked_comments(name: str, comments: Iterable[str]) -> tuple[str, ...]:
    """Comment lines: printable ASCII, one line each; trailing blanks dropped (§6.7.6)."""
    if isinstance(comments, str):
        comments = (comments,)
    checked = []
    for index, comment in enumerate(comments):
        if not isinstance(comment, str):
            raise InputError(f"{name}[{index}] must be a string, got {comment!r}")
        if not (comment.isascii() and comment.isprintable()):
            raise InputError(
                f"{name}[{index}]: {comment!r} must be one line of printable ASCII (§6.6.3); "
                "give several comments for several lines"
            )
        if len(comment) > MAX_LINE_CHARS - len("COMMENT "):
            raise InputError(
                f"{name}[{index}] has {len(comment)} characters; a comment line holds at most "
                f"{MAX_LINE_CHARS - len('COMMENT ')} (§6.6.1)"
            )
        checked.append(comment.rstrip())
    return tuple(checked)


def _creation_date(creation_date: Time | str | None) -> str:
    from astropy.time import Time

    with offline_time():
        if creation_date is None:
            date = Time.now()
        else:
            date = as_time(creation_date, "utc", name="creation_date")
            if not date.isscalar:
                raise InputError(f"creation_date must be a single epoch, got shape {date.shape}")
        text = Time(date.utc, precision=0).isot
    if not re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d", text):
        raise InputError(f"creation_date: {text!r} is outside the years 0000-9999 (§6.8.9)")
    return text


def _epoch_strings(times: Time, time_system: str, name: str) -> NDArray[np.str_]:
    """``times`` as §6.8.9 strings in ``time_system``, to 1 ns, still strictly increasing."""
    from astropy.time import Time

    with offline_time():
        # A new Time, so that setting the precision leaves the caller's object alone
        # (``t.utc`` is ``t`` itself when t is already UTC).
        epochs = np.asarray(
            iso_texts(Time(getattr(times, _SCALES[time_system]), precision=EPOCH_DECIMALS))
        )
    # The times increase, so the first and last epochs bound the years.
    for epoch in (epochs[0], epochs[-1]):
        if not _EPOCH_WRITTEN.fullmatch(epoch):
            raise InputError(
                f"{name}.times: {epoch} {time_system} is outside the years 0000-9999 (§6.8.9)"
            )
    repeated = np.flatnonzero(epochs[1:] <= epochs[:-1])
    if repeated.size:
        i = int(repeated[0]) + 1
        raise InputError(
            f"{name}.times[{i - 1}] and [{i}] are both written {epochs[i]} {time_system}: epochs "
            "closer than 1 ns would repeat a time tag (§4.2.4.8.1)"
        )
    return epochs


def _aem_quaternions(
    quaternions: NDArray[np.float64], previous: NDArray[np.float64] | None
) -> NDArray[np.float64]:
    """Our (w, x, y, z) as AEM (Q1, Q2, Q3, QC) = (x, y, z, w), signs made continuous.

    The first record of the file gets QC ≥ 0.  Each later record gets the sign that makes
    its dot product with the record before it non-negative, so that neighbours are in the
    same hemisphere, as an interpolating reader needs.
    """
    aem = quaternions[:, [1, 2, 3, 0]]
    first_dot = aem[0, 3] if previous is None else float(aem[0] @ previous)
    dots = np.einsum("ij,ij->i", aem[1:], aem[:-1])
    steps = np.where(np.concatenate(([first_dot], dots)) < 0.0, -1.0, 1.0)
    return aem * np.cumprod(steps)[:, np.newaxis]


# --- validation of the segments ----------------------------------


def _checked_times(times: Any) -> Time:
    from astropy.time import Time

    if not isinstance(times, Time):
        raise InputError(f"times must be an astropy.time.Time, got {type(times).__name__}")
    if times.ndim != 1:
        raise InputError(f"times must be 1-D, got shape {times.shape}")
    if len(times) == 0:
        raise InputError(
            "times: an empty segment cannot be written; a segment needs at least one epoch"
        )
    if times.masked:
        raise InputError("times: masked epochs cannot be written")
    finite = np.isfinite(times.jd1) & np.isfinite(times.jd2)
    if not finite.all():
        raise InputError(f"times[{int(np.argmin(finite))}] is not a finite epoch")
    if len(times) > 1:
        # In TT seconds, from the two-part JDs (UTC's quasi-JD must not be differenced).
        steps_s = tt_seconds(times[1:], times[:-1])
        bad = np.flatnonzero(~(steps_s > 0.0))
        if bad.size:
            i = int(bad[0]) + 1
            with offline_time():
                shown = Time(times[i - 1 : i + 1], precision=EPOCH_DECIMALS).isot
            raise InputError(
                f"times must increase strictly (§4.2.4.8.1): times[{i}] = {shown[1]} "
                f"{times.scale.upper()} is not after times[{i - 1}] = {shown[0]}"
            )
    return times.copy()  # a copy, like the arrays: a Time can be changed in place


def _checked_array(name: str, value: ArrayLike, rows: int, columns: int) -> NDArray[np.float64]:
    array = np.asarray(value)
    if array.dtype.kind not in "biuf":
        raise InputError(f"{name} must be numeric, got dtype {array.dtype}")
    if array.shape != (rows, columns):
        raise InputError(
            f"{name} must have shape ({rows}, {columns}) (one row per epoch), got {array.shape}"
        )
    array = np.array(array, dtype=np.float64)  # a copy: the segment must not change later
    finite = np.isfinite(array)
    if not finite.all():
        row, column = np.argwhere(~finite)[0]
        raise InputError(f"{name} must be finite, got {array[row, column]} at [{row}, {column}]")
    array.flags.writeable = False
    return array


def _check_unit_norm(name: str, quaternions: NDArray[np.float64]) -> None:
    norms = np.sqrt(np.einsum("ij,ij->i", quaternions, quaternions))
    worst = int(np.argmax(np.abs(norms - 1.0)))
    if abs(norms[worst] - 1.0) > UNIT_NORM_TOLERANCE:
        raise InputError(
            f"{name}[{worst}] = {quaternions[worst].tolist()} has norm {norms[worst]:.17g}; "
            f"a unit quaternion is needed (to {UNIT_NORM_TOLERANCE:g})"
        )
