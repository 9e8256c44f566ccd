"""An attitude read from a CCSDS Attitude Ephemeris Message (AEM 2.0, KVN) at an epoch.

For ``[initial_state] aem = "file.aem"``: the spacecraft starts in the attitude the file
gives at the scenario's epoch.  The file is parsed by ccsds-ndm-py and checked here
(:mod:`attitude.environment.ccsds`):

- ``CCSDS_AEM_VERS = 2.0`` (CCSDS 504.0-B-2).  Version 1 files are refused: their
  ``QUATERNION_TYPE`` and ``ATTITUDE_DIR`` keywords change what the numbers mean;
- ``ATTITUDE_TYPE`` ``QUATERNION``, ``QUATERNION/DERIVATIVE`` or ``QUATERNION/ANGVEL``;
- one of ``REF_FRAME_A``/``REF_FRAME_B`` is ``ICRF``, ``GCRF`` or ``EME2000`` and the
  other a spacecraft body frame (``SC_BODY_…``);
- quaternions have unit norm (to 1e-3; they are then normalized), epochs increase.

**Conventions** (annex F of the standard; the writer :mod:`attitude.outputs.aem_writer` follows them
too).  The quaternion (Q1, Q2, Q3, QC), scalar last, "from A to B" is the rotation that
carries A's axes onto B's.  With A inertial and B the body, it is our body → inertial
rotation, component for component; with A the body and B inertial it is its inverse.
``ANGVEL`` rates (deg/s) are the body's rate relative to the inertial frame, in
``ANGVEL_FRAME`` axes (body or inertial); a quaternion's rate is then
q̇ = ½ q ⊗ (0, ω_body) in our scalar-first notation.

**EME2000** is rotated to the ICRF by the IAU 2000 frame bias (23 mas,
:func:`attitude.environment.frames.eme2000_to_icrf`), after the interpolation: body → ICRF =
B · (body → EME2000).

**Interpolation**, as the segment declares it (``INTERPOLATION_METHOD``/``DEGREE``):
an epoch on a record (within 1 ns) takes that record; otherwise ``LAGRANGE`` (d + 1
records) and ``HERMITE`` (⌈(d + 1)/2⌉ records with their rates) interpolate the four
components of sign-aligned quaternions and normalize, and ``LINEAR`` is the spherical
linear interpolation (slerp) between the two records around the epoch, the geodesic
that "linear" means for rotations.  A segment that declares nothing is slerped, and
the notes say so.  An epoch outside every segment's useable span is refused.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from attitude.base.errors import InputError
from attitude.environment.ccsds import MAX_DEGREE, interpolate, parse_epochs, read_message, scale_of
from attitude.environment.frames import eme2000_to_icrf
from attitude.environment.timescales import SAME_INSTANT_S, as_time, tt_seconds

__all__ = ["attitude_from_aem"]

INERTIAL = ("ICRF", "GCRF", "EME2000")
TYPES = ("QUATERNION", "QUATERNION/DERIVATIVE", "QUATERNION/ANGVEL")
METHODS = ("HERMITE", "LAGRANGE", "LINEAR")


def attitude_from_aem(path: str | Path, epoch: Any) -> tuple[Rotation, list[str]]:
    """The body → ICRF rotation that the AEM file at ``path`` gives at ``epoch`` (a
    ``Time``), and notes for the user.  :class:`InputError` naming the file (and the
    segment and keyword) for a file this cannot use or an epoch outside it."""
    path = Path(path)
    file = path.name
    epoch = as_time(epoch, name="epoch")
    message, _ = read_message(path, "Aem")
    if str(message.version).strip() not in ("2.0", "2"):
        raise InputError(
            f"{file}: CCSDS_AEM_VERS = {message.version}: only AEM 2.0 is read (a version 1 "
            "file's QUATERNION_TYPE and ATTITUDE_DIR change what its numbers mean)"
        )
    spans = []
    for number, segment in enumerate(message.segments):
        where = f"{file}: segment {number}"
        meta = segment.metadata
        scale, offset_s = scale_of(meta.time_system, where)
        epochs = parse_epochs(segment.data.attitude_states_epochs, scale, offset_s, where)
        useable = parse_epochs(
            [
                meta.useable_start_time or meta.start_time,
                meta.useable_stop_time or meta.stop_time,
            ],
            scale,
            offset_s,
            where,
        )
        start_s, stop_s = (float(x) for x in tt_seconds(useable, epoch))
        spans.append(f"{useable[0].isot} to {useable[1].isot} {scale.upper()}")
        if not start_s - SAME_INSTANT_S <= 0.0 <= stop_s + SAME_INSTANT_S:
            continue
        later = [
            k
            for k in range(number + 1, len(message.segments))
            if _starts_at(message.segments[k], epoch, file, k)
        ]
        if later:  # two segments meet at the epoch: the later one is in force
            continue
        return _attitude_in(segment, tt_seconds(epochs, epoch), where)
    raise InputError(
        f"{file}: the scenario epoch {epoch.isot} {epoch.scale.upper()} is outside the "
        f"file's segments ({'; '.join(spans)})"
    )


def _starts_at(segment, epoch, file: str, number: int) -> bool:
    meta = segment.metadata
    scale, offset_s = scale_of(meta.time_system, f"{file}: segment {number}")
    start = parse_epochs(
        [meta.useable_start_time or meta.start_time], scale, offset_s, f"{file}: segment {number}"
    )
    return abs(float(tt_seconds(start, epoch)[0])) <= SAME_INSTANT_S


def _attitude_in(segment, node_s, where: str) -> tuple[Rotation, list[str]]:
    """The attitude at TT second 0 of ``node_s`` (the records' times from the epoch)."""
    meta = segment.metadata
    frame_a = (meta.ref_frame_a or "").strip().upper()
    frame_b = (meta.ref_frame_b or "").strip().upper()
    if frame_a in INERTIAL and frame_b.startswith("SC_BODY"):
        inertial, body_first = frame_a, False
    elif frame_b in INERTIAL and frame_a.startswith("SC_BODY"):
        inertial, body_first = frame_b, True
    else:
        raise InputError(
            f"{where}: REF_FRAME_A = {meta.ref_frame_a!r}, REF_FRAME_B = {meta.ref_frame_b!r}: "
            f"expected one of {', '.join(INERTIAL)} and a body frame (SC_BODY_1)"
        )
    kind = (meta.attitude_type or "").strip().upper()
    if kind not in TYPES:
        raise InputError(
            f"{where}: ATTITUDE_TYPE = {meta.attitude_type!r}: expected one of {', '.join(TYPES)}"
        )
    states = np.asarray(segment.data.attitude_states_numpy, dtype=np.float64)
    columns = 4 if kind == "QUATERNION" else 7 if kind.endswith("ANGVEL") else 8
    if states.ndim != 2 or states.shape[0] == 0 or states.shape[1] != columns:
        raise InputError(f"{where}: expected {columns} numbers a record for {kind}")
    if not np.all(np.isfinite(states)):
        row = int(np.argwhere(~np.isfinite(states))[0, 0])
        raise InputError(f"{where}: record {row} is not finite: {states[row].tolist()}")
    node_s = np.asarray(node_s, dtype=np.float64)
    if np.any(np.diff(node_s) <= 0.0):
        raise InputError(f"{where}: epochs must increase")
    # Ours: scalar first, body -> the file's inertial frame.
    q = states[:, [3, 0, 1, 2]]
    norm = np.linalg.norm(q, axis=1)
    if np.any(np.abs(norm - 1.0) > 1e-3):
        row = int(np.argmax(np.abs(norm - 1.0)))
        raise InputError(f"{where}: record {row}: quaternion norm {norm[row]:.9g}, not 1")
    q = q / norm[:, None]
    rates = None
    if kind == "QUATERNION/DERIVATIVE":
        rates = states[:, [7, 4, 5, 6]]
    if body_first:  # the file's q is inertial -> body: conjugate it (and its rate)
        q = q * np.array([1.0, -1.0, -1.0, -1.0])
        if rates is not None:
            rates = rates * np.array([1.0, -1.0, -1.0, -1.0])
    if kind == "QUATERNION/ANGVEL":
        omega = np.radians(states[:, 4:7])
        angvel_frame = (meta.angvel_frame or frame_b).strip().upper()
        if angvel_frame in INERTIAL:
            omega = Rotation.from_quat(q, scalar_first=True).apply(omega, inverse=True)
        elif not angvel_frame.startswith("SC_BODY"):
            raise InputError(f"{where}: ANGVEL_FRAME = {meta.angvel_frame!r}: not understood")
        # q ⊗ (0, ω) = (−v·ω, w ω + v × ω) for q = (w, v).
        w, v = q[:, :1], q[:, 1:]
        rates = 0.5 * np.hstack(
            [-np.sum(v * omega, axis=1, keepdims=True), w * omega + np.cross(v, omega)]
        )
    # Neighbouring records in one hemisphere, so that the components interpolate.
    flips = np.concatenate([[1.0], np.sign(np.sum(q[1:] * q[:-1], axis=1))])
    flips[flips == 0.0] = 1.0
    signs = np.cumprod(flips)[:, None]
    q = q * signs
    if rates is not None:
        rates = rates * signs
    notes: list[str] = []
    on_record = np.flatnonzero(np.abs(node_s) <= SAME_INSTANT_S)
    if on_record.size:
        value = q[on_record[0]]
    else:
        value = _interpolated(meta, node_s, q, rates, where, notes)
    rotation = Rotation.from_quat(value / np.linalg.norm(value), scalar_first=True)
    if inertial == "EME2000":
        rotation = eme2000_to_icrf() * rotation
    return rotation, notes


def _interpolated(meta, node_s, q, rates, where: str, notes: list[str]):
    method = (meta.interpolation_method or "").strip().upper()
    degree = meta.interpolation_degree
    if method and method not in METHODS:
        raise InputError(
            f"{where}: INTERPOLATION_METHOD = {meta.interpolation_method!r}: expected one of "
            f"{', '.join(METHODS)}"
        )
    if not method or method == "LINEAR":
        if not method:
            notes.append(f"{where} declares no INTERPOLATION_METHOD: slerp between records")
        return Slerp(node_s, Rotation.from_quat(q, scalar_first=True))(0.0).as_quat(
            scalar_first=True
        )
    if degree is None or not 1 <= degree <= MAX_DEGREE:
        raise InputError(f"{where}: INTERPOLATION_DEGREE = {degree}: expected 1 to {MAX_DEGREE}")
    if method == "HERMITE" and rates is None:
        raise InputError(
            f"{where}: INTERPOLATION_METHOD = HERMITE, but ATTITUDE_TYPE = QUATERNION gives no "
            "rates to interpolate with"
        )
    value, _ = interpolate(method, degree, node_s, q, rates, np.array([0.0]))
    return value[0]
