"""Numbers at the public edge: astropy Quantities to SI floats, and their checks.

The package computes in SI floats (seconds, kg m², N m s, rad/s).  Public functions
also accept ``astropy.units.Quantity``; these helpers convert them, and check type,
shape and finiteness, so that a bad value fails here with a message that names the
field instead of deep inside numpy.  astropy is imported only when a unit is given.

Units convert strictly, with no equivalency: an angle unit converts to radians
(``deg/s``, ``cycle/s`` = 2π rad/s), but a frequency does not become an angular
velocity.  ``Hz`` (= 1/s) would be 1 rad/s under astropy's ``dimensionless_angles``
and 2π rad/s as turns per second, so it is refused with a message saying which unit
to write instead.  Booleans, strings and None are refused, not read as 1, 0 or NaN.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from attitude.base.errors import InputError

__all__ = ["SI_UNITS", "as_si_array", "as_si_scalar", "as_vector3", "convert_unit"]

# The SI unit each kind of input is converted to (astropy unit strings).
SI_UNITS = {
    "time": "s",
    "moment_of_inertia": "kg m2",
    "angular_momentum": "kg m2 / s",
    "angular_velocity": "rad / s",
    "angular_acceleration": "rad / s2",
    "angle": "rad",
    "length": "m",
    "torque": "N m",
    "dimensionless": "",
}


def _is_quantity(value: Any) -> bool:
    return hasattr(value, "unit") and hasattr(value, "to_value")


def _kind_text(kind: str) -> str:
    text = kind.replace("_", " ")
    return f"{'an' if text[0] in 'aeiou' else 'a'} {text}"


def convert_unit(value: Any, unit: Any, kind: str, name: str, to: str | None = None) -> Any:
    """``value`` (numbers) in ``unit`` (an astropy unit or its text) as numbers in the
    SI unit of ``kind`` (or in ``to``, a unit of the same kind); :class:`InputError`
    naming ``name`` if it does not convert."""
    from astropy import units as u

    target = u.Unit(SI_UNITS[kind] if to is None else to)
    shown = (SI_UNITS[kind] if to is None else to) or "a pure number"
    try:
        unit = u.Unit(unit)
    except (ValueError, TypeError):
        raise InputError(
            f"unit {unit!r} cannot be converted to {shown} ({_kind_text(kind)}): "
            "astropy does not know it",
            key=name,
            value=unit,
        ) from None
    try:
        return u.Quantity(value, unit).to_value(target)
    except u.UnitConversionError:
        pass
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{name} must be numeric, got {value!r}") from None
    _refuse_ambiguous(unit, kind, name)
    raise InputError(
        f"unit {unit.to_string()!r} cannot be converted to {shown} ({_kind_text(kind)})",
        key=name,
        value=unit.to_string(),
    )


def _refuse_ambiguous(unit: Any, kind: str, name: str) -> None:
    """Raise the message for a unit that converts only by reading radians as pure
    numbers (Hz for an angular velocity: cycles or radians per second?)."""
    from astropy import units as u

    target = u.Unit(SI_UNITS[kind])
    try:
        u.Quantity(1.0, unit).to(target, equivalencies=u.dimensionless_angles())
    except u.UnitConversionError:
        return
    if kind == "angular_velocity":
        hint = "write 'cycle/s' for turns per second (2π rad/s each), or 'rad/s'"
    elif kind == "angle":
        hint = "write an angle unit: 'deg', 'rad', 'arcmin', 'cycle'"
    else:
        hint = f"write it in {SI_UNITS[kind] or 'a pure number'}"
    raise InputError(
        f"unit {u.Unit(unit).to_string()!r} is ambiguous for {_kind_text(kind)} "
        f"(cycles or radians?): {hint}",
        key=name,
        value=u.Unit(unit).to_string(),
    )


def _strip_unit(value: Any, kind: str, name: str) -> Any:
    if not _is_quantity(value):
        return value
    from astropy import units as u

    try:
        return value.to_value(u.Unit(SI_UNITS[kind]))
    except u.UnitConversionError:
        _refuse_ambiguous(value.unit, kind, name)
        raise InputError(
            f"{name} has unit {value.unit!s}, which cannot be converted to {SI_UNITS[kind]}"
        ) from None


def _check_numbers(value: Any, name: str) -> None:
    """Refuse booleans, strings and None (numpy would read them as 1, a number or NaN)."""
    if isinstance(value, np.ndarray):
        if value.dtype.kind not in "iuf":
            raise InputError(f"{name} must be numeric, got an array of {value.dtype}")
        return
    if isinstance(value, list | tuple):
        for item in value:
            _check_numbers(item, name)
        return
    if isinstance(value, bool | np.bool_) or not isinstance(value, int | float | np.number):
        raise InputError(f"{name} must be numeric, got {value!r}")


def as_si_array(
    value: Any, kind: str, name: str, *, allow_nonfinite: bool = False
) -> NDArray[np.float64]:
    """``value`` as a float64 array in the SI unit of ``kind``; checks that it is finite."""
    raw = _strip_unit(value, kind, name)
    if value is None:
        raise InputError(f"{name} is missing (got None)")
    _check_numbers(raw, name)
    try:
        array = np.asarray(raw, dtype=np.float64)
    except OverflowError:
        raise InputError(f"{name} is beyond the float range (about 1.8e308)") from None
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} must be numeric, got {value!r}") from exc
    if not allow_nonfinite and not np.all(np.isfinite(array)):
        if array.ndim == 0:
            raise InputError(f"{name} must be finite, got {float(array)}")
        index = tuple(int(i) for i in np.argwhere(~np.isfinite(array))[0])
        where = index[0] if len(index) == 1 else index
        raise InputError(f"{name} must be finite, got {float(array[index])} at index {where}")
    return array


def as_si_scalar(value: Any, kind: str, name: str) -> float:
    """``value`` as a finite float in the SI unit of ``kind``."""
    array = as_si_array(value, kind, name)
    if array.ndim != 0:
        raise InputError(f"{name} must be a scalar, got shape {array.shape}")
    return float(array)


def as_vector3(value: Any, kind: str, name: str) -> NDArray[np.float64]:
    """``value`` as a finite 3-vector in the SI unit of ``kind``."""
    array = as_si_array(value, kind, name)
    if array.shape != (3,):
        raise InputError(f"{name} must be a 3-vector, got shape {array.shape}: {value!r}")
    return array
