"""Sun vectors from JPL DE421 through skyfield, offline: where the Sun appears.

The ephemeris is the ``de421.bsp`` kernel that the ``skyfield-data`` package ships
(16 MB, 1899-07-29 to 2053-10-09 TDB).  It is opened once per process, on first use,
straight from the installed package (``importlib.resources``), and closed at exit:
nothing is downloaded, nothing is written, and no ``ResourceWarning`` is left.
(``skyfield_data.get_skyfield_data_path()`` is not used: it warns about an expired
``finals2000A.all`` that is not needed here.)  skyfield's own time scale is its
builtin one (``load.timescale(builtin=True)``: bundled ΔT and leap seconds).

Epochs are ``astropy.time.Time`` (or ISO strings, see
:func:`attitude.timescales.as_time`).  They reach skyfield as their exact two-part
TT Julian date, ``ts.tt_jd(t.tt.jd1, t.tt.jd2)``, converted inside
:func:`attitude.timescales.offline_time`; ``ts.from_astropy`` is avoided because it
goes through one float JD and loses up to 20 µs.

Vectors are in the GCRS: ICRF axes, origin at the Earth's centre (or at the
observer given), in metres, with shape ``times.shape + (3,)``.

The Sun is given at its **apparent** place, what a Sun sensor measures (see
:func:`sun_position_from_earth`).  Measured over 1900–2050 (docs/pointing.md, "The
Sun's direction: which place, which frame", with the published sources; and
``tests/test_sun_against_astropy.py``):

- light time (the Sun as it was ≈ 499 s earlier): shifts the direction by < 0.011";
- annual aberration (the Earth's 30 km/s barycentric velocity): ≈ 20.5";
- gravitational deflection: the Sun's deflection of its own light is zero by
  symmetry, and Jupiter's and Saturn's is < 1e-7" here, so it is not computed
  (``deflectors=()``), which makes the call about twice as fast.
The result agrees with astropy's own ephemeris to 0.016".
"""

from __future__ import annotations

import atexit
import importlib.resources
import threading
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from attitude.errors import InputError
from attitude.timescales import SECONDS_PER_DAY, as_time, offline_time

__all__ = [
    "EphemerisRangeError",
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
            f"{name}: epoch {shown} is outside the span of the DE421 ephemeris, "
            f"{_span_text()} (TDB){where if times.ndim else ''}"
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
    :mod:`attitude.eclipse`).  The length is the light-time distance (≈ 1 au).
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
    spacecraft.  The Sun's astrometric vector from the geocentre, minus the
    observer's offset, is the Sun seen one light time ago from the observer; the
    aberration of the observer's barycentric velocity (Earth's + its own) is then
    applied with ERFA ``ab`` (IERS Conventions 2010 / SOFA ``iauAb``, relativistic,
    the same formula as skyfield's ``apparent()``).

    Approximations, measured or bounded: the light time is the geocentre's; the
    observer's differs by |r|/c (23 ms in LEO, 0.14 s in GEO), during which the Sun
    moves ≤ 2.3 m about the barycentre: < 2e-11 rad.  Deflection by the Earth is left
    out (< 0.001").  Against skyfield ``(earth + satellite).at(t).observe(sun)
    .apparent()`` the direction agrees to 0.001" (``tests/test_orbit_interpolation_
    against_skyfield.py``).  The velocity of an ISS orbit (7.7 km/s) moves the Sun
    by up to 5.3" on top of the Earth's 20.5".
    """
    import erfa

    t, shape = skyfield_times(times)
    observer_m = _vectors(position_m, shape, "position_m")
    observer_m_s = _vectors(velocity_m_s, shape, "velocity_m_s")
    astrometric = _sun_astrometric(t)
    earth_m_s = _as_vectors(astrometric.center_barycentric.velocity.m_per_s, shape)
    natural_m = _as_vectors(astrometric.position.m, shape) - observer_m
    distance_m = np.linalg.norm(natural_m, axis=-1, keepdims=True)
    beta = (earth_m_s + observer_m_s) / _C_M_S
    proper = erfa.ab(
        natural_m / distance_m,
        beta,
        distance_m[..., 0] / _AU_M,
        np.sqrt(1.0 - np.sum(beta * beta, axis=-1)),
    )
    return proper * distance_m


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
