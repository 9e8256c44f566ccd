"""Our AEM files read back by an independent parser, with the checks it does not make.

ccsds-ndm-py (import name ``ccsds_ndm``, a Rust parser written apart from this project)
checks the structure, the keywords and the column count of a CCSDS AEM 2.0 KVN file, and
reports the numbers and epoch strings it finds.  It does not check that the quaternions
are unit, that the epochs increase, that the data lie inside START_TIME…STOP_TIME, or that
an epoch is one astropy reads as written.  ``read_back`` does those in numpy and returns
the segments in our convention.

Beware: the package ccsds-ndm (E. Imre) installs the same import name and reads v2 KVN
quaternions wrongly.  These helpers need ccsds-ndm-py.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import ccsds_ndm
import numpy as np
from astropy.time import Time

from attitude.environment.timescales import offline_time, tt_seconds

# Our inputs come from scipy's Rotation (norm within a few 1e-16) and are written with 16
# significant digits: the norm read back is 1 to well within this.
NORM_TOLERANCE = 1e-15
# CCSDS TIME_SYSTEM values we write (SANA registry) -> astropy scale.
_SCALES = {"UTC": "utc", "TT": "tt", "TAI": "tai", "TDB": "tdb", "TCG": "tcg", "TCB": "tcb"}


@dataclass
class Segment:
    """One segment as read back: times in the file's scale, our convention for the rest."""

    times: Time
    quaternion_body_to_inertial_scalar_first: np.ndarray
    angular_velocity_body_rad_s: np.ndarray
    metadata: object  # ccsds-ndm-py's metadata object, for the keywords


def parse(path):
    """The file as ccsds-ndm-py reads it, after its strict validation."""
    assert hasattr(ccsds_ndm, "Aem"), "ccsds_ndm is not ccsds-ndm-py (see the module docstring)"
    message = ccsds_ndm.from_file(str(path))
    message.validate(strict=True)
    return message


def _epochs(texts: list[str], scale: str, where: str) -> Time:
    """``texts`` as a Time in ``scale``, asserting that astropy reads each one as written.

    astropy reads ``00:00:60`` in TT, or an invented UTC leap second, as the next minute:
    the round trip to text exposes both.
    """
    with offline_time(), warnings.catch_warnings():
        # The comparison below is the check; the warning would only repeat it.
        warnings.filterwarnings("ignore", message=".*time is after end of day")
        times = Time(list(texts), format="isot", scale=scale, precision=9)
        written = list(np.atleast_1d(times.isot))
    changed = [(t, w) for t, w in zip(texts, written, strict=True) if t != w]
    assert not changed, f"{where}: astropy reads {changed[0][0]} {scale} as {changed[0][1]}"
    return times


def _seconds(later: Time, earlier: Time) -> float:
    return float(np.ravel(tt_seconds(later, earlier))[0])


