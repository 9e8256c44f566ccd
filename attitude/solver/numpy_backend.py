"""The numpy backend: the formula set of attitude.solver.closed_form on numpy arrays.

Runs the formulas with ``xp = numpy``, each case's formula once over arrays: its
constants as arrays of states (a batch) or as floats (one state), broadcast against
arrays of times.  Takes every case (both elliptic cases, the separatrix, steady,
rest, mc of any size), in any mix:

- one state at many times (``quaternions``, ``body_vectors``): in slices of ``CHUNK``
  samples, whose temporaries stay in the processor's cache;
- many states, one step each (``advance``): grouped by case (``ManyStates``: the
  batch's case test in double-double, with the exact integers where its bound leaves
  a doubt), in slices of ``FLOW_CHUNK`` states;
- many states at many times each (``Motions``, for attitude.solver.batch), each case's
  formula over its states and slices of their times.

Leaves nothing.  Its cost is a few hundred numpy calls per evaluation, ~0.3–2 µs each
whatever their size, plus a few tens of nanoseconds a sample: the backend for arrays
(attitude.solver.backends).  Results beyond the float range raise
``closed_form.NotRepresentable``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

from attitude.elliptic.functions import NEAR_ONE_MC
from attitude.solver.closed_form import (
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
from attitude.solver.invariants import Invariants, MomentConstants, invariants

__all__ = [
    "CHUNK",
    "FLOW_CHUNK",
    "ManyStates",
    "Motions",
    "SortedMoments",
    "advance",
    "body_vectors",
    "quaternions",
    "write_quaternions",
]

# One state's evaluations over many times run in slices of this many samples (see
# ``evaluate``): a slice's temporaries (at most ~130 B a sample) stay in the
# processor's cache, and bound what a call holds besides its output to ~1 MB.
CHUNK = 8192
# A flow over many states runs in slices of this many states, for the same reason.
FLOW_CHUNK = 4096


# ----------------------------------------------------------------- one state, many times


def evaluate(
    chunk: Callable[[NDArray, NDArray], None],
    τ_of: Callable[[int, int], NDArray],
    size: int,
    width: int,
) -> NDArray[np.float64]:
    """``chunk(τ, out)`` over ``size`` samples in slices of ``CHUNK``, into one (size,
    width) array; ``τ_of(start, stop)`` gives the slice's times τ = t − t0.

    A slice's temporaries stay in the processor's cache (over a million samples this
    is several times faster than whole-array passes), and each writes its own rows of
    the output: besides the result, memory holds only a slice's temporaries.  A sample
    whose angles leave the float range (its row not finite) raises NotRepresentable
    with its index.
    """
    out = np.empty((size, width))
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        for start in range(0, size, CHUNK):
            block = out[start : start + CHUNK]
            chunk(τ_of(start, start + CHUNK), block)
            if not np.isfinite(block).all():
                bad = start + int(np.flatnonzero(~np.isfinite(block).all(axis=1))[0])
                raise NotRepresentable(bad)
    return out


def write_body(
    motion: Motion, components: tuple, out: NDArray[np.float64], divisors: Any = None
) -> None:
    """``out[:, k]``: the body components of a vector given by its ``components`` in
    the formula's frame (each divided by ``divisors``, if given), that is v_frame @ S
    written column by column: a signed permutation for principal body axes (exact),
    three fused sums for a tensor.  No BLAS call: numpy's (n, 3) @ (3, 3) starts
    OpenBLAS threads above some n, and its cost per row jumps by a large factor."""
    if divisors is not None:
        components = tuple(c / d for c, d in zip(components, divisors, strict=True))
    for k, column in enumerate(motion.S_columns):
        if len(column) == 1:  # v_body[k] = ±v_frame[i]
            i, S_ik = column[0]
            np.multiply(components[i], S_ik, out=out[:, k])
        else:
            out[:, k] = components[0] * column[0][1] + components[1] * column[1][1]
            out[:, k] += components[2] * column[2][1]


def body_vectors(motion: Motion, times: NDArray[np.float64], velocity: bool) -> NDArray:
    """The body momentum (or angular velocity) at the times ``times`` (1-D), (n, 3)."""
    divisors = motion.I_frame if velocity else None

    def chunk(τ: NDArray, out: NDArray) -> None:
        write_body(motion, motion.formula.momentum(τ, np), out, divisors)

    return evaluate(chunk, lambda a, b: times[a:b] - motion.t0, times.size, 3)


def write_quaternions(
    motion: Motion, a: Any, b: Any, c: Any, half_ψ: Any, out: NDArray, columns: tuple
) -> None:
    """Unit attitude quaternions from m = (a, b, c) in the formula's frame and half the
    angle ψ(τ) − ψ(t0): q = M (Y ⊗ P), component i of (w, x, y, z) into
    ``out[:, columns[i]]``.

    The 4×4 product is written as four fused sums (no BLAS: see ``write_body``), each
    intermediate dropped as soon as it is used, and summed into ``out`` itself: a
    slice holds as few arrays as the formulas allow (the in-place forms do the same
    operations in the same order: the same bits).
    """
    p = p_quaternion(a, b, c, motion.G, np)
    del a, b, c
    yp = y_times_p(half_ψ, *p, np)
    del p, half_ψ
    M = motion.M
    term = np.empty_like(yp[0])
    for i in range(4):
        q_i = out[:, columns[i]]
        np.multiply(yp[0], M[i, 0], out=q_i)
        for k in (1, 2, 3):
            q_i += np.multiply(yp[k], M[i, k], out=term)
    del yp
    q = [out[:, columns[i]] for i in range(4)]
    norm_q = np.multiply(q[0], q[0])
    for i in (1, 2, 3):
        norm_q += np.multiply(q[i], q[i], out=term)
    np.sqrt(norm_q, out=norm_q)
    for q_i in q:
        q_i /= norm_q


def quaternion_chunk(motion: Motion, τ: NDArray, out: NDArray, columns: tuple) -> None:
    """Unit attitude quaternions at τ = t − t0, body → inertial, from the formula:
    one R_J a sample for ψ (the table backend replaces it)."""
    a, b, c, ψ = motion.formula.momentum_and_angle(τ, np)
    ψ -= motion.ψ_t0
    ψ *= 0.5
    write_quaternions(motion, a, b, c, ψ, out, columns)


def quaternions(motion: Motion, times: NDArray[np.float64], columns: tuple) -> NDArray:
    """The attitude quaternions at the times ``times`` (1-D), (n, 4), component i of
    (w, x, y, z) in column ``columns[i]``."""
    if isinstance(motion.formula, Rest):
        q = np.empty((times.size, 4))
        q[:, list(columns)] = motion.q0
        return q

    def chunk(τ: NDArray, out: NDArray) -> None:
        quaternion_chunk(motion, τ, out, columns)

    return evaluate(chunk, lambda a, b: times[a:b] - motion.t0, times.size, 4)


# ----------------------------------------------------------------- many states, one step each


def advance(inertia: NDArray, m: NDArray, q: NDArray, τ: NDArray) -> tuple[NDArray, NDArray]:
    """A batch of states after their steps, in slices of ``FLOW_CHUNK`` states whose
    temporaries stay in cache.  A state whose result is not finite raises
    NotRepresentable with its index."""
    n = inertia.shape[0]
    m_new, q_new = np.empty((n, 3)), np.empty((n, 4))
    for start in range(0, n, FLOW_CHUNK):
        part = slice(start, start + FLOW_CHUNK)
        try:
            m_new[part], q_new[part] = _advance(inertia[part], m[part], q[part], τ[part])
        except NotRepresentable as error:
            raise NotRepresentable(start + error.index) from None
    return m_new, q_new


def _advance(inertia: NDArray, m: NDArray, q: NDArray, τ: NDArray) -> tuple[NDArray, NDArray]:
    """Each case's formula over all of its states at once (``closed_form.step``)."""
    states = ManyStates(inertia, m)
    n = inertia.shape[0]
    m_frame = np.zeros((n, 3))
    step_q = np.zeros((n, 4))
    step_q[:, 0] = 1.0  # rest: the attitude stays
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        for k, formula in states.groups:
            if isinstance(formula, Rest):
                continue
            picked = slice(None) if k.size == n else k  # one case for every state: no gather
            (a, b, c), s = step(formula, states.G[picked], τ[picked], np)
            m_frame[picked] = np.stack([a, b, c], axis=-1)
            step_q[picked] = np.stack(s, axis=-1)
    # Back to the body, x_body[index[k]] = sign[k] x_frame[k], by flat indices.
    flat = states.index + 3 * np.arange(n)[:, None]
    m_new = np.empty((n, 3))
    m_new.put(flat, states.sign * m_frame)
    v = np.empty((n, 3))
    v.put(flat, states.sign * step_q[:, 1:])
    q_new = np.stack(hamilton(tuple(q.T), (step_q[:, 0], *v.T)), axis=-1)
    if not (np.isfinite(q_new).all() and np.isfinite(m_new).all()):
        finite = np.isfinite(q_new).all(axis=1) & np.isfinite(m_new).all(axis=1)
        raise NotRepresentable(int(np.flatnonzero(~finite)[0]))
    return m_new, q_new / np.linalg.norm(q_new, axis=1, keepdims=True)


