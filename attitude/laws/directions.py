"""The directions a law can point a body vector at, with their time derivatives.

A :class:`Direction` gives, at any epochs (:class:`attitude.laws.inputs.InputsAt`), a
vector from the spacecraft along the direction (GCRS, any length) as a jet of order 2:
the law normalizes it and differentiates through the normalization.  Each says which
inputs it needs (:data:`attitude.laws.inputs.INPUTS`).

The named directions (:func:`direction` reads their names):

- ``sun``, ``moon``: the apparent Sun and Moon from the spacecraft (light time and
  aberration, as the pointing layer: :mod:`attitude.laws.inputs`);
- ``nadir``: geodetic nadir, down the normal of the WGS 84 ellipsoid through the
  spacecraft, towards the sub-satellite point (Orekit's ``NadirPointing`` and
  ``PredefinedTarget.NADIR``); found without latitude or longitude
  (:func:`geodetic_nadir`), so it is as regular over the poles as anywhere;
- ``earth_centre``: geocentric nadir, −r (Orekit's ``BodyCenterPointing``, the z axis
  of LVLH);
- ``velocity``: the spacecraft's velocity in the GCRS (inertial);
- ``orbit_normal``: h = r × v;
- ``ground_velocity``: the velocity of the sub-satellite point relative to the ground
  (Earth-fixed), in GCRS axes: the direction of zero-Doppler steering (Orekit's
  ``YawCompensation``).  It is tangent to the ellipsoid, so perpendicular to geodetic
  nadir; it vanishes only where the ground track stands still (a geostationary
  orbit), and then has no direction.

and ``-name`` for the opposite direction (``-earth_centre`` is the radial direction,
zenith).  Others are objects: :class:`GroundSite` (a point on the Earth, geodetic),
:class:`CelestialTarget` (right ascension and declination), :class:`FixedDirection`
(a fixed ICRF vector).
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from typing import Any

import numpy as np
from numpy.typing import NDArray

from attitude.base.errors import InputError
from attitude.base.jets import Jet, cross, dot, matvec, normalized, reciprocal
from attitude.base.quantities import as_si_scalar, as_vector3
from attitude.environment.earth_rotation import (
    WGS84_FLATTENING,
    WGS84_SEMI_MAJOR_AXIS_M,
    geodetic_to_itrs,
)
from attitude.laws.inputs import InputsAt

__all__ = [
    "NAMED_DIRECTIONS",
    "CelestialTarget",
    "Direction",
    "FixedDirection",
    "GroundSite",
    "Opposite",
    "direction",
    "geodetic_nadir",
]


class Direction(ABC):
    """A direction from the spacecraft, as a function of time (see the module notes)."""

    name: str = "direction"
    needs: frozenset[str] = frozenset()

    @abstractmethod
    def vector(self, at: InputsAt) -> Jet:
        """A vector along the direction at ``at``'s epochs, GCRS, jet of order 2."""

    def describe(self) -> str:
        """What the direction is, in words (for messages and summaries)."""
        return self.name

    def __neg__(self) -> Direction:
        return Opposite(self)

    def __eq__(self, other: object) -> bool:
        return type(self) is type(other) and vars(self) == vars(other)

    def __hash__(self) -> int:
        return hash((type(self), self.name))

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.describe()!r})"


class Opposite(Direction):
    """The direction opposite to another (``-"earth_centre"`` is zenith)."""

    def __init__(self, inner: Direction) -> None:
        self.inner = inner
        self.name = f"-{inner.name}"
        self.needs = inner.needs

    def vector(self, at: InputsAt) -> Jet:
        return -self.inner.vector(at)

    def describe(self) -> str:
        return f"opposite of {self.inner.describe()}"

    def __neg__(self) -> Direction:
        return self.inner


class _Sun(Direction):
    name, needs = "sun", frozenset({"sun"})

    def vector(self, at: InputsAt) -> Jet:
        return at.apparent("sun")

    def describe(self) -> str:
        return "the apparent Sun"


class _Moon(Direction):
    name, needs = "moon", frozenset({"moon"})

    def vector(self, at: InputsAt) -> Jet:
        return at.apparent("moon")

    def describe(self) -> str:
        return "the apparent Moon"


class _EarthCentre(Direction):
    name, needs = "earth_centre", frozenset({"orbit"})

    def vector(self, at: InputsAt) -> Jet:
        return -at.position.truncated(2)

    def describe(self) -> str:
        return "the Earth's centre (geocentric nadir)"


class _Nadir(Direction):
    name, needs = "nadir", frozenset({"orbit", "earth_rotation"})

    def vector(self, at: InputsAt) -> Jet:
        down, _ = geodetic_nadir(at.position_itrs.truncated(2))
        return matvec(at.itrs_to_gcrs.truncated(2), down)

    def describe(self) -> str:
        return "geodetic nadir (WGS 84)"


class _Velocity(Direction):
    name, needs = "velocity", frozenset({"orbit"})

    def vector(self, at: InputsAt) -> Jet:
        return at.velocity

    def describe(self) -> str:
        return "the velocity (GCRS)"


