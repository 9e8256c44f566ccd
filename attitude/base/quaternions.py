"""Hamilton quaternion algebra, scalar first, vectorized.

``scipy.spatial.transform.Rotation`` is the package's attitude type; these few
helpers exist because composing a million rotations through ``Rotation.__mul__`` costs
about 0.7 µs each, while a constant 4×4 matrix applied to a stack of quaternions costs
a few nanoseconds.  Convention: q = (w, x, y, z), the product is Hamilton's, and a
quaternion q rotates a vector v as q ⊗ (0, v) ⊗ q* (the active rotation that
``Rotation.from_quat(q, scalar_first=True).apply(v)`` performs).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["left_matrix", "right_matrix"]


def left_matrix(a: ArrayLike) -> NDArray[np.float64]:
    """The 4×4 matrix L(a) such that a ⊗ b = L(a) b."""
    w, x, y, z = np.asarray(a, dtype=np.float64)
    return np.array([[w, -x, -y, -z], [x, w, -z, y], [y, z, w, -x], [z, -y, x, w]])


def right_matrix(b: ArrayLike) -> NDArray[np.float64]:
    """The 4×4 matrix R(b) such that a ⊗ b = R(b) a."""
    w, x, y, z = np.asarray(b, dtype=np.float64)
    return np.array([[w, -x, -y, -z], [x, w, z, -y], [y, -z, w, x], [z, y, -x, w]])
