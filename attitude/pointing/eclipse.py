"""Earth's shadow: the conical umbra/penumbra model, and eclipse intervals of an orbit.

The Sun and the Earth are spheres.  Seen from the spacecraft at ``r`` (from the
Earth's centre), with the Sun at ``s`` (from the Earth's centre), Montenbruck & Gill,
*Satellite Orbits* (Springer 2000), §3.4.2 "Shadow" (p. 81), compare three angles:

    a = asin(R_sun / |s − r|)      apparent radius of the Sun (≈ 0.27°)
    b = asin(R_earth / |r|)        apparent radius of the Earth (≈ 70° from the ISS)
    c = angle(−r, s − r)           between the centres of the two discs

- umbra, no sunlight:   c ≤ b − a (the Earth's disc covers the Sun's);
- full sun:             c ≥ a + b (the discs do not overlap);
- penumbra otherwise; the lit fraction is 1 − A / (π a²), where A is the area of
  overlap of the two discs (the area of a lens).
If the spacecraft is so far behind the Earth that b < a (beyond the tip of the umbra,
1.4 million km), the Earth's disc can lie inside the Sun's: an annular eclipse,
lit fraction 1 − b²/a², reported as penumbra.

The discs are treated as plane circles of radii a and b, as in M&G.  On the sky
the Earth's limb is a small circle of radius b, which curves less than a plane
circle of radius b; across the Sun's disc (0.27°) the two differ by 1e-3 of the
Sun's radius, and the lit fraction by up to 2.6e-4 on an ISS orbit (measured
against a direct count of the rays from the Sun's disc that miss the Earth,
``tests/test_eclipse_against_direct_geometry.py``).  The edges themselves (discs
touching) are exact.  The Sun's disc is uniformly bright here (no limb darkening),
the Earth has no atmosphere and no flattening; each of those moves the shadow's
edges by far more (the atmosphere: seconds of time in LEO).  ``earth_radius_m``
can be raised to an effective radius to model an absorbing layer.

Which Sun vector: the apparent one from the Earth's centre
(:func:`attitude.environment.ephemeris.sun_position_from_earth`).  In the GCRS, sunlight arrives
from the aberrated direction, so the shadow's axis is the apparent Sun, not the
geometric one; the difference (≈ 20.5") moves the edges of an ISS eclipse by
up to 45 ms.  Lengths in metres; vectors ``(..., 3)`` broadcast against each other.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from attitude.base.errors import InputError
from attitude.base.quantities import as_si_array, as_si_scalar
from attitude.base.vectors import angle_between
from attitude.environment.earth import EARTH_EQUATORIAL_RADIUS_M, angular_radius
from attitude.environment.ephemeris import sun_position_from_earth
from attitude.environment.timescales import as_time, offline_time, time_from_tt_seconds, tt_seconds
from attitude.pointing.intervals import find_intervals

__all__ = [
    "SUN_RADIUS_M",
    "EclipseIntervals",
    "EclipseState",
    "eclipse_intervals",
    "eclipse_state",
    "fraction_from_angles",
    "shadow_angles",
    "sunlit_fraction",
]

# The IAU 2015 nominal solar radius, Resolution B3 (Prša et al. 2016, AJ 152, 41):
# 695 700 km, the photospheric radius.  (M&G use the older 696 000 km; the 300 km
# difference moves the shadow edges of the ISS by 1.8 ms.)
SUN_RADIUS_M = 695_700_000.0


class EclipseState(enum.IntEnum):
    """How much of the Sun the spacecraft sees; the codes order by light."""

    UMBRA = 0  # none of the Sun's disc
    PENUMBRA = 1  # part of it (also an annular eclipse beyond the umbra's tip)
    SUNLIT = 2  # all of it


def _vectors(value: Any, name: str) -> NDArray[np.float64]:
    """``value`` as vectors of shape ``(..., 3)`` in metres, else InputError."""
    array = as_si_array(value, "length", name)
    if array.ndim == 0 or array.shape[-1] != 3:
        raise InputError(f"{name} must be vectors of shape (..., 3), got shape {array.shape}")
    return array


def _length(value: Any, name: str) -> float:
    """``value`` as a positive length in metres, else InputError."""
    array = as_si_array(value, "length", name)
    if array.ndim != 0:
        raise InputError(f"{name} must be a scalar, got shape {array.shape}")
    if not array > 0.0:
        raise InputError(f"{name} must be positive, got {float(array)}")
    return float(array)


def shadow_angles(
    r_sat_m: ArrayLike,
    r_sun_m: ArrayLike,
    *,
    earth_radius_m: float = EARTH_EQUATORIAL_RADIUS_M,
    sun_radius_m: float = SUN_RADIUS_M,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The angles (a, b, c) of Montenbruck & Gill §3.4.2, radians (see the module notes).

    ``r_sat_m``: spacecraft from the Earth's centre; ``r_sun_m``: Sun from the Earth's
    centre (apparent); both metres, shape ``(..., 3)``, broadcast.  The spacecraft
    must be outside the Earth and outside the Sun, else :class:`InputError`.
    """
    r = _vectors(r_sat_m, "r_sat_m")
    s = _vectors(r_sun_m, "r_sun_m")
    earth_radius_m = _length(earth_radius_m, "earth_radius_m")
    sun_radius_m = _length(sun_radius_m, "sun_radius_m")
    to_sun = s - r
    r_norm = np.linalg.norm(r, axis=-1)
    to_sun_norm = np.linalg.norm(to_sun, axis=-1)
    _outside(r_norm, earth_radius_m, r, "r_sat_m", "the Earth")
    _outside(to_sun_norm, sun_radius_m, to_sun, "r_sun_m - r_sat_m", "the Sun")
    a = np.arcsin(sun_radius_m / to_sun_norm)
    b = angular_radius(r, earth_radius_m - EARTH_EQUATORIAL_RADIUS_M)
    c = angle_between(-r, to_sun)
    return a, b, c


