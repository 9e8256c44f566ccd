"""Attitude laws, slews, wheels and ground sites in scenario files (``docs/scenarios.md``,
"Attitude laws").

The tables this reads (every key checked, every error naming the file and the key):

- ``[[sites]]``: named ground sites (``name``, ``latitude``, ``longitude`` with their
  angle units, ``height`` in m or with a unit), which a law names as a target or a
  direction;
- a **law** table (``[initial_state.law]``, or ``law = { ... }`` in a ``mode_change``
  or ``control_resume`` event): ``name`` = ``inertial``, ``orbit_frame``, ``nadir``,
  ``sun``, ``target`` or ``align_constrain``, and that law's keys
  (:data:`LAW_KEYS`);
- ``slew = { max_rate = ..., max_acceleration = ... }`` (with units: ``deg/s``,
  ``deg/s2``);
- ``wheels = { case = "locked" | "spinning", momentum = [hx, hy, hz] }`` (N m s, body
  axes).

A direction is a name (``sun``, ``moon``, ``nadir``, ``earth_centre``, ``velocity``,
``orbit_normal``, ``ground_velocity``, or a site of ``[[sites]]``; ``-name`` for the
opposite), 3 numbers (a fixed ICRF direction), or ``{ ra = ..., dec = ... }`` (a point
of the sky, angles with units).  A body vector is ``"+x"``, ``"-z"``, ... or 3 numbers.

The reading is given the scenario reader's table object (its ``fail``, ``allow``,
``string``, ``quantity``, ... methods), so that the errors are worded as everywhere
else in the file.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.environment.frames import ORBIT_FRAMES
from attitude.laws.align_constrain import AlignConstrainLaw, AttitudeLaw
from attitude.laws.directions import NAMED_DIRECTIONS, CelestialTarget, GroundSite
from attitude.laws.named_laws import (
    YAW_STEERING,
    InertialLaw,
    NadirLaw,
    OrbitFrameLaw,
    SunLaw,
    TargetLaw,
)
from attitude.laws.slews import SlewLimits
from attitude.scenario.modes import WHEEL_CASES, Wheels

__all__ = [
    "LAW_KEYS",
    "LAW_NAMES",
    "read_law",
    "read_rotation",
    "read_sites",
    "read_slew",
    "read_wheels",
]

# Each law's keys besides ``name``.
LAW_KEYS: dict[str, tuple[str, ...]] = {
    "inertial": ("quaternion", "matrix"),
    "orbit_frame": ("frame", "quaternion", "matrix"),
    "nadir": ("yaw_steering", "vertical", "phasing_axis"),
    "sun": ("axis", "constraint_axis", "constraint"),
    "target": ("target", "axis", "constraint_axis", "constraint"),
    "align_constrain": ("primary_axis", "primary", "secondary_axis", "secondary"),
}
LAW_NAMES = tuple(LAW_KEYS)


def _call(
    table: Any,
    key: str | None,
    build: Any,
    *args: Any,
    keys: dict[str, str] | None = None,
    **kwargs: Any,
) -> Any:
    """``build(...)``, its InputError said at the key of ``table`` it names (``keys`` maps
    the builder's own names to the table's), else at ``key``."""
    try:
        return build(*args, **kwargs)
    except InputError as exc:
        table.refuse(exc, key, keys)


def read_sites(root: Any) -> dict[str, GroundSite]:
    """``[[sites]]``: the ground sites by name."""
    sites: dict[str, GroundSite] = {}
    for table in root.tables("sites"):
        table.allow("name", "latitude", "longitude", "height")
        name = table.string("name")
        if not name or name.lstrip("+-").lower() in NAMED_DIRECTIONS or name.startswith("-"):
            table.fail(
                f"expected a name that is not a direction's ({', '.join(NAMED_DIRECTIONS)}) and "
                f"does not start with '-', got {name!r}",
                "name",
            )
        if name in sites:
            table.fail(f"a site named {name!r} is already given", "name")
        latitude = table.quantity("latitude", "angle", (), to="deg")
        if not -90.0 <= latitude <= 90.0:
            reason = f"must be between -90 and 90 deg, got {table.written_text('latitude')}"
            table.fail(reason, "latitude", latitude)
        longitude = table.quantity("longitude", "angle", (), to="deg")
        # East of Greenwich, either way round the globe (-180 to 180, or 0 to 360).
        if not -180.0 <= longitude <= 360.0:
            reason = (
                f"must be between -180 and 360 deg (east), got {table.written_text('longitude')}"
            )
            table.fail(reason, "longitude", longitude)
        height = table.quantity("height", "length", (), required=False)
        if height is not None and not -1.2e4 <= height <= 1e5:
            table.fail(
                f"must be between -12 km and 100 km (a point on or near the Earth), got "
                f"{table.written_text('height', 'm')}",
                "height",
                height,
            )
        sites[name] = _call(
            table,
            None,
            GroundSite,
            math.radians(latitude),
            math.radians(longitude),
            0.0 if height is None else height,
            name,
        )
    return sites


def _body_vector(table: Any, key: str, default: str | None = None) -> Any:
    """A body vector: "+x"-like text, or 3 numbers."""
    value = table.raw(key, required=default is None, default=default)
    if isinstance(value, str):
        return value
    return table.quantity(key, "dimensionless", (3,))


def _direction(table: Any, key: str, sites: dict[str, GroundSite], required: bool = True) -> Any:
    """A direction: a name (a site's included, ``-`` for the opposite), 3 numbers, or
    ``{ ra, dec }``; None when absent and not required."""
    value = table.raw(key, required=required)
    if value is None:
        return None
    if isinstance(value, str):
        negate = value.startswith("-")
        name = value.lstrip("+-")
        if name in sites:
            return -sites[name] if negate else sites[name]
        if name.lower().replace(" ", "_") not in NAMED_DIRECTIONS:
            known = [*NAMED_DIRECTIONS, *sites]
            table.fail(
                f"unknown direction {value!r}: expected one of {', '.join(known)} ('-name' for "
                "the opposite), 3 numbers (a fixed ICRF direction) or { ra = ..., dec = ... }",
                key,
            )
        return value
    if isinstance(value, dict):
        sub = table.table(key)
        sub.allow("ra", "dec", "name")
        ra = sub.quantity("ra", "angle", ())
        dec = sub.quantity("dec", "angle", ())
        label = sub.string("name", required=False)
        return _call(sub, None, CelestialTarget, ra, dec, label)
    return table.quantity(key, "dimensionless", (3,))


def read_rotation(table: Any, what: str, required: bool) -> Rotation | None:
    """``quaternion`` (w, x, y, z, ``what``) or ``matrix``, or None when neither is
    given and it is not ``required``."""
    given = [key for key in ("quaternion", "matrix") if table.has(key)]
    if len(given) > 1:
        table.fail("give one of quaternion and matrix, not both")
    if not given:
        if required:
            table.fail(f"missing quaternion (w, x, y, z, {what}) or matrix")
        return None
    if given[0] == "quaternion":
        q = table.quantity("quaternion", "dimensionless", (4,))
        norm = float(np.linalg.norm(q))
        if abs(norm - 1.0) > 1e-6:
            table.fail(f"quaternion must have unit norm, got |q| = {norm:.9g}", "quaternion")
        return Rotation.from_quat(q, scalar_first=True)
    a = table.quantity("matrix", "dimensionless", (3, 3))
    if np.max(np.abs(a @ a.T - np.eye(3))) > 1e-6 or np.linalg.det(a) < 0:
        table.fail(f"matrix must be a rotation (orthonormal, det +1), got {a.tolist()}", "matrix")
    return Rotation.from_matrix(a)


def read_law(table: Any, sites: dict[str, GroundSite]) -> AttitudeLaw:
    """A law table (module notes) as an :class:`~attitude.laws.align_constrain.AttitudeLaw`."""
    name = table.choice("name", LAW_NAMES)
    table.allow("name", *LAW_KEYS[name])
    if name == "inertial":
        return _call(table, None, InertialLaw, read_rotation(table, "body -> ICRF", True))
    if name == "orbit_frame":
        frame = table.choice("frame", ORBIT_FRAMES, default="lvlh")
        return _call(
            table, None, OrbitFrameLaw, frame, read_rotation(table, f"body -> {frame}", False)
        )
    if name == "nadir":
        steering = table.choice("yaw_steering", YAW_STEERING, default="none")
        vertical = table.choice("vertical", ("geodetic", "geocentric"), default="geodetic")
        phasing = _body_vector(table, "phasing_axis", "+x")
        return _call(table, None, NadirLaw, steering, vertical, phasing)
    if name == "sun":
        return _call(
            table,
            None,
            SunLaw,
            _body_vector(table, "axis", "+z"),
            _body_vector(table, "constraint_axis", "+x"),
            _direction(table, "constraint", sites, required=False),
        )
    if name == "target":
        target = _direction(table, "target", sites)
        if isinstance(target, str) and target.lstrip("+-") not in ("moon", *sites):
            table.fail(
                f"a target is a site of [[sites]] ({', '.join(sites) or 'none given'}), 'moon', "
                f"or {{ ra = ..., dec = ... }}, got {target!r}",
                "target",
            )
        return _call(
            table,
            None,
            TargetLaw,
            target,
            _body_vector(table, "axis", "+z"),
            _body_vector(table, "constraint_axis", "+x"),
            _direction(table, "constraint", sites, required=False),
        )
    return _call(
        table,
        None,
        AlignConstrainLaw,
        _body_vector(table, "primary_axis"),
        _direction(table, "primary", sites),
        _body_vector(table, "secondary_axis"),
        _direction(table, "secondary", sites),
    )


def read_slew(table: Any) -> SlewLimits:
    """``slew = { max_rate, max_acceleration }``."""
    table.allow("max_rate", "max_acceleration")
    rate = table.positive("max_rate", "angular_velocity", unit_needed=True)
    acceleration = table.positive("max_acceleration", "angular_acceleration", unit_needed=True)
    keys = {"slew.max_rate": "max_rate", "slew.max_acceleration": "max_acceleration"}
    return _call(table, None, SlewLimits, rate, acceleration, keys=keys)


def read_wheels(table: Any) -> Wheels:
    """``wheels = { case, momentum }``."""
    table.allow("case", "momentum")
    case = table.choice("case", WHEEL_CASES)
    momentum = table.quantity("momentum", "angular_momentum", (3,))
    return _call(table, None, Wheels, case, momentum, keys={"wheels.case": "case"})
