"""The exact torque-free flow map: many states, each advanced by its own step.

``advance(inertia, angular_momentum, quaternion_wxyz, dt)`` gives the exact state of
each of N free rigid bodies after its own time step, vectorized over the states: the
primitive that torque splitting (a kick, then the exact free flow: Celledoni, Fassò,
Säfström and Zanna, SIAM J. Sci. Comput. 30(4), 2008, doi:10.1137/070704393) and
Monte Carlo batches stand on.  ``EulerSolver`` is the other axis (one state, many
times), ``EulerSolverBatch`` both; all evaluate the same formula set,
attitude.solver.closed_form, through its backends (attitude.solver.backends).

Every state goes first through the numba backend (attitude.solver.numba_backend): the
elliptic cases (i) and (ii) with a certain double-double case test and mc ≥ 2^-128,
nearly every state of a real spacecraft, at about 1 µs a state, one state alone or a
batch.  The states it leaves (the separatrix and its 1e-13 neighbourhood, the sphere,
bodies whose rate underflows, rest, mc < 2^-128) take the backend ``select`` picks for
them: the float backend for a few, one at a time, the numpy backend for more (split by
their exact case, each case's formula once over all of its states).  The backends
agree to rounding (tests/test_compiled_flow_against_numpy_flow.py).

The attitude step is, with the frame S of the state's formula, P(m) the rotation taking
m onto G e3 and Y(ψ) the rotation by ψ about e3 (attitude.solver.closed_form):

    q(t0 + dt) = q(t0) ⊗ S⁻¹ ⊗ P(m(t0))⁻¹ ⊗ Y(ψ(dt) − ψ(0)) ⊗ P(m(dt)) ⊗ S,

continuous in dt and equal to q(t0) at dt = 0, so that the quaternion of a composition
of steps is that of the whole step (no sign flip between steps).  S is a signed
permutation, so S⁻¹ ⊗ x ⊗ S is x with its vector part permuted and signed.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.base.quantities import as_si_array
from attitude.solver import float_backend
from attitude.solver.backends import select
from attitude.solver.closed_form import NotRepresentable

__all__ = ["UnitBatch", "advance", "advance_floats", "advance_unit_batch"]


_KERNELS: list[Any] = []  # flow_one and flow_many, once imported


def _kernels() -> list[Any]:
    """attitude.solver.numba_backend's flow_one and flow_many, imported on first use:
    numba's import and the loading of the compiled code (~0.6 s) are paid only by a
    process that flows (a run without torques or orbit does not)."""
    if not _KERNELS:
        from attitude.solver import numba_backend

        _KERNELS[:] = [numba_backend.flow_one, numba_backend.flow_many]
    return _KERNELS


def advance(
    inertia: ArrayLike,
    angular_momentum: ArrayLike,
    quaternion_wxyz: ArrayLike,
    dt: ArrayLike,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The exact torque-free motion of each state after its step ``dt``.

    Parameters
    ----------
    inertia
        (3,) or (N, 3): principal moments of inertia, kg m², along the body axes (the
        body axes are principal axes; the moments in any order, as for ``EulerSolver``).
    angular_momentum
        (3,) or (N, 3): body-frame angular momentum, N m s.
    quaternion_wxyz
        (4,) or (N, 4): attitude, body → inertial, scalar FIRST; normalized here.  Or a
        ``scipy.spatial.transform.Rotation`` (one, or a stack of N), body → inertial.
    dt
        scalar or (N,): time steps, s, any sign.

    Returns
    -------
    m_new, q_new
        The body momentum (N m s) and the unit attitude quaternion (body → inertial,
        scalar first) after ``dt``: shapes (3,) and (4,) for a single state, (N, 3) and
        (N, 4) for a batch (the leading shapes of the inputs broadcast together).

    Every case is exact: both sides of the separatrix and on it, symmetric bodies, the
    sphere, rest, spin about any axis.  Astropy Quantities are accepted.  Bad values
    raise an InputError naming the argument, the state and the value, and so does a
    step whose angles would leave the float range.
    """
    moments = _as_floats(inertia, "moment_of_inertia", "inertia")
    m = _as_floats(angular_momentum, "angular_momentum", "angular_momentum")
    if isinstance(quaternion_wxyz, Rotation):  # an attitude, as the package returns them
        quaternion_wxyz = quaternion_wxyz.as_quat(scalar_first=True)
    q = _as_floats(quaternion_wxyz, None, "quaternion_wxyz")
    τ = _as_floats(dt, "time", "dt")
    if moments.shape == (3,) and m.shape == (3,) and q.shape == (4,) and τ.ndim == 0:
        m_new, q_new = _one_compiled(*_one_state(moments, m, q, τ))
        return np.array(m_new), np.array(q_new)
    moments, m, q, τ = _broadcast(moments, m, q, τ)
    q = _checked_batch(moments, m, q, τ)
    return _many_compiled(
        np.ascontiguousarray(moments),
        np.ascontiguousarray(m),
        q,
        np.ascontiguousarray(τ),
    )


