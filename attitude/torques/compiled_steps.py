"""The splitting loop compiled, for one spacecraft under gravity gradient alone.

:class:`attitude.torques.solver.TorquedSolver` advances its state a chunk of steps at a
time, each step a composition of exact kicks and exact free flows
(:mod:`attitude.torques.splitting`).  In Python a step of the default fourth-order
method (ABA(10,6,4): eight kicks, eight flows) costs about 35 µs, nearly all of it the
interpreter around 1 µs flows; :func:`gravity_gradient_steps` runs the same loop
compiled (numba, :mod:`attitude.base.jit`) when the only torque is the gravity
gradient, the commonest case (a validity horizon, a tumbler on its orbit), at a few
µs a step.

It does what ``_Engine.step`` does, operation for operation: the kick

    m ← m + w · (3μ/r³) ((I3 − I2) r2 r3, (I1 − I3) r3 r1, (I2 − I1) r1 r2),

r the unit position in principal axes (:func:`attitude.torques.models.rotate_into_principal`,
compiled from the same source) at the kick's clock, and the exact free flow
(:func:`attitude.solver.numba_backend.flow_one`) over the flows owed since the last
kick, merged across the steps.  The states are those of the Python loop to rounding.
A state the compiled flow does not take (the separatrix and its neighbourhood, rest:
``flow_one``'s ``ok`` false), or one spun up beyond what the solver accepts (or not
finite), stops the kernel before that step; the caller's Python loop goes on from
there (and refuses the latter).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from attitude.base.jit import inline, jit
from attitude.solver.numba_backend import flow_one
from attitude.torques.models import rotate_into_principal

__all__ = ["gravity_gradient_steps"]

inline([rotate_into_principal])


@jit
def gravity_gradient_steps(
    flows: NDArray[np.float64],
    kicks: NDArray[np.float64],
    moments: NDArray[np.float64],
    state: NDArray[np.float64],
    sizes: NDArray[np.float64],
    data: NDArray[np.float64],
    largest: float,
    out_m: NDArray[np.float64],
    out_q: NDArray[np.float64],
    out_pending: NDArray[np.float64],
) -> int:
    """Steps of ``sizes`` (K,) from ``state`` = (m1, m2, m3, qw, qx, qy, qz, pending)
    (principal axes; the flow still owed, s); the composition's ``flows`` a_j and
    ``kicks`` b_j; ``moments`` (I1, I2, I3); ``data`` (K, active kicks, 4): the gravity
    gradient's (ux, uy, uz, 3μ/r³) at each non-zero kick of each step; ``largest``: the
    largest |m1| + |m2| + |m3| a state may reach (N m s).  Writes each
    step's end state into ``out_m`` (K, 3), ``out_q`` (K, 4), ``out_pending`` (K,);
    returns the number of steps done (K, or the step where it stopped: module
    docstring)."""
    I1, I2, I3 = moments[0], moments[1], moments[2]
    m1, m2, m3 = state[0], state[1], state[2]
    qw, qx, qy, qz = state[3], state[4], state[5], state[6]
    pending = state[7]
    s = flows.size
    for k in range(sizes.size):
        h = sizes[k]
        column = 0
        for j in range(s + 1):
            if kicks[j] != 0.0:
                if pending != 0.0:
                    ok, n1, n2, n3, pw, px, py, pz = flow_one(
                        I1, I2, I3, m1, m2, m3, qw, qx, qy, qz, pending
                    )
                    if not ok:
                        return k
                    m1, m2, m3, qw, qx, qy, qz = n1, n2, n3, pw, px, py, pz
                    pending = 0.0
                r1, r2, r3 = rotate_into_principal(
                    (qw, qx, qy, qz), (data[k, column, 0], data[k, column, 1], data[k, column, 2])
                )
                factor = data[k, column, 3]
                w = kicks[j] * h
                m1 = m1 + w * (factor * (I3 - I2) * r2 * r3)
                m2 = m2 + w * (factor * (I1 - I3) * r3 * r1)
                m3 = m3 + w * (factor * (I2 - I1) * r1 * r2)
                column += 1
            if j < s:
                pending = pending + flows[j] * h
        norm = math.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
        if not (abs(m1) + abs(m2) + abs(m3) <= largest and norm > 0.0 and math.isfinite(norm)):
            return k
        qw, qx, qy, qz = qw / norm, qx / norm, qy / norm, qz / norm
        out_m[k, 0], out_m[k, 1], out_m[k, 2] = m1, m2, m3
        out_q[k, 0], out_q[k, 1], out_q[k, 2], out_q[k, 3] = qw, qx, qy, qz
        out_pending[k] = pending
    return sizes.size
