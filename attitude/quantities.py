"""Numbers at the public edge: astropy Quantities to SI floats, and their checks.

The package computes in SI floats (seconds, kg m², N m s, rad/s).  Public functions
also accept ``astropy.units.Quantity``; these helpers convert them, and check shape
and finiteness, so that a bad value fails here with a message that names the field
instead of deep inside numpy.  astropy is imported only when a Quantity is given.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from attitude.errors import InputError

__all__ = ["SI_UNITS", "as_si_array", "as_si_scalar", "as_vector3"]

# The SI unit each kind of input is converted to (astropy unit strings).
SI_UNITS = {
    "time": "s",
    "moment_of_inertia": "kg m2",
    "angular_momentum": "kg m2 / s",
    "angular_velocity": "rad / s",
    "angle": "rad",
    "length": "m",
}


def _is_quantity(value: Any) -> bool:
    return hasattr(value, "unit") and hasattr(value, "to_value")


def _strip_unit(value: Any, kind: str, name: str) -> Any:
    if not _is_quantity(value):
        return value
    from astropy import units as u

    try:
        return value.to_value(u.Unit(SI_UNITS[kind]), equivalencies=u.dimensionless_angles())
    except u.UnitConversionError as exc:
        raise InputError(
            f"{name} has unit {value.unit!s}, which cannot be converted to {SI_UNITS[kind]}"
        ) from exc


def as_si_array(
    value: Any, kind: str, name: str, *, allow_nonfinite: bool = False
) -> NDArray[np.float64]:
    """``value`` as a float64 array in the SI unit of ``kind``; checks that it is finite."""
    raw = _strip_unit(value, kind, name)
    try:
        array = np.asarray(raw, dtype=np.float64)
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
