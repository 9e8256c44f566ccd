"""Sun and Moon vectors from JPL DE421 through skyfield, offline: where they appear.

The ephemeris is the ``de421.bsp`` kernel that the ``skyfield-data`` package ships
(16 MB, 1899-07-29 to 2053-10-09 TDB).  It is opened once per process, on first use,
straight from the installed package (``importlib.resources``), and closed at exit:
nothing is downloaded, nothing is written, and no ``ResourceWarning`` is left.
(``skyfield_data.get_skyfield_data_path()`` is not used: it warns about an expired
``finals2000A.all`` that is not needed here.)  skyfield's own time scale is its
builtin one (``load.timescale(builtin=True)``: bundled ΔT and leap seconds).

Epochs are ``astropy.time.Time`` (or ISO strings, see
:func:`attitude.environment.timescales.as_time`).  They reach skyfield as their exact two-part
TT Julian date, ``ts.tt_jd(t.tt.jd1, t.tt.jd2)``, converted inside
:func:`attitude.environment.timescales.offline_time`; ``ts.from_astropy`` is avoided because it
goes through one float JD and loses up to 20 µs.

Vectors are in the GCRS: ICRF axes, origin at the Earth's centre (or at the
observer given), in metres, with shape ``times.shape + (3,)``.

The Sun and the Moon are given at their **apparent** place, what a sensor measures
(see :func:`sun_position_from_earth`, :func:`apparent_from_observer`).  Measured over
1900–2050 for the Sun (docs/pointing.md, "The Sun's direction: which place, which
frame", with the published sources; and ``tests/test_sun_against_astropy.py``):

- light time (the Sun as it was ≈ 499 s earlier): shifts the direction by < 0.011";
- annual aberration (the Earth's 30 km/s barycentric velocity): ≈ 20.5";
- gravitational deflection: the Sun's deflection of its own light is zero by
  symmetry, and Jupiter's and Saturn's is < 1e-7" here, so it is not computed
  (``deflectors=()``), which makes the call about twice as fast.
The result agrees with astropy's own ephemeris to 0.016".  The Moon (1.3 s of light
time, the same aberration, and a parallax of up to 1° from low orbit) agrees with
astropy's ``get_body`` on the same kernel to 0.011 mas
(``tests/test_moon_against_astropy.py``).

:class:`SunMoonFromEarth` samples both bodies once per span on nodes 600 s of TT apart
and joins them by cubic Hermite polynomials, so that the pointing layer pays
skyfield's price (≈ 50 µs an epoch) once every 10 minutes, not at every epoch.
"""

from __future__ import annotations

import atexit
import importlib.resources
import math
import threading
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from attitude.base.errors import InputError
from attitude.environment.timescales import SECONDS_PER_DAY, as_time, offline_time

__all__ = [
    "EphemerisRangeError",
    "SunMoonFromEarth",
    "apparent_from_observer",
    "moon_position_from_earth",
    "moon_position_from_observer",
    "skyfield_times",
    "sun_direction_from_earth",
    "sun_position_from_earth",
    "sun_position_from_observer",
    "timescale",
]

# Speed of light (m/s), exact by definition of the metre, and the IAU 2012 au (m).
_C_M_S = 299_792_458.0
_AU_M = 149_597_870_700.0

# skyfield's light-time iteration evaluates the Sun up to τ ≤ 1.017 au / c = 508 s
# before the epoch; epochs closer than this to the kernel's start cannot be observed.
_LIGHT_TIME_MARGIN_DAYS = 600.0 / SECONDS_PER_DAY

_lock = threading.Lock()
_kernel: Any = None
_timescale: Any = None


class EphemerisRangeError(InputError):
    """An epoch lies outside the span of the DE421 ephemeris (1899-07-29 to 2053-10-09)."""


def timescale():
    """skyfield's builtin ``Timescale`` (bundled ΔT and leap seconds; no file, no network)."""
    global _timescale
    with _lock:
        if _timescale is None:
            from skyfield.api import load

            _timescale = load.timescale(builtin=True)
        return _timescale


def _ephemeris():
    """The DE421 kernel shipped by ``skyfield-data``, opened once and closed at exit."""
    global _kernel
    with _lock:
        if _kernel is None:
            from skyfield.api import load_file

            path = importlib.resources.files("skyfield_data") / "data" / "de421.bsp"
            with importlib.resources.as_file(path) as file:
                _kernel = load_file(str(file))
            # load_file keeps the file open; without this, exit warns ResourceWarning.
            atexit.register(_kernel.close)
        return _kernel


