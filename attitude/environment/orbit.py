"""Where the spacecraft is: the orbit sources, and SGP4 from a TLE evaluated exactly.

Every orbit source is an :class:`Orbit`: its GCRS position (m) and velocity (m/s) at
any epoch of its span, from TT two-part Julian dates (:meth:`Orbit.state_tt`, what the
pointing layer calls) or from ``astropy.time.Time`` (:meth:`Orbit.position_velocity`).
The sources: :class:`TleOrbit` here (SGP4), :class:`attitude.environment.keplerian.KeplerianOrbit`
(elements at an epoch, two-body or J2 secular) and :class:`attitude.environment.oem.OemOrbit` (a
CCSDS OEM file).  This is the one owner of orbit sampling: nothing downstream
interpolates an orbit again.

**SGP4 at every epoch, not interpolated.** A skyfield ``EarthSatellite.at`` costs
45–80 µs an epoch, almost all of it the TEME → GCRS rotation (IAU 2000A nutation),
and SGP4 itself 0.5 µs.  So SGP4 (the ``sgp4`` package's vectorized ``sgp4_array``,
the code skyfield calls) runs at every epoch asked, and only the rotation, which
changes with precession and nutation over days, is interpolated: skyfield's own
``TEME.rotation_at`` on whole TT hours, joined by cubic Lagrange polynomials (4 nodes
around each epoch, so that the result does not depend on which other epochs are
asked with it).  The rotation changes over days (precession, nutation, the equation
of the equinoxes), and the cubic follows it to 4e-13 rad (against ``rotation_at`` at
2000 random epochs of a year: 15 µm at GEO distance).  Measured
against direct ``EarthSatellite.at`` over a day at 1 s on the Vallado et al. (2006)
verification satellites (``tests/test_orbit_against_direct_sgp4.py``): ≤ 3 µm and
≤ 0.6 nm/s, eccentric (e = 0.19 to 0.74), deep-space, GEO and LEO alike, at 1/45 to
1/130 of the cost.  Each orbit keeps the rotation nodes it computed (a year of them at
most), so that the many small calls of a root search or a splitting integrator do not
pay skyfield's nutation again.

This replaces an interpolation of the SGP4 states every 60 s by cubic Hermite
polynomials, which met 0.4 m on the ISS but not on eccentric orbits (7 to 24 m on the
Vallado satellites), and forced the spline's slope through SGP4's velocity, which is
not the derivative of SGP4's positions (1 to 4 m/s apart on eccentric orbits: the
short-period terms of the velocity are SGP4's own): matching either SGP4's positions
or its velocities then cost the other.  Here both are SGP4's.

Vectors are GCRS (ICRF axes, origin at the Earth's centre), SI: metres, m/s, with
shape ``times.shape + (3,)``.  Epochs are ``astropy.time.Time`` or ISO strings.
"""

from __future__ import annotations

import math
import re
from abc import ABC, abstractmethod
from typing import Any

import numpy as np
from numpy.typing import NDArray

from attitude.base.errors import InputError
from attitude.base.quantities import as_si_scalar
from attitude.environment.earth import HILL_RADIUS_M
from attitude.environment.ephemeris import timescale
from attitude.environment.timescales import SECONDS_PER_DAY, as_time, offline_time

__all__ = [
    "TLE_NOTED_AFTER_DAYS",
    "TLE_REFUSED_AFTER_DAYS",
    "Orbit",
    "TleOrbit",
    "coverage_seconds",
    "tt_jd",
]

_LINE_LENGTH = 69
# SGP4 elements are for days to weeks around their epoch: beyond the first limit a
# run says how old they are, beyond the second it is refused.
TLE_NOTED_AFTER_DAYS = 30.0
TLE_REFUSED_AFTER_DAYS = 365.0
# Nodes of the TEME -> GCRS rotation: whole TT hours from J2000 (JD 2451545.0 TT); each
# orbit keeps at most this many computed nodes (a year of hours), a cache that changes
# no value: a node is the same matrix whenever it is computed.
_ROTATION_ORIGIN_JD = 2451545.0
_ROTATION_CACHE = 10_000


