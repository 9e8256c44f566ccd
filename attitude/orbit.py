"""Where the spacecraft is: a TLE orbit (SGP4 through skyfield), fast at many epochs.

:class:`TleOrbit` wraps skyfield's ``EarthSatellite``.  A skyfield position costs
45–80 µs, almost all of it the TEME→GCRS rotation (full IAU 2000A nutation), not
SGP4 itself (1.3 µs).  So SGP4 is sampled on a coarse grid of nodes, every 60 s by
default, and the positions *and velocities* at the nodes are joined by cubic Hermite
polynomials (scipy ``CubicHermiteSpline``), which match both at every node.  Measured
on an ISS orbit (``tests/test_orbit_interpolation_against_skyfield.py``, one day at
1 s against direct ``EarthSatellite.at``): position error ≤ 0.38 m at 60 s
(≤ 0.06 m at 30 s, 6 m at 120 s); velocity error ≤ 0.033 m/s, most of which is
SGP4's own: its velocity differs from the derivative of its positions by up to
0.02 m/s.  SGP4's error against the real orbit is kilometres after a day, so the
interpolation costs nothing in truth.

Vectors are GCRS (ICRF axes, origin at the Earth's centre), SI: metres, m/s, with
shape ``times.shape + (3,)``.  Epochs are ``astropy.time.Time`` or ISO strings.
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import CubicHermiteSpline

from attitude.ephemeris import sun_position_from_observer, timescale
from attitude.errors import InputError
from attitude.quantities import as_si_scalar
from attitude.timescales import SECONDS_PER_DAY, as_time, offline_time

__all__ = ["EARTH_EQUATORIAL_RADIUS_M", "TleOrbit"]

# WGS 84 semi-major axis (NIMA TR8350.2, 3rd ed., table 3.1).  The Earth is taken as
# this sphere: its equatorial limb seen from orbit.  The polar radius is 21.4 km
# shorter; where the limb is at high latitude the true limb is lower by up to that.
EARTH_EQUATORIAL_RADIUS_M = 6_378_137.0

_LINE_LENGTH = 69


class TleOrbit:
    """A spacecraft on an SGP4 orbit given by a two-line element set.

    ``line1``, ``line2``: the TLE lines (69 characters each, checksums checked).
    ``name``: optional label.  ``step_s``: spacing of the SGP4 nodes of the Hermite
    interpolation (60 s: ≤ 0.4 m in LEO); ``None`` evaluates skyfield at every epoch
    (exact SGP4, 45–80 µs per epoch).  A bad TLE raises :class:`InputError` naming
    the line and the value.
    """

    def __init__(
        self, line1: str, line2: str, name: str | None = None, *, step_s: float | None = 60.0
    ) -> None:
        from sgp4.api import SGP4_ERRORS
        from skyfield.api import EarthSatellite

        line1 = _check_line(line1, 1)
        line2 = _check_line(line2, 2)
        _check_format(line1, line2)
        if step_s is not None:
            step_s = as_si_scalar(step_s, "time", "step_s")
            if not step_s > 0.0:
                raise InputError(f"step_s must be positive or None, got {step_s}")
        self.step_s = step_s
        self.name = name
        self.satellite = EarthSatellite(line1, line2, name, timescale())
        error = self.satellite.model.error
        if error:
            model = self.satellite.model
            raise InputError(
                f"line2: SGP4 rejects the elements: {SGP4_ERRORS[error]} (eccentricity "
                f"{model.ecco}, mean motion {model.no_kozai * 1440 / (2 * np.pi)} rev/day)"
            )

    def __repr__(self) -> str:
        return f"TleOrbit({self.satellite})"

    @property
    def epoch(self):
        """The TLE's epoch, an ``astropy.time.Time`` in UTC (the scale TLEs are given in)."""
        from astropy.time import Time

        model = self.satellite.model
        with offline_time():
            return Time(model.jdsatepoch, model.jdsatepochF, format="jd", scale="utc")

    def position_velocity(self, times: Any) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Position (m) and velocity (m/s) in the GCRS at ``times``.

        The SGP4 nodes are the multiples of ``step_s`` (TT, counted from a whole TT
        day) that bracket each epoch: only the intervals that hold an epoch are
        computed, so a sparse set of far-apart epochs costs no more than it needs.
        Each epoch is then evaluated on its own interval (cubic Hermite, position and
        velocity).  Raises :class:`InputError` if SGP4 fails at an epoch (e.g. the
        satellite has decayed by then).
        """
        times = as_time(times, name="times")
        with offline_time():
            tt = times.tt
            jd1 = np.ravel(tt.jd1)
            jd2 = np.ravel(tt.jd2)
        if jd1.size == 0:
            position_m = velocity_m_s = np.zeros((0, 3))
        elif self.step_s is None:
            position_m, velocity_m_s = self._sgp4(jd1, jd2)
        else:
            # TT seconds from a whole day: exact parts, rounding of 1e-7 s at 30 years.
            day0 = np.floor(np.min(jd1 + jd2))
            seconds = (jd1 - day0) * SECONDS_PER_DAY + jd2 * SECONDS_PER_DAY
            below = np.floor(seconds / self.step_s)
            nodes = np.unique(np.concatenate([below, below + 1.0]))
            node_s = nodes * self.step_s
            whole, fraction_s = np.divmod(node_s, SECONDS_PER_DAY)
            r_m, v_m_s = self._sgp4(day0 + whole, fraction_s / SECONDS_PER_DAY)
            # Consecutive nodes a step apart bracket every epoch; a longer gap between
            # two nodes holds no epoch, so its (meaningless) polynomial is never used.
            spline = CubicHermiteSpline(node_s, r_m, v_m_s, axis=0)
            position_m = spline(seconds)
            velocity_m_s = spline(seconds, nu=1)
        shape = (*times.shape, 3)
        return position_m.reshape(shape), velocity_m_s.reshape(shape)

    def sgp4_failure(self, times: Any) -> str | None:
        """Why SGP4 fails at the first of ``times`` where it does (e.g. the satellite
        has decayed by then), or None: a check of a whole span at SGP4's own cost
        (about a microsecond an epoch), without the rotation to the GCRS."""
        times = as_time(times, name="times")
        with offline_time():
            utc = times.utc
            jd1, jd2 = np.ravel(utc.jd1), np.ravel(utc.jd2)
        errors, _, _ = self.satellite.model.sgp4_array(jd1, jd2)
        failed = np.flatnonzero(errors)
        if failed.size == 0:
            return None
        from sgp4.api import SGP4_ERRORS

        index = int(failed[0])
        with offline_time():
            when = times.ravel()[index].utc.isot if times.ndim else times.utc.isot
        return f"SGP4 fails from {when} UTC on: {SGP4_ERRORS[int(errors[index])]}"

    def _sgp4(self, jd1, jd2) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """skyfield's GCRS position and velocity at TT (jd1, jd2), as (n, 3) arrays."""
        at = self.satellite.at(timescale().tt_jd(jd1, jd2))
        position_m = at.position.m.T
        failed = ~np.all(np.isfinite(position_m), axis=1)
        if np.any(failed):
            index = int(np.flatnonzero(failed)[0])
            message = np.ravel(at.message)[index] if at.message is not None else "no position"
            when = timescale().tt_jd(jd1[index], jd2[index]).utc_strftime()
            raise InputError(f"times: SGP4 fails near {when} for {self.satellite}: {message}")
        return position_m, at.velocity.m_per_s.T

    def sun_position_from_spacecraft(self, times: Any) -> NDArray[np.float64]:
        """Apparent position of the Sun from the spacecraft, GCRS axes, metres.

        What a Sun sensor on board measures: the Sun one light time ago, seen with
        the aberration of the spacecraft's barycentric velocity (Earth's 30 km/s plus
        its orbital velocity), see :func:`attitude.ephemeris.sun_position_from_observer`.
        The geometric vector (Sun minus spacecraft at the same instant) would be off
        by 19–24" on an ISS orbit (20.5" of annual aberration ± 5.3" from the orbital
        velocity); the parallax from the geocentre is ≤ 9.5" and is included.
        """
        position_m, velocity_m_s = self.position_velocity(times)
        return sun_position_from_observer(times, position_m, velocity_m_s)

    def nadir_direction(self, times: Any) -> NDArray[np.float64]:
        """Unit vector from the spacecraft to the Earth's centre (geocentric nadir), GCRS.

        Geocentric, not geodetic: the normal to the WGS 84 ellipsoid below the
        spacecraft differs from it by up to 0.19° (at 45° latitude).
        """
        position_m, _ = self.position_velocity(times)
        return -position_m / np.linalg.norm(position_m, axis=-1, keepdims=True)

    def earth_angular_radius(self, times: Any) -> NDArray[np.float64]:
        """Angular radius of the Earth seen from the spacecraft, radians: asin(R/|r|).

        R is the WGS 84 equatorial radius, :data:`EARTH_EQUATORIAL_RADIUS_M`: the
        Earth is a sphere touching the equator.  The true limb is lower where it
        crosses high latitudes (21 km at the poles, 0.5° in angle from the ISS), and
        the atmosphere raises the visible limb by tens of kilometres.
        """
        position_m, _ = self.position_velocity(times)
        return np.arcsin(EARTH_EQUATORIAL_RADIUS_M / np.linalg.norm(position_m, axis=-1))


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
        # A number that does not parse: name the line that holds it.
        token = re.search(r"'(.*)'$", text)
        number = 2 if token and token.group(1) not in line1 else 1
        line = line1 if number == 1 else line2
        raise InputError(f"line{number}: not a TLE number ({text}): {line!r}") from None
    except ArithmeticError as exc:
        raise InputError(
            f"line2: SGP4 cannot start from these elements ({exc}; mean motion "
            f"{line2[52:63].strip()} rev/day, eccentricity 0.{line2[26:33]}): {line2!r}"
        ) from None
