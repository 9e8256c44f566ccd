"""The spacecraft: a name and an inertia in its own body axes.

The inertia is given as principal moments along the body axes or as a full
symmetric tensor in body axes (diagonalized by ``numpy.linalg.eigh``; the body →
principal rotation is kept, and every output stays in the body axes).  Invalid
tensors are refused; moments that no real body has (Ia + Ib < Ic) only warn.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from attitude.base.errors import InertiaWarning, InputError
from attitude.solver.inertia import PrincipalAxes, principal_axes, violates_triangle_inequality

__all__ = ["Spacecraft", "check_inertia"]


def check_inertia(inertia: Any, name: str) -> PrincipalAxes:
    """Principal axes of ``inertia``, warning if the moments break the triangle inequality."""
    axes = principal_axes(inertia, name)
    if violates_triangle_inequality(axes.moments):
        low, mid, high = np.sort(axes.moments)
        warnings.warn(
            InertiaWarning(
                f"principal moments {axes.moments.tolist()} kg m² break the triangle "
                f"inequality ({low:g} + {mid:g} < {high:g}): no real body has them",
                key=name,
            ),
            stacklevel=3,
        )
    return axes


class Spacecraft:
    """A rigid spacecraft.

    Parameters
    ----------
    name
        Used in reports and exported files.
    inertia
        Three principal moments along the body x, y, z axes, or the symmetric 3×3
        inertia tensor in body axes, kg m² (or a ``Quantity``).
    """

    def __init__(self, name: str, inertia: Any) -> None:
        if not isinstance(name, str) or not name.strip():
            raise InputError(
                f"spacecraft name must be a non-empty string, got {name!r}", key="name", value=name
            )
        self._name = name
        self._axes = check_inertia(inertia, "inertia")

    @property
    def name(self) -> str:
        return self._name

    @property
    def principal_axes(self) -> PrincipalAxes:
        """The principal moments and the body → principal rotation (computed once)."""
        return self._axes

    @property
    def inertia_tensor(self) -> NDArray[np.float64]:
        """Inertia tensor in body axes, kg m²."""
        return self._axes.tensor.copy()

    @property
    def principal_moments(self) -> NDArray[np.float64]:
        """Principal moments, kg m² (along the body axes if given so, else ascending)."""
        return self._axes.moments.copy()

    @property
    def body_to_principal(self) -> Rotation:
        """Rotation taking body coordinates to principal-axis coordinates."""
        return self._axes.body_to_principal

    def __repr__(self) -> str:
        return f"Spacecraft({self._name!r}, inertia={self._axes.tensor.tolist()})"