def tt_jd(times: Any) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The two-part TT Julian date of ``times`` (a ``Time`` or ISO text), flattened."""
    times = as_time(times, name="times")
    with offline_time():
        tt = times.tt
        return np.ravel(tt.jd1).astype(np.float64), np.ravel(tt.jd2).astype(np.float64)


def coverage_seconds(orbit: Any, jd: tuple[float, float]) -> tuple[float, float]:
    """The epochs ``orbit`` serves (:meth:`Orbit.coverage_tt`) as TT seconds since the
    two-part TT Julian date ``jd``: (−inf, inf) for a source that serves every epoch,
    or any object without ``coverage_tt``.  What samples an orbit with a margin about a
    span keeps the margin within these (an orbit file may cover the span exactly)."""
    coverage = getattr(orbit, "coverage_tt", None)
    found = coverage() if coverage is not None else None
    if found is None:
        return -math.inf, math.inf
    jd1, jd2 = jd
    (a1, a2), (b1, b2) = found
    return ((a1 - jd1) + (a2 - jd2)) * SECONDS_PER_DAY, ((b1 - jd1) + (b2 - jd2)) * SECONDS_PER_DAY


class Orbit(ABC):
    """A spacecraft's path about the Earth: GCRS position and velocity at any epoch.

    Subclasses implement :meth:`state_tt`; :meth:`check_span` refuses (InputError) a
    span the source cannot cover and returns notes for the user.  ``key`` is the
    scenario file's key for the source, which starts every message about it.
    """

    key: str = "pointing.orbit"
    name: str | None = None

    @abstractmethod
    def state_tt(
        self, jd1: NDArray[np.float64], jd2: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Position (m) and velocity (m/s), GCRS, at the TT Julian dates jd1 + jd2
        (flat arrays of one length): two arrays of shape (n, 3)."""

    @abstractmethod
    def describe(self) -> str:
        """One line saying what the source is (for ``attitude check`` and the summary)."""

    def check_span(self, start: Any, stop: Any) -> list[str]:
        """Refuse (InputError) a span [start, stop] (``Time``) the source cannot cover;
        return notes.  By default every span is covered."""
        return []

    def coverage_tt(self) -> tuple[tuple[float, float], tuple[float, float]] | None:
        """The first and last epochs the source serves, as two-part TT Julian dates, or
        None where it serves every epoch (a TLE or a Keplerian orbit: their limits are
        refused by :meth:`check_span`, days from their epoch, not at an instant).  What
        samples the orbit around a span (the shared surroundings' aligned pieces) keeps
        within it."""
        return None

    def position_velocity(self, times: Any) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Position (m) and velocity (m/s) in the GCRS at ``times`` (``Time`` or ISO
        text, any shape): arrays of shape ``times.shape + (3,)``."""
        times = as_time(times, name="times")
        jd1, jd2 = tt_jd(times)
        if jd1.size == 0:
            position_m = velocity_m_s = np.zeros((0, 3))
        else:
            position_m, velocity_m_s = self.state_tt(jd1, jd2)
        shape = (*times.shape, 3)
        return position_m.reshape(shape), velocity_m_s.reshape(shape)


class TleOrbit(Orbit):
    """A spacecraft on an SGP4 orbit given by a two-line element set.

    ``line1``, ``line2``: the TLE lines (69 characters each, checksums checked).
    ``name``: optional label.  ``rotation_step_s``: spacing of the nodes of the TEME →
    GCRS rotation (whole TT hours by default); ``None`` evaluates skyfield's
    ``EarthSatellite.at`` at every epoch (45–80 µs an epoch: the reference the tests
    compare against).  A bad TLE raises :class:`InputError` naming the line and value.
    """

    key = "pointing.tle"

    def __init__(
        self,
        line1: str,
        line2: str,
        name: str | None = None,
        *,
        rotation_step_s: float | None = 3600.0,
    ) -> None:
        from sgp4.api import SGP4_ERRORS
        from skyfield.api import EarthSatellite

        line1 = _check_line(line1, 1)
        line2 = _check_line(line2, 2)
        _check_format(line1, line2)
        if rotation_step_s is not None:
            rotation_step_s = as_si_scalar(rotation_step_s, "time", "rotation_step_s")
            if not 0.0 < rotation_step_s <= 86400.0:
                raise InputError(
                    f"rotation_step_s must be in (0, 86400] s or None, got {rotation_step_s}"
                )
        self.lines = (line1, line2)
        self.rotation_step_s = rotation_step_s
        self._rotation_nodes: dict[float, NDArray[np.float64]] = {}
        self.name = name
        self.satellite = EarthSatellite(line1, line2, name, timescale())
        model = self.satellite.model
        if model.error:
            raise InputError(
                f"line2: SGP4 rejects the elements: {SGP4_ERRORS[model.error]} (eccentricity "
                f"{model.ecco}, mean motion {model.no_kozai * 1440 / (2 * np.pi)} rev/day)"
            )
        # SGP4's semi-major axis, in Earth radii (of its own WGS 72 Earth).
        apogee_m = model.a * (1.0 + model.ecco) * model.radiusearthkm * 1e3
        if not apogee_m < HILL_RADIUS_M:
            raise InputError(
                f"line2: mean motion {line2[52:63].strip()} rev/day and eccentricity "
                f"0.{line2[26:33]} put the apogee {apogee_m / 1e3:.4g} km from the Earth's "
                f"centre, beyond the Earth's Hill sphere ({HILL_RADIUS_M / 1e3:.3g} km), "
                "where the Sun's pull dominates: no orbit about the Earth reaches there"
            )

    def __reduce__(self):
        # sgp4's Satrec cannot be pickled: rebuild from the lines (Monte Carlo workers).
        return (_rebuild_tle_orbit, (self.lines, self.name, self.rotation_step_s))

    def __repr__(self) -> str:
        return f"TleOrbit({self.satellite})"

    @property
    def epoch(self):
        """The TLE's epoch, an ``astropy.time.Time`` in UTC (the scale TLEs are given in)."""
        from astropy.time import Time

        model = self.satellite.model
        with offline_time():
            return Time(model.jdsatepoch, model.jdsatepochF, format="jd", scale="utc")

    def describe(self) -> str:
        with offline_time():
            epoch = self.epoch.isot
        return f"TLE {self.lines[0][2:7]} (SGP4, element epoch {epoch} UTC)"

    @property
    def international_designator(self) -> str | None:
        """The COSPAR designator from line 1 (columns 10–17: launch year, launch number,
        piece), written as 1998-067A; None when the TLE leaves it blank or malformed."""
        designator = self.lines[0][9:17].strip()
        if len(designator) < 5 or not designator[:5].isdigit():
            return None
        year = int(designator[:2])  # two digits: 57-99 are 1957-1999
        return f"{1900 + year if year >= 57 else 2000 + year}-{designator[2:]}"

    def state_tt(self, jd1, jd2):
        """SGP4 at every epoch (TEME), rotated to the GCRS as skyfield rotates it."""
        t = timescale().tt_jd(jd1, jd2)
        if self.rotation_step_s is None:
            return self._skyfield(t)
        # SGP4's time argument is UTC, split as skyfield splits it (sgp4lib.py).
        utc_fraction = t.tai_fraction - t._leap_seconds() / SECONDS_PER_DAY
        errors, r_km, v_km_s = self.satellite.model.sgp4_array(t.whole, utc_fraction)
        if np.any(errors):
            self._fail(t, np.flatnonzero(errors)[0], errors)
        rotation = self._teme_to_gcrs(jd1, jd2, self.rotation_step_s)
        position_m = np.einsum("nij,nj->ni", rotation, r_km) * 1e3
        velocity_m_s = np.einsum("nij,nj->ni", rotation, v_km_s) * 1e3
        return position_m, velocity_m_s

    def _teme_to_gcrs(self, jd1, jd2, rotation_step_s: float) -> NDArray[np.float64]:
        """The TEME → GCRS matrices at each epoch, (n, 3, 3): skyfield's
        ``TEME.rotation_at`` (transposed) on nodes every ``rotation_step_s`` of TT from
        J2000, joined by cubic Lagrange polynomials through the 4 nodes around each."""
        from skyfield.sgp4lib import TEME

        step_days = rotation_step_s / SECONDS_PER_DAY
        position = ((jd1 - _ROTATION_ORIGIN_JD) + jd2) / step_days
        below = np.floor(position)
        x = position - below  # in [0, 1)
        around = below[:, None] + np.arange(-1.0, 3.0)[None, :]
        first, last = float(below.min()) - 1.0, float(below.max()) + 2.0
        if last - first < 4 * below.size + 16:  # the nodes from the first to the last
            needed = np.arange(first, last + 1.0)
            index = (around - first).astype(np.intp)
        else:  # epochs far apart: only the nodes around them
            needed, index = np.unique(around, return_inverse=True)
            index = index.reshape(around.shape)
        nodes = np.empty((needed.size, 3, 3))
        known = [self._rotation_nodes.get(k) for k in needed.tolist()]  # threads: no KeyError
        cached = np.array([node is not None for node in known], dtype=bool)
        for i in np.flatnonzero(cached):
            nodes[i] = known[i]
        missing = needed[~cached]
        if missing.size:
            whole, fraction = np.divmod(missing * step_days, 1.0)
            at = TEME.rotation_at(timescale().tt_jd(_ROTATION_ORIGIN_JD + whole, fraction))
            computed = np.moveaxis(at, -1, 0).transpose(0, 2, 1)  # (m, 3, 3), TEME -> GCRS
            nodes[~cached] = computed
            if len(self._rotation_nodes) + missing.size > _ROTATION_CACHE:
                self._rotation_nodes = {}
            self._rotation_nodes.update(zip(missing.tolist(), computed, strict=True))
        # Lagrange weights of the nodes at −1, 0, 1, 2 for a point x in [0, 1).
        weights = np.stack(
            [
                -x * (x - 1.0) * (x - 2.0) / 6.0,
                (x + 1.0) * (x - 1.0) * (x - 2.0) / 2.0,
                -(x + 1.0) * x * (x - 2.0) / 2.0,
                (x + 1.0) * x * (x - 1.0) / 6.0,
            ],
            axis=1,
        )
        return np.einsum("nk,nkij->nij", weights, nodes[index])

    def _skyfield(self, t):
        """skyfield's GCRS position and velocity (direct ``EarthSatellite.at``)."""
        at = self.satellite.at(t)
        position_m = np.atleast_2d(at.position.m.T)
        failed = ~np.all(np.isfinite(position_m), axis=1)
        if np.any(failed):
            errors = np.where(failed, 1, 0)
            self._fail(t, int(np.flatnonzero(failed)[0]), errors, np.ravel(at.message))
        return position_m, np.atleast_2d(at.velocity.m_per_s.T)

    def _fail(self, t, index: int, errors, messages=None) -> None:
        from sgp4.api import SGP4_ERRORS

        index = int(index)
        when = t[index].utc_strftime() if t.shape else t.utc_strftime()
        if messages is not None:
            reason = messages[index] if messages[index] else "no position"
        else:
            reason = SGP4_ERRORS[int(errors[index])]
        raise InputError(f"times: SGP4 fails near {when} for {self.satellite}: {reason}")

    def age_days(self, start: Any, stop: Any) -> float:
        """The largest distance in days between the TLE's epoch and [start, stop]."""
        from attitude.environment.timescales import tt_seconds

        ends = [as_time(start, name="start"), as_time(stop, name="stop")]
        return max(abs(float(tt_seconds(end, self.epoch))) for end in ends) / 86400.0

    def check_span(self, start: Any, stop: Any) -> list[str]:
        """The span against the TLE's epoch (refused beyond
        :data:`TLE_REFUSED_AFTER_DAYS`, noted with the TLE's age beyond
        :data:`TLE_NOTED_AFTER_DAYS`) and SGP4 over it (a decayed orbit is refused)."""
        days = self.age_days(start, stop)
        with offline_time():
            epoch = self.epoch.isot
        if days > TLE_REFUSED_AFTER_DAYS:
            raise InputError(
                f"the span reaches {days:.0f} days from the TLE's epoch "
                f"{epoch} UTC: SGP4 elements describe an orbit for days to weeks "
                f"around their epoch (this tool refuses beyond {TLE_REFUSED_AFTER_DAYS:g} "
                "days): use elements from near the span",
                key=self.key,
            )
        notes = []
        if days > TLE_NOTED_AFTER_DAYS:
            notes.append(
                f"{self.key}: the span reaches {days:.0f} days from the TLE's epoch "
                f"({epoch} UTC): the elements are {days:.0f} days old there, and SGP4 "
                "drifts by kilometres a day, so eclipse times and nadir angles are approximate"
            )
        failure = self.sgp4_failure(start, stop)
        if failure:
            raise InputError(failure, key=self.key)
        return notes

    def sgp4_failure(self, start: Any, stop: Any, step_s: float = 60.0) -> str | None:
        """Why SGP4 fails at the first epoch of [start, stop] (every ``step_s`` and at
        both ends) where it does (e.g. the satellite has decayed by then), or None: a
        check of a whole span at SGP4's own cost (0.5 µs an epoch), without the
        rotation to the GCRS."""
        from sgp4.api import SGP4_ERRORS

        start = as_time(start, name="start")
        stop = as_time(stop, name="stop")
        with offline_time():
            a, b = start.utc, stop.utc
            span_days = (b.jd1 - a.jd1) + (b.jd2 - a.jd2)
            count = max(int(np.ceil(span_days * SECONDS_PER_DAY / step_s)), 1) + 1
            fraction = np.linspace(0.0, span_days, count)
            jd1 = np.full(count, a.jd1)
            jd2 = a.jd2 + fraction
        errors, _, _ = self.satellite.model.sgp4_array(jd1, jd2)
        failed = np.flatnonzero(errors)
        if failed.size == 0:
            return None
        from astropy.time import Time

        index = int(failed[0])
        with offline_time():
            when = Time(jd1[index], jd2[index], format="jd", scale="utc").isot
        return f"SGP4 fails from {when} UTC on: {SGP4_ERRORS[int(errors[index])]}"