def advance_floats(
    inertia: tuple[float, float, float],
    angular_momentum: tuple[float, float, float],
    quaternion_wxyz: tuple[float, float, float, float],
    dt: float,
) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
    """``advance`` of one state on Python floats, for callers that step one state many
    times (attitude.torques.solver): tuples in, tuples out, no numpy on the way.

    The same formulas and bits as ``advance`` on that state; the quaternion must be a
    unit one (it is not normalized here, only its result is), the moments positive and
    every value finite: they are not checked one by one as by ``advance``, but a
    non-finite state or result raises an InputError.
    """
    try:
        return _one_compiled(inertia, angular_momentum, quaternion_wxyz, dt)
    except (ValueError, OverflowError):  # a NaN or an infinity met by the exact integers
        raise InputError(
            f"the free flow needs a finite state, got angular_momentum {list(angular_momentum)}"
            f" and quaternion_wxyz {list(quaternion_wxyz)} with inertia {list(inertia)} "
            f"and dt {dt!r}"
        ) from None


def advance_unit_batch(
    inertia: NDArray[np.float64],
    angular_momentum: NDArray[np.float64],
    quaternion_wxyz: NDArray[np.float64],
    dt: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``advance`` of a batch the caller built itself, for callers that step one batch
    many times (attitude.torques.solver): float64 arrays (N, 3), (N, 3), (N, 4) and
    (N,), unit quaternions (not normalized again), positive moments.

    Only the momentum is checked (finite; the rest comes from a previous step), so that
    a step costs the flow itself; the results are those of ``advance`` on the same
    arrays to rounding (``advance`` normalizes the quaternions first).
    """
    return UnitBatch(inertia).advance(angular_momentum, quaternion_wxyz, dt)


class UnitBatch:
    """``advance_unit_batch`` for a batch whose moments stay from call to call (the
    spacecraft of attitude.torques.solver.propagate_batch, kicked between flows)."""

    def __init__(self, inertia: NDArray[np.float64]) -> None:
        self.inertia = np.ascontiguousarray(inertia, dtype=np.float64)  # (N, 3), positive

    def advance(
        self,
        angular_momentum: NDArray[np.float64],
        quaternion_wxyz: NDArray[np.float64],
        dt: NDArray[np.float64],
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The states after their steps: arrays (N, 3), (N, 4) and (N,) as in
        ``advance_unit_batch``, with this batch's moments."""
        if not np.isfinite(angular_momentum).all():
            k = int(np.flatnonzero(~np.isfinite(angular_momentum).all(axis=1))[0])
            raise InputError(
                f"the free flow needs a finite state, got angular_momentum[{k}] "
                f"{angular_momentum[k].tolist()}"
            )
        return _many_compiled(
            self.inertia,
            np.ascontiguousarray(angular_momentum, dtype=np.float64),
            np.ascontiguousarray(quaternion_wxyz, dtype=np.float64),
            np.ascontiguousarray(dt, dtype=np.float64),
        )


def _one_compiled(inertia: tuple, m: tuple, q0: tuple, τ: float, at: str = ""):
    """One state on floats: the numba backend, or the float backend for a state that
    it leaves (``at``: the state's index, for messages)."""
    ok, m1, m2, m3, qw, qx, qy, qz = _kernels()[0](*inertia, *m, *q0, τ)
    if ok:
        return (m1, m2, m3), (qw, qx, qy, qz)
    try:
        return float_backend.advance_one(inertia, m, q0, τ)
    except NotRepresentable:
        raise InputError(_too_far(τ, at)) from None


def _many_compiled(inertia: NDArray, m: NDArray, q: NDArray, τ: NDArray):
    """A checked batch (C-contiguous float64 arrays): the numba backend over every
    state, then the states it leaves (the separatrix and its neighbourhood, the sphere,
    underflowing rates, rest, mc < 2^-128) to the backend ``select`` picks for them."""
    n = inertia.shape[0]
    m_new, q_new = np.empty((n, 3)), np.empty((n, 4))
    ok = np.empty(n, dtype=np.bool_)
    _kernels()[1](inertia, m, q, τ, m_new, q_new, ok)
    if ok.all():
        return m_new, q_new
    left = np.flatnonzero(~ok)
    backend = select(left.size, None)
    assert backend is not None  # one time each
    try:
        m_new[left], q_new[left] = backend.advance(inertia[left], m[left], q[left], τ[left])
    except NotRepresentable as error:
        k = int(left[error.index])
        raise InputError(_too_far(float(τ[k]), f"[{k}]")) from None
    return m_new, q_new


def _as_floats(value: Any, kind: str | None, name: str) -> NDArray[np.float64]:
    """``value`` as a float64 array, in SI if it is a Quantity (checked later)."""
    if kind is not None and hasattr(value, "unit"):
        return as_si_array(value, kind, name, allow_nonfinite=True)
    try:
        return np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} must be numeric, got {value!r}") from exc