def _span_tdb_jd() -> tuple[float, float]:
    """First and last TDB Julian dates at which every segment of the kernel is defined."""
    segments = _ephemeris().segments
    start = max(segment.spk_segment.start_jd for segment in segments)
    end = min(segment.spk_segment.end_jd for segment in segments)
    return start, end


def _span_text() -> str:
    ts = timescale()
    start, end = _span_tdb_jd()
    return " to ".join(ts.tdb_jd(jd).tdb_strftime("%Y-%m-%d") for jd in (start, end))


def skyfield_times(times: Any, name: str = "times"):
    """``times`` as a flat skyfield ``Time`` inside DE421's span, and their shape.

    The conversion is exact (two-part TT JD).  Every epoch is checked against the
    kernel's span *before* skyfield sees it (with a 600 s margin at the start for
    the light time), so that the error names the epoch and the span.
    Raises :class:`EphemerisRangeError` (an :class:`InputError`) otherwise.
    """
    times = as_time(times, name=name)
    with offline_time():
        tt = times.tt
        jd1 = np.ravel(tt.jd1)
        jd2 = np.ravel(tt.jd2)
    t = timescale().tt_jd(jd1, jd2)
    start, end = _span_tdb_jd()
    # whole + fraction, never one float: the check is exact to the nanosecond.
    tdb_after_start = (t.whole - start) + t.tdb_fraction
    tdb_after_end = (t.whole - end) + t.tdb_fraction
    outside = ~((tdb_after_start >= _LIGHT_TIME_MARGIN_DAYS) & (tdb_after_end <= 0.0))
    if np.any(outside):
        index = int(np.flatnonzero(outside)[0])
        with offline_time():
            epoch = times.ravel()[index] if times.ndim else times
            shown = f"{epoch.isot} {epoch.scale.upper()}"
        where = f" (index {index}, {int(outside.sum())} of {outside.size} outside)"
        raise EphemerisRangeError(
            f"epoch {shown} is outside the span of the DE421 ephemeris, "
            f"{_span_text()} (TDB){where if times.ndim else ''}",
            key=name,
            value=shown,
        )
    return t, times.shape


def _as_vectors(xyz: NDArray[np.float64], shape: tuple[int, ...]) -> NDArray[np.float64]:
    """skyfield's (3, n) array as ``shape + (3,)``."""
    return np.ascontiguousarray(np.moveaxis(xyz, 0, -1).reshape((*shape, 3)))


def _sun_astrometric(t):
    """skyfield's astrometric Sun from the geocentre: light time, no aberration yet."""
    eph = _ephemeris()
    return eph["earth"].at(t).observe(eph["sun"])


def sun_position_from_earth(times: Any) -> NDArray[np.float64]:
    """Apparent position of the Sun from the Earth's centre, GCRS, metres.

    skyfield ``earth.at(t).observe(sun).apparent()``: the Sun where it was one
    light time ago (≈ 499 s; moves the direction < 0.011"), seen with the aberration
    of the Earth's barycentric velocity (relativistic formula; ≈ 20.5").  This is the
    direction a Sun sensor on the Earth's centre would measure, and the direction of
    the sunlight's rays in the GCRS, hence of the Earth's shadow axis (see
    :mod:`attitude.pointing.eclipse`).  The length is the light-time distance (≈ 1 au).
    Gravitational deflection is left out (< 1e-7" for the Sun, see the module notes).

    ``times``: ``Time`` (any scale) or ISO string(s), scalar or array; the result has
    shape ``times.shape + (3,)``.  Raises :class:`EphemerisRangeError` outside DE421.
    """
    t, shape = skyfield_times(times)
    apparent = _sun_astrometric(t).apparent(deflectors=())
    return _as_vectors(apparent.position.m, shape)


def sun_direction_from_earth(times: Any) -> NDArray[np.float64]:
    """Unit vector from the Earth's centre to the apparent Sun, GCRS (see
    :func:`sun_position_from_earth`); shape ``times.shape + (3,)``."""
    position = sun_position_from_earth(times)
    return position / np.linalg.norm(position, axis=-1, keepdims=True)


