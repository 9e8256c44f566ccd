"""The float backend: the formula set of attitude.solver.closed_form on Python floats.

Runs the formulas with ``xp = attitude.base.float_math.FLOAT`` (``math`` on floats, with
numpy's IEEE results where ``math`` would raise).  Why a backend of its own: a numpy
call costs 0.3 to 2 µs whatever the size of its arrays, 10 to 100 times the arithmetic
of one state, while an operation on a float costs ~30 ns.

Takes every case (both elliptic cases, the separatrix, steady, rest, mc of any size),
for one state at a time:

- ``OneState``: the case test of one state (the exact integers of
  attitude.solver.invariants) and its formula and frame;
- ``motion``: one state's ``Motion``, the constants ``EulerSolver`` keeps;
- ``quaternion``, ``body_vector``: the attitude and a body vector at one time;
- ``advance_one``, ``advance``: the flow of one state, and of a few states one at a
  time: the states the numba backend leaves, when they are fewer than
  attitude.solver.backends.SMALL_BATCH.

Leaves nothing; it is chosen for one state at one time (attitude.solver.backends).
Results beyond the float range raise ``closed_form.NotRepresentable``.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from attitude.base.float_math import FLOAT
from attitude.elliptic.functions import NEAR_ONE_MC
from attitude.solver.closed_form import (
    FLIP_23,
    FLIP_NONE,
    RELABEL,
    CaseFormula,
    Elliptic,
    Motion,
    NotRepresentable,
    Rest,
    Separatrix,
    Steady,
    hamilton,
    norm,
    p_quaternion,
    permutation_quaternion,
    preferred_flips,
    step,
    y_times_p,
)
from attitude.solver.invariants import invariants

__all__ = ["OneState", "advance", "advance_one", "body_vector", "motion", "quaternion"]


class OneState:
    """The case formula of a single state and its frame, on Python floats.

    ``moments`` are principal moments along the principal axes (any order),
    ``momentum`` the momentum in those axes.  ``index``/``sign``: the signed permutation
    to the P-frame, P[k] = sign[k] · principal[index[k]] (a proper rotation).
    """

    formula: CaseFormula

    def __init__(self, moments: tuple[float, float, float], momentum: tuple[float, ...]) -> None:
        order = sorted(range(3), key=moments.__getitem__)  # stable, as numpy's
        o0, o1, o2 = order
        odd = (o1 - o0) * (o2 - o0) * (o2 - o1) < 0
        sorted_signs = (1.0, -1.0 if odd else 1.0, 1.0)
        I1, I2, I3 = moments[o0], moments[o1], moments[o2]
        m1, m2, m3 = momentum[o0], sorted_signs[1] * momentum[o1], momentum[o2]
        G = norm(m1, m2, m3, FLOAT)
        self.G, self.I = G, (I1, I2, I3)
        if G == 0.0:
            case, flips = "rest", FLIP_NONE
        elif I1 == I3:
            case, flips = "steady", (FLIP_23 if m3 < 0.0 else FLIP_NONE)
        else:
            inv = invariants(I1, I2, I3, m1, m2, m3, FLOAT)
            if inv.sign == 0.0:
                case = "iii"
                flips = preferred_flips(m1 < 0.0, m3 < 0.0, FLOAT)
            else:
                case = "ii" if inv.sign > 0.0 else "i"
                flips = preferred_flips(case == "i" and m1 < 0.0, case == "ii" and m3 < 0.0, FLOAT)
        m1, m2, m3 = flips[0] * m1, flips[1] * m2, flips[2] * m3
        formula: CaseFormula
        if case in ("i", "ii"):
            elliptic = Elliptic(
                I1, I2, I3, m1, m2, m3, G, inv, case == "ii", inv.mc < NEAR_ONE_MC, FLOAT
            )
            formula = elliptic
            if elliptic.λ == 0.0:  # underflows: see Steady
                case, more = "steady", (FLIP_23 if m3 < 0.0 else FLIP_NONE)
                flips = (flips[0] * more[0], flips[1] * more[1], flips[2] * more[2])
                m1, m2, m3 = more[0] * m1, more[1] * m2, more[2] * m3
        if case == "iii":
            formula = Separatrix(I1, I2, I3, m1, m2, m3, G, inv, FLOAT)
            if formula.onto_e1:
                case = "iii-e1"
        if case == "steady":
            formula = Steady(I1, I2, I3, m1, m2, m3, G, FLOAT)
        if case == "rest":
            formula = Rest()
        self.formula = formula
        self.preferred = (m1, m2, m3)
        # P[k] = r_sign[k] f[r_index[k]] s[r_index[k]] principal[order[r_index[k]]].
        (r0, r1, r2), (rs0, rs1, rs2) = RELABEL[case]
        self.index = (order[r0], order[r1], order[r2])
        self.sign = (
            rs0 * flips[r0] * sorted_signs[r0],
            rs1 * flips[r1] * sorted_signs[r1],
            rs2 * flips[r2] * sorted_signs[r2],
        )


# ----------------------------------------------------------------- one state's Motion


def _constant_matrix(
    r: tuple[float, float, float, float], s: tuple[float, float, float, float]
) -> tuple[tuple[float, float, float, float], ...]:
    """The rows of M = L(r) R(s), the 4×4 matrix of v ↦ r ⊗ v ⊗ s (docs/derivation.md
    §10): its column j is r ⊗ (e_j ⊗ s), e_j ⊗ s being s with its components permuted
    and signed."""
    sw, sx, sy, sz = s
    columns = (
        hamilton(r, s),
        hamilton(r, (-sx, sw, -sz, sy)),  # i ⊗ s
        hamilton(r, (-sy, sz, sw, -sx)),  # j ⊗ s
        hamilton(r, (-sz, -sy, sx, sw)),  # k ⊗ s
    )
    c0, c1, c2, c3 = columns
    return tuple((c0[i], c1[i], c2[i], c3[i]) for i in range(4))


def motion(
    moments: tuple[float, float, float],
    momentum: tuple[float, float, float],
    q0: tuple[float, float, float, float],
    t0: float,
    body_to_principal: Rotation | None = None,
) -> Motion:
    """One state's ``Motion``: ``moments`` along the principal axes (any order), the
    ``momentum`` in those axes, the attitude ``q0`` (body → inertial, unit, scalar
    first) at ``t0``, and the rotation from body to principal axes (None: they are the
    body axes).  On floats: a few tens of microseconds, so that building one solver per
    state costs little."""
    state = OneState(moments, momentum)
    formula = state.formula
    index, sign = state.index, state.sign
    i0, i1, i2 = index
    # S: the signed permutation of the principal axes onto the formula's frame, after
    # the body → principal rotation V of a tensor.  Row vectors go back to the body as
    # v_frame @ S (S_columns: the entries of each column of S, exact for a signed
    # permutation).
    S = permutation_quaternion(index, sign)
    V: NDArray[np.float64] | None = None
    if body_to_principal is None:
        position = {i0: 0, i1: 1, i2: 2}  # column k of S: its entry sign[i] at row i
        S_columns: tuple = tuple(((position[k], sign[position[k]]),) for k in range(3))
    else:
        V = body_to_principal.as_matrix()
        rows = V.tolist()  # row k of S is sign[k] times row index[k] of V
        S_rows = [[sign[k] * v for v in rows[index[k]]] for k in range(3)]
        S_columns = tuple(tuple((i, S_rows[i][j]) for i in range(3)) for j in range(3))
        x, y, z, w = body_to_principal.as_quat().tolist()
        S = hamilton(S, (w, x, y, z))  # S ∘ V
    # R = Q0 ∘ S⁻¹ ∘ P(t0)⁻¹, so that q(t0) = Q0; with S, the constant matrix M:
    # q(t) = R ⊗ (Y ⊗ P)(t) ⊗ S = M (Y ⊗ P)(t), scalar first.
    a, b, c, ψ_t0 = formula.momentum_and_angle(0.0, FLOAT)
    if isinstance(formula, Rest):
        p0, p1, p2 = 1.0, 0.0, 0.0
    else:
        p0, p1, p2 = p_quaternion(a, b, c, state.G, FLOAT)
    R = hamilton(hamilton(q0, (S[0], -S[1], -S[2], -S[3])), (p0, -p1, -p2, -0.0))
    return Motion(
        formula=formula,
        G=state.G,
        t0=t0,
        moments=state.I,
        preferred=state.preferred,
        index=index,
        sign=sign,
        body_to_principal=V,
        S_columns=S_columns,
        I_frame_floats=(float(moments[i0]), float(moments[i1]), float(moments[i2])),
        M_rows=_constant_matrix(R, S),
        ψ_t0=float(ψ_t0),
        q0=q0,
    )


# ----------------------------------------------------------------- one time


def quaternion(motion: Motion, τ: float) -> tuple[float, float, float, float]:
    """The unit attitude quaternion (w, x, y, z), body → inertial, at τ = t − t0: the
    formulas of numpy_backend's ``quaternion_chunk`` on floats."""
    f = motion.formula
    if isinstance(f, Rest):
        return motion.q0
    try:
        a, b, c, ψ = f.momentum_and_angle(τ, FLOAT)
        yp = y_times_p(0.5 * (ψ - motion.ψ_t0), *p_quaternion(a, b, c, motion.G, FLOAT), FLOAT)
    except (ValueError, OverflowError):  # math on an angle beyond the float range
        raise NotRepresentable from None
    y0, y1, y2, y3 = yp
    r0, r1, r2, r3 = motion.M_rows
    w = y0 * r0[0] + y1 * r0[1] + y2 * r0[2] + y3 * r0[3]
    x = y0 * r1[0] + y1 * r1[1] + y2 * r1[2] + y3 * r1[3]
    y = y0 * r2[0] + y1 * r2[1] + y2 * r2[2] + y3 * r2[3]
    z = y0 * r3[0] + y1 * r3[1] + y2 * r3[2] + y3 * r3[3]
    norm_q = math.sqrt(w * w + x * x + y * y + z * z)
    if not math.isfinite(norm_q):
        raise NotRepresentable
    return w / norm_q, x / norm_q, y / norm_q, z / norm_q


