"""The exact torque-free flow map: states advanced by a time step (PROVISIONAL).

Provisional implementation, replaced by the solver branch's vectorized one at merge:
it builds one :class:`EulerSolver` per state, which is exact but costs about 1.7 ms
a state.  The contract (shapes, frames, units) is the one the real module keeps:

    m_new, q_new = advance(moments, angular_momentum, quaternion_wxyz, dt)

``moments`` (3,) or (N, 3): principal moments (kg m²) along the body axes, in any
order; ``angular_momentum`` (3,) or (N, 3): body frame, N m s; ``quaternion_wxyz``
(4,) or (N, 4): attitude body → inertial, scalar first; ``dt`` scalar or (N,): s.
Returns the torque-free state after ``dt``, with the shapes of the inputs.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from attitude.euler_solver import EulerSolver

__all__ = ["advance"]


def advance(
    moments: ArrayLike, angular_momentum: ArrayLike, quaternion_wxyz: ArrayLike, dt: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Body momentum and attitude quaternion (scalar first) after the free motion over ``dt``."""
    moments = np.asarray(moments, dtype=np.float64)
    m = np.asarray(angular_momentum, dtype=np.float64)
    q = np.asarray(quaternion_wxyz, dtype=np.float64)
    dt = np.asarray(dt, dtype=np.float64)
    single = moments.ndim == 1 and m.ndim == 1 and q.ndim == 1 and dt.ndim == 0
    n = max(
        np.atleast_2d(moments).shape[0],
        np.atleast_2d(m).shape[0],
        np.atleast_2d(q).shape[0],
        np.atleast_1d(dt).shape[0],
    )
    # Copies, not broadcast views: EulerSolver keeps (and scipy writes to) its inputs.
    moments_n = np.array(np.broadcast_to(np.atleast_2d(moments), (n, 3)))
    m_n = np.array(np.broadcast_to(np.atleast_2d(m), (n, 3)))
    q_n = np.array(np.broadcast_to(np.atleast_2d(q), (n, 4)))
    dt_n = np.array(np.broadcast_to(np.atleast_1d(dt), (n,)))
    m_out = np.empty((n, 3))
    q_out = np.empty((n, 4))
    for k in range(n):
        solver = EulerSolver(moments_n[k], m_n[k], Rotation.from_quat(q_n[k], scalar_first=True))
        m_out[k] = solver.angular_momentum(dt_n[k])
        q_out[k] = solver.attitude_quaternion(dt_n[k])
    if single:
        return m_out[0], q_out[0]
    return m_out, q_out