def sun_position_from_observer(
    times: Any, position_m: ArrayLike, velocity_m_s: ArrayLike
) -> NDArray[np.float64]:
    """Apparent position of the Sun from an observer near the Earth, GCRS axes, metres.

    The observer is at ``position_m`` from the Earth's centre and moves at
    ``velocity_m_s`` relative to it (GCRS, shape ``times.shape + (3,)``), e.g. a
    spacecraft.  Computed at every epoch from DE421 (no interpolation); see
    :func:`apparent_from_observer` for the formula.  Against skyfield
    ``(earth + satellite).at(t).observe(sun).apparent()`` the direction agrees to
    0.001" (``tests/test_orbit_against_direct_sgp4.py``).  The velocity of an ISS orbit
    (7.7 km/s) moves the Sun by up to 5.3" on top of the Earth's 20.5".
    """
    return _from_observer("sun", times, position_m, velocity_m_s)


def moon_position_from_observer(
    times: Any, position_m: ArrayLike, velocity_m_s: ArrayLike
) -> NDArray[np.float64]:
    """Apparent position of the Moon from an observer near the Earth, GCRS axes, metres
    (as :func:`sun_position_from_observer`; from low orbit the parallax reaches 1°)."""
    return _from_observer("moon", times, position_m, velocity_m_s)


def moon_position_from_earth(times: Any) -> NDArray[np.float64]:
    """Apparent position of the Moon from the Earth's centre, GCRS, metres: light time
    (≈ 1.3 s) and the aberration of the Earth's barycentric velocity, no deflection."""
    zeros = np.zeros((*as_time(times, name="times").shape, 3))
    return _from_observer("moon", times, zeros, zeros)


def _from_observer(body: str, times: Any, position_m, velocity_m_s) -> NDArray[np.float64]:
    """The apparent ``body`` ("sun" or "moon") from an observer, at every epoch."""
    t, shape = skyfield_times(times)
    observer_m = _vectors(position_m, shape, "position_m").reshape(-1, 3)
    observer_m_s = _vectors(velocity_m_s, shape, "velocity_m_s").reshape(-1, 3)
    eph = _ephemeris()
    earth = eph["earth"].at(t)
    sun = earth.observe(eph["sun"])
    target = sun if body == "sun" else earth.observe(eph["moon"])
    earth_m_s = _as_vectors(earth.velocity.m_per_s, (-1,))
    apparent = apparent_from_observer(
        _as_vectors(target.position.m, (-1,)),
        _as_vectors(target.velocity.m_per_s, (-1,)) + earth_m_s,
        earth_m_s,
        observer_m,
        observer_m_s,
        np.linalg.norm(_as_vectors(sun.position.m, (-1,)) - observer_m, axis=-1),
    )
    return apparent.reshape((*shape, 3))


def apparent_from_observer(
    astrometric_m: NDArray[np.float64],
    body_velocity_m_s: NDArray[np.float64],
    earth_velocity_m_s: NDArray[np.float64],
    observer_m: NDArray[np.float64],
    observer_m_s: NDArray[np.float64],
    sun_distance_m: NDArray[np.float64],
) -> NDArray[np.float64]:
    """Apparent position of a body from an observer near the Earth, GCRS axes, metres.

    ``astrometric_m``: the body's astrometric position from the Earth's centre (its
    barycentric position one light time τ = |A|/c before, minus the Earth's now);
    ``body_velocity_m_s``, ``earth_velocity_m_s``: barycentric velocities;
    ``observer_m``, ``observer_m_s``: the observer from the Earth's centre (GCRS);
    ``sun_distance_m``: from the Sun to the observer.  All ``(n, 3)`` or ``(n,)``.

    1. Light time from the observer: the body's position is moved back along its
       barycentric velocity V by the difference of the light times, N = A − r −
       V (|A − r| − |A|)/c (first order in V/c: the second order is 1e-9 of the
       correction).  For the Moon from GEO the difference is 0.14 s, 4 km along the
       Moon's 30 km/s, 2"; for the Sun it is < 2e-11 rad.
    2. Aberration of the observer's barycentric velocity (the Earth's plus its own),
       ERFA ``ab`` (IERS Conventions 2010 / SOFA ``iauAb``, relativistic, with the
       Sun's potential at the observer: Klioner 2003), the formula skyfield's
       ``apparent()`` applies.
    Deflection of light by the Sun, Jupiter and Saturn is left out (< 1e-7" for the
    Sun; for the Moon < 0.005" more than 10° from the Sun), and so is the Earth's
    (< 0.001").
    """
    import erfa

    natural_m = astrometric_m - observer_m
    distance_m = np.linalg.norm(natural_m, axis=-1, keepdims=True)
    delay_s = (distance_m - np.linalg.norm(astrometric_m, axis=-1, keepdims=True)) / _C_M_S
    natural_m = natural_m - body_velocity_m_s * delay_s
    distance_m = np.linalg.norm(natural_m, axis=-1, keepdims=True)
    beta = (earth_velocity_m_s + observer_m_s) / _C_M_S
    proper = erfa.ab(
        natural_m / distance_m,
        beta,
        sun_distance_m / _AU_M,
        np.sqrt(1.0 - np.sum(beta * beta, axis=-1)),
    )
    return proper * distance_m