# ----------------------------------------------------------------- many states, many times


class Motions:
    """Many states' motions, each evaluated at many times: ``closed_form.Motion`` for a
    batch, with every case in any mix (attitude.solver.batch).

    ``moments`` (N, 3): principal moments along the principal axes (any order);
    ``momentum`` (N, 3): the momentum in those axes; ``q0`` (N, 4): the unit attitudes
    at ``t0`` (N,), body → inertial, scalar first; ``body_to_principal``: None (the
    body axes are principal) or the rotations V (N, 3, 3) and their quaternions (N, 4).
    Each case's formula runs once over its states (``ManyStates``), with the constants
    of each state in arrays (N,) against times (T, N): the formulas broadcast over
    them as over a flow's two ends.  Per state, as ``closed_form.Motion``:
    S = S_perm ∘ V (``S``, (N, 3, 3)), R = Q0 ∘ S⁻¹ ∘ P(m(t0))⁻¹ and M = L(R) R(S)
    (``M``, (N, 4, 4)), ψ(t0) (``ψ_t0``).
    """

    def __init__(
        self,
        moments: NDArray[np.float64],
        momentum: NDArray[np.float64],
        q0: NDArray[np.float64],
        t0: NDArray[np.float64],
        body_to_principal: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
    ) -> None:
        n = moments.shape[0]
        self.t0 = t0
        self.q0 = q0
        with np.errstate(divide="ignore", invalid="ignore", over="ignore", under="ignore"):
            self.states = ManyStates(moments, momentum)
        index, sign = self.states.index, self.states.sign
        # The frame's moments and S_perm, each state's signed permutation.
        self.I_frame = np.take_along_axis(moments, index, axis=1)
        S_perm = np.zeros((n, 3, 3))
        np.put_along_axis(S_perm, index[:, :, None], sign[:, :, None], axis=2)
        S_q = _permutation_quaternions(index, sign)
        if body_to_principal is None:
            self.S = S_perm
        else:
            V, V_q = body_to_principal
            self.S = np.einsum("nij,njk->nik", S_perm, V)
            S_q = np.stack(hamilton(tuple(S_q.T), tuple(V_q.T)), axis=-1)  # S_perm ∘ V
        # m and ψ at t0 from each state's formula (both ends from the same formula).
        P0 = np.zeros((n, 4))
        P0[:, 0] = 1.0  # rest: P is the identity
        self.ψ_t0 = np.zeros(n)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore", under="ignore"):
            for k, formula in self.states.groups:
                if isinstance(formula, Rest):
                    continue
                a, b, c, ψ = formula.momentum_and_angle(np.zeros(k.size), np)
                P0[k, :3] = np.stack(p_quaternion(a, b, c, self.states.G[k], np), axis=-1)
                self.ψ_t0[k] = ψ
        s = tuple(S_q.T)
        R = hamilton(hamilton(tuple(q0.T), (s[0], -s[1], -s[2], -s[3])), tuple((P0 * _CONJUGATE).T))
        # M's column j: R ⊗ (e_j ⊗ S), as closed_form's one-state M.
        sw, sx, sy, sz = s
        columns = (
            hamilton(R, s),
            hamilton(R, (-sx, sw, -sz, sy)),
            hamilton(R, (-sy, sz, sw, -sx)),
            hamilton(R, (-sz, -sy, sx, sw)),
        )
        self.M = np.stack([np.stack(column, axis=-1) for column in columns], axis=-1)

    def quaternions(self, τ: NDArray[np.float64], columns: tuple) -> NDArray[np.float64]:
        """The unit attitude quaternions at τ = t − t0 (N, T), (N, T, 4), component i of
        (w, x, y, z) in column ``columns[i]``."""
        out = np.empty((4, τ.shape[1], τ.shape[0]))  # (component, time, state): see _slices
        for k, formula, τ_slice, times in self._slices(τ):
            if isinstance(formula, Rest):  # the attitude stays
                for i in range(4):
                    out[columns[i]][times, k] = self.q0[k, i]
                continue
            a, b, c, ψ = formula.momentum_and_angle(τ_slice, np)
            ψ -= self.ψ_t0[k]
            ψ *= 0.5
            yp = y_times_p(ψ, *p_quaternion(a, b, c, self.states.G[k], np), np)
            M = self.M[k]
            q = [
                yp[0] * M[:, i, 0] + yp[1] * M[:, i, 1] + yp[2] * M[:, i, 2] + yp[3] * M[:, i, 3]
                for i in range(4)
            ]
            norm_q = np.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
            for i in range(4):
                out[columns[i]][times, k] = q[i] / norm_q
        return self._finished(out)

    def body_vectors(self, τ: NDArray[np.float64], velocity: bool) -> NDArray[np.float64]:
        """The body momentum (or angular velocity) at τ (N, T), (N, T, 3)."""
        out = np.empty((3, τ.shape[1], τ.shape[0]))
        for k, formula, τ_slice, times in self._slices(τ):
            components = formula.momentum(τ_slice, np)
            if velocity:
                components = tuple(c / self.I_frame[k, i] for i, c in enumerate(components))
            S = self.S[k]
            for j in range(3):  # v_body = v_frame @ S
                body = components[0] * S[:, 0, j] + components[1] * S[:, 1, j]
                body += components[2] * S[:, 2, j]
                out[j][times, k] = body
        return self._finished(out)

    def _slices(self, τ: NDArray[np.float64]):
        """(states, formula, τ (T', n) of those states, the times' slice) over each
        case's states and slices of times of about ``CHUNK`` samples in all.

        Time runs along the first axis and the states along the second, so that each
        state's constants (n,) broadcast over the times as they do over a flow's two
        ends; the results are written in that layout, (component, time, state), and
        turned to (state, time, component) once at the end.  A case that every state
        shares takes slices, not gathers.
        """
        τ_T = np.ascontiguousarray(τ.T)
        n, T = τ.shape
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            for k, formula in self.states.groups:
                states: Any = slice(None) if k.size == n else k
                step_T = max(1, CHUNK // k.size)
                for start in range(0, T, step_T):
                    times = slice(start, start + step_T)
                    yield states, formula, τ_T[times, states], times

    @staticmethod
    def _finished(out: NDArray[np.float64]) -> NDArray[np.float64]:
        """(component, time, state) as a contiguous (state, time, component) array; a
        sample beyond the float range raises NotRepresentable with its flat index
        state × T + time."""
        result = np.ascontiguousarray(out.transpose(2, 1, 0))
        finite = np.isfinite(result).all(axis=-1)
        if not finite.all():
            raise NotRepresentable(int(np.flatnonzero(~finite.ravel())[0]))
        return result


def _permutation_quaternions(index: NDArray, sign: NDArray) -> NDArray[np.float64]:
    """The quaternions (N, 4) of each state's signed permutation (one of 24)."""
    code = (index @ [9, 3, 1]) * 8 + (sign > 0.0) @ [4, 2, 1]
    _, first, inverse = np.unique(code, return_index=True, return_inverse=True)
    table = np.array(
        [
            permutation_quaternion(
                (int(index[f, 0]), int(index[f, 1]), int(index[f, 2])),
                (float(sign[f, 0]), float(sign[f, 1]), float(sign[f, 2])),
            )
            for f in first
        ]
    )
    return table[inverse.ravel()]


_CONJUGATE = np.array([1.0, -1.0, -1.0, -1.0])


# ----------------------------------------------------------------- the case of each state


class ManyStates:
    """The case formulas of a batch of states, grouped by case, on numpy arrays.

    ``moments`` (N, 3) and ``momentum`` (N, 3) as in ``OneState``.  ``groups`` lists
    (indices, formula) with one formula per case present (the elliptic cases split by
    the regime of their kernels, mc above or below ``NEAR_ONE_MC``); ``index`` and
    ``sign`` (N, 3) are the signed permutations to each state's P-frame.

    In the steps of the module docstring: sorted (``SortedMoments``, step 1), each
    state's case (``_cases``), the preferred flips (``_preferred_flips_per_case``,
    step 2), the formulas (``_group_formulas``: an elliptic rate that underflows makes
    the state steady) and the relabelling into the P-frame (``_relabel``, step 3).
    """

    def __init__(self, moments: np.ndarray, momentum: np.ndarray) -> None:
        sorted_moments = SortedMoments(moments)
        I1, I2, I3 = sorted_moments.I
        order, sorted_signs = sorted_moments.order, sorted_moments.sorted_signs
        m_sorted = momentum.take(sorted_moments.flat_order)  # its rows permuted alike
        m1, m2, m3 = m_sorted[:, 0], sorted_signs[:, 1] * m_sorted[:, 1], m_sorted[:, 2]
        m = np.stack([m1, m2, m3], axis=-1)
        G = norm(m1, m2, m3, np)
        self.G = G
        case, inv = _cases(I1, I2, I3, m1, m2, m3, G, sorted_moments.constants)
        flips = _preferred_flips_per_case(case, m1, m3)
        m = flips * m
        self.groups = _group_formulas((I1, I2, I3), m, G, inv, case, flips)
        self.index, self.sign = _relabel(case, order, flips, sorted_signs)


def _cases(I1: Any, I2: Any, I3: Any, m1: Any, m2: Any, m3: Any, G: Any, constants: Any):
    """Each state's case code (``_CODE``: rest for G = 0, steady for the sphere I1 = I3,
    else i, ii or iii by the sign of Δ2) and its invariants δ1, δ3, mc, log mc (zeros and
    NaNs where the case has none; ``sign`` left out).  ``constants``: a callable giving
    the moments' ``MomentConstants`` (``SortedMoments.constants``)."""
    N = G.shape[0]
    case = np.full(N, _CODE["rest"], dtype=np.int8)
    sphere = (G > 0.0) & (I1 == I3)
    general = (G > 0.0) & ~sphere
    case[sphere] = _CODE["steady"]
    if general.all():  # the usual batch: no gather
        inv = invariants(I1, I2, I3, m1, m2, m3, np, constants())
        case = np.where(
            inv.sign < 0.0, _CODE["i"], np.where(inv.sign > 0.0, _CODE["ii"], _CODE["iii"])
        ).astype(np.int8)
        return case, Invariants(None, inv.δ1, inv.δ3, inv.mc, inv.log_mc)
    g = np.flatnonzero(general)
    mc = np.full(N, np.nan)
    log_mc = np.full(N, np.nan)
    δ1 = np.zeros(N)
    δ3 = np.zeros(N)
    if g.size:
        inv = invariants(I1[g], I2[g], I3[g], m1[g], m2[g], m3[g], np)
        case[g] = np.where(
            inv.sign < 0.0, _CODE["i"], np.where(inv.sign > 0.0, _CODE["ii"], _CODE["iii"])
        )
        mc[g], log_mc[g], δ1[g], δ3[g] = inv.mc, inv.log_mc, inv.δ1, inv.δ3
    return case, Invariants(None, δ1, δ3, mc, log_mc)


def _preferred_flips_per_case(case: np.ndarray, m1: np.ndarray, m3: np.ndarray) -> np.ndarray:
    """(N, 3) axis signs of step 2: the component carrying dn (m1 in case i, m3 in case
    ii), both sech components on the separatrix, and m3 of a steady state made ≥ 0."""
    flip1 = (m1 < 0.0) & ((case == _CODE["i"]) | (case == _CODE["iii"]))
    flip3 = (m3 < 0.0) & ((case == _CODE["ii"]) | (case == _CODE["iii"]))
    flip3 |= (m3 < 0.0) & (case == _CODE["steady"])
    return np.stack(preferred_flips(flip1, flip3, np), axis=-1)


def _group_formulas(
    moments: tuple[np.ndarray, np.ndarray, np.ndarray],
    m: np.ndarray,
    G: np.ndarray,
    inv: Invariants,
    case: np.ndarray,
    flips: np.ndarray,
) -> list[tuple[np.ndarray, CaseFormula]]:
    """(indices, formula) per case present, from the preferred components ``m`` (N, 3).

    An elliptic state whose rate λ underflows is steady (``_elliptic_groups``): its
    ``case``, ``flips`` and ``m`` are updated in place.  A separatrix state that P maps
    onto e1 gets the case code iii-e1 (its relabelling).
    """

    def constants(k: np.ndarray) -> tuple[Any, Any, Any, Any, Any, Any, Any, Invariants]:
        return _constants(k, moments, m, G, inv)

    with np.errstate(divide="ignore", invalid="ignore", over="ignore", under="ignore"):
        groups = _elliptic_groups(constants, inv.mc, case, flips, m)
        k = np.flatnonzero(case == _CODE["iii"])
        if k.size:
            formula = Separatrix(*constants(k), np)
            case[k[formula.onto_e1]] = _CODE["iii-e1"]
            groups.append((k, formula))
        k = np.flatnonzero(case == _CODE["steady"])
        if k.size:
            groups.append((k, Steady(*constants(k)[:7], np)))
        k = np.flatnonzero(case == _CODE["rest"])
        if k.size:
            groups.append((k, Rest()))
    return groups


def _constants(
    k: np.ndarray, moments: tuple, m: np.ndarray, G: np.ndarray, inv: Invariants
) -> tuple[Any, Any, Any, Any, Any, Any, Any, Invariants]:
    """I1, I2, I3, m1, m2, m3, G and the invariants of the states ``k``, as the formulas
    take them (every state: the arrays themselves, no gather)."""
    I1, I2, I3 = moments
    if k.size == G.shape[0]:
        return (I1, I2, I3, m[:, 0], m[:, 1], m[:, 2], G, inv)
    inv_k = Invariants(None, inv.δ1[k], inv.δ3[k], inv.mc[k], inv.log_mc[k])
    return (I1[k], I2[k], I3[k], m[k, 0], m[k, 1], m[k, 2], G[k], inv_k)


def _elliptic_groups(
    constants: Callable[[np.ndarray], tuple[Any, Any, Any, Any, Any, Any, Any, Invariants]],
    mc: np.ndarray,
    case: np.ndarray,
    flips: np.ndarray,
    m: np.ndarray,
) -> list[tuple[np.ndarray, CaseFormula]]:
    """The elliptic formulas, one per regime of the kernels (mc above or below
    ``NEAR_ONE_MC``).  A state whose rate λ underflows cannot move (``Steady``): it is
    made steady, its ``case``, ``flips`` and ``m`` updated in place with Steady's flip
    of m3, and the formula of the others made again."""
    groups: list[tuple[np.ndarray, CaseFormula]] = []
    elliptic = (case == _CODE["i"]) | (case == _CODE["ii"])
    for near_one in (False, True):
        k = np.flatnonzero(elliptic & ((mc < NEAR_ONE_MC) == near_one))
        if not k.size:
            continue
        formula = Elliptic(*constants(k), case[k] == _CODE["ii"], near_one, np)
        still = formula.λ != 0.0
        if not np.all(still):
            lost = k[~still]
            case[lost] = _CODE["steady"]
            sign3 = np.where(m[lost, 2] < 0.0, -1.0, 1.0)  # Steady's flip of m3
            more = np.stack([np.ones_like(sign3), sign3, sign3], axis=-1)
            flips[lost] *= more
            m[lost] *= more
            k = k[still]
            if k.size:
                formula = Elliptic(*constants(k), case[k] == _CODE["ii"], near_one, np)
        if k.size:
            groups.append((k, formula))
    return groups


def _relabel(
    case: np.ndarray, order: np.ndarray, flips: np.ndarray, sorted_signs: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Step 3: the signed permutations (N, 3) to each state's P-frame,
    P[k] = r_sign[k] f[r_index[k]] s[r_index[k]] principal[order[r_index[k]]]."""
    # Flat indices into the rows (N, 3): one gather each, cheaper than take_along_axis.
    flat = _RELABEL_INDEX[case] + 3 * np.arange(case.shape[0])[:, None]
    index = order.take(flat)
    sign = _RELABEL_SIGN[case] * flips.take(flat) * sorted_signs.take(flat)
    return index, sign


class SortedMoments:
    """The moments of a batch sorted, step 1 of the module docstring, with what the case
    test needs of them alone (``constants``, made only if a state needs the test).

    ``I``: the sorted moments as columns (I1, I2, I3); ``order`` (N, 3): the stable
    permutation that sorts each row; ``sorted_signs`` (N, 3): the middle axis reversed
    for an odd permutation.  A sorting network of three compare-exchanges over columns
    (bubble sort, stable), several times cheaper than ``argsort`` along rows of three.
    """

    def __init__(self, moments: np.ndarray) -> None:
        Is = [moments[:, 0], moments[:, 1], moments[:, 2]]
        N = moments.shape[0]
        index = [np.zeros(N, np.intp), np.ones(N, np.intp), np.full(N, 2, np.intp)]
        odd = np.zeros(N, dtype=bool)
        for a, b in ((0, 1), (1, 2), (0, 1)):
            swap = Is[a] > Is[b]
            for column in (Is, index):
                column[a], column[b] = (
                    np.where(swap, column[b], column[a]),
                    np.where(swap, column[a], column[b]),
                )
            odd ^= swap
        self.I = tuple(Is)
        self.order = np.stack(index, axis=-1)
        self.flat_order = self.order + 3 * np.arange(N)[:, None]  # into a flat (N, 3) array
        self.sorted_signs = np.ones((N, 3))
        self.sorted_signs[:, 1] = np.where(odd, -1.0, 1.0)
        self._constants: MomentConstants | None = None

    def constants(self) -> MomentConstants:
        """The double-double constants of the sorted moments (made on first use)."""
        if self._constants is None:
            self._constants = MomentConstants(*self.I)
        return self._constants


# The relabelling of each case as arrays indexed by a small integer code, for batches.
_CODE = {name: code for code, name in enumerate(RELABEL)}
_RELABEL_INDEX = np.array([RELABEL[name][0] for name in RELABEL])
_RELABEL_SIGN = np.array([RELABEL[name][1] for name in RELABEL], dtype=float)
