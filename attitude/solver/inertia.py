"""Inertia of a rigid body: principal moments and axes from moments or a full tensor.

A body's inertia is given either as its three principal moments along the body x,
y, z axes, or as a symmetric 3×3 tensor in body axes.  A tensor is diagonalized
with ``numpy.linalg.eigh``; the rotation from body to principal axes is kept so that
every result can be given back in the user's body axes.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.base.quantities import as_si_array

__all__ = ["PrincipalAxes", "principal_axes", "violates_triangle_inequality"]

# A tensor whose asymmetry is below this fraction of its largest entry is taken as
# symmetric (rounding in a CAD export); above, it is refused.
_SYMMETRY_TOLERANCE = 1e-9


@dataclass(frozen=True)
class PrincipalAxes:
    """Principal moments (kg m²) and the rotation taking body to principal coordinates.

    ``moments[k]`` is the moment about principal axis k; for moments given directly
    the principal axes are the body axes (``body_to_principal`` is the identity and
    the moments keep their order), for a tensor they come out ascending.
    ``tensor`` is the inertia tensor in body axes.
    """

    moments: NDArray[np.float64]
    body_to_principal: Rotation
    tensor: NDArray[np.float64]

    @property
    def is_diagonal(self) -> bool:
        return bool(np.all(self.tensor == np.diag(np.diag(self.tensor))))


def principal_axes(inertia: Any, name: str = "inertia") -> PrincipalAxes:
    """Principal moments and axes of ``inertia`` (3 moments or a 3×3 tensor, kg m²).

    Raises :class:`InputError` for non-finite values, a wrong shape, an asymmetric
    tensor, or one that is not positive definite (a moment ≤ 0).
    """
    array = as_si_array(inertia, "moment_of_inertia", name)
    if array.shape == (3,):
        if not np.all(array > 0.0):
            raise InputError(
                f"principal moments must be positive, got {array.tolist()}", key=name, value=inertia
            )
        return PrincipalAxes(array.copy(), Rotation.identity(), np.diag(array))
    if array.shape != (3, 3):
        raise InputError(
            f"{name} must be 3 principal moments or a 3x3 tensor, got shape {array.shape}"
        )
    asymmetry = np.max(np.abs(array - array.T))
    if asymmetry > _SYMMETRY_TOLERANCE * np.max(np.abs(array)):
        raise InputError(
            f"tensor is not symmetric (|T - Tᵀ| = {asymmetry:.3g}): {array.tolist()}",
            key=name,
            value=inertia,
        )
    tensor = 0.5 * (array + array.T)
    if np.all(tensor == np.diag(np.diag(tensor))):
        moments = np.diag(tensor).copy()
        if not np.all(moments > 0.0):
            raise InputError(
                f"tensor is not positive definite: {tensor.tolist()}", key=name, value=inertia
            )
        return PrincipalAxes(moments, Rotation.identity(), tensor)
    moments, vectors = np.linalg.eigh(tensor)  # columns: principal axes in body coordinates
    if not np.all(moments > 0.0):
        raise InputError(
            f"tensor is not positive definite (eigenvalues {moments.tolist()}): {tensor.tolist()}",
            key=name,
            value=inertia,
        )
    if np.linalg.det(vectors) < 0.0:
        vectors[:, 2] = -vectors[:, 2]  # a right-handed principal frame
    return PrincipalAxes(moments, Rotation.from_matrix(vectors.T), tensor)


def violates_triangle_inequality(moments: NDArray[np.float64]) -> bool:
    """True if the largest moment exceeds the sum of the two others.

    For any real body Ia + Ib ≥ Ic (the moments are sums of r² over pairs of axes),
    with equality only for a flat plate; beyond a relative 1e-9 it is impossible.
    """
    low, mid, high = np.sort(moments)
    return bool(low + mid < high * (1.0 - 1e-9))
