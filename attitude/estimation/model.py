"""The motion the fit adjusts: its parameters, and the predicted rates and attitudes with
their Jacobian.

Parameters (the vector ``x``, in this order; each block present or not, ``Layout``):

- ``θ`` (3): the attitude at t = 0, body → ICRF, as Q0 = Q_ref exp([θ]×) (body axes);
  only when attitude quaternions are fitted (gyro rates alone cannot see it);
- ``w`` (3): the body angular velocity at t = 0 in the telemetry's body axes, in units
  of ``rate_unit`` (a power of two near the rate: every parameter is then of order one,
  whatever the units of the telemetry);
- ``ρ`` (2): the logarithms of the second and third principal moments over the first,
  J = e^σ (1, e^ρ2, e^ρ3) along the principal axes;
- ``σ`` (1): the logarithm of the first moment in kg m², only when the absolute moments
  are observable (a known angular impulse or burn in the arc); otherwise J1 = 1 and the
  moments are in units of the first;
- ``α`` (3): the principal axes, A = A_ref exp([α]×) taking principal to body axes,
  only when the fit estimates them (a misaligned gyro or star tracker);
- ``b`` (3): a constant gyro bias, in units of ``rate_unit``, added to the predicted
  rates, only when the fit estimates it.

Logarithms keep the moments positive; a rotation vector about a reference that the fit
moves between its stages (``recentred``) keeps the attitude and the axes away from
their singularities.

``ExactModel`` is the torque-free motion with known angular impulses and burns:
``EulerSolver`` between them, and the Jacobian from the exact flow's sensitivities
(attitude.solver.sensitivities) chained through each impulse by the chain rule, and
across each burn by the variational equations integrated with the motion
(attitude.estimation.burns).
``ScenarioModel`` (attitude.estimation.scenario_model) is the same interface over a
propagated scenario (gravity gradient), with a finite-difference Jacobian.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.environment.timescales import SAME_INSTANT_S
from attitude.estimation.burns import KnownBurn, burn_flow, torque_pieces
from attitude.solver.euler_solver import EulerSolver
from attitude.solver.sensitivities import flow_sensitivities, skew

__all__ = [
    "ExactModel",
    "Impulse",
    "Layout",
    "Prediction",
    "left_jacobian_inverse",
    "right_jacobian",
]


def right_jacobian(φ: NDArray[np.float64]) -> NDArray[np.float64]:
    """J_r(φ) of SO(3): exp([φ + dφ]×) = exp([φ]×) exp([J_r(φ) dφ]×) to first order."""
    angle = float(np.linalg.norm(φ))
    K = skew(φ)
    if angle < 1e-8:
        return np.eye(3) - 0.5 * K
    a = (1.0 - np.cos(angle)) / angle**2
    b = (angle - np.sin(angle)) / angle**3
    return np.eye(3) - a * K + b * (K @ K)


def _inside(times: NDArray[np.float64] | None, lo: float, hi: float) -> NDArray[np.intp] | None:
    """The indices of ``times`` in [lo, hi), or None (no times, or none there)."""
    if times is None:
        return None
    inside = np.flatnonzero((times >= lo) & (times < hi))
    return inside if inside.size else None


def left_jacobian_inverse(r: NDArray[np.float64]) -> NDArray[np.float64]:
    """J_l(r)⁻¹ for each row of r (N, 3): log(exp([a]×) exp([r]×)) = r + J_l(r)⁻¹ a."""
    angle = np.linalg.norm(r, axis=1)
    K = skew(r)
    with np.errstate(divide="ignore", invalid="ignore"):
        c = np.where(
            angle < 1e-6,
            1.0 / 12.0,
            1.0 / angle**2 - (1.0 + np.cos(angle)) / (2.0 * angle * np.sin(angle)),
        )
    return np.eye(3) - 0.5 * K + c[:, None, None] * (K @ K)


# Times evaluated at once for the Jacobian (a bound on the memory of a long arc).
_CHUNK = 65_536

# One solver's stretch of a prediction: m_p (N, 3), Q_p (a Rotation, or None when the
# attitude is not needed) and ∂(δθ_p, m_p)/∂x (N, 6, n, or None without the Jacobian).
_Piece = tuple[NDArray[np.float64], Rotation | None, NDArray[np.float64] | None]


@dataclass(frozen=True)
class Impulse:
    """A known angular impulse: at ``t`` (s from t = 0), ``vector`` (N m s) in body axes
    or in ICRF axes (``frame``), as a scenario's ``angular_impulse`` event."""

    t: float
    vector: NDArray[np.float64]
    frame: str = "body"


