"""Two small vector helpers: the angle between vectors, and a basis across a unit vector."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["angle_between", "basis_across"]


def angle_between(u: ArrayLike, v: ArrayLike) -> NDArray[np.float64]:
    """The angle between vectors (last axis), from atan2(|u×v|, u·v): accurate at every
    angle, where arccos of the dot product loses half its digits near 0 and π."""
    u = np.asarray(u, dtype=np.float64)
    v = np.asarray(v, dtype=np.float64)
    return np.arctan2(np.linalg.norm(np.cross(u, v), axis=-1), np.sum(u * v, axis=-1))


def basis_across(axis: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Unit vectors e1, e2 such that (e1, e2, axis) is right-handed and orthonormal.

    ``axis`` is a unit 3-vector; e1 is built from whichever of x, y is further from it.
    """
    axis = np.asarray(axis, dtype=np.float64)
    e1 = np.cross(axis, [1.0, 0.0, 0.0] if abs(axis[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(axis, e1)
