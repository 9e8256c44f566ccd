"""The exact motion of a torque-free rigid body from one state: ``EulerSolver``.

One state, evaluated at any number of times: the closed form of attitude.solver.closed_form
(Celledoni, Fassò, Säfström and Zanna [CFSZ08] with Leroy's corrections [Leroy]; the
project's derivation is docs/derivation.md) with float constants, built once, and
numpy arrays of times.  No numerical integration: evaluation at any time costs the
same and does not drift.  (Many states at one time each: attitude.solver.free_flow.)

The attitude is Q(t) = R ∘ Y(ψ(t) − ψ(t0)) ∘ P(t) ∘ S ([Leroy] "An alternative
quaternionic solution"): S maps the user's body axes onto the frame of the state's
formula (the principal axes of a tensor, sorted, flipped and relabelled: see
attitude.solver.closed_form), P(t) maps m(t) onto G e3, Y(ψ) turns about e3 and R, constant,
makes Q(t0) the given attitude.  The glossary of [Leroy]'s symbols is in
attitude.solver.closed_form.

Cases (the exact sign of Δ2 of the float inputs, attitude.solver.invariants):
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

from attitude.base.errors import InputError
from attitude.base.quantities import as_si_array, as_si_scalar, as_vector3
from attitude.elliptic.phase_table import PiecewiseChebyshev
from attitude.solver import float_backend
from attitude.solver.backends import select
from attitude.solver.closed_form import CaseFormula, Elliptic, Motion, NotRepresentable, Separatrix
from attitude.solver.inertia import PrincipalAxes, principal_axes

__all__ = ["EulerSolver"]

try:  # numpy's array-API namespace as scipy's Rotation keeps it (see _one_rotation)
    from scipy._lib._array_api import array_namespace as _array_namespace

    _NUMPY_NAMESPACE: Any = _array_namespace(np.empty(0))
except ImportError:  # pragma: no cover
    _NUMPY_NAMESPACE = None


def _three_floats(value: Any) -> tuple[float, float, float] | None:
    """``value`` as three finite Python floats when it is plainly three numbers (a list
    or tuple of floats and ints, or a float64 array of shape (3,)), else None: the
    general checks of attitude.base.quantities then run (Quantities, other types, and
    every error message).  They cost more than the rest of the construction."""
    if type(value) is np.ndarray:
        if value.shape != (3,) or value.dtype != np.float64:
            return None
        a, b, c = value.tolist()
    elif type(value) in (list, tuple) and len(value) == 3:
        a, b, c = value
        for v in (a, b, c):
            if not (type(v) is float or type(v) is int or type(v) is np.float64):
                return None
        try:
            a, b, c = float(a), float(b), float(c)
        except OverflowError:  # an int beyond the float range: refused by the checks
            return None
    else:
        return None
    if not (math.isfinite(a) and math.isfinite(b) and math.isfinite(c)):
        return None
    return a, b, c


def _attitude_quaternion(attitude: Any) -> tuple[float, float, float, float]:
    """The attitude at t0 as a unit quaternion (w, x, y, z), checked."""
    if attitude is None:
        return 1.0, 0.0, 0.0, 0.0
    if not isinstance(attitude, Rotation):
        raise InputError(
            "attitude must be a scipy.spatial.transform.Rotation (body -> inertial), "
            f"got {type(attitude).__name__}: {attitude!r}"
        )
    if not attitude.single:
        raise InputError(f"attitude must be a single rotation, got a stack of {len(attitude)}")
    x, y, z, w = attitude.as_quat().tolist()  # scalar last: scipy's own order, no copy
    if not (math.isfinite(w) and math.isfinite(x) and math.isfinite(y) and math.isfinite(z)):
        raise InputError(f"attitude must be finite, got quaternion {[w, x, y, z]}")
    return w, x, y, z


def _one_rotation(q_scalar_last: NDArray[np.float64]) -> Rotation:
    """One ``Rotation`` from a unit quaternion, scalar last.

    scipy's public constructors cost ~8 µs for a single quaternion (array-API
    dispatch and checks), five times the rest of a scalar ``attitude(t)``; its internal
    constructor, which skips them, ~2 µs.  That one is private, so it is used only
    where it exists with the signature we know, and
    tests/test_fast_paths_against_the_general_ones.py checks that it gives the public
    constructor's rotation.
    """
    try:
        # Private, so scipy-stubs does not declare it.
        return Rotation._from_raw_quat(q_scalar_last, xp=_NUMPY_NAMESPACE)  # type: ignore[attr-defined]
    except (AttributeError, TypeError):  # pragma: no cover  (another scipy)
        return Rotation(q_scalar_last, normalize=False, copy=False)


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

    Notes
    -----
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
        # Three plain positive moments (the usual case) need neither the checks of
        # principal_axes nor its rotation; a tensor, a Quantity or anything else does.
        moments = _three_floats(inertia)
        self._axes: PrincipalAxes | None = None
        if moments is None or not (moments[0] > 0.0 and moments[1] > 0.0 and moments[2] > 0.0):
            self._axes = principal_axes(inertia)
            moments = _three_floats(self._axes.moments)
            assert moments is not None
        self._moments = moments
        m_body = _three_floats(angular_momentum)
        if m_body is None:
            m_body = _three_floats(
                as_vector3(angular_momentum, "angular_momentum", "angular_momentum")
            )
            assert m_body is not None
        q0 = _attitude_quaternion(attitude)
        self._initial_attitude = attitude
        if type(t0) is float and math.isfinite(t0):
            self._t0 = t0
        else:
            self._t0 = as_si_scalar(t0, "time", "t0")
        self._initial_angular_momentum = m_body
        self._motion = self._solve(moments, m_body, q0, self._t0, self._axes)
        self._formula: CaseFormula = self._motion.formula
        self._G = self._motion.G
        I1, I2, I3 = self._motion.moments
        m1, m2, m3 = self._motion.preferred
        G = self._G
        x1, x2, x3 = (m1 / G, m2 / G, m3 / G) if G > 0.0 else (0.0, 0.0, 0.0)
        # 2T = G² Σ xj²/Ij; Python floats: an energy beyond the float range is inf.
        self._kinetic_energy = 0.5 * G * (G * (x1 * x1 / I1 + x2 * x2 / I2 + x3 * x3 / I3))

    @staticmethod
    def _solve(
        moments: tuple[float, float, float],
        m_body: tuple[float, float, float],
        q0: tuple[float, float, float, float],
        t0: float,
        axes: PrincipalAxes | None,
    ) -> Motion:
        """The state's ``Motion`` (attitude.solver.float_backend.motion): its case,
        formula and frame, and the constant rotations.

        Refuses a state whose angular velocity |m|/I1 is beyond the float range.
        """
        V = None if axes is None or axes.is_diagonal else axes.body_to_principal
        momentum = m_body
        if V is not None:
            a, b, c = V.apply(np.array(m_body)).tolist()
            momentum = (a, b, c)
        G = math.hypot(*momentum)  # math.hypot scales: no overflow of the squares
        if not math.isfinite(G / min(moments)):
            raise InputError(
                f"angular_momentum {list(m_body)} with moments {list(moments)}: the "
                f"angular velocity |m|/I1 = {G / min(moments):g} rad/s is beyond the float range"
            )
        return float_backend.motion(moments, momentum, q0, t0, V)

    @property
    def _principal_axes(self) -> PrincipalAxes:
        """The inertia's principal axes (made at first use for three plain moments)."""
        if self._axes is None:
            self._axes = principal_axes(np.array(self._moments))
        return self._axes

    @classmethod
    def from_angular_velocity(
        cls,
        inertia: ArrayLike,
        angular_velocity: ArrayLike,
        attitude: Rotation | None = None,
        t0: float = 0.0,
    ) -> EulerSolver:
        """Build the solver from the body angular velocity at ``t0`` (rad/s)."""
        moments, ω = _three_floats(inertia), _three_floats(angular_velocity)
        if moments is not None and ω is not None and min(moments) > 0.0:
            # tensor @ ω of a diagonal tensor, term by term
            m = [moments[0] * ω[0], moments[1] * ω[1], moments[2] * ω[2]]
            return cls(moments, m, attitude, t0)
        tensor = principal_axes(inertia).tensor
        ω_array = as_vector3(angular_velocity, "angular_velocity", "angular_velocity")
        return cls(inertia, tensor @ ω_array, attitude, t0)

    # ----------------------------------------------------------------- evaluation

    def _times(self, t: Any) -> NDArray[np.float64]:
        """``t`` as float seconds (no copy of a float64 array); τ = t − t0 is formed a
        slice at a time by the backends."""
        return as_si_array(t, "time", "t")

    def _too_far(self, t: Any, index: int) -> InputError:
        """Far enough from t0 (|t − t0| beyond ~1.8e308 divided by the motion's fastest
        angular rate) an angle λ(t − t0) or ψ(t) leaves the float range and the result
        would be NaN: that time gets an InputError that names it instead."""
        t_bad = np.ravel(as_si_array(t, "time", "t"))[index] if np.ndim(t) else t
        return InputError(
            f"t = {float(t_bad)!r} s is too far from t0 = {self._t0!r} s for this motion: "
            f"its angles, at rates up to {self._motion.fastest_rate:.3g} rad/s, times t - t0 "
            "exceed the float range (1.8e308)"
        )

    @property
    def _table(self) -> PiecewiseChebyshev | None:
        """The table of ψ's periodic part (attitude.solver.table_backend), if a call
        has built one."""
        return self._motion.table.per if self._motion.table else None

    def _body_vectors(self, t: Any, velocity: bool) -> NDArray[np.float64]:
        """The body momentum (or angular velocity) at ``t``, shape ``np.shape(t) + (3,)``."""
        if isinstance(t, float) and math.isfinite(t):  # one time: no numpy on the way
            try:
                return float_backend.body_vector(
                    self._motion, t - self._t0, self._motion.I_frame_floats if velocity else None
                )
            except NotRepresentable:
                raise self._too_far(t, 0) from None
        times = self._times(t)
        try:
            backend = select(1, times.size, self._formula)
            assert backend is not None  # one state
            out = backend.body_vectors(self._motion, times.ravel(), velocity)
        except NotRepresentable as error:
            raise self._too_far(t, error.index) from None
        return out.reshape((*times.shape, 3))

    def angular_momentum(self, t: ArrayLike) -> NDArray[np.float64]:
        """Body-frame angular momentum at ``t`` (N m s), shape ``np.shape(t) + (3,)``."""
        return self._body_vectors(t, velocity=False)

    def angular_velocity(self, t: ArrayLike) -> NDArray[np.float64]:
        """Body-frame angular velocity at ``t`` (rad/s), shape ``np.shape(t) + (3,)``."""
        return self._body_vectors(t, velocity=True)

    def attitude(self, t: ArrayLike) -> Rotation:
        """Rotation taking body coordinates to inertial coordinates at ``t``.

        One ``Rotation`` for a scalar ``t``, a stack for a 1-D array.
        """
        if isinstance(t, float) and math.isfinite(t):  # one time: no numpy on the way
            w, x, y, z = self._quaternion_at(t, t)
            return _one_rotation(np.array([x, y, z, w]))
        times = self._times(t)
        if times.ndim > 1:
            raise InputError(
                f"t must be a scalar or a 1-D array for attitude(), got shape {times.shape}"
            )
        if times.ndim == 0:
            w, x, y, z = self._quaternion_at(float(times), t)
            return _one_rotation(np.array([x, y, z, w]))
        # Unit quaternions, scalar last: scipy takes them as they are, without a copy.
        return Rotation(self._quaternions(t, times, (3, 0, 1, 2)), normalize=False, copy=False)

    def attitude_quaternion(self, t: ArrayLike, scalar_first: bool = True) -> NDArray[np.float64]:
        """The attitude at ``t`` as unit quaternions, body → inertial, shape ``np.shape(t) + (4,)``.

        Scalar first (w, x, y, z) by default.  The same rotation as ``attitude(t)``,
        without building a ``Rotation``: for writing files and for callers that
        assemble many segments.
        """
        columns = (0, 1, 2, 3) if scalar_first else (3, 0, 1, 2)
        times = np.float64(t) if isinstance(t, float) and math.isfinite(t) else self._times(t)
        if times.ndim == 0:
            q = self._quaternion_at(float(times), t)
            return np.array(q if scalar_first else (q[1], q[2], q[3], q[0]))
        return self._quaternions(t, times, columns)

    def _quaternion_at(self, t_float: float, t: Any) -> tuple[float, float, float, float]:
        """The unit attitude quaternion (w, x, y, z) at one time (the float backend)."""
        try:  # one time: the float backend (backends.select's rule 1)
            return float_backend.quaternion(self._motion, t_float - self._t0)
        except NotRepresentable:
            raise self._too_far(t, 0) from None

    def _quaternions(self, t: Any, times: NDArray[np.float64], columns: tuple) -> NDArray:
        """The attitude quaternions at an array of times (the numpy or table backend)."""
        backend = select(1, times.size, self._formula)
        assert backend is not None  # one state
        try:
            q = backend.quaternions(self._motion, times.ravel(), columns)
        except NotRepresentable as error:
            raise self._too_far(t, error.index) from None
        return q.reshape((*times.shape, 4))

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
        axis = np.dot(np.array([0.0, 0.0, 1.0]), self._motion.S_matrix)  # v_frame @ S
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
        I1, I2, I3 = self._motion.moments
        if not (I1 < I2 < I3) or not isinstance(f, Elliptic | Separatrix) or f.λ == 0.0:
            return None
        if not math.isfinite(f.ν):  # a steady spin about the intermediate axis
            return None
        # The amplitude of m2 is |A_s| = B21 (case i) or B23 (case ii).
        if isinstance(f, Elliptic) and abs(f.A_s) <= self._G * math.sqrt(0.5):
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
        if not isinstance(f, Elliptic):  # the separatrix (phases are None otherwise)
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
        phases = self._flip_phases(t_start, t_end)
        if count == 0 or phases is None:
            return np.empty(0)
        u_a, _ = phases
        f = self._formula
        if isinstance(f, Separatrix):
            zeros_u = np.array([0.0])
        elif isinstance(f, Elliptic):
            zeros_u = 2.0 * f.K * (float(math.ceil(u_a / (2.0 * f.K))) + np.arange(count))
        else:  # pragma: no cover (phases are None for the other cases)
            return np.empty(0)
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
        return np.array(self._moments)

    @property
    def inertia_tensor(self) -> NDArray[np.float64]:
        """The inertia tensor in body axes, kg m²."""
        return self._principal_axes.tensor.copy()

    @property
    def initial_angular_momentum(self) -> NDArray[np.float64]:
        """Body-frame angular momentum at ``t0``, N m s."""
        return np.array(self._initial_angular_momentum)

    @property
    def initial_attitude(self) -> Rotation:
        """Attitude (body → inertial) at ``t0``."""
        if self._initial_attitude is None:
            self._initial_attitude = Rotation.identity()
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
            I1, I2, I3 = self._motion.moments
            m1, m2, m3 = self._motion.preferred
            G = self._G
            x2_over_I = (m1 / G) ** 2 / I1 + (m2 / G) ** 2 / I2 + (m3 / G) ** 2 / I3
            log10_T = 2.0 * math.log10(G) + math.log10(0.5 * x2_over_I)
            raise InputError(
                f"the kinetic energy of angular_momentum {list(self._initial_angular_momentum)}"
                f" with moments {list(self._moments)}, about 1e{log10_T:.0f} J, is "
                "beyond the float range"
            )
        return self._kinetic_energy

    @property
    def inertial_angular_momentum(self) -> NDArray[np.float64]:
        """The angular momentum in inertial axes, N m s (conserved)."""
        return self.initial_attitude.apply(np.array(self._initial_angular_momentum))

    def __repr__(self) -> str:
        return (
            f"EulerSolver(inertia={list(self._moments)}, "
            f"angular_momentum={list(self._initial_angular_momentum)}, t0={self._t0}, "
            f"formula={self.formula!r}, period={self.period:.6g} s)"
        )