def _one_state(inertia: NDArray, m: NDArray, q: NDArray, τ: Any, k: int | None = None):
    """One state as Python floats, checked (``k``: its index in a batch, for messages)."""
    at = "" if k is None else f"[{k}]"
    I_list, m_list, q_list, τ_float = inertia.tolist(), m.tolist(), q.tolist(), float(τ)
    for name, values in (("inertia", I_list), ("angular_momentum", m_list)):
        if not all(map(math.isfinite, values)):
            raise InputError(f"{name}{at} must be finite, got {values}")
    if not min(I_list) > 0.0:
        raise InputError(f"inertia{at} must be positive, got {I_list}")
    w, x, y, z = q_list
    norm = math.sqrt(w * w + x * x + y * y + z * z)
    if not (math.isfinite(norm) and norm > 0.0):
        raise InputError(
            f"quaternion_wxyz{at} must be a finite, non-zero quaternion (w, x, y, z), got {q_list}"
        )
    if not math.isfinite(τ_float):
        raise InputError(f"dt{at} must be finite, got {τ_float}")
    if not math.isfinite(math.hypot(*m_list) / min(I_list)):
        raise InputError(
            f"angular_momentum{at} {m_list} with inertia {I_list}: the angular velocity "
            "|m|/I1 is beyond the float range"
        )
    return tuple(I_list), tuple(m_list), (w / norm, x / norm, y / norm, z / norm), τ_float, at


def _broadcast(inertia: NDArray, m: NDArray, q: NDArray, τ: NDArray):
    """Arrays (N, 3), (N, 3), (N, 4) and (N,), broadcast together (shapes checked)."""
    for name, array, width in (("inertia", inertia, 3), ("angular_momentum", m, 3)):
        if array.ndim not in (1, 2) or array.shape[-1] != width:
            raise InputError(
                f"{name} must have shape ({width},) or (N, {width}), got {array.shape}"
            )
    if q.ndim not in (1, 2) or q.shape[-1] != 4:
        raise InputError(f"quaternion_wxyz must have shape (4,) or (N, 4), got {q.shape}")
    if τ.ndim > 1:
        raise InputError(f"dt must be a scalar or have shape (N,), got {τ.shape}")
    try:
        N = np.broadcast_shapes(inertia.shape[:-1], m.shape[:-1], q.shape[:-1], τ.shape)
    except ValueError:
        raise InputError(
            f"the numbers of states do not match: inertia {inertia.shape}, angular_momentum "
            f"{m.shape}, quaternion_wxyz {q.shape}, dt {τ.shape}"
        ) from None
    n = N[0] if N else 1
    return tuple(
        array if array.shape == shape else np.broadcast_to(array, shape)  # as given, or a view
        for array, shape in ((inertia, (n, 3)), (m, (n, 3)), (q, (n, 4)), (τ, (n,)))
    )


def _checked_batch(inertia: NDArray, m: NDArray, q: NDArray, τ: NDArray) -> NDArray:
    """The checks of ``_one_state`` on a whole batch; returns the normalized quaternions."""
    for name, array in (("inertia", inertia), ("angular_momentum", m), ("dt", τ)):
        finite = np.isfinite(array)
        if not finite.all():
            k = int(np.flatnonzero(~finite.reshape(len(array), -1).all(axis=1))[0])
            raise InputError(f"{name}[{k}] must be finite, got {array[k].tolist()}")
    if not (inertia > 0.0).all():
        bad = np.flatnonzero(~np.all(inertia > 0.0, axis=1))
        raise InputError(f"inertia[{bad[0]}] must be positive, got {inertia[bad[0]].tolist()}")
    norms = np.linalg.norm(q, axis=1)
    if not (np.isfinite(norms) & (norms > 0.0)).all():
        bad = np.flatnonzero(~(np.isfinite(norms) & (norms > 0.0)))
        raise InputError(
            f"quaternion_wxyz[{bad[0]}] must be a finite, non-zero quaternion "
            f"(w, x, y, z), got {q[bad[0]].tolist()}"
        )
    # |m|/I1 ≤ √3 max|m_k| / min I: beyond the float range only past this bound.
    if np.max(np.abs(m)) > 1e300 * np.min(inertia):
        G = np.hypot(np.hypot(m[:, 0], m[:, 1]), m[:, 2])
        with np.errstate(over="ignore", divide="ignore"):
            fast = G / np.min(inertia, axis=1)
        bad = np.flatnonzero(~np.isfinite(fast))
    else:
        bad = np.empty(0, np.intp)
    if len(bad):
        k = bad[0]
        raise InputError(
            f"angular_momentum[{k}] {m[k].tolist()} with inertia {inertia[k].tolist()}: "
            f"the angular velocity |m|/I1 is beyond the float range"
        )
    return q / norms[:, None]


def _too_far(τ: float, at: str) -> str:
    return (
        f"dt{at} = {τ!r} s is too long for this state: its angles (rate times dt) exceed "
        "the float range (1.8e308)"
    )
