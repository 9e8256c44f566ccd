"""Many states at many times: ``EulerSolverBatch``, N torque-free rigid bodies at once.

``EulerSolver`` is one state at many times, ``attitude.solver.free_flow.advance`` many
states at one time each; a Monte Carlo dispersion, the failure times of an envelope or
the iterations of a fit need both axes: N states, each at T times.  Building one
``EulerSolver`` per state costs about 20 scalar ``scipy.special.ellipj`` calls of
construction and a few hundred numpy calls per evaluation (docs/solver.md, "Speed"):
for small T that is most of the work.  ``EulerSolverBatch`` builds the N states'
constants in one pass over arrays (each case's formula once over its states, the case
test in double-double with the exact integers where it is in doubt:
attitude.solver.numpy_backend) and evaluates each case's formula over its states and
the times together.  From ``backends.TABLE_MIN_SAMPLES`` times a state, a state's own
table of ψ pays for itself: each state is then evaluated alone, as its ``EulerSolver``
(``batch[k]``) would (``backends.select``'s rule 3).

Every case, in any mix: both sides of the separatrix and on it, mc below the float
range, symmetric bodies, the sphere, rest, spin about any axis, tensors.  The results
are ``EulerSolver``'s to rounding (tests/test_batch_against_euler_solver.py).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from attitude.base.errors import AttitudeError, InputError
from attitude.base.quantities import as_si_array
from attitude.solver.backends import select
from attitude.solver.closed_form import Elliptic, NotRepresentable
from attitude.solver.euler_solver import EulerSolver
from attitude.solver.numpy_backend import Motions

__all__ = ["EulerSolverBatch"]

# A tensor whose asymmetry is below this fraction of its largest entry is symmetric
# (as attitude.solver.inertia.principal_axes takes one).
_SYMMETRY_TOLERANCE = 1e-9


class EulerSolverBatch:
    """Exact torque-free motion of N rigid bodies, each from its own state at its ``t0``.

    The batch of ``EulerSolver``: the same arguments with a leading axis of N states
    (or without it, shared by every state), the same methods with a leading axis of N
    in their results.

    Parameters
    ----------
    inertia
        Principal moments along the body x, y, z axes (3,) or (N, 3), in any order, or
        symmetric inertia tensors in body axes (3, 3) or (N, 3, 3), kg m² (or a
        ``Quantity``).  Tensors are diagonalized and every result is in body axes.
    angular_momentum
        Body-frame angular momenta at ``t0``, (N, 3) or (3,), N m s.
    attitude
        ``scipy.spatial.transform.Rotation`` (body → inertial) at ``t0``: a stack of N,
        or a single rotation for every state; identity when None.
    t0
        The epoch of each state, seconds: a scalar, or (N,).

    Evaluations take times ``t`` (seconds): a scalar, an array (T,) of times shared by
    every state, or an array (N, T), a row of times per state.  ``attitude_quaternion``
    returns (N, T, 4) (N, 4 for a scalar), ``angular_momentum`` and
    ``angular_velocity`` (N, T, 3); ``attitude`` a ``Rotation`` of shape (N, T) (N-D
    rotations need scipy ≥ 1.17) or (N,).  ``batch[k]`` is state k's ``EulerSolver``.
    """

    def __init__(
        self,
        inertia: ArrayLike,
        angular_momentum: ArrayLike,
        attitude: Rotation | None = None,
        t0: ArrayLike = 0.0,
    ) -> None:
        inertia_array = as_si_array(inertia, "moment_of_inertia", "inertia")
        m = as_si_array(angular_momentum, "angular_momentum", "angular_momentum")
        t0_array = as_si_array(t0, "time", "t0")
        if m.ndim not in (1, 2) or m.shape[-1] != 3:
            raise InputError(f"angular_momentum must have shape (3,) or (N, 3), got {m.shape}")
        tensor = inertia_array.shape[-2:] == (3, 3)
        if inertia_array.shape not in ((3,), (3, 3)) and not (
            inertia_array.ndim == (3 if tensor else 2) and inertia_array.shape[-1] == 3
        ):
            raise InputError(
                "inertia must be moments (3,) or (N, 3), or tensors (3, 3) or (N, 3, 3), "
                f"got shape {inertia_array.shape}"
            )
        if t0_array.ndim > 1:
            raise InputError(f"t0 must be a scalar or have shape (N,), got {t0_array.shape}")
        lead = [
            inertia_array.shape[: inertia_array.ndim - (2 if tensor else 1)],
            m.shape[:-1],
            t0_array.shape,
        ]
        q0, attitude_lead = _attitude_quaternions(attitude)
        lead.append(attitude_lead)
        try:
            shape = np.broadcast_shapes(*lead)
        except ValueError:
            raise InputError(
                f"the numbers of states do not match: inertia {inertia_array.shape}, "
                f"angular_momentum {m.shape}, attitude {attitude_lead}, t0 {t0_array.shape}"
            ) from None
        n = shape[0] if shape else 1
        self._tensor = tensor
        if tensor:
            tensors = np.broadcast_to(inertia_array, (n, 3, 3))
            moments, V = _principal_axes(tensors)
            self._tensors = np.array(tensors)
        else:
            moments = np.array(np.broadcast_to(inertia_array, (n, 3)))
            if not (moments > 0.0).all():
                k = int(np.flatnonzero(~(moments > 0.0).all(axis=1))[0])
                raise InputError(
                    f"inertia[{k}]: principal moments must be positive, got {moments[k].tolist()}"
                )
            V = None
        self._moments = moments
        self._m_body = np.array(np.broadcast_to(m, (n, 3)))
        self._q0 = np.array(np.broadcast_to(q0, (n, 4)))
        self._t0 = np.array(np.broadcast_to(t0_array, (n,)), dtype=np.float64)
        self._attitude = attitude
        m_principal = self._m_body if V is None else np.einsum("nij,nj->ni", V, self._m_body)
        with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
            G = np.hypot(np.hypot(m_principal[:, 0], m_principal[:, 1]), m_principal[:, 2])
            fast = G / moments.min(axis=1)
        if not np.isfinite(fast).all():
            k = int(np.flatnonzero(~np.isfinite(fast))[0])
            raise InputError(
                f"angular_momentum[{k}] {self._m_body[k].tolist()} with moments "
                f"{moments[k].tolist()}: the angular velocity |m|/I1 is beyond the float range"
            )
        self._V = V
        rotations = None
        if V is not None:
            V_q = Rotation.from_matrix(V).as_quat(scalar_first=True)
            rotations = (V, V_q)
        self._motions = Motions(moments, m_principal, self._q0, self._t0, rotations)
        self._solvers: dict[int, EulerSolver] = {}

    @classmethod
    def from_angular_velocity(
        cls,
        inertia: ArrayLike,
        angular_velocity: ArrayLike,
        attitude: Rotation | None = None,
        t0: ArrayLike = 0.0,
    ) -> EulerSolverBatch:
        """Build the batch from the body angular velocities at ``t0`` (rad/s)."""
        inertia_array = as_si_array(inertia, "moment_of_inertia", "inertia")
        ω = as_si_array(angular_velocity, "angular_velocity", "angular_velocity")
        if inertia_array.shape[-2:] == (3, 3):
            m = np.einsum("...ij,...j->...i", inertia_array, ω)
        else:
            m = inertia_array * ω
        return cls(inertia, m, attitude, t0)

    def __len__(self) -> int:
        return self._moments.shape[0]

    def __getitem__(self, k: int) -> EulerSolver:
        """State k's ``EulerSolver`` (the same state: made at first use, then kept)."""
        k = range(len(self))[k]  # an IndexError past the end; negative k from the end
        if k not in self._solvers:
            inertia = self._tensors[k] if self._tensor else self._moments[k]
            attitude = None
            if self._attitude is not None:
                attitude = self._attitude if self._attitude.single else self._attitude[k]
            self._solvers[k] = EulerSolver(inertia, self._m_body[k], attitude, float(self._t0[k]))
        return self._solvers[k]

    # ----------------------------------------------------------------- evaluation

    def _times(self, t: Any) -> tuple[NDArray[np.float64], NDArray[np.float64], bool]:
        """The times as given, τ = t − t0 as (N, T), and whether ``t`` was a scalar."""
        times = as_si_array(t, "time", "t")
        if times.ndim == 0:
            return times, (times - self._t0)[:, None], True
        if times.ndim == 1:
            return times, times[None, :] - self._t0[:, None], False
        if times.ndim == 2 and times.shape[0] == len(self):
            return times, times - self._t0[:, None], False
        raise InputError(
            f"t must be a scalar, (T,) times for every state or (N, T) = ({len(self)}, T) "
            f"times, one row per state; got shape {times.shape}"
        )

    def _evaluate(self, t: Any, width: int, evaluate: Any, alone: Any) -> NDArray[np.float64]:
        """``evaluate(τ)`` of every state at once (the numpy backend), or ``alone`` of
        each state's ``EulerSolver`` at its times where ``backends.select`` says so (so
        many times a state that its own table pays)."""
        times, τ, scalar = self._times(t)
        n, T = τ.shape
        if select(n, T) is None:  # each state alone
            out = np.empty((n, T, width))
            for k in range(n):
                row = times if times.ndim < 2 else times[k]
                try:
                    out[k] = alone(self[k], np.atleast_1d(row))
                except InputError as error:  # a time too far from t0: name the state
                    raise InputError(f"state {k}: {error}") from None
        else:
            try:
                out = evaluate(τ)
            except NotRepresentable as error:
                k, i = divmod(error.index, T)
                t_bad = times if times.ndim == 0 else (times[i] if times.ndim == 1 else times[k, i])
                raise InputError(
                    f"state {k}: t = {float(t_bad)!r} s is too far from t0 = "
                    f"{float(self._t0[k])!r} s for this motion: its angles, times t - t0, "
                    "exceed the float range (1.8e308)"
                ) from None
        return out[:, 0] if scalar else out

    def attitude_quaternion(self, t: ArrayLike, scalar_first: bool = True) -> NDArray[np.float64]:
        """The attitudes at ``t`` as unit quaternions, body → inertial: (N, T, 4), or
        (N, 4) for a scalar ``t``.  Scalar first (w, x, y, z) by default."""
        columns = (0, 1, 2, 3) if scalar_first else (3, 0, 1, 2)
        return self._evaluate(
            t,
            4,
            lambda τ: self._motions.quaternions(τ, columns),
            lambda solver, times: solver.attitude_quaternion(times, scalar_first),
        )

    def attitude(self, t: ArrayLike) -> Rotation:
        """The attitudes at ``t`` (body → inertial): a ``Rotation`` of shape (N, T), or
        (N,) for a scalar ``t``."""
        q = self.attitude_quaternion(t, scalar_first=False)
        try:
            return Rotation(q, normalize=False, copy=False)
        except ValueError:  # pragma: no cover  (scipy < 1.17 has no N-D rotations)
            raise AttitudeError(
                "attitude() of many states at many times needs scipy >= 1.17 (N-D "
                "rotations); attitude_quaternion() gives the same attitudes as an array"
            ) from None

    def angular_momentum(self, t: ArrayLike) -> NDArray[np.float64]:
        """Body-frame angular momenta at ``t`` (N m s): (N, T, 3), or (N, 3)."""
        return self._evaluate(
            t,
            3,
            lambda τ: self._motions.body_vectors(τ, velocity=False),
            lambda solver, times: solver.angular_momentum(times),
        )

    def angular_velocity(self, t: ArrayLike) -> NDArray[np.float64]:
        """Body-frame angular velocities at ``t`` (rad/s): (N, T, 3), or (N, 3)."""
        return self._evaluate(
            t,
            3,
            lambda τ: self._motions.body_vectors(τ, velocity=True),
            lambda solver, times: solver.angular_velocity(times),
        )

    # ----------------------------------------------------------------- properties

    def _per_state(self, value: Any) -> NDArray[np.float64]:
        """A property of each case's formula, gathered per state (N,)."""
        out = np.empty(len(self))
        for k, formula in self._motions.states.groups:
            out[k] = value(formula)
        return out

    @property
    def formula(self) -> tuple[str, ...]:
        """Each state's closed form: 'i', 'ii', 'iii', 'steady' or 'rest' (as
        ``EulerSolver.formula``)."""
        names = np.empty(len(self), dtype=object)
        for k, formula in self._motions.states.groups:
            if isinstance(formula, Elliptic):
                names[k] = np.where(formula.case_ii, "ii", "i")
            else:
                names[k] = formula.name
        return tuple(names.tolist())

    @property
    def mc(self) -> NDArray[np.float64]:
        """Each state's complementary parameter 1 − m (0 on the separatrix, NaN for the
        steady and rest states)."""
        return self._per_state(lambda f: f.mc)

    @property
    def period(self) -> NDArray[np.float64]:
        """Each state's period of m(t), 4K/|λ| (s); ``inf`` on the separatrix, for a
        sphere and at rest."""
        return self._per_state(lambda f: f.period if isinstance(f, Elliptic) else math.inf)

    @property
    def t0(self) -> NDArray[np.float64]:
        """Each state's epoch, seconds."""
        return self._t0.copy()

    @property
    def moments_of_inertia(self) -> NDArray[np.float64]:
        """Principal moments (N, 3), kg m²: as given, or ascending for tensors."""
        return self._moments.copy()

    @property
    def initial_angular_momentum(self) -> NDArray[np.float64]:
        """Body-frame angular momenta at t0 (N, 3), N m s."""
        return self._m_body.copy()

    @property
    def angular_momentum_norm(self) -> NDArray[np.float64]:
        """G = |m| of each state (N,), N m s (conserved)."""
        return self._motions.states.G.copy()

    @property
    def kinetic_energy(self) -> NDArray[np.float64]:
        """T = ½ Σ mj²/Ij of each state (N,), J (conserved).  An InputError names a
        state whose energy is beyond the float range."""
        m = self._m_body if self._V is None else np.einsum("nij,nj->ni", self._V, self._m_body)
        G = self._motions.states.G
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            x = m / np.where(G > 0.0, G, 1.0)[:, None]
            energy = 0.5 * G * (G * np.sum(x * x / self._moments, axis=1))
        if not np.isfinite(energy).all():
            k = int(np.flatnonzero(~np.isfinite(energy))[0])
            raise InputError(
                f"the kinetic energy of state {k} (angular_momentum "
                f"{self._m_body[k].tolist()}) is beyond the float range"
            )
        return energy

    @property
    def inertial_angular_momentum(self) -> NDArray[np.float64]:
        """Each state's angular momentum in inertial axes (N, 3), N m s (conserved)."""
        return Rotation.from_quat(self._q0, scalar_first=True).apply(self._m_body)

    def __repr__(self) -> str:
        counts: dict[str, int] = {}
        for name in self.formula:
            counts[name] = counts.get(name, 0) + 1
        return f"EulerSolverBatch({len(self)} states: {counts})"


