"""The torque-free flow in mpmath with every input an mpf, for finite differences in
extended precision: Jadczyk's closed form of ``benchmarks/reference.py`` (a derivation
independent of the package's solver, evaluated with mpmath's elliptic functions),
taking the moments, the momentum and the initial attitude as mpf so that they can be
perturbed by 1e-20 of themselves."""

from __future__ import annotations

import sys
from pathlib import Path

import mpmath as mp
import numpy as np

sys.path.insert(0, str(Path(__file__).parents[1]))
from benchmarks import reference


def flow(inertia, momentum, q0, times, dps: int = 50):
    """(q(t) body → inertial scalar first, m(t) body) as mpf lists, for mpf inputs.

    ``inertia``: three distinct moments along body x, y, z; ``momentum``: body m0;
    ``q0``: the attitude at t = 0 (normalized here).  Times are floats (s)."""
    with mp.workdps(dps):
        inertia = [mp.mpf(x) for x in inertia]
        order = sorted(range(3), key=lambda k: inertia[k])
        inversions = sum(1 for i in range(3) for j in range(i + 1, 3) if order[i] > order[j])
        signs = [1, -1 if inversions % 2 else 1, 1]
        I_sorted = [inertia[k] for k in order]
        scale = I_sorted[1]
        I1, I2, I3 = (x / scale for x in I_sorted)
        m_sorted = [signs[k] * mp.mpf(momentum[order[k]]) for k in range(3)]
        G = mp.sqrt(sum(x * x for x in m_sorted))
        family, u0 = reference._family(I1, I2, I3, [x / G for x in m_sorted])
        S = [[mp.mpf(0)] * 3 for _ in range(3)]
        for k in range(3):
            S[k][order[k]] = mp.mpf(signs[k])
        qS = reference._matrix_to_quaternion(S)
        _, q_start = family.state(u0)
        q_init = [mp.mpf(x) for x in q0]
        norm = mp.sqrt(sum(x * x for x in q_init))
        q_init = [x / norm for x in q_init]
        left = reference._qmul(
            reference._qmul(q_init, reference._conj(qS)), reference._conj(q_start)
        )
        out = []
        for t in times:
            s = G * mp.mpf(float(t)) / scale
            L, qJ = family.state(u0 + family.B * s)
            q = reference._qmul(reference._qmul(left, qJ), qS)
            m_body = [mp.mpf(0)] * 3
            for k in range(3):
                m_body[order[k]] = signs[k] * L[k] * G
            out.append((q, m_body))
        return out


def jacobian(inertia, momentum, q0, times, dps: int = 50, relative_step: float = 1e-20):
    """(N, 6, 9) central differences of ``flow``: rows (δθ(t) body, m(t)), columns
    (δθ0 body, m0, J), the convention of attitude.solver.sensitivities."""
    with mp.workdps(dps):
        J = [mp.mpf(float(x)) for x in inertia]
        m0 = [mp.mpf(x) for x in momentum]
        q0 = [mp.mpf(float(x)) for x in q0]
        G = mp.sqrt(sum(x * x for x in m0))
        nominal = flow(J, m0, q0, times, dps)
        columns = []
        for k in range(9):
            step = relative_step * (1 if k < 3 else G if k < 6 else J[k - 6])
            outs = []
            for sign in (1, -1):
                Jk, mk, qk = list(J), list(m0), list(q0)
                if k < 3:
                    rot = [mp.mpf(1), mp.mpf(0), mp.mpf(0), mp.mpf(0)]
                    rot[1 + k] = sign * step / 2  # exp(δθ/2) to first order...
                    rot[0] = mp.sqrt(1 - rot[1 + k] ** 2)  # ...and exactly a unit quaternion
                    qk = reference._qmul(q0, rot)
                elif k < 6:
                    mk[k - 3] += sign * step
                else:
                    Jk[k - 6] += sign * step
                outs.append(flow(Jk, mk, qk, times, dps))
            column = []
            for (q_nom, _), (q_p, m_p), (q_m, m_m) in zip(nominal, outs[0], outs[1], strict=True):
                d_plus = reference._qmul(reference._conj(q_nom), q_p)
                d_minus = reference._qmul(reference._conj(q_nom), q_m)
                # rotation vector 2 atan(|v|/w) v/|v| = 2 v/w (1 + O(h²)): central differences
                θ_p = [2 * x / d_plus[0] for x in d_plus[1:]]
                θ_m = [2 * x / d_minus[0] for x in d_minus[1:]]
                column.append(
                    [(a - b) / (2 * step) for a, b in zip(θ_p + m_p, θ_m + m_m, strict=True)]
                )
            columns.append(column)
        return np.array(
            [
                [[float(columns[k][n][r]) for k in range(9)] for r in range(6)]
                for n in range(len(times))
            ]
        )