def _outside(
    distance_m: NDArray[np.float64],
    radius_m: float,
    vectors: NDArray[np.float64],
    name: str,
    body: str,
) -> None:
    """InputError if a distance from the centre of ``body`` is not above its radius."""
    inside = distance_m <= radius_m
    if np.any(inside):
        index = tuple(int(i) for i in np.argwhere(inside)[0]) if inside.ndim else ()
        where = f" at index {index[0] if len(index) == 1 else index}" if index else ""
        raise InputError(
            f"{name}: the spacecraft is inside {body}, {float(distance_m[index])} m from its "
            f"centre (radius {radius_m} m){where}: {vectors[index]}"
        )


def sunlit_fraction(
    r_sat_m: ArrayLike,
    r_sun_m: ArrayLike,
    *,
    earth_radius_m: float = EARTH_EQUATORIAL_RADIUS_M,
    sun_radius_m: float = SUN_RADIUS_M,
) -> NDArray[np.float64]:
    """Fraction of the Sun's disc visible from the spacecraft: 0 in umbra, 1 in full sun.

    Conical model of Montenbruck & Gill §3.4.2: in the penumbra, 1 − A/(π a²) with A
    the overlap of the discs of radii a (Sun) and b (Earth) at distance c:

        x = (c² + a² − b²) / (2c),   y = √(a² − x²),
        A = a² acos(x/a) + b² acos((c − x)/b) − c y.

    It is continuous (→ 1 at c = a + b, → 0 at c = b − a) and decreases with c.
    Shape: the broadcast of ``r_sat_m[..., 0]`` and ``r_sun_m[..., 0]``.
    """
    a, b, c = shadow_angles(
        r_sat_m, r_sun_m, earth_radius_m=earth_radius_m, sun_radius_m=sun_radius_m
    )
    return fraction_from_angles(a, b, c)


def fraction_from_angles(a: ArrayLike, b: ArrayLike, c: ArrayLike) -> NDArray[np.float64]:
    """The visible fraction of the Sun's disc from the angles (a, b, c) of
    :func:`shadow_angles` (radians, broadcast): see :func:`sunlit_fraction`."""
    sun, earth, apart = np.broadcast_arrays(*(np.asarray(x, dtype=np.float64) for x in (a, b, c)))
    fraction = np.ones(apart.shape)
    fraction[apart <= earth - sun] = 0.0
    annular = apart <= sun - earth  # the Earth's disc inside the Sun's
    fraction[annular] = 1.0 - (earth[annular] / sun[annular]) ** 2
    partial = (apart > np.abs(earth - sun)) & (apart < sun + earth)
    fraction[partial] = _penumbra_fraction(sun[partial], earth[partial], apart[partial])
    return fraction[()] if fraction.ndim == 0 else fraction