def _rebuild_tle_orbit(
    lines: tuple[str, str], name: str | None, rotation_step_s: float | None
) -> TleOrbit:
    return TleOrbit(*lines, name, rotation_step_s=rotation_step_s)


def _check_line(line: Any, number: int) -> str:
    """``line`` as a TLE line ``number`` (1 or 2), trailing blanks removed; else InputError."""
    from sgp4.io import compute_checksum

    field = f"line{number}"
    if not isinstance(line, str):
        raise InputError(f"{field} must be a string, got {line!r}")
    text = line.strip()
    if not text.isascii():
        raise InputError(f"{field} must be ASCII, got {line!r}")
    if len(text) != _LINE_LENGTH:
        raise InputError(f"{field} must have {_LINE_LENGTH} characters, got {len(text)}: {line!r}")
    if not text.startswith(f"{number} "):
        raise InputError(f"{field} must start with '{number} ', got {line!r}")
    if not text[-1].isdigit() or int(text[-1]) != compute_checksum(text):
        raise InputError(
            f"{field}: checksum is {text[-1]!r} but the line tallies to "
            f"{compute_checksum(text)}: {line!r}"
        )
    return text


def _check_format(line1: str, line2: str) -> None:
    """The column layout and numbers of the TLE, checked by sgp4's own strict reader.

    The compiled reader that skyfield uses accepts misplaced columns silently; the
    pure-Python ``sgp4.io.twoline2rv`` checks them against the official layout, reads
    every number, and initialises SGP4 (which divides by the mean motion).
    """
    from sgp4.earth_gravity import wgs72
    from sgp4.io import LINE1, LINE2, twoline2rv

    try:
        twoline2rv(line1, line2, wgs72)
    except ValueError as exc:
        text = str(exc)
        if "do not match" in text:
            raise InputError(
                f"line2: catalog number {line2[2:7]!r} differs from line1's {line1[2:7]!r}"
            ) from None
        layout = re.search(r"for line (\d)", text)
        if layout:
            number = int(layout.group(1))
            line, template = (line1, LINE1) if number == 1 else (line2, LINE2)
            raise InputError(
                f"line{number}: columns do not follow the TLE layout {template!r}: {line!r}"
            ) from None
        # A number that does not parse: name the field, in our words (sgp4's message is
        # Python's, "invalid literal for int() with base 10", about a text it reshaped).
        raise _not_a_number(line1, line2) from None
    except ArithmeticError as exc:
        what = "a division by zero" if isinstance(exc, ZeroDivisionError) else "an overflow"
        raise InputError(
            f"line2: SGP4 cannot start from these elements ({what} in its initialisation; "
            f"mean motion {line2[52:63].strip()} rev/day, eccentricity 0.{line2[26:33]}): "
            f"{line2!r}"
        ) from None


