"""The Earth seen from the spacecraft: its size, its angular radius, nadir and the limb.

The Earth is a sphere of the WGS 84 equatorial radius, the one place its size is
defined in the package (the shadow of :mod:`attitude.pointing.eclipse`, the limb and nadir of
:mod:`attitude.pointing` and the J2 of :mod:`attitude.environment.keplerian` all take it from
here).  The polar radius is 21.4 km shorter: where the limb crosses high latitudes the
true limb is lower than this sphere's by up to that (0.5° in angle seen from the ISS).

Angles, from a spacecraft at ``position_m`` (GCRS, from the Earth's centre):

- **angular radius** ρ = asin((R + h) / |r|), the half-angle of the cone from the
  spacecraft tangent to the sphere of radius R + h (h: an atmosphere height, 0 for
  the solid Earth);
- **nadir angle** of a direction u: the angle between u and −r (geocentric nadir);
- **limb angle** of u: nadir angle − ρ, the angular distance from u to the limb
  circle, *positive above the limb* (u misses the Earth, and clears it by that angle)
  and negative below it (u meets the Earth).  On the sphere the distance from a point
  at angle θ from a circle's centre to the circle of radius ρ is |θ − ρ|, along the
  great circle through the centre: this is exact, not a small-angle approximation.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from attitude.base.vectors import angle_between

__all__ = [
    "EARTH_EQUATORIAL_RADIUS_M",
    "GM_EARTH_M3_S2",
    "HILL_RADIUS_M",
    "J2_EARTH",
    "MAX_ENCOUNTER_SPEED_M_S",
    "angular_radius",
    "limb_angle",
    "nadir_angle",
]

# WGS 84 semi-major axis (NIMA TR8350.2, 3rd ed., table 3.1).
EARTH_EQUATORIAL_RADIUS_M = 6_378_137.0
# The Earth's gravitational parameter, atmosphere included (IERS Conventions 2010,
# IERS Technical Note 36, table 1.1, TT-compatible), and the unnormalized second
# zonal harmonic of EGM2008, J2 = −√5 C̄20 with C̄20 = −4.84165143790815e-4 (Pavlis et
# al., J. Geophys. Res. 117, B04406, 2012, doi:10.1029/2011JB008916).
GM_EARTH_M3_S2 = 3.986004418e14
J2_EARTH = 1.0826261738522227e-3

# The Sun's gravitational parameter (IAU 2015 Resolution B3, nominal GM☉) and the
# astronomical unit (IAU 2012 Resolution B2).
_GM_SUN_M3_S2 = 1.3271244e20
_AU_M = 1.495978707e11
# The Earth's Hill radius, a (m/3M)^(1/3) (Murray & Dermott, *Solar System Dynamics*,
# 1999, eq. 3.75): about 1.5 million km.  Beyond it the Sun's pull, not the Earth's,
# holds a body: no orbit about the Earth reaches there, so an orbit source whose
# apogee or states lie beyond it is refused (a semi-major axis of 1e30 m is a typo).
HILL_RADIUS_M = _AU_M * (GM_EARTH_M3_S2 / (3.0 * _GM_SUN_M3_S2)) ** (1.0 / 3.0)
# The fastest a body that circles the Sun passes the Earth, far from it: the Earth's
# orbital speed plus the Sun's escape speed at 1 au, √(GM☉/au) (1 + √2), 71.9 km/s.
# A state of an orbit file faster than this plus the escape speed where it is (the
# Earth's pull adds that much, √(v∞² + 2GM/r)) is not a body near the Earth.
MAX_ENCOUNTER_SPEED_M_S = math.sqrt(_GM_SUN_M3_S2 / _AU_M) * (1.0 + math.sqrt(2.0))


def angular_radius(position_m: ArrayLike, height_m: float = 0.0) -> NDArray[np.float64]:
    """Angular radius of the Earth (plus ``height_m``) seen from ``position_m``, radians.

    asin((R + h)/|r|); ``position_m`` has shape ``(..., 3)``.  From inside the sphere
    (|r| ≤ R + h) the Earth fills half the sky and more: clipped to π/2.
    """
    r = np.linalg.norm(np.asarray(position_m, dtype=np.float64), axis=-1)
    return np.arcsin(np.minimum(1.0, (EARTH_EQUATORIAL_RADIUS_M + height_m) / r))


def nadir_angle(direction: ArrayLike, position_m: ArrayLike) -> NDArray[np.float64]:
    """Angle between ``direction`` and geocentric nadir (−position), radians."""
    return angle_between(direction, -np.asarray(position_m, dtype=np.float64))


def limb_angle(
    direction: ArrayLike, position_m: ArrayLike, height_m: float = 0.0
) -> NDArray[np.float64]:
    """Angle of ``direction`` above the Earth's limb (radians; negative below it).

    The nadir angle minus the angular radius of the sphere of radius R + ``height_m``
    (see the module notes).
    """
    return nadir_angle(direction, position_m) - angular_radius(position_m, height_m)
