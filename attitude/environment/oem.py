"""An orbit read from a CCSDS Orbit Ephemeris Message (OEM, CCSDS 502.0-B-3, KVN).

The file is parsed by ccsds-ndm-py and checked here (:mod:`attitude.environment.ccsds`):

- ``CENTER_NAME = EARTH``; ``REF_FRAME`` one of ``ICRF``, ``GCRF`` (both the GCRS
  axes here: the origin is the Earth's centre) or ``EME2000`` (rotated to the ICRF
  by the IAU 2000 frame bias, 23 mas: :func:`attitude.environment.frames.eme2000_to_icrf`);
- ``TIME_SYSTEM`` UTC, TT, TAI, TDB, TCG, TCB or GPS;
- every data line holds an epoch and 6 (or 9, with accelerations) finite numbers,
  in km and km/s; epochs increase strictly within a segment;
- ``INTERPOLATION`` ``HERMITE``, ``LAGRANGE`` or ``LINEAR``, of
  ``INTERPOLATION_DEGREE`` ≤ 15, is used as declared; a segment that declares none is
  interpolated by Hermite of degree 5 (3 states around each epoch), and
  :attr:`OemOrbit.notes` says so.  Lagrange interpolates positions and velocities
  each; Hermite takes the velocity as the derivative of the position polynomial.

Each epoch asked is served by the segment whose useable span holds it (the later one
where two meet, as CCSDS 502.0-B-3 §5.2.4 lets consecutive segments share an epoch);
an epoch outside every segment is refused with the file's span.  Every message
names the file and the key: ``orbit.oem: sat.oem: segment 1: REF_FRAME = ITRF2000: ...``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from attitude.base.errors import InputError
from attitude.environment.ccsds import MAX_DEGREE, interpolate, parse_epochs, read_message, scale_of
from attitude.environment.earth import GM_EARTH_M3_S2, HILL_RADIUS_M, MAX_ENCOUNTER_SPEED_M_S
from attitude.environment.frames import eme2000_to_icrf
from attitude.environment.orbit import Orbit, tt_jd
from attitude.environment.timescales import SECONDS_PER_DAY, offline_time

__all__ = ["OemOrbit"]

FRAMES = ("ICRF", "GCRF", "EME2000")
METHODS = ("HERMITE", "LAGRANGE", "LINEAR")
_DEFAULT = ("HERMITE", 5)
# A data line: an epoch, then numbers.
_DATA_LINE = re.compile(r"^\s*(\d{4}-\d{2,3}[-T]\S*)\s+(.*)$")


@dataclass
class _Segment:
    """One segment's states on TT seconds from the file's reference day."""

    start_s: float
    stop_s: float
    node_s: NDArray[np.float64]
    position_m: NDArray[np.float64]
    velocity_m_s: NDArray[np.float64]
    method: str
    degree: int


class OemOrbit(Orbit):
    """The orbit of a CCSDS OEM file (KVN), GCRS, interpolated as the file declares.

    ``path``: the file.  Raises :class:`InputError` naming the file (and the segment
    and keyword) for a file this cannot use.
    """

    key = "pointing.oem"

    def __init__(self, path: str | Path, name: str | None = None) -> None:
        self.path = Path(path)
        self.name = name
        self.notes: list[str] = []
        file = self.path.name
        message, text = read_message(self.path, "Oem")
        _check_data_lines(text, file)
        bias = eme2000_to_icrf().as_matrix()
        self._segments: list[_Segment] = []
        self._day: float | None = None
        for number, segment in enumerate(message.segments):
            where = f"{file}: segment {number}"
            meta = segment.metadata
            if (meta.center_name or "").strip().upper() != "EARTH":
                raise InputError(
                    f"{where}: CENTER_NAME = {meta.center_name!r}: only EARTH is supported"
                )
            frame = (meta.ref_frame or "").strip().upper()
            if frame not in FRAMES:
                raise InputError(
                    f"{where}: REF_FRAME = {meta.ref_frame!r}: expected one of {', '.join(FRAMES)}"
                )
            method = (meta.interpolation or "").strip().upper()
            degree = meta.interpolation_degree
            if not method:
                method, degree = _DEFAULT
                self.notes.append(f"{where} declares no INTERPOLATION: Hermite of degree 5 is used")
            elif method not in METHODS:
                raise InputError(
                    f"{where}: INTERPOLATION = {meta.interpolation!r}: expected one of "
                    f"{', '.join(METHODS)}"
                )
            if method != "LINEAR":
                if degree is None:
                    raise InputError(f"{where}: INTERPOLATION = {method} without a degree")
                if not 1 <= degree <= MAX_DEGREE:
                    raise InputError(
                        f"{where}: INTERPOLATION_DEGREE = {degree}: expected 1 to {MAX_DEGREE}"
                    )
            scale, offset_s = scale_of(meta.time_system, where)
            epochs = parse_epochs(segment.data.state_vector_epochs, scale, offset_s, where)
            states = np.asarray(segment.data.state_vector_numpy, dtype=np.float64)
            if states.ndim != 2 or states.shape[0] == 0 or states.shape[1] < 6:
                raise InputError(f"{where}: no state vectors")
            if not np.all(np.isfinite(states[:, :6])):
                row = int(np.argwhere(~np.isfinite(states[:, :6]))[0, 0])
                raise InputError(f"{where}: state {row} is not finite: {states[row, :6].tolist()}")
            _check_near_the_earth(states, where)
            jd1, jd2 = tt_jd(epochs)
            if self._day is None:
                self._day = float(np.floor(jd1[0] + jd2[0]))
            node_s = ((jd1 - self._day) + jd2) * SECONDS_PER_DAY
            if np.any(np.diff(node_s) <= 0.0):
                row = int(np.flatnonzero(np.diff(node_s) <= 0.0)[0]) + 1
                raise InputError(
                    f"{where}: epochs must increase: state {row} "
                    f"({segment.data.state_vector_epochs[row]}) is not after the one before"
                )
            if len(node_s) < 2:
                raise InputError(f"{where}: one state: nothing to interpolate")
            useable = [
                meta.useable_start_time or segment.data.state_vector_epochs[0],
                meta.useable_stop_time or segment.data.state_vector_epochs[-1],
            ]
            ujd1, ujd2 = tt_jd(parse_epochs(useable, scale, offset_s, where))
            start_s, stop_s = ((ujd1 - self._day) + ujd2) * SECONDS_PER_DAY
            start_s, stop_s = max(start_s, node_s[0]), min(stop_s, node_s[-1])
            position_m = states[:, :3] * 1e3
            velocity_m_s = states[:, 3:6] * 1e3
            if frame == "EME2000":
                position_m = position_m @ bias.T
                velocity_m_s = velocity_m_s @ bias.T
            self._segments.append(
                _Segment(start_s, stop_s, node_s, position_m, velocity_m_s, method, degree or 1)
            )
        self._object = message.segments[0].metadata.object_name

    def describe(self) -> str:
        return f"OEM file {self.path.name} ({self._object}, {len(self._segments)} segments)"

    def _span_text(self) -> str:
        from astropy.time import Time

        with offline_time():
            ends = Time(
                self._day,
                np.array([self._segments[0].start_s, self._segments[-1].stop_s]) / SECONDS_PER_DAY,
                format="jd",
                scale="tt",
            ).utc.isot
        return f"{ends[0]} to {ends[1]} UTC"

    def coverage_tt(self) -> tuple[tuple[float, float], tuple[float, float]] | None:
        """The first segment's useable start and the last one's stop (TT)."""
        if self._day is None:
            return None
        first, last = self._segments[0].start_s, self._segments[-1].stop_s
        return (self._day, first / SECONDS_PER_DAY), (self._day, last / SECONDS_PER_DAY)

    def _seconds(self, jd1, jd2) -> NDArray[np.float64]:
        if self._day is None:
            raise ValueError("the OEM has no segment yet")
        return ((np.asarray(jd1, dtype=np.float64) - self._day) + jd2) * SECONDS_PER_DAY

    def _segment_of(self, seconds: NDArray[np.float64]) -> NDArray[np.intp]:
        """The segment serving each epoch (the later one where two meet), or −1."""
        which = np.full(seconds.shape, -1, dtype=np.intp)
        tolerance = 1e-6  # s: an epoch written to the microsecond at a segment's end
        for k, segment in enumerate(self._segments):
            inside = (seconds >= segment.start_s - tolerance) & (
                seconds <= segment.stop_s + tolerance
            )
            which[inside] = k
        return which

    def state_tt(self, jd1, jd2):
        seconds = self._seconds(jd1, jd2)
        which = self._segment_of(seconds)
        if np.any(which < 0):
            from astropy.time import Time

            bad = float(seconds[np.argmax(which < 0)])
            with offline_time():
                when = Time(self._day, bad / SECONDS_PER_DAY, format="jd", scale="tt").utc.isot
            raise InputError(
                f"{self.path.name}: {when} UTC is outside the file's segments "
                f"({self._span_text()})",
                key=self.key,
            )
        position_m = np.empty((seconds.size, 3))
        velocity_m_s = np.empty((seconds.size, 3))
        for k in np.unique(which):
            segment = self._segments[k]
            mask = which == k
            at = np.clip(seconds[mask], segment.node_s[0], segment.node_s[-1])
            if segment.method == "HERMITE":
                position_m[mask], velocity_m_s[mask] = interpolate(
                    "HERMITE",
                    segment.degree,
                    segment.node_s,
                    segment.position_m,
                    segment.velocity_m_s,
                    at,
                )
            else:
                position_m[mask], _ = interpolate(
                    segment.method, segment.degree, segment.node_s, segment.position_m, None, at
                )
                velocity_m_s[mask], _ = interpolate(
                    segment.method, segment.degree, segment.node_s, segment.velocity_m_s, None, at
                )
        return position_m, velocity_m_s

    def check_span(self, start, stop) -> list[str]:
        """Refuse a span the file's segments do not cover; return the file's notes."""
        (a1, b1), (a2, b2) = tt_jd(start), tt_jd(stop)
        ends = self._seconds(np.concatenate([a1, a2]), np.concatenate([b1, b2]))
        covered = self._segment_of(ends) >= 0
        if not np.all(covered):
            raise InputError(
                f"{self.path.name} covers {self._span_text()}, not the span's "
                f"{'start' if not covered[0] else 'end'}",
                key=self.key,
            )
        gaps = [
            (a.stop_s, b.start_s)
            for a, b in zip(self._segments, self._segments[1:], strict=False)
            if b.start_s - a.stop_s > 1e-6 and a.stop_s < ends[1] and b.start_s > ends[0]
        ]
        if gaps:
            raise InputError(
                f"{self.path.name} has a gap between segments inside the span "
                f"({gaps[0][1] - gaps[0][0]:.6g} s)",
                key=self.key,
            )
        return [f"{self.key}: {note}" for note in self.notes]


def _check_near_the_earth(states: NDArray[np.float64], where: str) -> None:
    """Refuse states (km, km/s) that no body near the Earth has: beyond the Earth's Hill
    sphere, or faster than the fastest body circling the Sun passes the Earth plus the
    speed the Earth's pull adds where the state is (:mod:`attitude.environment.earth`)."""
    radius_m = np.linalg.norm(states[:, :3], axis=1) * 1e3
    speed_m_s = np.linalg.norm(states[:, 3:6], axis=1) * 1e3
    far = np.flatnonzero(~(radius_m < HILL_RADIUS_M))
    if far.size:
        row = int(far[0])
        raise InputError(
            f"{where}: state {row} is {radius_m[row] / 1e3:.4g} km from the Earth's centre, "
            f"beyond the Earth's Hill sphere ({HILL_RADIUS_M / 1e3:.3g} km), where the Sun's "
            "pull dominates: not an orbit about the Earth (positions are in km)"
        )
    with np.errstate(divide="ignore"):
        limit = np.sqrt(MAX_ENCOUNTER_SPEED_M_S**2 + 2.0 * GM_EARTH_M3_S2 / radius_m)
    fast = np.flatnonzero(~(speed_m_s <= limit))
    if fast.size:
        row = int(fast[0])
        raise InputError(
            f"{where}: state {row} moves at {speed_m_s[row] / 1e3:.4g} km/s, faster than any "
            f"body near the Earth ({limit[row] / 1e3:.3g} km/s at "
            f"{radius_m[row] / 1e3:.4g} km from its centre; velocities are in km/s)"
        )


def _check_data_lines(text: str, file: str) -> None:
    """Every data line holds an epoch and 6 or 9 numbers: the parser reads a line
    with a missing value as if the value were 0."""
    in_data = False
    in_covariance = False
    for number, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if stripped.startswith("META_STOP"):
            in_data = True
            continue
        if stripped.startswith("META_START"):
            in_data = False
            continue
        if stripped.startswith("COVARIANCE_START"):
            in_covariance = True
        if stripped.startswith("COVARIANCE_STOP"):
            in_covariance = False
            continue
        if not in_data or in_covariance or not stripped or stripped.startswith("COMMENT"):
            continue
        found = _DATA_LINE.match(line)
        if not found:
            continue
        values = found.group(2).split()
        if len(values) not in (6, 9):
            raise InputError(
                f"{file}: line {number}: a state needs an epoch and 6 numbers (X Y Z X_DOT "
                f"Y_DOT Z_DOT, km and km/s), or 9 with accelerations; got {len(values)}"
            )