class _OrbitNormal(Direction):
    name, needs = "orbit_normal", frozenset({"orbit"})

    def vector(self, at: InputsAt) -> Jet:
        return cross(at.position.truncated(2), at.velocity)

    def describe(self) -> str:
        return "the orbit normal r × v"


class _GroundVelocity(Direction):
    name, needs = "ground_velocity", frozenset({"orbit", "earth_rotation"})

    def vector(self, at: InputsAt) -> Jet:
        _, foot = geodetic_nadir(at.position_itrs)  # order 3: its derivative is order 2
        return matvec(at.itrs_to_gcrs.truncated(2), foot.derivative())

    def describe(self) -> str:
        return "the ground-relative velocity of the sub-satellite point"


NAMED_DIRECTIONS: dict[str, Direction] = {
    d.name: d
    for d in (
        _Sun(),
        _Moon(),
        _Nadir(),
        _EarthCentre(),
        _Velocity(),
        _OrbitNormal(),
        _GroundVelocity(),
    )
}


class FixedDirection(Direction):
    """A fixed direction in the ICRF (``vector``: 3 numbers, any non-zero length)."""

    needs = frozenset()

    def __init__(self, vector: Any, name: str | None = None) -> None:
        v = as_vector3(vector, "dimensionless", "direction")
        length = float(np.linalg.norm(v))
        if not length > 0.0:
            raise InputError(f"direction: a fixed direction must not be zero, got {v.tolist()}")
        self.unit = v / length
        self.name = name or "fixed"

    def vector(self, at: InputsAt) -> Jet:
        return Jet.constant(np.broadcast_to(self.unit, (at.seconds.size, 3)), 2)

    def describe(self) -> str:
        return f"the fixed ICRF direction {np.array2string(self.unit, precision=6)}"

    def __eq__(self, other: object) -> bool:
        return isinstance(other, FixedDirection) and bool(np.all(self.unit == other.unit))

    def __hash__(self) -> int:
        return hash(tuple(self.unit))


class CelestialTarget(FixedDirection):
    """A point of the sky given by right ascension and declination (ICRF; radians or
    angle Quantities).  The catalogue direction, fixed: the aberration of the
    spacecraft's velocity (up to 25") is not applied, unlike the Sun and the Moon's."""

    def __init__(self, ra: Any, dec: Any, name: str | None = None) -> None:
        self.ra = as_si_scalar(ra, "angle", "ra")
        self.dec = as_si_scalar(dec, "angle", "dec")
        if not -math.pi / 2 <= self.dec <= math.pi / 2:
            raise InputError(
                f"dec must be between -90 and 90 deg, got {math.degrees(self.dec):g} deg"
            )
        cos_dec = math.cos(self.dec)
        super().__init__(
            [cos_dec * math.cos(self.ra), cos_dec * math.sin(self.ra), math.sin(self.dec)],
            name or "celestial target",
        )

    def describe(self) -> str:
        return (
            f"{self.name} (RA {math.degrees(self.ra) % 360.0:.6f} deg, "
            f"Dec {math.degrees(self.dec):+.6f} deg)"
        )