@dataclass(frozen=True)
class Layout:
    """Which parameter blocks the fit adjusts, and where they sit in ``x``."""

    attitude: bool
    scale: bool
    axes: bool
    bias: bool = False

    @property
    def size(self) -> int:
        return 5 + 3 * self.attitude + self.scale + 3 * self.axes + 3 * self.bias

    def block(self, name: str) -> slice:
        start = 0
        for key, width, present in (
            ("θ", 3, self.attitude),
            ("w", 3, True),
            ("ρ", 2, True),
            ("σ", 1, self.scale),
            ("α", 3, self.axes),
            ("b", 3, self.bias),
        ):
            if key == name:
                return slice(start, start + width) if present else slice(start, start)
            start += width * present
        raise KeyError(name)

    def names(self) -> list[str]:
        out = []
        if self.attitude:
            out += ["theta_x", "theta_y", "theta_z"]
        out += ["omega_x", "omega_y", "omega_z", "ln_J2_over_J1", "ln_J3_over_J1"]
        if self.scale:
            out += ["ln_J1"]
        if self.axes:
            out += ["axes_x", "axes_y", "axes_z"]
        if self.bias:
            out += ["bias_x", "bias_y", "bias_z"]
        return out


@dataclass
class Prediction:
    """Rates (N, 3) and attitudes at the requested times, with their Jacobians:
    ``dω`` (N, 3, n) and ``dθ`` (N, 3, n), the attitude's as a body-axes rotation
    vector (Q → Q exp([δθ]×))."""

    ω: NDArray[np.float64] | None = None
    dω: NDArray[np.float64] | None = None
    attitude: Rotation | None = None
    dθ: NDArray[np.float64] | None = None


