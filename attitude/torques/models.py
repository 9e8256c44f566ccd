"""External torques on a rigid spacecraft: gravity gradient, constant torques, user torques.

These are the "kick" half of the splitting in :mod:`attitude.torques.solver`: over a kick
the attitude and the clock are frozen and the body angular momentum changes by the
integral of the torque.  For every torque that depends only on the time and the
attitude (gravity gradient, a constant torque, a user torque of (t, attitude)), the
torque Γ is then constant over the kick, and m ← m + h Γ is the *exact* flow of the
kick: no approximation enters but the splitting itself.  A torque that depends on the
angular velocity (a damper) changes during its own kick; its kick is integrated by
the classical Runge–Kutta method (4 evaluations, local error O(h⁵)), which caps the
order of the whole solver at 4 (see :class:`UserTorque`).

Frames and units: torques in N m; the solver works in the principal axes of the body,
and a model is asked for its torque there (:meth:`Torque.principal_torque`), given the
attitude quaternion q = (w, x, y, z) of the rotation principal axes → inertial and
the angular velocity ω in principal axes.  ``PrincipalFrame`` carries the principal
moments and the rotation between the user's body axes and the principal axes.

Vectors inside a kick are passed as tuples of components, each a float (one
spacecraft: pure-Python arithmetic, a few µs a kick) or an array of N values (a batch):
the same formula serves both.

References
----------
[Wertz1978] J. R. Wertz (ed.), Spacecraft Attitude Determination and Control, D. Reidel,
    1978, §17.2 (environmental torques: the gravity-gradient torque).
[Hughes1986] P. C. Hughes, Spacecraft Attitude Dynamics, Wiley, 1986 (Dover, 2004),
    ch. 8 (gravitational torques) and ch. 9 (gravity-gradient stabilization).
[IERS2010] G. Petit, B. Luzum (eds.), IERS Conventions (2010), IERS Technical Note 36,
    table 1.1: GM of the Earth 3.986004418e14 m³/s².
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.base.quantities import as_si_array, as_si_scalar, as_vector3

__all__ = [
    "MU_EARTH_M3_S2",
    "ConstantTorque",
    "ConstantTorqueSchedule",
    "GravityGradient",
    "PrincipalFrame",
    "Torque",
    "UserTorque",
    "as_torque_list",
    "merged_constant_torques",
]

MU_EARTH_M3_S2 = 3.986004418e14  # [IERS2010] table 1.1

Components = tuple[Any, ...]  # floats, or equal-length 1-D arrays


def rotate_into_principal(q: Components, v: Components) -> Components:
    """Components in principal axes of the inertial vector v, for the attitude q.

    q = (w, x, y, z), a unit quaternion of the rotation principal → inertial; the
    inverse rotation is v' = v − 2w (u × v) + 2 u × (u × v), u = (x, y, z).
    """
    w, x, y, z = q
    vx, vy, vz = v
    cx, cy, cz = y * vz - z * vy, z * vx - x * vz, x * vy - y * vx
    return (
        vx - 2.0 * w * cx + 2.0 * (y * cz - z * cy),
        vy - 2.0 * w * cy + 2.0 * (z * cx - x * cz),
        vz - 2.0 * w * cz + 2.0 * (x * cy - y * cx),
    )


@dataclass(frozen=True)
class PrincipalFrame:
    """The body's principal moments and the rotation between body and principal axes.

    ``moments``: (I1, I2, I3), kg m², about principal axes 1, 2, 3 (floats, or arrays
    of N values for a batch).  ``principal_to_body``: the 3×3 matrix M with
    v_body = M v_principal, or None when the body axes are the principal axes.
    """

    moments: Components
    principal_to_body: NDArray[np.float64] | None = None

    def to_body(self, v: Components) -> Components:
        if self.principal_to_body is None:
            return v
        M = self.principal_to_body
        return tuple(M[i, 0] * v[0] + M[i, 1] * v[1] + M[i, 2] * v[2] for i in range(3))

    def to_principal(self, v: Components) -> Components:
        if self.principal_to_body is None:
            return v
        M = self.principal_to_body
        return tuple(M[0, i] * v[0] + M[1, i] * v[1] + M[2, i] * v[2] for i in range(3))

    def body_attitude(self, q: Components) -> Rotation:
        """The attitude body → inertial, from q (principal → inertial)."""
        q_array = np.stack(np.broadcast_arrays(*q), axis=-1)
        attitude = Rotation.from_quat(q_array, scalar_first=True)
        if self.principal_to_body is None:
            return attitude
        return attitude * Rotation.from_matrix(self.principal_to_body.T)


class Torque:
    """A torque model for :class:`attitude.torques.solver.TorquedSolver`.

    A model splits its work in two, so that the time-dependent part (an orbit
    position, say) is computed once for many kicks, vectorized:

    - ``time_data(t, t_step)``: for kicks at clock times ``t`` (M,) inside steps whose
      midpoints are ``t_step`` (M,), an array (M, ``data_width``) of whatever the
      torque needs that depends only on time;
    - ``principal_torque(data, q, ω, frame)``: the torque in principal axes for one
      row of that array (as a tuple of components), the attitude q (principal →
      inertial) and the angular velocity ω (principal axes).

    ``breakpoints``: times where the torque jumps; the solver ends a step there.
    ``depends_on_angular_velocity``: False if the torque is a function of the time and
    the attitude only (then a kick is exact).
    """

    data_width: int = 1
    depends_on_angular_velocity: bool = False

    @property
    def breakpoints(self) -> tuple[float, ...]:
        return ()

    def time_data(self, t: NDArray[np.float64], t_step: NDArray[np.float64]) -> NDArray[np.float64]:
        raise NotImplementedError

    def principal_torque(
        self, data: Components, q: Components, ω: Components, frame: PrincipalFrame
    ) -> Components:
        raise NotImplementedError


class GravityGradient(Torque):
    """Gravity-gradient torque of a point-mass central body on the spacecraft.

    Γ_body = (3μ/r³) r̂_b × (I r̂_b)   ([Wertz1978] §17.2, [Hughes1986] ch. 8)

    with r̂_b the unit vector from the body's centre to the spacecraft, in body axes,
    and I the inertia tensor.  In principal axes this reads Γ1 = (3μ/r³)(I3 − I2) r2 r3
    and cyclically.  It is the torque of the potential V = (μ/2r³)(3 r̂ᵀ I r̂ − tr I)
    (MacCullagh's formula, the first term of the expansion in the body's size over
    r), so a kick is a symplectic map and the splitting a Poisson integrator.

    ``position``: where the spacecraft is, in inertial axes (m), as

    - a callable t → position, t in seconds of the solver's time (an array), returning
      shape ``t.shape + (3,)``; or
    - an orbit object with a ``position(times)`` or ``position_velocity(times)``
      method taking ``astropy.time.Time`` (e.g. :class:`attitude.environment.orbit.TleOrbit`);
      then ``epoch`` (an ``astropy.time.Time``, default the orbit's own ``epoch``) is
      the instant that the solver's t = 0 stands for.

    ``mu``: gravitational parameter μ of the central body, m³/s² (Earth: IERS 2010).

    Not modelled: the oblateness of the central body (J2 in the gradient, a relative
    change of order J2 (R/r)² ~ 1e-3 in LEO), and the next term of the expansion in the
    body's size (its ratio to this one is ~ size/r ~ 1e-6).
    """

    data_width = 4  # (ux, uy, uz, 3μ/r³): the inertial unit position and the factor

    def __init__(self, position: Any, mu: float = MU_EARTH_M3_S2, *, epoch: Any = None) -> None:
        self.mu = as_si_scalar(_without_unit(mu, "m3 / s2", "mu"), "length", "mu")
        if not self.mu > 0.0:
            raise InputError(f"mu must be positive (m^3/s^2), got {self.mu}")
        self._position = _position_function(position, epoch)
        self.source = position

    def __repr__(self) -> str:
        return f"GravityGradient({self.source!r}, mu={self.mu!r})"

    def position(self, t: ArrayLike) -> NDArray[np.float64]:
        """Inertial position (m) at the solver times ``t`` (s), shape ``t.shape + (3,)``."""
        t = np.asarray(t, dtype=np.float64)
        r = np.asarray(self._position(t), dtype=np.float64)
        if r.shape != (*t.shape, 3):
            raise InputError(
                f"GravityGradient position: {self.source!r} returned shape {r.shape} for "
                f"times of shape {t.shape}; expected {(*t.shape, 3)} (metres, inertial axes)"
            )
        radius = np.linalg.norm(r, axis=-1)
        bad = ~(np.isfinite(radius) & (radius > 0.0))
        if np.any(bad):
            index = np.unravel_index(np.argmax(bad), radius.shape)
            raise InputError(
                f"GravityGradient position: {self.source!r} gave {r[index].tolist()} m at "
                f"t = {t[index]!r} s; a position must be finite and away from the centre"
            )
        return r

    def time_data(self, t: NDArray[np.float64], t_step: NDArray[np.float64]) -> NDArray[np.float64]:
        r = self.position(t)
        radius = np.linalg.norm(r, axis=-1, keepdims=True)
        return np.concatenate([r / radius, 3.0 * self.mu / radius**3], axis=-1)

    def principal_torque(
        self, data: Components, q: Components, ω: Components, frame: PrincipalFrame
    ) -> Components:
        ux, uy, uz, k = data
        r1, r2, r3 = rotate_into_principal(q, (ux, uy, uz))
        I1, I2, I3 = frame.moments
        return (k * (I3 - I2) * r2 * r3, k * (I1 - I3) * r3 * r1, k * (I2 - I1) * r1 * r2)

    def potential(self, t: ArrayLike, attitude: Rotation, inertia_tensor: ArrayLike) -> NDArray:
        """V = (μ/2r³)(3 r̂_bᵀ I r̂_b − tr I), J: the energy whose gradient is the torque.

        ``attitude``: body → inertial at ``t`` (one rotation, or a stack matching t);
        ``inertia_tensor``: 3×3 in body axes, kg m².  For conservation checks: on a
        circular orbit, T + V − n·H_inertial is constant (the Jacobi integral).
        """
        r = self.position(t)
        radius = np.linalg.norm(r, axis=-1)
        r_hat_body = attitude.inv().apply(r / radius[..., None])
        tensor = np.asarray(inertia_tensor, dtype=np.float64)
        quadratic = np.einsum("...i,ij,...j->...", r_hat_body, tensor, r_hat_body)
        return 0.5 * self.mu / radius**3 * (3.0 * quadratic - np.trace(tensor))


class ConstantTorque(Torque):
    """A constant torque over [start, stop): a finite thruster burn, a spin-up.

    ``torque``: N m, fixed in the body axes (``frame="body"``) or in inertial axes
    (``frame="inertial"``); ``start``, ``stop``: seconds of the solver's time
    (``stop`` may be ``math.inf``).  The solver ends a step at ``start`` and ``stop``,
    so that no step straddles a switch; inside a step the torque is on or off for all
    of its kicks (negative splitting coefficients put some kick clocks slightly outside
    the step, where the torque continues as it is inside).  An inertial torque changes
    the inertial angular momentum by exactly torque × duration, whatever the step; a
    body-fixed one by ∫ R(t) Γ dt, to the method's order.
    """

    data_width = 4  # (Γx, Γy, Γz, on) with Γ in the model's frame, on ∈ {0, 1}

    def __init__(self, torque: ArrayLike, start: float, stop: float, frame: str = "body") -> None:
        self.torque = as_vector3(_without_unit(torque, "N m", "torque"), "length", "torque")
        self.start = as_si_scalar(start, "time", "start")
        self.stop = float(as_si_array(stop, "time", "stop", allow_nonfinite=True))
        if not (self.stop > self.start) or math.isnan(self.stop):
            raise InputError(f"stop must be after start, got start={self.start}, stop={self.stop}")
        if frame not in ("body", "inertial"):
            raise InputError(f"frame must be 'body' or 'inertial', got {frame!r}")
        self.frame = frame

    def __repr__(self) -> str:
        return (
            f"ConstantTorque({self.torque.tolist()}, start={self.start}, stop={self.stop}, "
            f"frame={self.frame!r})"
        )

    @property
    def breakpoints(self) -> tuple[float, ...]:
        return (self.start, self.stop) if math.isfinite(self.stop) else (self.start,)

    def time_data(self, t: NDArray[np.float64], t_step: NDArray[np.float64]) -> NDArray[np.float64]:
        on = ((t_step >= self.start) & (t_step < self.stop)).astype(np.float64)
        return np.concatenate([on[:, None] * self.torque, on[:, None]], axis=-1)

    def principal_torque(
        self, data: Components, q: Components, ω: Components, frame: PrincipalFrame
    ) -> Components:
        torque = data[:3]
        if self.frame == "inertial":
            return rotate_into_principal(q, torque)
        return frame.to_principal(torque)


class ConstantTorqueSchedule(Torque):
    """Many :class:`ConstantTorque` s as one model: their sum, piecewise constant.

    The solver kicks with every model at every kick, so N burns as N models cost N
    torque evaluations a kick, over a grid that has about 2N breakpoints more: a cost
    that grows as N².  Their sum is constant between consecutive switches; this model
    holds it per elementary interval [e_j, e_j+1) (body and inertial parts apart) and
    finds the interval of a step by bisection, so a kick costs the same for one burn
    as for a thousand.  The sums are exact sums of the torques on in that interval
    (``math.fsum``): after the last burn the torque is exactly zero.  The switch rule
    is :class:`ConstantTorque`'s: a torque is on for a whole step when the step's
    midpoint lies in [start, stop).
    """

    data_width = 6  # (body Γx, Γy, Γz, inertial Γx, Γy, Γz), each the sum of those on

    def __init__(self, torques: Sequence[ConstantTorque]) -> None:
        self.torques = tuple(torques)
        if not self.torques or not all(isinstance(t, ConstantTorque) for t in self.torques):
            raise InputError("ConstantTorqueSchedule needs one or more ConstantTorque")
        edges = sorted({b for t in self.torques for b in (t.start, t.stop)})
        self._edges = np.array(edges, dtype=np.float64)
        # Sweep the edges: the torques on over [e_j, e_j+1), summed exactly.
        starts = sorted(range(len(self.torques)), key=lambda i: self.torques[i].start)
        on: set[int] = set()
        sums = np.zeros((len(edges), 6))
        k = 0
        for j, edge in enumerate(edges):
            on = {i for i in on if self.torques[i].stop > edge}
            while k < len(starts) and self.torques[starts[k]].start <= edge:
                if self.torques[starts[k]].stop > edge:
                    on.add(starts[k])
                k += 1
            for offset, frame in ((0, "body"), (3, "inertial")):
                chosen = [self.torques[i].torque for i in on if self.torques[i].frame == frame]
                if chosen:
                    sums[j, offset : offset + 3] = [
                        math.fsum(v[c] for v in chosen) for c in range(3)
                    ]
        self._sums = sums
        self._body = bool(np.any(sums[:, :3]))
        self._inertial = bool(np.any(sums[:, 3:]))

    def __repr__(self) -> str:
        return f"ConstantTorqueSchedule({len(self.torques)} torques)"

    @property
    def breakpoints(self) -> tuple[float, ...]:
        return tuple(float(e) for e in self._edges if math.isfinite(e))

    def time_data(self, t: NDArray[np.float64], t_step: NDArray[np.float64]) -> NDArray[np.float64]:
        j = np.searchsorted(self._edges, t_step, side="right") - 1
        out = np.zeros((np.shape(t_step)[0], 6))
        inside = j >= 0  # before the first switch, nothing is on
        out[inside] = self._sums[j[inside]]
        return out

    def principal_torque(
        self, data: Components, q: Components, ω: Components, frame: PrincipalFrame
    ) -> Components:
        if not self._body:
            return rotate_into_principal(q, data[3:])
        body = frame.to_principal(data[:3])
        if not self._inertial:
            return body
        inertial = rotate_into_principal(q, data[3:])
        return (body[0] + inertial[0], body[1] + inertial[1], body[2] + inertial[2])


def merged_constant_torques(torques: Sequence[Torque]) -> list[Torque]:
    """``torques`` with every :class:`ConstantTorque` gathered into one
    :class:`ConstantTorqueSchedule` (in the place of the first), for the solver's kicks;
    a single one is left as it is."""
    constant = [t for t in torques if isinstance(t, ConstantTorque)]
    if len(constant) < 2:
        return list(torques)
    merged: list[Torque] = []
    for torque in torques:
        if not isinstance(torque, ConstantTorque):
            merged.append(torque)
        elif torque is constant[0]:
            merged.append(ConstantTorqueSchedule(constant))
    return merged


class UserTorque(Torque):
    """Any torque, from a Python function: magnetic, dampers, solar pressure, drag.

    ``function(t, attitude, angular_velocity) -> torque``: ``t`` in seconds of the
    solver's time, ``attitude`` a ``Rotation`` (body → inertial), ``angular_velocity``
    in body axes (rad/s); returns the torque in body axes (N m).  Called with one state
    (t a float, ω of shape (3,)) unless ``vectorized=True``, in which case it may also
    receive N states at once (t of shape (N,) or a float, a stack of N rotations, ω
    (N, 3)) and must return (N, 3).

    ``depends_on_angular_velocity``: say False if the torque is a function of (t,
    attitude) only; then each kick is exact and the solver keeps its full order.  If
    True (the default, the safe assumption), the angular velocity changes during the
    kick, whose own equation dm/dt = Γ(t, R, I⁻¹m) at frozen R and t is integrated by
    the classical Runge–Kutta method: the solver's order is then at most 4, and the
    order-6 method, which needs a kick independent of m, is refused.

    ``breakpoints``: times where the torque jumps (the solver ends steps there).  Between
    them it must be smooth in t, and defined slightly outside each step (negative
    splitting coefficients evaluate it there), which a smooth formula is.
    """

    data_width = 1  # the time

    def __init__(
        self,
        function: Callable[..., ArrayLike],
        *,
        depends_on_angular_velocity: bool = True,
        vectorized: bool = False,
        breakpoints: Sequence[float] = (),
        name: str | None = None,
    ) -> None:
        if not callable(function):
            raise InputError(f"UserTorque needs a callable, got {type(function).__name__}")
        self.function = function
        self.depends_on_angular_velocity = bool(depends_on_angular_velocity)
        self.vectorized = bool(vectorized)
        self._breakpoints = tuple(
            as_si_scalar(b, "time", "breakpoints") for b in np.atleast_1d(breakpoints)
        )
        self.name = name or getattr(function, "__name__", repr(function))

    def __repr__(self) -> str:
        return f"UserTorque({self.name})"

    @property
    def breakpoints(self) -> tuple[float, ...]:
        return self._breakpoints

    def time_data(self, t: NDArray[np.float64], t_step: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.asarray(t, dtype=np.float64)[:, None]

    def principal_torque(
        self, data: Components, q: Components, ω: Components, frame: PrincipalFrame
    ) -> Components:
        (t,) = data
        attitude = frame.body_attitude(q)
        ω_body = np.stack(np.broadcast_arrays(*frame.to_body(ω)), axis=-1)
        if attitude.single:
            torque = self._call(float(t), attitude, ω_body)
        elif self.vectorized:
            torque = self._call(t, attitude, ω_body, n=len(attitude))
        else:
            times = np.broadcast_to(np.asarray(t, dtype=np.float64), (len(attitude),))
            torque = np.array(
                [self._call(float(times[i]), attitude[i], ω_body[i]) for i in range(len(attitude))]
            )
        return frame.to_principal(tuple(torque[..., i] for i in range(3)))

    def _call(self, t, attitude: Rotation, ω: NDArray[np.float64], n: int | None = None):
        torque = np.asarray(self.function(t, attitude, ω), dtype=np.float64)
        expected = (3,) if n is None else (n, 3)
        if torque.shape != expected or not np.all(np.isfinite(torque)):
            shown = torque.tolist() if torque.size <= 6 else torque.shape
            raise InputError(
                f"UserTorque {self.name}: returned {shown} at "
                f"t = {t!r}; expected a finite torque of shape {expected} (N m, body axes)"
            )
        return torque


def as_torque_list(torques: Any) -> list[Torque]:
    """The torques of a solver: Torque models, or bare callables taken as UserTorque."""
    if torques is None:
        return []
    if isinstance(torques, Torque) or callable(torques):
        torques = [torques]
    out = []
    for index, item in enumerate(torques):
        if isinstance(item, Torque):
            out.append(item)
        elif callable(item):
            out.append(UserTorque(item))
        else:
            raise InputError(
                f"torques[{index}] must be a Torque (GravityGradient, ConstantTorque, "
                f"UserTorque) or a callable torque(t, attitude, angular_velocity), got {item!r}"
            )
    return out


def _without_unit(value: Any, unit: str, name: str) -> Any:
    """An astropy Quantity converted to ``unit``; anything else as it is.

    (The kinds of attitude.base.quantities have no torque or gravitational parameter.)
    """
    if not (hasattr(value, "unit") and hasattr(value, "to_value")):
        return value
    from astropy import units as u

    try:
        return value.to_value(u.Unit(unit))
    except u.UnitConversionError as exc:
        raise InputError(
            f"{name} has unit {value.unit!s}, which cannot be converted to {unit}"
        ) from exc


def _position_function(position: Any, epoch: Any) -> Callable[[NDArray], NDArray]:
    """t (solver seconds) → inertial position (m), from a callable or an orbit object."""
    method = getattr(position, "position", None)
    if method is None:
        pair = getattr(position, "position_velocity", None)
        if pair is not None:

            def method(times):
                return pair(times)[0]

    if method is not None and callable(method):
        if epoch is None:
            epoch = getattr(position, "epoch", None)
        if epoch is None:
            raise InputError(
                f"GravityGradient: an orbit {position!r} needs epoch=, the astropy Time "
                "that t = 0 stands for"
            )

        def from_orbit(t: NDArray[np.float64]) -> NDArray[np.float64]:
            from astropy import units as u  # only for orbit objects: keeps this layer light

            return np.asarray(method(epoch + np.asarray(t) * u.s), dtype=np.float64)

        return from_orbit
    if callable(position):
        return position
    raise InputError(
        "GravityGradient position must be a callable t -> inertial position (m) or an orbit "
        f"with a position(times) or position_velocity(times) method, got {position!r}"
    )
