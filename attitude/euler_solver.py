"""The exact motion of a torque-free rigid body from one state: ``EulerSolver``.

One state, evaluated at any number of times: the closed form of attitude.closed_form
(Celledoni, Fassò, Säfström and Zanna [CFSZ08] with Leroy's corrections [Leroy]; the
project's derivation is docs/derivation.md) with float constants, built once, and
numpy arrays of times.  No numerical integration: evaluation at any time costs the
same and does not drift.  (Many states at one time each: attitude.free_flow.)

The attitude is Q(t) = R ∘ Y(ψ(t) − ψ(t0)) ∘ P(t) ∘ S ([Leroy] "An alternative
quaternionic solution"): S maps the user's body axes onto the frame of the state's
formula (the principal axes of a tensor, sorted, flipped and relabelled: see
attitude.closed_form), P(t) maps m(t) onto G e3, Y(ψ) turns about e3 and R, constant,
makes Q(t0) the given attitude.  The glossary of [Leroy]'s symbols is in
attitude.closed_form.

Cases (the exact sign of Δ2 of the float inputs, attitude.invariants):
  (i)   Δ2 < 0: m circulates about the axis of least inertia, m1 = B13 dn > 0
  (ii)  Δ2 > 0: m circulates about the axis of greatest inertia, m3 = B31 dn > 0
  (iii) Δ2 = 0: the separatrix, m1 = B13 sech, m3 = B31 sech, m2 = G th
  steady and rest are the special cases whose formulas would be 0/0 or ∞·0: the
  sphere (I1 = I3), a rate λ that underflows (m within ~1e-160 G of an axis of a
  symmetric body), and G = 0.  Every other degenerate body (I1 = I2, I2 = I3, spin
  about any axis, the intermediate one included) goes through the general formulas,
  and so does every state next to the separatrix, however small its mc.

References
----------
[CFSZ08] E. Celledoni, F. Fassò, N. Säfström, A. Zanna, "The exact computation of the
    free rigid body motion and its use in splitting methods", SIAM J. Sci. Comput. 30(4)
    (2008) 2084–2112, doi:10.1137/070704393.
[Leroy] P. Leroy, "On an Article by Celledoni et al." (2020), in Principia's
    documentation:
    https://github.com/mockingbirdnest/Principia/blob/master/documentation/Celledoni.pdf
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from attitude.closed_form import CaseFormula, Elliptic, OneState, p_quaternion, y_times_p
from attitude.errors import InputError
from attitude.float_math import FLOAT
from attitude.inertia import PrincipalAxes, principal_axes
from attitude.quantities import as_si_array, as_si_scalar, as_vector3
from attitude.quaternions import left_matrix, right_matrix

__all__ = ["EulerSolver"]

# Evaluations over many times run in slices of this many samples (see _in_chunks).
_CHUNK = 16384


def _as_rotation(attitude: Any) -> Rotation:
    if attitude is None:
        return Rotation.identity()
    if not isinstance(attitude, Rotation):
        raise InputError(
            "attitude must be a scipy.spatial.transform.Rotation (body -> inertial), "
            f"got {type(attitude).__name__}: {attitude!r}"
        )
    if not attitude.single:
        raise InputError(f"attitude must be a single rotation, got a stack of {len(attitude)}")
    q = attitude.as_quat(scalar_first=True)
    if not np.all(np.isfinite(q)):
        raise InputError(f"attitude must be finite, got quaternion {q.tolist()}")
    return attitude


class EulerSolver:
    """Exact torque-free motion of a rigid body from its state at ``t0``.

    Parameters
    ----------
    inertia
        The three principal moments of inertia along the body x, y, z axes, in any
        order, or the symmetric 3×3 inertia tensor in body axes, kg m² (or a
        ``Quantity``).  A tensor is diagonalized and every result is still given in
        the body axes.
    angular_momentum
        Body-frame angular momentum at ``t0``, N m s (kg m²/s).
    attitude
        ``scipy.spatial.transform.Rotation`` taking body coordinates to inertial
        coordinates at ``t0``; identity when None.
    t0
        Epoch of the initial state, seconds (the solver's own time origin).

    The attitude at t is ``Q(t) = R ∘ Y(ψ(t) − ψ(t0)) ∘ P(t) ∘ S`` (module docstring),
    built so that ``Q(t0)`` is the given attitude and nothing is singular anywhere
    on the sphere of momenta.  All evaluations accept a scalar or an array of times
    (seconds, before or after ``t0``) and are vectorized.
    """

    def __init__(
        self,
        inertia: ArrayLike,
        angular_momentum: ArrayLike,
        attitude: Rotation | None = None,
        t0: float = 0.0,
    ) -> None:
        axes = principal_axes(inertia)
        m_body = as_vector3(angular_momentum, "angular_momentum", "angular_momentum")
        self._initial_attitude = _as_rotation(attitude)
        self._t0 = as_si_scalar(t0, "time", "t0")
        self._axes = axes
        self._initial_angular_momentum = m_body
        self._state = self._select_formula(axes, m_body)
        self._formula: CaseFormula = self._state.formula
        self._G = self._state.G
        self._S_matrix = self._body_to_formula_frame(axes)
        # The moments along the axes of the formula's frame (for ω = m/I there).
        self._I_frame = np.array([float(axes.moments[k]) for k in self._state.index])
        self._M_T_scalar_last, self._ψ_t0 = self._constant_rotation()
        I1, I2, I3 = self._state.I
        m1, m2, m3 = self._state.preferred
        G = self._G
        x1, x2, x3 = (m1 / G, m2 / G, m3 / G) if G > 0.0 else (0.0, 0.0, 0.0)
        # 2T = G² Σ xj²/Ij; Python floats: an energy beyond the float range is inf.
        self._kinetic_energy = 0.5 * G * (G * (x1 * x1 / I1 + x2 * x2 / I2 + x3 * x3 / I3))
        self._inertial_angular_momentum = self._initial_attitude.apply(m_body)

    @staticmethod
    def _select_formula(axes: PrincipalAxes, m_body: NDArray[np.float64]) -> OneState:
        """The case, its formula and the preferred flips (attitude.closed_form.OneState).

        Refuses a state whose angular velocity |m|/I1 is beyond the float range.
        """
        m_principal = m_body if axes.is_diagonal else axes.body_to_principal.apply(m_body)
        moments = tuple(float(v) for v in axes.moments)
        momentum = tuple(float(v) for v in m_principal)
        G = math.hypot(*momentum)  # math.hypot scales: no overflow of the squares
        if not math.isfinite(G / min(moments)):
            raise InputError(
                f"angular_momentum {m_body.tolist()} with moments {axes.moments.tolist()}: the "
                f"angular velocity |m|/I1 = {G / min(moments):g} rad/s is beyond the float range"
            )
        return OneState(moments, momentum)

    def _body_to_formula_frame(self, axes: PrincipalAxes) -> NDArray[np.float64]:
        """S as a matrix: the signed permutation of the principal axes onto the
        formula's frame, after the body → principal rotation of a tensor.  Row vectors
        go back to the body as v_frame @ S (exact for a signed permutation)."""
        S_matrix = np.zeros((3, 3))
        S_matrix[np.arange(3), self._state.index] = self._state.sign
        if not axes.is_diagonal:
            S_matrix = S_matrix @ axes.body_to_principal.as_matrix()
        return np.ascontiguousarray(S_matrix)

    def _constant_rotation(self) -> tuple[NDArray[np.float64], float]:
        """R = Q0 ∘ S⁻¹ ∘ P(t0)⁻¹, folded with S into one 4×4 matrix, and ψ(t0).

        q(t) = R ⊗ (Y ⊗ P)(t) ⊗ S = L(R) Rr(S) (Y ⊗ P)(t).  Kept transposed, with its
        columns reordered so that the product comes out scalar last, the layout
        Rotation.from_quat takes without a copy.
        """
        S = Rotation.from_matrix(self._S_matrix).as_quat(scalar_first=True)
        Q0 = self._initial_attitude.as_quat(scalar_first=True)
        a, b, c, ψ_t0 = self._formula.momentum_and_angle(0.0, FLOAT)  # float constants
        if self._formula.name == "rest":
            P0 = np.array([1.0, 0.0, 0.0, 0.0])
        else:
            P0 = np.array([*p_quaternion(a, b, c, self._G, FLOAT), 0.0])
        conjugate = np.array([1.0, -1.0, -1.0, -1.0])
        R = left_matrix(Q0) @ left_matrix(S * conjugate) @ (P0 * conjugate)
        M = left_matrix(R) @ right_matrix(S)
        return np.ascontiguousarray(M[[1, 2, 3, 0]].T), float(ψ_t0)

    @classmethod
    def from_angular_velocity(
        cls,
        inertia: ArrayLike,
        angular_velocity: ArrayLike,
        attitude: Rotation | None = None,
        t0: float = 0.0,
    ) -> EulerSolver:
        """Build the solver from the body angular velocity at ``t0`` (rad/s)."""
        tensor = principal_axes(inertia).tensor
        ω = as_vector3(angular_velocity, "angular_velocity", "angular_velocity")
        return cls(inertia, tensor @ ω, attitude, t0)

    # ----------------------------------------------------------------- evaluation

    def _τ(self, t: Any) -> NDArray[np.float64]:
        return as_si_array(t, "time", "t") - self._t0

    def _evaluate(self, chunk, t: Any, width: int, τ: NDArray[np.float64] | None = None):
        """``chunk`` over the times ``t`` in slices, refusing a time too far from t0.

        Far enough from t0 (|t − t0| beyond ~1.8e308 divided by the motion's fastest
        angular rate) an angle λ(t − t0) or ψ(t) leaves the float range and the
        result would be NaN: that time gets an InputError that names it instead.
        """
        if τ is None:
            τ = self._τ(t)
        with np.errstate(over="ignore", invalid="ignore"):
            out = self._in_chunks(chunk, τ, width)
        if not np.isfinite(out).all():
            bad = np.flatnonzero(~np.isfinite(out).reshape(-1, width).all(axis=-1))[0]
            t_bad = np.ravel(as_si_array(t, "time", "t"))[bad] if np.ndim(t) else t
            rate = max(abs(getattr(self._formula, "λ", 0.0)), self._G / self._state.I[0])
            raise InputError(
                f"t = {float(t_bad)!r} s is too far from t0 = {self._t0!r} s for this motion: "
                f"its angles, at rates up to {rate:.3g} rad/s, times t - t0 exceed the float "
                "range (1.8e308)"
            )
        return out

    def _to_body(self, v_frame: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.dot(v_frame, self._S_matrix)

    def _momentum_chunk(self, τ: NDArray[np.float64]) -> NDArray[np.float64]:
        return self._to_body(np.stack(self._formula.momentum(τ, np), axis=-1))

    def _velocity_chunk(self, τ: NDArray[np.float64]) -> NDArray[np.float64]:
        return self._to_body(np.stack(self._formula.momentum(τ, np), axis=-1) / self._I_frame)

    def _quaternion_chunk(self, τ: NDArray[np.float64]) -> NDArray[np.float64]:
        """Attitude quaternions at τ = t − t0, scalar LAST (x, y, z, w), body → inertial."""
        a, b, c, ψ = self._formula.momentum_and_angle(τ, np)
        p0, p1, p2 = p_quaternion(a, b, c, self._G, np)
        yp = np.stack(y_times_p(0.5 * (ψ - self._ψ_t0), p0, p1, p2, np), axis=-1)
        return np.dot(yp, self._M_T_scalar_last)

    @staticmethod
    def _in_chunks(function, τ: NDArray[np.float64], width: int) -> NDArray[np.float64]:
        """Apply ``function`` to τ in slices of ``_CHUNK`` elements.

        A slice's temporaries stay in the processor's cache; over a million samples
        this is about 1.7 times faster than one pass over the whole array.
        """
        flat = τ.ravel()
        if flat.size <= _CHUNK:
            return function(flat).reshape((*τ.shape, width))
        out = np.empty((flat.size, width))
        for start in range(0, flat.size, _CHUNK):
            out[start : start + _CHUNK] = function(flat[start : start + _CHUNK])
        return out.reshape((*τ.shape, width))

    def angular_momentum(self, t: ArrayLike) -> NDArray[np.float64]:
        """Body-frame angular momentum at ``t`` (N m s), shape ``np.shape(t) + (3,)``."""
        return self._evaluate(self._momentum_chunk, t, 3)

    def angular_velocity(self, t: ArrayLike) -> NDArray[np.float64]:
        """Body-frame angular velocity at ``t`` (rad/s), shape ``np.shape(t) + (3,)``."""
        return self._evaluate(self._velocity_chunk, t, 3)

    def attitude(self, t: ArrayLike) -> Rotation:
        """Rotation taking body coordinates to inertial coordinates at ``t``.

        One ``Rotation`` for a scalar ``t``, a stack for a 1-D array.
        """
        τ = self._τ(t)
        if τ.ndim > 1:
            raise InputError(
                f"t must be a scalar or a 1-D array for attitude(), got shape {τ.shape}"
            )
        return Rotation.from_quat(self._quaternions_scalar_last(t, τ))

    def attitude_quaternion(self, t: ArrayLike, scalar_first: bool = True) -> NDArray[np.float64]:
        """The attitude at ``t`` as unit quaternions, body → inertial, shape ``np.shape(t) + (4,)``.

        Scalar first (w, x, y, z) by default.  The same rotation as ``attitude(t)``,
        without building a ``Rotation``: for writing files and for callers that
        assemble many segments.
        """
        q = self._quaternions_scalar_last(t, self._τ(t))
        q /= np.linalg.norm(q, axis=-1, keepdims=True)
        return q[..., [3, 0, 1, 2]] if scalar_first else q

    def _quaternions_scalar_last(self, t: Any, τ: NDArray[np.float64]) -> NDArray[np.float64]:
        if self._formula.name == "rest":
            return np.broadcast_to(self._initial_attitude.as_quat(), (*τ.shape, 4)).copy()
        return self._evaluate(self._quaternion_chunk, t, 4, τ)

    def spin_axis_cone(self) -> tuple[NDArray[np.float64], float, float] | None:
        """The body axis about which m circulates, and the cone it describes about m.

        In case (i) m circulates about the axis of least inertia (m1 = B13 dn u), in
        case (ii) about the axis of greatest inertia (m3 = B31 dn u).  Returns that
        axis as a unit vector in body coordinates, and the least and greatest angle
        (rad) between it and the angular momentum: arccos(B/G) at dn = 1 and
        arccos(B √mc/G) at dn = √mc, reached alternately every period/2 (the
        nutation).  None on the separatrix, for a sphere and at rest.
        """
        f = self._formula
        if not isinstance(f, Elliptic):
            return None
        B = f.A_d  # B13 (case i) or B31 (case ii), along e3 of the formula's frame
        axis = self._to_body(np.array([0.0, 0.0, 1.0]))
        G = self._G
        return axis, math.acos(min(1.0, B / G)), math.acos(min(1.0, B * f.parameter.kc / G))

    def _flip_phases(self, t_start: Any, t_end: Any) -> tuple[float, float] | None:
        """The phases u at t_start and t_end (ascending), or None if the body never flips.

        A flip is a sign change of the momentum component along the intermediate
        principal axis while the body turns over: m2 ∝ sn(u) vanishes at u = 2jK in
        cases (i) and (ii), every period/2; on the separatrix there is one, at u = 0.
        The body turns over only if the intermediate axis swings from near +m to
        near −m: we count flips when the amplitude of m2 exceeds G/√2 (that axis
        comes within 45° of the angular momentum).  Below, m2 changes sign too, but
        as part of a nutation about the spin axis, not as a flip.  None also for a
        body without a distinct intermediate axis (I1 = I2 or I2 = I3).
        """
        t_start = as_si_scalar(t_start, "time", "t_start")
        t_end = as_si_scalar(t_end, "time", "t_end")
        f = self._formula
        I1, I2, I3 = self._state.I
        if not (I1 < I2 < I3) or f.name not in ("i", "ii", "iii") or f.λ == 0.0:
            return None
        if not math.isfinite(f.ν):  # a steady spin about the intermediate axis
            return None
        # The amplitude of m2 is |A_s| = B21 (case i) or B23 (case ii).
        if f.name != "iii" and abs(f.A_s) <= self._G * math.sqrt(0.5):
            return None
        phases = []
        for name, t in (("t_start", t_start), ("t_end", t_end)):
            u = f.λ * (t - self._t0) - f.ν
            if not math.isfinite(u):
                raise InputError(
                    f"{name} = {t!r} s is too far from t0 = {self._t0!r} s: the phase of the "
                    f"motion, {f.λ:.3g} rad/s times {name} - t0, exceeds the float range"
                )
            phases.append(u)
        u_a, u_b = sorted(phases)
        return u_a, u_b

    def flip_count(self, t_start: float, t_end: float) -> int:
        """The number of flips in [t_start, t_end], in closed form (no array is built).

        The count of j with 2jK in [u(t_start), u(t_end)] (``flip_times`` says what a
        flip is): floor(u_b/2K) − ceil(u_a/2K) + 1, exact for the float phases u;
        0 or 1 on the separatrix.  A flip within rounding of t_start or t_end (a few
        ulps of λ(t − t0)) may be counted on either side.
        """
        phases = self._flip_phases(t_start, t_end)
        if phases is None:
            return 0
        u_a, u_b = phases
        f = self._formula
        if f.name == "iii":
            return int(u_a <= 0.0 <= u_b)
        return max(0, math.floor(u_b / (2.0 * f.K)) - math.ceil(u_a / (2.0 * f.K)) + 1)

    def flip_times(
        self, t_start: float, t_end: float, limit: int = 10_000_000
    ) -> NDArray[np.float64]:
        """Times in [t_start, t_end] at which the body flips (the Джанибеков effect).

        The exact times t = t0 + (2jK + ν)/λ, every period/2, at which the momentum
        component along the intermediate axis changes sign while the body turns over
        (see ``_flip_phases``); on the separatrix there is one, at u = 0.  Empty if
        the body never turns over.

        A span with more than ``limit`` flips (80 MB of float64 at the default) is
        refused with an InputError naming the count: ``flip_count`` gives the count
        alone, at no cost, for any span.
        """
        count = self.flip_count(t_start, t_end)
        if count > limit:
            count_text = str(count) if count < 10**12 else f"{float(count):.4g}"
            raise InputError(
                f"flip_times({t_start!r}, {t_end!r}): the body flips {count_text} times in "
                f"this span ({count * 8 / 2**30:.3g} GiB of float64), beyond limit={limit}; "
                "ask for a shorter span, or flip_count() for the number alone"
            )
        if count == 0:
            return np.empty(0)
        u_a, _ = self._flip_phases(t_start, t_end)
        f = self._formula
        if f.name == "iii":
            zeros_u = np.array([0.0])
        else:
            zeros_u = 2.0 * f.K * (float(math.ceil(u_a / (2.0 * f.K))) + np.arange(count))
        return np.sort(self._t0 + (zeros_u + f.ν) / f.λ)

    # ----------------------------------------------------------------- properties

    @property
    def period(self) -> float:
        """Period of the body-frame motion m(t), seconds: 4K/|λ|.

        ``math.inf`` on the separatrix, for a sphere and at rest.  For a steady spin
        about axis 1 or 3 (m constant) it is the period of the nearby motions.
        """
        return float(self._formula.period)

    @property
    def formula(self) -> str:
        """Which closed form applies: 'i', 'ii', 'iii' (separatrix), 'steady' (the sphere,
        or m fixed to within float range) or 'rest'."""
        return self._formula.name

    @property
    def mc(self) -> float:
        """Complementary parameter 1 − m of the Jacobi functions (0 on the separatrix)."""
        return float(self._formula.mc)

    @property
    def t0(self) -> float:
        """Epoch of the initial state, seconds."""
        return self._t0

    @property
    def moments_of_inertia(self) -> NDArray[np.float64]:
        """Principal moments, kg m²: as given, or ascending for a tensor."""
        return self._axes.moments.copy()

    @property
    def inertia_tensor(self) -> NDArray[np.float64]:
        """The inertia tensor in body axes, kg m²."""
        return self._axes.tensor.copy()

    @property
    def initial_angular_momentum(self) -> NDArray[np.float64]:
        """Body-frame angular momentum at ``t0``, N m s."""
        return self._initial_angular_momentum.copy()

    @property
    def initial_attitude(self) -> Rotation:
        """Attitude (body → inertial) at ``t0``."""
        return self._initial_attitude

    @property
    def angular_momentum_norm(self) -> float:
        """G = |m|, N m s (conserved)."""
        return self._G

    @property
    def kinetic_energy(self) -> float:
        """T = ½ Σ mj²/Ij, J (conserved).

        Raises an InputError, naming its size, for a state whose energy is beyond the
        float range (|m| above ~1e154 N m s on unit moments), whose motion is computed.
        """
        if not math.isfinite(self._kinetic_energy):
            I1, I2, I3 = self._state.I
            m1, m2, m3 = self._state.preferred
            G = self._G
            x2_over_I = (m1 / G) ** 2 / I1 + (m2 / G) ** 2 / I2 + (m3 / G) ** 2 / I3
            log10_T = 2.0 * math.log10(G) + math.log10(0.5 * x2_over_I)
            raise InputError(
                f"the kinetic energy of angular_momentum {self._initial_angular_momentum.tolist()}"
                f" with moments {self._axes.moments.tolist()}, about 1e{log10_T:.0f} J, is "
                "beyond the float range"
            )
        return self._kinetic_energy

    @property
    def inertial_angular_momentum(self) -> NDArray[np.float64]:
        """The angular momentum in inertial axes, N m s (conserved)."""
        return self._inertial_angular_momentum.copy()

    def __repr__(self) -> str:
        return (
            f"EulerSolver(inertia={self._axes.moments.tolist()}, "
            f"angular_momentum={self._initial_angular_momentum.tolist()}, t0={self._t0}, "
            f"formula={self.formula!r}, period={self.period:.6g} s)"
        )