# The TLE's numeric fields that sgp4 reads (line, first and last column, 1-based, what
# it holds, the form of its text): a float, an exponent with an assumed decimal point
# (" 18000-4" is 0.18e-4), or digits.
_FLOAT = r"[+-]?(\d+\.?\d*|\.\d+)"
_ASSUMED = r"[+-]?\d*[+-]\d"
_DIGITS = r"\d+"
_TLE_NUMBERS = (
    (1, 19, 20, "epoch year", _DIGITS),
    (1, 21, 32, "epoch day", _FLOAT),
    (1, 34, 43, "first derivative of the mean motion", _FLOAT),
    (1, 45, 52, "second derivative of the mean motion", _ASSUMED),
    (1, 54, 61, "BSTAR drag term", _ASSUMED),
    (1, 65, 68, "element set number", _DIGITS),
    (2, 9, 16, "inclination", _FLOAT),
    (2, 18, 25, "right ascension of the ascending node", _FLOAT),
    (2, 27, 33, "eccentricity", _DIGITS),
    (2, 35, 42, "argument of perigee", _FLOAT),
    (2, 44, 51, "mean anomaly", _FLOAT),
    (2, 53, 63, "mean motion", _FLOAT),
)


def _not_a_number(line1: str, line2: str) -> InputError:
    """The refusal of a TLE whose number sgp4 cannot read: the first field that is
    not a number of its form, by column (else the lines)."""
    for number, first, last, name, form in _TLE_NUMBERS:
        line = line1 if number == 1 else line2
        field = line[first - 1 : last]
        if not re.fullmatch(form, field.strip()):
            return InputError(
                f"line{number}: columns {first}-{last} ({name}) hold {field!r}, not a number "
                f"as the TLE layout writes it: {line!r}"
            )
    return InputError(f"a field is not a number as the TLE layout writes it: {line1!r}, {line2!r}")