# Nodes of SunMoonFromEarth: every 600 s of TT from J2000 (JD 2451545.0 TT).
_NODE_STEP_S = 600.0
_NODE_ORIGIN_JD = 2451545.0


class SunMoonFromEarth:
    """The Sun and the Moon from the Earth's centre over a span, at any epoch in it.

    At TT nodes every 600 s (counted from J2000, so that the nodes, and hence every
    value, do not depend on the span asked): the astrometric positions of the Sun and
    the Moon from the geocentre with their velocities, and the Earth's barycentric
    position and velocity, from DE421.  Between nodes each is a cubic Hermite
    polynomial (position and velocity at both ends), a local interpolant.  Measured
    against direct skyfield over a day: the Moon to 0.06 m (2e-10 rad), the Sun to
    5 mm, the Earth's velocity to 20 µm/s.

    ``jd1``, ``first_jd2``, ``last_jd2``: the span, a TT Julian date jd1 + jd2.
    Raises :class:`EphemerisRangeError` when the nodes leave DE421.
    """

    def __init__(self, jd1: float, first_jd2: float, last_jd2: float) -> None:
        step_days = _NODE_STEP_S / SECONDS_PER_DAY
        first = math.floor(((jd1 - _NODE_ORIGIN_JD) + first_jd2) / step_days)
        last = math.floor(((jd1 - _NODE_ORIGIN_JD) + last_jd2) / step_days) + 1
        self._first = first
        index = np.arange(first, last + 1, dtype=np.float64)
        whole, fraction = np.divmod(index * step_days, 1.0)
        self._jd1 = float(jd1)
        from astropy.time import Time

        with offline_time():
            nodes = Time(_NODE_ORIGIN_JD + whole, fraction, format="jd", scale="tt")
        t, _ = skyfield_times(nodes, name="span")
        eph = _ephemeris()
        earth = eph["earth"].at(t)
        sun = earth.observe(eph["sun"])
        moon = earth.observe(eph["moon"])
        self._values = {
            "sun": (_as_vectors(sun.position.m, (-1,)), _as_vectors(sun.velocity.m_per_s, (-1,))),
            "moon": (
                _as_vectors(moon.position.m, (-1,)),
                _as_vectors(moon.velocity.m_per_s, (-1,)),
            ),
            "earth": (
                _as_vectors(earth.position.m, (-1,)),
                _as_vectors(earth.velocity.m_per_s, (-1,)),
            ),
        }

    def _piece(self, jd2: ArrayLike) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
        """The piece (index into the nodes) and the fraction s in [0, 1) of it of each
        TT Julian date jd1 + jd2.  (jd1 − J2000) counted in pieces is split into its
        whole and fractional parts before jd2 is added, so that s keeps the precision
        of jd2 (1e-14 of a piece) instead of that of 1.3 million pieces since J2000
        (2e-10 of a piece: 0.16 µs)."""
        pieces_per_day = SECONDS_PER_DAY / _NODE_STEP_S
        base = (self._jd1 - _NODE_ORIGIN_JD) * pieces_per_day
        base_whole = math.floor(base)
        position = np.asarray(jd2, dtype=np.float64) * pieces_per_day + (base - base_whole)
        below = np.floor(position)
        k = (below.astype(np.int64) + base_whole) - self._first
        count = len(self._values["sun"][0])
        if k.size and (k.min() < 0 or k.max() + 1 >= count):
            raise EphemerisRangeError("an epoch is outside the span the ephemeris was sampled on")
        return k, position - below

    def at(self, jd2: NDArray[np.float64]) -> dict[str, NDArray[np.float64]]:
        """At the TT Julian dates ``jd1 + jd2`` (``jd1`` the span's): ``sun_m``,
        ``moon_m`` (astrometric from the geocentre), ``sun_velocity_m_s``,
        ``moon_velocity_m_s``, ``earth_velocity_m_s`` (barycentric), shapes (n, 3)."""
        k, s = self._piece(jd2)
        s = s[:, None]
        h = _NODE_STEP_S
        # Cubic Hermite basis on [0, 1] and its derivative (per second: / h).
        h00, h10 = (1 + 2 * s) * (1 - s) ** 2, s * (1 - s) ** 2
        h01, h11 = s * s * (3 - 2 * s), s * s * (s - 1)
        d00, d10 = 6 * s * (s - 1) / h, (1 - s) * (1 - 3 * s) / h
        d01, d11 = 6 * s * (1 - s) / h, s * (3 * s - 2) / h

        def hermite(name: str, derivative: bool = False) -> NDArray[np.float64]:
            p, v = self._values[name]
            p0, p1, v0, v1 = p[k], p[k + 1], v[k] * h, v[k + 1] * h
            if derivative:
                return d00 * p0 + d10 * v0 + d01 * p1 + d11 * v1
            return h00 * p0 + h10 * v0 + h01 * p1 + h11 * v1

        earth_m_s = hermite("earth", derivative=True)
        return {
            "sun_m": hermite("sun"),
            "moon_m": hermite("moon"),
            "sun_velocity_m_s": hermite("sun", derivative=True) + earth_m_s,
            "moon_velocity_m_s": hermite("moon", derivative=True) + earth_m_s,
            "earth_velocity_m_s": earth_m_s,
        }

    def derivatives(
        self, jd2: NDArray[np.float64], order: int = 3
    ) -> dict[str, NDArray[np.float64]]:
        """At the TT Julian dates ``jd1 + jd2``: the interpolants' positions and their
        first ``order`` (≤ 3) time derivatives, per second, stacked on axis 0:
        ``sun`` and ``moon`` (astrometric from the geocentre, as :meth:`at`) and
        ``earth`` (the Earth's barycentric position), each (order + 1, n, 3).  They are
        the exact derivatives of the cubic pieces :meth:`at` evaluates (within one 600 s
        piece; the third derivative is constant on each piece)."""
        if not 0 <= order <= 3:
            raise ValueError(f"order must be 0 to 3, got {order}")
        k, s = self._piece(jd2)
        h = _NODE_STEP_S
        one = np.ones_like(s)
        # The cubic Hermite basis h00, h10, h01, h11 on [0, 1] and its derivatives in s.
        basis = [
            (2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s, 3 * s**2 - 2 * s**3, s**3 - s**2),
            (6 * s**2 - 6 * s, 3 * s**2 - 4 * s + 1, 6 * s - 6 * s**2, 3 * s**2 - 2 * s),
            (12 * s - 6, 6 * s - 4, 6 - 12 * s, 6 * s - 2),
            (12 * one, 6 * one, -12 * one, 6 * one),
        ]
        out = {}
        for name in ("sun", "moon", "earth"):
            p, v = self._values[name]
            p0, p1, v0, v1 = p[k], p[k + 1], v[k] * h, v[k + 1] * h
            out[name] = np.stack(
                [
                    (b00[:, None] * p0 + b10[:, None] * v0 + b01[:, None] * p1 + b11[:, None] * v1)
                    / h**n
                    for n, (b00, b10, b01, b11) in enumerate(basis[: order + 1])
                ]
            )
        return out


def _vectors(value: ArrayLike, shape: tuple[int, ...], name: str) -> NDArray[np.float64]:
    """``value`` as finite float vectors of shape ``shape + (3,)``, else InputError."""
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} must be numeric, got {value!r}") from exc
    if array.shape != (*shape, 3):
        raise InputError(
            f"{name} must have shape {(*shape, 3)} (times.shape + (3,)), got {array.shape}"
        )
    if not np.all(np.isfinite(array)):
        index = tuple(int(i) for i in np.argwhere(~np.isfinite(array))[0])
        raise InputError(f"{name} must be finite, got {array[index]} at index {index}")
    return array