@dataclass
class ExactModel:
    """The torque-free motion with known impulses (module docstring)."""

    layout: Layout
    impulses: tuple[Impulse, ...] = ()
    burns: tuple[KnownBurn, ...] = ()
    Q_ref: Rotation = field(default_factory=Rotation.identity)
    A_ref: Rotation = field(default_factory=Rotation.identity)
    rate_unit: float = 1.0  # rad/s

    # ------------------------------------------------------------------ parameters

    def start(self, moments: NDArray[np.float64], axes: Rotation, ω0, attitude) -> tuple:
        """(model, x) for a start: moments along the principal axes ``axes``
        (principal → body), body rate ω0 and attitude (None without quaternions)."""
        largest = float(np.max(np.abs(ω0)))
        unit = 2.0 ** round(np.log2(largest)) if largest > 0.0 else 1.0
        model = replace(self, Q_ref=attitude or Rotation.identity(), A_ref=axes, rate_unit=unit)
        x = np.zeros(self.layout.size)
        L = self.layout
        x[L.block("w")] = ω0 / unit
        x[L.block("ρ")] = np.log(moments[1:] / moments[0])
        if L.scale:
            x[L.block("σ")] = np.log(moments[0])
        return model, x

    def recentred(self, x: NDArray[np.float64]) -> tuple[ExactModel, NDArray[np.float64]]:
        """The same motion with the references moved to the current attitude and axes
        (their rotation vectors in ``x`` reset to zero)."""
        L = self.layout
        x = x.copy()
        Q_ref, A_ref = self.Q_ref, self.A_ref
        if L.attitude:
            Q_ref = Q_ref * Rotation.from_rotvec(x[L.block("θ")])
            x[L.block("θ")] = 0.0
        if L.axes:
            A_ref = A_ref * Rotation.from_rotvec(x[L.block("α")])
            x[L.block("α")] = 0.0
        return replace(self, Q_ref=Q_ref, A_ref=A_ref), x

    def rate(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """The body angular velocity at t = 0, rad/s."""
        return x[self.layout.block("w")] * self.rate_unit

    def moments(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """J along the principal axes (kg m² with a scale, else in units of J1)."""
        L = self.layout
        σ = x[L.block("σ")][0] if L.scale else 0.0
        ρ = x[L.block("ρ")]
        return np.exp(σ + np.array([0.0, ρ[0], ρ[1]]))

    def axes(self, x: NDArray[np.float64]) -> Rotation:
        """A: principal → body axes."""
        L = self.layout
        return self.A_ref * Rotation.from_rotvec(x[L.block("α")]) if L.axes else self.A_ref

    def initial_attitude(self, x: NDArray[np.float64]) -> Rotation:
        """Q0: body → ICRF at t = 0 (the reference alone without quaternions)."""
        L = self.layout
        return self.Q_ref * Rotation.from_rotvec(x[L.block("θ")]) if L.attitude else self.Q_ref

    def solver(self, x: NDArray[np.float64]) -> EulerSolver:
        """The motion up to the first impulse as an ``EulerSolver`` at t = 0, in the
        telemetry's body axes (a full tensor when the principal axes are rotated)."""
        J, R = self.moments(x), self.axes(x).as_matrix()
        ω0 = self.rate(x)
        if np.array_equal(R, np.eye(3)):
            return EulerSolver(J, J * ω0, self.initial_attitude(x))
        tensor = R @ np.diag(J) @ R.T
        tensor = 0.5 * (tensor + tensor.T)
        return EulerSolver(tensor, tensor @ ω0, self.initial_attitude(x))

    # ------------------------------------------------------------------ the motion

    def _initial(self, x: NDArray[np.float64]):
        """J, A, m_p(0), Q_p(0) and D0 = ∂(δθ_p(0), m_p(0), J)/∂x (9 × n)."""
        L = self.layout
        n = L.size
        J = self.moments(x)
        A = self.axes(x)
        Ar = A.as_matrix()
        ω_p = Ar.T @ self.rate(x)
        m_p = J * ω_p
        Q_p = self.initial_attitude(x) * A
        D = np.zeros((9, n))
        dlnJ = np.zeros((3, n))
        dlnJ[1, L.block("ρ").start] = 1.0
        dlnJ[2, L.block("ρ").start + 1] = 1.0
        if L.scale:
            dlnJ[:, L.block("σ").start] = 1.0
        dJ = J[:, None] * dlnJ
        D[6:9] = dJ
        D[3:6, L.block("w")] = J[:, None] * Ar.T * self.rate_unit
        D[3:6] += ω_p[:, None] * dJ
        if L.attitude:
            D[0:3, L.block("θ")] = Ar.T @ right_jacobian(x[L.block("θ")])
        if L.axes:
            Jr_α = right_jacobian(x[L.block("α")])
            D[0:3, L.block("α")] = Jr_α
            D[3:6, L.block("α")] = np.diag(J) @ skew(ω_p) @ Jr_α
        return J, A, m_p, Q_p, D

    def predict(
        self,
        x: NDArray[np.float64],
        t_rates: NDArray[np.float64] | None,
        t_attitude: NDArray[np.float64] | None,
        jacobian: bool = True,
    ) -> tuple[Prediction, Prediction]:
        """The body rates at ``t_rates`` and the attitudes at ``t_attitude`` (either
        may be None), with their Jacobians with respect to ``x`` if asked."""
        L = self.layout
        J, A, m_p, Q_p, D = self._initial(x)
        Ar = A.as_matrix()
        need_attitude = (
            t_attitude is not None
            or any(i.frame != "body" for i in self.impulses)
            or any(b.frame != "body" for b in self.burns)
        )
        rates, attitudes = Prediction(), Prediction()
        pieces: dict[str, list[tuple[NDArray[np.intp], _Piece]]] = {"rates": [], "attitude": []}
        wanted = {"rates": t_rates, "attitude": t_attitude}
        t0, lo = 0.0, -np.inf
        for t_end, torque, impulses in self._time_line():
            # A sample within a nanosecond before an impulse is at it, and after it (the
            # scenarios' rule: an epoch's outputs are the post-event state); a burn's
            # edges are where the motion is continuous.
            hi = t_end - SAME_INSTANT_S if impulses else t_end
            last = not math.isfinite(t_end)
            if torque is None:
                # One evaluation of the piece for every sample in it and its end (the
                # solver's constants and their gradients once).
                solver = EulerSolver(J, m_p, Q_p, t0)
                chosen = [
                    (name, inside)
                    for name, times in wanted.items()
                    if (inside := _inside(times, lo, hi)) is not None
                ]
                parts = [wanted[name][inside] for name, inside in chosen]  # type: ignore[index]
                if not last:
                    parts.append(np.array([t_end]))
                if parts:
                    m_at, Q_at, dY_at = self._segment(
                        solver, np.concatenate(parts), D, J, need_attitude, jacobian
                    )
                first = 0
                for name, inside in chosen:
                    part = slice(first, first + inside.size)
                    first += inside.size
                    pieces[name].append(
                        (
                            inside,
                            (
                                m_at[part],
                                None if Q_at is None else Q_at[part],
                                None if dY_at is None else dY_at[part],
                            ),
                        )
                    )
                if last:
                    break
                m_end = m_at[-1]
                Q_end = Q_at[-1] if Q_at is not None else Q_p
                dY = dY_at[-1] if dY_at is not None else None
            else:
                m_end, Q_end, dY = self._across_burn(
                    x, J, Ar, m_p, Q_p, D, t0, t_end, lo, hi, torque, wanted, pieces, jacobian
                )
            if dY is not None:
                D = np.concatenate([dY, D[6:9]], axis=0)
            for event in impulses:
                if event.frame == "body":
                    Δm = Ar.T @ event.vector
                    if L.axes:
                        D[3:6, L.block("α")] += skew(Δm) @ right_jacobian(x[L.block("α")])
                else:
                    Δm = Q_end.inv().apply(event.vector)
                    D[3:6] += skew(Δm) @ D[0:3]
                m_end = m_end + Δm
            m_p, Q_p, t0, lo = m_end, Q_end, t_end, hi
        ω_scale = 1.0 / J
        if t_rates is not None:
            m_all = np.empty((t_rates.size, 3))
            dY_all = np.empty((t_rates.size, 6, L.size)) if jacobian else None
            for inside, (m, _, dY) in pieces["rates"]:
                m_all[inside] = m
                if dY_all is not None and dY is not None:
                    dY_all[inside] = dY
            ω_p = m_all * ω_scale
            rates.ω = ω_p @ Ar.T
            if L.bias:  # what the gyro reads: the rate plus its bias
                rates.ω = rates.ω + x[L.block("b")] * self.rate_unit
            if dY_all is not None:
                dJ = D[6:9]  # the moments do not change at an impulse
                dω_p = (
                    dY_all[:, 3:6, :] * ω_scale[None, :, None]
                    - (ω_p * ω_scale)[:, :, None] * dJ[None, :, :]
                )
                rates.dω = np.einsum("ij,njp->nip", Ar, dω_p)
                if L.axes:
                    Jr_α = right_jacobian(x[L.block("α")])
                    rates.dω[:, :, L.block("α")] -= np.einsum("ij,njk,kl->nil", Ar, skew(ω_p), Jr_α)
                if L.bias:
                    rates.dω[:, :, L.block("b")] += np.eye(3) * self.rate_unit
        if t_attitude is not None:
            quats = np.empty((t_attitude.size, 4))
            dθ = np.empty((t_attitude.size, 3, L.size)) if jacobian else None
            for inside, (_, R, dY) in pieces["attitude"]:
                assert R is not None  # need_attitude holds with t_attitude
                quats[inside] = (R * A.inv()).as_quat()
                if dθ is not None and dY is not None:
                    dθ[inside] = np.einsum("ij,njp->nip", Ar, dY[:, 0:3, :])
            attitudes.attitude = Rotation.from_quat(quats)
            if dθ is not None and L.axes:
                dθ[:, :, L.block("α")] -= Ar @ right_jacobian(x[L.block("α")])
            attitudes.dθ = dθ
        return rates, attitudes

    def _time_line(self):
        """The motion's pieces from t = 0: (end, torque, impulses at the end), with
        torque None where the motion is torque-free and (Γ_body, Γ_inertial) over a
        burn; the last piece ends at +inf."""
        pieces = torque_pieces(self.burns)
        edges = {e for a, b, _, _ in pieces for e in (a, b)} - {0.0}
        breaks = sorted({i.t for i in self.impulses} | edges)
        on = {a: (Γ_b, Γ_i) for a, _, Γ_b, Γ_i in pieces}
        t0 = 0.0
        for t_end in [*breaks, math.inf]:
            impulses = [i for i in self.impulses if i.t == t_end]  # in the order given
            yield t_end, on.get(t0), impulses
            t0 = t_end

    def _across_burn(
        self, x, J, Ar, m_p, Q_p, D, t0, t_end, lo, hi, torque, wanted, pieces, jacobian
    ):
        """A piece of a burn: the samples in [lo, hi) (attitude.estimation.burns), and
        the state (with its derivative, if asked) at its end."""
        L = self.layout
        Γ_b, Γ_i = torque
        g_b = Ar.T @ Γ_b  # the body torque in the principal axes
        G_α = None
        if jacobian and L.axes:  # g_b = Aᵀ Γ_b moves with the axes
            G_α = np.zeros((3, L.size))
            G_α[:, L.block("α")] = skew(g_b) @ right_jacobian(x[L.block("α")])
        if t0 <= 0.0 and any(t is not None and np.any(t < 0.0) for t in wanted.values()):
            raise InputError(
                "the motion before t = 0 under a burn on at t = 0 is not modelled: "
                "times before the first sample"
            )
        index, times = [], []
        for t in wanted.values():
            inside = _inside(t, lo, hi)
            index.append(inside)
            times.append(np.empty(0) if inside is None or t is None else t[inside])
        flow = burn_flow(
            J,
            m_p,
            Q_p,
            D[0:6] if jacobian else None,
            D[6:9] if jacobian else None,
            t0,
            t_end,
            np.concatenate(times),
            g_b,
            Γ_i,
            G_α,
        )
        first = 0
        for name, inside, t in zip(wanted, index, times, strict=True):
            if inside is None:
                continue
            part = slice(first, first + t.size)
            first += t.size
            pieces[name].append(
                (
                    inside,
                    (
                        flow.m[part],
                        flow.attitude[part],
                        None if flow.jacobian is None else flow.jacobian[part],
                    ),
                )
            )
        return flow.m_end, flow.attitude_end, flow.jacobian_end

    @staticmethod
    def _segment(solver: EulerSolver, times, D, J, attitude: bool, jacobian: bool) -> _Piece:
        """m_p (N, 3), Q_p (Rotation, or None) and ∂(δθ_p, m_p)/∂x (N, 6, n) at ``times``."""
        if not jacobian:
            m = solver.angular_momentum(times)
            R = solver.attitude(times) if attitude else None
            return m, R, None
        if times.size <= _CHUNK:
            sens = flow_sensitivities(solver, times, attitude=attitude)
            jac = sens.jacobian
            if not attitude:  # the attitude rows are not computed, and nothing needs them
                jac[:, 0:3, :] = 0.0
            return sens.angular_momentum, sens.attitude, np.einsum("nij,jp->nip", jac, D)
        # In chunks: the sensitivities' (N, 6, 9) of a long arc need not all exist at once.
        m = np.empty((times.size, 3))
        out = np.empty((times.size, 6, D.shape[1]))
        quats = np.empty((times.size, 4)) if attitude else None
        for first in range(0, times.size, _CHUNK):
            part = slice(first, first + _CHUNK)
            sens = flow_sensitivities(solver, times[part], attitude=attitude)
            jac = sens.jacobian
            if not attitude:  # the attitude rows are not computed, and nothing needs them
                jac[:, 0:3, :] = 0.0
            m[part] = sens.angular_momentum
            np.einsum("nij,jp->nip", jac, D, out=out[part])
            if quats is not None and sens.attitude is not None:
                quats[part] = sens.attitude.as_quat()
        R = Rotation.from_quat(quats) if quats is not None else None
        return m, R, out