def _attitude_quaternions(attitude: Any) -> tuple[NDArray[np.float64], tuple[int, ...]]:
    """The attitudes at t0 as unit quaternions (..., 4), scalar first, and their
    leading shape ((), or (N,) for a stack)."""
    if attitude is None:
        return np.array([1.0, 0.0, 0.0, 0.0]), ()
    if not isinstance(attitude, Rotation):
        raise InputError(
            "attitude must be a scipy.spatial.transform.Rotation (body -> inertial), "
            f"got {type(attitude).__name__}: {attitude!r}"
        )
    q = attitude.as_quat(scalar_first=True)
    if q.ndim > 2:
        raise InputError(f"attitude must be one rotation or a stack of N, got shape {q.shape[:-1]}")
    if not np.isfinite(q).all():
        k = 0 if q.ndim == 1 else int(np.flatnonzero(~np.isfinite(q).all(axis=1))[0])
        bad = q.reshape(-1, 4)[k].tolist()
        raise InputError(f"attitude[{k}] must be finite, got quaternion {bad}")
    return q, q.shape[:-1]


def _principal_axes(tensors: NDArray[np.float64]) -> tuple[NDArray, NDArray]:
    """Ascending principal moments (N, 3) and the rotations V (N, 3, 3) taking body to
    principal coordinates, as attitude.solver.inertia.principal_axes for each tensor
    (numpy's eigh over the stack)."""
    asymmetry = np.max(np.abs(tensors - np.swapaxes(tensors, 1, 2)), axis=(1, 2))
    scale = np.max(np.abs(tensors), axis=(1, 2))
    if (asymmetry > _SYMMETRY_TOLERANCE * scale).any():
        k = int(np.flatnonzero(asymmetry > _SYMMETRY_TOLERANCE * scale)[0])
        raise InputError(
            f"inertia[{k}]: tensor is not symmetric (|T - Tᵀ| = {asymmetry[k]:.3g}): "
            f"{tensors[k].tolist()}"
        )
    symmetric = 0.5 * (tensors + np.swapaxes(tensors, 1, 2))
    moments, vectors = np.linalg.eigh(symmetric)  # columns: principal axes in body coordinates
    if not (moments > 0.0).all():
        k = int(np.flatnonzero(~(moments > 0.0).all(axis=1))[0])
        raise InputError(
            f"inertia[{k}]: tensor is not positive definite (eigenvalues "
            f"{moments[k].tolist()}): {symmetric[k].tolist()}"
        )
    left = np.linalg.det(vectors) < 0.0
    vectors[left, :, 2] *= -1.0  # right-handed principal frames
    return moments, np.ascontiguousarray(np.swapaxes(vectors, 1, 2))