def body_vector(
    motion: Motion, τ: float, divisors: tuple[float, float, float] | None = None
) -> NDArray[np.float64]:
    """The body momentum (or, with ``divisors`` the moments of the frame, the angular
    velocity) at τ: numpy_backend's ``write_body`` on floats."""
    try:
        v = motion.formula.momentum(τ, FLOAT)
    except (ValueError, OverflowError):  # math on an angle beyond the float range
        raise NotRepresentable from None
    if divisors is not None:
        v = tuple(c / d for c, d in zip(v, divisors, strict=True))
    out = np.empty(3)
    for k, column in enumerate(motion.S_columns):
        if len(column) == 1:
            i, S_ik = column[0]
            out[k] = v[i] * S_ik
        else:
            out[k] = (v[0] * column[0][1] + v[1] * column[1][1]) + v[2] * column[2][1]
    if not np.isfinite(out).all():
        raise NotRepresentable
    return out


# ----------------------------------------------------------------- one state's flow


def advance(
    inertia: NDArray[np.float64], m: NDArray[np.float64], q: NDArray[np.float64], τ: NDArray
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A few states (arrays (n, 3), (n, 3), (n, 4), (n,)) after their steps, one at a
    time (``advance_one``); NotRepresentable names the first state beyond the float
    range."""
    n = inertia.shape[0]
    m_new, q_new = np.empty((n, 3)), np.empty((n, 4))
    for k in range(n):
        try:
            m_new[k], q_new[k] = advance_one(
                tuple(inertia[k].tolist()), tuple(m[k].tolist()), tuple(q[k].tolist()), float(τ[k])
            )
        except NotRepresentable:
            raise NotRepresentable(k) from None
    return m_new, q_new


def advance_one(
    inertia: tuple[float, float, float],
    m: tuple[float, float, float],
    q0: tuple[float, float, float, float],
    τ: float,
) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
    """One state after its step τ (``closed_form.step``), on floats throughout: tuples
    in, tuples out."""
    state = OneState(inertia, m)
    if isinstance(state.formula, Rest):
        return (0.0, 0.0, 0.0), q0
    try:
        m_frame, step_q = step(state.formula, state.G, τ, FLOAT)
    except (ValueError, OverflowError):  # math on an angle beyond the float range
        raise NotRepresentable from None
    # Back to the body: x_body[index[k]] = sign[k] x_frame[k].
    m_new = [0.0, 0.0, 0.0]
    v = [0.0, 0.0, 0.0]
    (i0, i1, i2), (s0, s1, s2) = state.index, state.sign
    m_new[i0], m_new[i1], m_new[i2] = s0 * m_frame[0], s1 * m_frame[1], s2 * m_frame[2]
    v[i0], v[i1], v[i2] = s0 * step_q[1], s1 * step_q[2], s2 * step_q[3]
    w, x, y, z = hamilton(q0, (step_q[0], v[0], v[1], v[2]))
    norm_q = math.sqrt(w * w + x * x + y * y + z * z)  # 1 to a few ulps; kept from drifting
    if not (math.isfinite(norm_q) and all(map(math.isfinite, m_new))):
        raise NotRepresentable
    return (m_new[0], m_new[1], m_new[2]), (w / norm_q, x / norm_q, y / norm_q, z / norm_q)