def read_back(path) -> tuple[list[Segment], object]:
    """Parse ``path`` with ccsds-ndm-py and check, in numpy, what the parser does not.

    Asserts: unit quaternions; epochs astropy reads as written, strictly increasing (in TT
    seconds); the data inside START_TIME…STOP_TIME and the useable span inside that; the
    useable spans of consecutive segments not overlapping (table 4-3).  Returns the
    segments (quaternions (w, x, y, z) body → inertial, rates rad/s) and the message.
    """
    message = parse(path)
    segments = []
    previous_useable_stop = None
    for index, parsed in enumerate(message.segments):
        meta = parsed.metadata
        where = f"{path} segment {index}"
        assert meta.time_system in _SCALES, f"{where}: TIME_SYSTEM = {meta.time_system}"
        scale = _SCALES[meta.time_system]
        times = _epochs(parsed.data.attitude_states_epochs, scale, where)
        start, stop = (_epochs([text], scale, where) for text in (meta.start_time, meta.stop_time))
        useable_start = _epochs([meta.useable_start_time or meta.start_time], scale, where)
        useable_stop = _epochs([meta.useable_stop_time or meta.stop_time], scale, where)

        values = np.asarray(parsed.data.attitude_states_numpy)  # Q1 Q2 Q3 QC, deg/s
        norms = np.linalg.norm(values[:, :4], axis=1)
        worst = int(np.argmax(np.abs(norms - 1.0)))
        assert abs(norms[worst] - 1.0) <= NORM_TOLERANCE, (
            f"{where} record {worst}: quaternion norm {float(norms[worst])!r}"
        )
        if len(times) > 1:
            steps_s = tt_seconds(times[1:], times[:-1])
            assert np.all(steps_s > 0.0), f"{where}: epochs do not increase strictly"
        assert _seconds(times[:1], start) >= 0.0, f"{where}: data before START_TIME"
        assert _seconds(stop, times[-1:]) >= 0.0, f"{where}: data after STOP_TIME"
        assert _seconds(useable_start, start) >= 0.0 and _seconds(stop, useable_stop) >= 0.0, (
            f"{where}: useable span outside START_TIME ... STOP_TIME"
        )
        assert _seconds(useable_stop, useable_start) >= 0.0, f"{where}: useable span reversed"
        if previous_useable_stop is not None:
            assert _seconds(useable_start, previous_useable_stop) >= 0.0, (
                f"{where}: useable span starts before the previous one ends"
            )
        previous_useable_stop = useable_stop
        segments.append(
            Segment(
                times,
                values[:, [3, 0, 1, 2]],  # (Q1, Q2, Q3, QC) -> our (w, x, y, z)
                np.radians(values[:, 4:]),  # deg/s -> rad/s
                meta,
            )
        )
    return segments, message


def interpolate_as_declared(segment: Segment, t_s: np.ndarray, epoch: Time) -> np.ndarray:
    """``segment``'s attitude at ``t_s`` (TT seconds after ``epoch``), read the way its
    metadata declares: INTERPOLATION_METHOD = LAGRANGE of INTERPOLATION_DEGREE d, on
    each of Q1, Q2, Q3, QC as written, over the d + 1 records centred on t's interval
    (shifted to stay inside the segment), then normalized.  Returns (w, x, y, z).

    Written apart from the package (which has its own reading in
    ``attitude.outputs.aem_sampling``): Neville's recurrence, vectorized over the epochs.
    """
    meta = segment.metadata
    assert meta.interpolation_method == "LAGRANGE", meta.interpolation_method
    degree = int(meta.interpolation_degree)
    x = tt_seconds(segment.times, epoch)  # the records' epochs as written (1 ns)
    # The quaternions as written: scalar last, signs as in the file.
    q = segment.quaternion_body_to_inertial_scalar_first[:, [1, 2, 3, 0]]
    count = x.size
    interval = np.clip(np.searchsorted(x, t_s, side="right") - 1, 0, count - 2)
    first = np.clip(interval - (degree - 1) // 2, 0, count - degree - 1)
    nodes = first[:, None] + np.arange(degree + 1)
    xs, values = x[nodes], q[nodes]  # (m, d+1), (m, d+1, 4)
    t = np.asarray(t_s)[:, None]
    table = values.copy()
    for width in range(1, degree + 1):
        for i in range(degree + 1 - width):
            j = i + width
            table[:, i] = (
                (t - xs[:, j : j + 1]) * table[:, i] - (t - xs[:, i : i + 1]) * table[:, i + 1]
            ) / (xs[:, i : i + 1] - xs[:, j : j + 1])
    result = table[:, 0]
    result = result / np.linalg.norm(result, axis=1, keepdims=True)
    return result[:, [3, 0, 1, 2]]


def rotation_angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The angle of the rotation between unit quaternions a and b (either sign), rad,
    accurate for tiny angles: 2 atan2(|vector part|, |scalar part|) of a* ⊗ b."""
    w1, v1 = a[:, 0], a[:, 1:]
    w2, v2 = b[:, 0], b[:, 1:]
    scalar = w1 * w2 + np.einsum("ij,ij->i", v1, v2)
    vector = w1[:, None] * v2 - w2[:, None] * v1 - np.cross(v1, v2)
    return 2.0 * np.arctan2(np.linalg.norm(vector, axis=1), np.abs(scalar))