class GroundSite(Direction):
    """A point on the Earth: geodetic ``latitude``, ``longitude`` (east positive;
    radians or angle Quantities) and ``height`` above the WGS 84 ellipsoid (m or a
    length Quantity), fixed in the ITRS.  Its direction from the spacecraft is
    geometric (no light time: 3 ms, 1.4 m of the Earth's rotation).

    :meth:`elevation` says where the spacecraft stands above the site's horizon: the
    direction is defined through the Earth as well, and a law tracking a site that
    has set still gives an attitude; the later layers ask when it is visible.
    """

    needs = frozenset({"orbit", "earth_rotation"})

    def __init__(
        self, latitude: Any, longitude: Any, height: Any = 0.0, name: str | None = None
    ) -> None:
        self.latitude = as_si_scalar(latitude, "angle", "latitude")
        self.longitude = as_si_scalar(longitude, "angle", "longitude")
        self.height = as_si_scalar(height, "length", "height")
        if not -math.pi / 2 <= self.latitude <= math.pi / 2:
            raise InputError(
                f"latitude must be between -90 and 90 deg, got {math.degrees(self.latitude):g} deg"
            )
        # East of Greenwich, either way round (-180 to 180, or 0 to 360): beyond, a typo.
        if not -math.pi <= self.longitude <= 2.0 * math.pi:
            raise InputError(
                f"longitude must be between -180 and 360 deg (east), got "
                f"{math.degrees(self.longitude):g} deg"
            )
        if not -1.2e4 <= self.height <= 1e5:
            raise InputError(
                f"height must be between -12 km and 100 km (a point on or near the Earth), "
                f"got {self.height:g} m"
            )
        self.name = name or "ground site"
        self.itrs_m = geodetic_to_itrs(self.latitude, self.longitude, self.height)
        cos_lat = math.cos(self.latitude)
        # The local vertical (the ellipsoid's normal), ITRS.
        self.up_itrs = np.array(
            [
                cos_lat * math.cos(self.longitude),
                cos_lat * math.sin(self.longitude),
                math.sin(self.latitude),
            ]
        )

    def vector(self, at: InputsAt) -> Jet:
        site = matvec(
            at.itrs_to_gcrs.truncated(2),
            Jet.constant(np.broadcast_to(self.itrs_m, (at.seconds.size, 3)), 2),
        )
        return site - at.position.truncated(2)

    def elevation(self, at: InputsAt) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The spacecraft's elevation above the site's horizon (radians; negative below
        it: the site does not see the spacecraft, nor the spacecraft the site) and its
        rate (rad/s), at ``at``'s epochs.  sin e = up · (r − site)/|r − site|, in the
        ITRS (the horizon is the plane normal to the geodetic vertical)."""
        n = at.seconds.size
        line = at.position_itrs.truncated(1) - np.broadcast_to(self.itrs_m, (n, 3))
        sin_e = dot(normalized(line), Jet.constant(np.broadcast_to(self.up_itrs, (n, 3)), 1))
        value = np.arcsin(np.clip(sin_e.value, -1.0, 1.0))
        rate = sin_e.c[1] / np.maximum(np.cos(value), 1e-300)
        return value, rate

    def describe(self) -> str:
        return (
            f"{self.name} (latitude {math.degrees(self.latitude):+.6f} deg, longitude "
            f"{math.degrees(self.longitude):+.6f} deg, height {self.height:g} m)"
        )

    def __eq__(self, other: object) -> bool:
        return isinstance(other, GroundSite) and np.array_equal(self.itrs_m, other.itrs_m)

    def __hash__(self) -> int:
        return hash(tuple(self.itrs_m))


def direction(value: Any) -> Direction:
    """A :class:`Direction` from a name (see the module notes; ``-name`` for the
    opposite), a Direction, or a fixed ICRF 3-vector."""
    if isinstance(value, Direction):
        return value
    if isinstance(value, str):
        text = value.strip().lower().replace(" ", "_")
        negate = text.startswith("-")
        found = NAMED_DIRECTIONS.get(text.lstrip("-+"))
        if found is None:
            raise InputError(
                f"direction: unknown direction {value!r}: expected one of "
                f"{', '.join(NAMED_DIRECTIONS)} (or '-name' for the opposite), a ground "
                "site, a celestial target or a fixed 3-vector"
            )
        return -found if negate else found
    return FixedDirection(value)


def geodetic_nadir(position_itrs: Jet) -> tuple[Jet, Jet]:
    """Down the WGS 84 ellipsoid's normal through points outside it, and the foot of
    that normal (the sub-satellite point), both ITRS jets of ``position_itrs``'s order.

    The foot point f of p satisfies p = f + λ ∇g(f)/2 on the ellipsoid g(f) = 1,
    g(x) = (x² + y²)/a² + z²/b²: with q = p/a, e = (1, 1, a²/b²) and μ = λ/a²,
    f_i = a q_i / (1 + μ e_i), where μ is the root of
    F(μ) = Σ e_i q_i² / (1 + μ e_i)² − 1 (decreasing for μ > −1/max e: one root
    outside the ellipsoid's evolute).  μ is found by Newton's method on floats, then
    two Newton steps on the jets give its derivatives exactly (each step doubles the
    number of exact Taylor coefficients).  The normal (down) is −(e_i f_i), not
    normalized.  No latitude or longitude is formed, so the poles are ordinary points.
    """
    a = WGS84_SEMI_MAJOR_AXIS_M
    e = np.array([1.0, 1.0, 1.0 / (1.0 - WGS84_FLATTENING) ** 2])
    q = position_itrs * (1.0 / a)
    qv = q.value
    radius = np.linalg.norm(qv, axis=-1)
    if np.any(radius * a < 1e3):
        raise InputError(
            "nadir is undefined at the Earth's centre (the orbit passes within 1 km of it)"
        )
    mu = radius - 1.0  # the sphere's answer; Newton from there converges in ~4 steps
    for _ in range(50):
        s = 1.0 / (1.0 + mu[:, None] * e)
        f_value = np.sum(e * qv**2 * s**2, axis=-1) - 1.0
        slope = -2.0 * np.sum(e**2 * qv**2 * s**3, axis=-1)
        step = f_value / slope
        mu = mu - step
        if np.all(np.abs(step) <= 4e-16 * (1.0 + np.abs(mu))):
            break
    mu_jet = Jet.constant(mu, q.order)
    exact = 1
    while exact < q.order + 1:
        s = reciprocal(mu_jet.column() * e + 1.0)
        f_value = dot(q * e, q * s * s) - 1.0
        slope = dot(q * e * e, q * s * s * s) * -2.0
        mu_jet = mu_jet - f_value / slope
        exact *= 2
    s = reciprocal(mu_jet.column() * e + 1.0)
    foot_q = q * s
    return -(foot_q * e), foot_q * a