def _penumbra_fraction(
    a: NDArray[np.float64], b: NDArray[np.float64], c: NDArray[np.float64]
) -> NDArray[np.float64]:
    """1 − A/(π a²) where the discs partly overlap (|b − a| < c < a + b): see
    :func:`sunlit_fraction` for the lens area A."""
    # c² − b² as (c − b)(c + b): no cancellation where c ≈ b ≫ a.
    x = ((c - b) * (c + b) + a * a) / (2.0 * c)
    y = np.sqrt(np.maximum(a * a - x * x, 0.0))
    overlap = (
        a * a * np.arccos(np.clip(x / a, -1.0, 1.0))
        + b * b * np.arccos(np.clip((c - x) / b, -1.0, 1.0))
        - c * y
    )
    return np.clip(1.0 - overlap / (np.pi * a * a), 0.0, 1.0)


def eclipse_state(
    r_sat_m: ArrayLike,
    r_sun_m: ArrayLike,
    *,
    earth_radius_m: float = EARTH_EQUATORIAL_RADIUS_M,
    sun_radius_m: float = SUN_RADIUS_M,
) -> NDArray[np.int8]:
    """:class:`EclipseState` codes (0 umbra, 1 penumbra, 2 sunlit), an int8 array.

    Decided on the angles, as :func:`sunlit_fraction` (c ≤ b − a, c ≥ a + b), so the
    two always agree: code 0 ⇔ fraction 0, code 2 ⇔ fraction 1.
    """
    a, b, c = shadow_angles(
        r_sat_m, r_sun_m, earth_radius_m=earth_radius_m, sun_radius_m=sun_radius_m
    )
    state = np.full(np.broadcast(a, b, c).shape, EclipseState.PENUMBRA, dtype=np.int8)
    state[np.broadcast_to(c <= b - a, state.shape)] = EclipseState.UMBRA
    state[np.broadcast_to(c >= a + b, state.shape)] = EclipseState.SUNLIT
    return state


@dataclass(frozen=True)
class EclipseIntervals:
    """Shadow intervals of an orbit, as ``Time`` arrays of shape (n, 2): [entry, exit].

    ``shadow``: the Sun at least partly hidden (penumbra or umbra); ``umbra``: the Sun
    wholly hidden.  An interval cut by the start or the end of the span is clipped to
    it.  Epochs are in TT.
    """

    shadow: Any
    umbra: Any


def eclipse_intervals(
    orbit: Any,
    start: Any,
    stop: Any,
    *,
    step_s: float = 30.0,
    precision_s: float = 1e-6,
    earth_radius_m: float = EARTH_EQUATORIAL_RADIUS_M,
    sun_radius_m: float = SUN_RADIUS_M,
) -> EclipseIntervals:
    """The shadow and umbra intervals of ``orbit`` between ``start`` and ``stop``.

    ``orbit``: an :class:`attitude.environment.orbit.Orbit` (anything with
    ``position_velocity(times)``).  The edges are the roots of the continuous functions
    c − (a + b) (shadow) and c − (b − a) (umbra), sampled every ``step_s`` seconds;
    each sign change is refined on the orbit and the ephemeris themselves
    (:func:`attitude.pointing.intervals.find_intervals`) to ``precision_s``.  Measured on an
    ISS orbit over a day: the edges agree with a root search on direct skyfield
    positions (``tests/test_eclipse_against_direct_geometry.py``) to the precision
    asked.  A shadow shorter than ``step_s`` (a grazing pass) may be missed.
    """
    start = as_time(start, name="start")
    stop = as_time(stop, name="stop")
    step_s = as_si_scalar(step_s, "time", "step_s")
    if not step_s > 0.0:
        raise InputError(f"step_s must be positive, got {step_s}")
    span_s = float(tt_seconds(stop, start))
    if not span_s > 0.0:
        with offline_time():
            raise InputError(f"stop must be after start, got {start.isot} to {stop.isot}")
    count = max(int(np.ceil(span_s / step_s)) + 1, 2)
    seconds = np.linspace(0.0, span_s, count)

    def margins(τ: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        times = time_from_tt_seconds(start, τ)
        r_m, _ = orbit.position_velocity(times)
        a, b, c = shadow_angles(
            r_m,
            sun_position_from_earth(times),
            earth_radius_m=earth_radius_m,
            sun_radius_m=sun_radius_m,
        )
        return (a + b) - c, (b - a) - c  # > 0 inside the shadow, inside the umbra

    shadow_on_grid, umbra_on_grid = margins(seconds)

    def edges(which: int, on_grid: NDArray[np.float64]):
        found = find_intervals(lambda τ: margins(τ)[which], seconds, precision_s, on_grid)
        edges_s = np.array([[i.start_s, i.end_s] for i in found]).reshape(-1, 2)
        return time_from_tt_seconds(start, edges_s)

    return EclipseIntervals(shadow=edges(0, shadow_on_grid), umbra=edges(1, umbra_on_grid))
