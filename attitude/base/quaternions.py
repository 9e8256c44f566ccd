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

__all__ = ["left_matrix", "right_matrix", "rotation_rows"]


def left_matrix(a: ArrayLike) -> NDArray[np.float64]:
    """The 4×4 matrix L(a) such that a ⊗ b = L(a) b."""
    w, x, y, z = np.asarray(a, dtype=np.float64)
    return np.array([[w, -x, -y, -z], [x, w, -z, y], [y, z, w, -x], [z, -y, x, w]])


def right_matrix(b: ArrayLike) -> NDArray[np.float64]:
    """The 4×4 matrix R(b) such that a ⊗ b = R(b) a."""
    w, x, y, z = np.asarray(b, dtype=np.float64)
    return np.array([[w, -x, -y, -z], [x, w, z, -y], [y, -z, w, x], [z, y, -x, w]])


Rows = tuple[
    tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]],
    tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]],
    tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]],
]


def rotation_rows(q: NDArray[np.float64]) -> Rows:
    """The rotation matrix R(q) of unit quaternions ``q`` ((n, 4), w, x, y, z), row by
    row, each entry an array over the n instants: R v for a few v without an (n, 3, 3)
    product, element by element (an instant's entries do not depend on the others)."""
    w, x, y, z = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    xx, yy, zz = x * x, y * y, z * z
    xy, xz, yz, wx, wy, wz = x * y, x * z, y * z, w * x, w * y, w * z
    return (
        (1.0 - 2.0 * (yy + zz), 2.0 * (xy - wz), 2.0 * (xz + wy)),
        (2.0 * (xy + wz), 1.0 - 2.0 * (xx + zz), 2.0 * (yz - wx)),
        (2.0 * (xz - wy), 2.0 * (yz + wx), 1.0 - 2.0 * (xx + yy)),
    )
