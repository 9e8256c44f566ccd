"""Gravity gradient as averaged kicks along the exact free flow: the validity horizon's long steps.

The validity horizon (:mod:`attitude.trajectory.horizon`) asks when the gravity-gradient
torque that a scenario neglects would have moved its attitude by a threshold.  That
torque is a small perturbation of the free motion, whose flow φ_t is exact
(:class:`attitude.solver.euler_solver.EulerSolver`); its slow time scale is the
orbit's, its fast one the spin's.  This module propagates the perturbed motion in
steps H set by the size of the perturbation's effect, not by the spin, with the fast
spin handled exactly by integrating along the free flow: the averaged-force
("mollified impulse") idea of B. García-Archilla, J. M. Sanz-Serna and R. D. Skeel,
"Long-time-step methods for oscillatory differential equations", SIAM J. Sci.
Comput. 20 (1998) 930–963, written here for the rigid body.

**Derivation.**  In principal axes, with attitude R (principal → inertial) and body
momentum m, the motion is Hamiltonian, H = T(m) + V(R, t), with T = ½ mᵀJ⁻¹m and the
gravity-gradient potential (MacCullagh)

    V(R, t) = (3μ / 2r³) ûᵀ J û,   û = Rᵀ r̂(t),

up to a term that does not depend on R; the torque is Γ = −∂V/∂θ = (3μ/r³) û × Jû
(body axes, δθ a body rotation vector), the model of
:class:`attitude.torques.models.GravityGradient`.  A function F(R, m) generates the
flow Ṙ = R[∂F/∂m]×, ṁ = m × ∂F/∂m − ∂F/∂θ (for F = T these are Euler's equations).
Over one step [τ − H/2, τ + H/2], written in the interaction picture of the free flow
(variation of constants), the exact perturbed map is, to first order in V,

    Φ_H = φ_{H/2} ∘ exp(X_V̄) ∘ φ_{H/2} + O(V²),   V̄(x) = ∫_{−H/2}^{H/2} V(φ_s(x), τ + s) ds,

because the pull-back of the Hamiltonian vector field X_V by the (Poisson) free flow
is the Hamiltonian vector field of V ∘ φ_s: the kicks of the step, each carried to
the middle by the free flow, add up to the vector field of the potential averaged
along the free flow through the middle state x.  Its flow for a unit time, to first
order, is the **kick** at the middle of the step:

    m ← m + RᵀΔL + m × a,   R ← R exp([a]×),
    ΔL = ∫ Γ_inertial(φ_s(x), τ + s) ds   (−∂V̄/∂θ, carried to inertial axes),
    a  = ∂V̄/∂m                            (a body rotation vector, rad).

ΔL is the torque integrated along the exact free flow (the inertial angular momentum
changes by it, exactly to first order); a is what a plain impulse ΔL at the middle
misses: a kick at time s moves the attitude by what the changed momentum turns it
through until the middle (the shear of the spin phase by the changed energy and |m|,
and the nutation that a momentum given at once excites but a torque spread over many
turns does not).  Without a, the 0.65 rad/s spinner of
``tests/test_validity_horizon_against_dop853.py`` (on a circular orbit) crosses 1° at
6 to 16 % of its horizon, at steps of 50 to 1000 s: each impulse excites a nutation
the torque never does.

The free flow handles the spin (every φ_s is exact, at any s), so H is not limited by
it.  The map's error is of second order in the perturbation: O(ε²) a step, ε the size
of the kick, and O(ε) over a run relative to the effect measured.  The size that sets
the step is how far the kick moves the attitude within the step: |a|, plus the kick's
momentum carried by the linearized free flow to every node (the finite differences
below give its columns), which holds the shear of a tumbler's phase (the frequencies
change with |m| and T) and the growth of the linearized flow near a separatrix.  It is
held to :data:`LARGEST_KICK` (and to :data:`KICK_FRACTION` of the threshold): a step
whose kick exceeds twice that is made again shorter, the next step is scaled to it (at
most twice the last), and a step is at most :data:`ORBIT_FRACTION` of the orbit period
(and :data:`MOST_NODES` nodes).  A long run is what sets the bound: the kicks'
second-order remainder changes |m| and T, and the spin phase turns that into an angle
growing with the time left; the 0.65 rad/s spinner of
``tests/test_validity_horizon_against_dop853.py`` (its crossing after 31 550 s, the
angle growing by 0.035° in 1000 s there) crosses 1.6 % early with kicks of 1e-3 rad,
0.7 % at 5e-4.

**Evaluation.**  Every integral over a step is a Gauss–Legendre rule (:data:`NODES`
nodes on each sub-interval of at most :data:`TURNS` fastest turns of the body at the
bound √(2T/I_min) of its rate, and of an eighth of the orbit period): the attitudes at
all the nodes come from one vectorized call of the exact solver through the middle
state, the orbit's positions from one call of its (interpolated) position.  The
integrand of V̄ holds the spin's first and second harmonics, at four nodes a bound
turn (more a turn of the body, whose rate is below the bound): against eight, the
crossings of the hostile cases move by 2e-4 of themselves or less, except the spinner
about its minor axis, whose rate is the bound (1.3e-3, most of its error).  a is a
derivative of V̄.  Along m it needs no other run: Euler's equations are quadratic in
m, so the motion from m(1 + ε) is the same motion run 1 + ε times faster, which turns
the attitude at s by ε (s − τ) ω(s) and changes V by −Γ·ε (s − τ) ω(s).  Across m, by
finite differences with two more exact solvers from the middle state, its momentum
moved by 1e-6 of |m| (less when the step is many turns long), at the same nodes (a
tenth of that moves the crossings by 8e-6 of themselves or less).

**The comparison.**  At each node, the attitude of the run through the middle state
(every earlier kick included, not yet this step's) is compared with the scenario's own
(the torque-free one): the angle between them, a step at a time for the first
:data:`ONE_STEP_AT_A_TIME` nodes, then :data:`COMPARED_AT_ONCE` at once (the free
run's solver then evaluates them from its table).  Near the crossing, that run lags
the torqued one by at most the step's kick, so a crossing found in a step whose kick
is larger than :data:`ACCEPTED_LAG` of the threshold is searched again from the step
before, at an eighth of the step, until it is not; the first node at or past the
threshold, after the last below it, is then refined by bisection to a millisecond on
the run through that step's middle.

**Accuracy** (to 1 % for crossings up to about nine hours, not beyond: so
:func:`attitude.trajectory.horizon.validity_horizon` uses it as a screen, at half its
threshold, and states only the splitting's crossings).  Against DOP853 at rtol 1e-12
(``tests/test_validity_horizon_against_dop853.py``,
``tests/test_validity_horizon_hostile_cases_against_dop853.py``), the crossing comes
6.9e-3 of itself early for the spinner whose angle creeps up to the threshold after
31550 s, 1.3e-3 early near the separatrix (spinning about the intermediate axis) and
for a spinner at 4 rad/s about its minor axis, and within 2e-4 for a slow body
turning at the orbit rate, spinners at 3 rad/s and 5 rpm, a crossing 2.5 minutes
after the start under a huge torque, an impulse on a full tensor, and a tumbler on an
eccentric orbit; the Envisat-like tumbler of ``scenarios/tumbling_defunct_satellite.toml``
crosses 5.6e-4 of itself before the splitting.  **Not met over days**: the 5 rpm
spinner of ``benchmarks.horizon_share`` (nutating after its pulse) crosses 0.05° after
10 610 s (DOP853) 2.1 % early, 0.2° after 52 390 s 4.6 % late, and 1° after about 2.7
days 10.6 % late against the splitting (converged there to 0.2 %); with steps of a
fortieth of an orbit, 2.9 %.  The error grows with the run, faster than the kick
size says: the kicks' second-order remainder, over steps long against the orbit's
period, is a slow drift of |m| and T that the spin and nutation phases turn into an
angle growing with the time (a second-order secular term of the averaging that a
first-order kick per step leaves out).  On the benchmark's day the horizon is beyond
the span either way (the angle stays below 0.4°, within 1.5e-3° of DOP853 over the
first 59 000 s).  Other limits: the quadrature of the spin's harmonics (four nodes a
bound turn) and, near the crossing, the lag of the compared run (bounded by the
refinement).  Not covered: a kick that is not small even over a millisecond (a
torque that turns the momentum by more than the threshold within a millisecond): the
refinement stops there, and the crossing is the first node of that search past the
threshold.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from attitude.base.quaternions import right_matrix, rotation_rows
from attitude.scenario.events import State
from attitude.solver.backends import TABLE_MIN_SAMPLES
from attitude.solver.closed_form import hamilton
from attitude.solver.euler_solver import EulerSolver
from attitude.torques.models import GravityGradient
from attitude.torques.solver import angles_between

__all__ = [
    "ACCEPTED_LAG",
    "KICK_FRACTION",
    "NODES",
    "ORBIT_FRACTION",
    "TURNS",
    "Departure",
    "departure",
]

# Gauss–Legendre nodes per sub-interval, and the sub-interval's length in fastest
# turns of the body (module docstring, "Evaluation").
NODES = 8
TURNS = 2.0
# A step's kick (how far it moves the attitude within the step, rad) is held to this
# fraction of the threshold and to LARGEST_KICK, the step to this fraction of the
# orbit period (module docstring).
KICK_FRACTION = 0.1
LARGEST_KICK = 5e-4
ORBIT_FRACTION = 0.5
# A step is at most this many times the last, and has at most this many nodes (its
# arrays: some 30 of them, 8 bytes a node).
GROWTH = 2.0
MOST_NODES = 1 << 16
# A crossing is accepted from a step whose kick is below this fraction of the
# threshold: the comparison then lags the torqued run by at most that angle.
ACCEPTED_LAG = 2e-4
# The first step: this fraction of the orbit period (the kick then sets the next).
_FIRST_ORBIT_FRACTION = 1.0 / 64.0
# The free run is compared a step at a time for its first ONE_STEP_AT_A_TIME nodes (a
# short horizon computes little past its crossing), then COMPARED_AT_ONCE nodes at once
# (its solver evaluates them from a table: attitude.solver.backends.TABLE_MIN_SAMPLES);
# and a step at a time in a refinement.
COMPARED_AT_ONCE = TABLE_MIN_SAMPLES
ONE_STEP_AT_A_TIME = 2048
# A refinement restarts one step back at this fraction of the step.
_REFINE = 1.0 / 8.0
# The finite differences of a: the momentum moved by this fraction of |m|, divided by
# the turns of half a step (the phase of the moved motion then moves by ~1e-6 rad).
_DIFFERENCE = 1e-6
# A step shorter than this (s) is accepted as it is (a crossing bisected to a ms).
_SHORTEST_STEP = 1e-3

Angles = Callable[[NDArray[np.float64], NDArray[np.float64]], NDArray[np.float64]]


@dataclass(frozen=True)
class Departure:
    """What :func:`departure` found on one segment: ``crossing_s`` (TT s, or inf), the
    torqued state at the segment's end (None after a crossing) and the largest step
    (s)."""

    crossing_s: float
    end_state: State | None
    largest_step_s: float


@dataclass(frozen=True)
class _Step:
    """A step made: from ``t``, of ``h``, along ``through`` (the run before its kick),
    its nodes and the attitudes there, and its kick's size."""

    t: float
    h: float
    through: EulerSolver
    nodes: NDArray[np.float64]
    qs: NDArray[np.float64]
    size: float


class _Body:
    """The body in principal axes: moments J, the rotation body → principal."""

    def __init__(self, state: State) -> None:
        axes = state.inertia
        self.J = np.asarray(axes.moments, dtype=np.float64)
        self.moments = (float(self.J[0]), float(self.J[1]), float(self.J[2]))
        self.to_principal = axes.body_to_principal
        self.identity = bool(np.allclose(self.to_principal.as_matrix(), np.eye(3), 0.0, 0.0))
        # q_principal = q_body ⊗ q(principal → body): a constant right factor.
        self.right = right_matrix(self.to_principal.inv().as_quat(scalar_first=True))

    def principal(self, state: State) -> tuple[NDArray[np.float64], Rotation]:
        if self.identity:
            return np.asarray(state.angular_momentum, dtype=np.float64), state.attitude
        m = self.to_principal.apply(state.angular_momentum)
        return m, state.attitude * self.to_principal.inv()

    def body(self, m: NDArray[np.float64], attitude: Rotation, inertia) -> State:
        if self.identity:
            return State(attitude, m, inertia)
        return State(attitude * self.to_principal, self.to_principal.inv().apply(m), inertia)

    def principal_quaternions(self, q_body: NDArray[np.float64]) -> NDArray[np.float64]:
        return q_body if self.identity else q_body @ self.right.T


def _hamilton(p: NDArray[np.float64], q: NDArray[np.float64]) -> NDArray[np.float64]:
    """Hamilton products p ⊗ q of quaternion stacks (n, 4), scalar first."""
    return np.stack(hamilton(tuple(p.T), tuple(q.T)), axis=-1)


def _sinc_half(angle: float) -> float:
    """sin(angle/2)/angle, the factor of a rotation vector in its quaternion."""
    return 0.5 - angle * angle / 48.0 if angle < 1e-4 else math.sin(0.5 * angle) / angle


def _basis(m: NDArray[np.float64]) -> list[NDArray[np.float64]]:
    """An orthonormal basis whose first vector is along m (any, for m = 0)."""
    G = float(np.linalg.norm(m))
    first = m / G if G > 0.0 else np.array([1.0, 0.0, 0.0])
    trial = np.eye(3)[int(np.argmin(np.abs(first)))]
    second = np.cross(first, trial)
    second /= np.linalg.norm(second)
    return [first, second, np.cross(first, second)]


def _nodes(a: float, b: float, longest: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Gauss–Legendre nodes and weights on [a, b], NODES on each of the fewest equal
    sub-intervals no longer than ``longest``."""
    x, w = _RULE
    k = max(1, math.ceil((b - a) / longest - 1e-9))
    h = (b - a) / k
    starts = a + h * np.arange(k)
    return (starts[:, None] + h * x[None, :]).ravel(), np.tile(h * w, k)


_x, _w = np.polynomial.legendre.leggauss(NODES)
_RULE = (0.5 * (_x + 1.0), 0.5 * _w)


class _Run:
    """The torqued run of one segment by averaged kicks, compared with ``free``."""

    def __init__(
        self,
        body: _Body,
        gradient: GravityGradient,
        period: float,
        free: Angles,
        threshold: float,
    ) -> None:
        self.body, self.gradient, self.period = body, gradient, period
        self.free, self.threshold = free, threshold
        self.largest = 0.0
        self.compared = 0  # nodes compared so far
        self.sub = 1.0  # the last step's sub-interval (s)

    def _potential(self, q: NDArray, u: tuple, factor: NDArray) -> NDArray[np.float64]:
        """V (J) at principal attitudes q, for the inertial unit positions u."""
        J = self.body.J
        R = rotation_rows(q)
        b = [R[0][i] * u[0] + R[1][i] * u[1] + R[2][i] * u[2] for i in range(3)]
        return factor * (J[0] * b[0] * b[0] + J[1] * b[1] * b[1] + J[2] * b[2] * b[2])

    def kick(self, through: EulerSolver, tau: float, h: float):
        """The step of size h whose middle is tau, along ``through`` (the run with every
        earlier kick): its nodes, the angles there, the solver after the kick, and the
        kick's size and lag (rad)."""
        J = self.body.J
        m = np.asarray(through.angular_momentum(tau), dtype=np.float64)
        q = through.attitude_quaternion(tau)
        G = float(np.linalg.norm(m))
        rate = math.sqrt(max(float(m @ (m / J)), 0.0) / float(J.min()))
        turn = 2.0 * math.pi / rate if rate > 0.0 else math.inf
        longest = min(TURNS * turn, self.period / 8.0)
        self.sub = longest
        t, w = _nodes(tau - 0.5 * h, tau + 0.5 * h, longest)
        qs = through.attitude_quaternion(t)
        r = self.gradient.position(t)
        radius = np.sqrt(np.einsum("ij,ij->i", r, r))
        u = tuple(r[:, i] / radius for i in range(3))
        factor = 1.5 * self.gradient.mu / radius**3
        V = self._potential(qs, u, factor)
        # Γ_inertial = (3μ/r³) û × (R J Rᵀ û): the torque at every node, integrated.
        R = rotation_rows(qs)
        b = [R[0][i] * u[0] + R[1][i] * u[1] + R[2][i] * u[2] for i in range(3)]
        g = (
            (J[2] - J[1]) * b[1] * b[2],
            (J[0] - J[2]) * b[2] * b[0],
            (J[1] - J[0]) * b[0] * b[1],
        )
        wf = 2.0 * factor * w
        dL = np.array(
            [float(wf @ (R[i][0] * g[0] + R[i][1] * g[1] + R[i][2] * g[2])) for i in range(3)]
        )
        attitude = Rotation.from_quat(q, scalar_first=True)
        delta = G * _DIFFERENCE / max(1.0, rate * 0.5 * h) if G > 0.0 else _DIFFERENCE
        basis = _basis(m)
        # Along m the moved run is the same run faster (Euler's equations are quadratic
        # in m): m(1 + ε) turns the attitude at s by ε (s − τ) ω(s), and V by
        # −Γ·ε (s − τ) ω(s).  Across m, finite differences: each moved run's attitude at
        # the nodes as the body rotation vector from the run through the middle
        # (q ⊗ δ = q_moved, small angles).  Both give a column of the linearized
        # flow, ∂θ(s)/∂m along the basis vector, and a's component along it.
        omega = through.angular_momentum(t) / J
        along = omega * ((t - tau) / G)[:, None] if G > 0.0 else np.zeros_like(omega)
        torque = (2.0 * factor)[:, None] * np.stack(g, axis=-1)
        components = [-float(w @ np.einsum("ij,ij->i", torque, along))]
        columns = [along]
        conjugate = qs * np.array([1.0, -1.0, -1.0, -1.0])
        for e in basis[1:]:
            q_moved = EulerSolver(
                self.body.moments, m + delta * e, attitude, tau
            ).attitude_quaternion(t)
            components.append(float(w @ (self._potential(q_moved, u, factor) - V)) / delta)
            product = _hamilton(conjugate, q_moved)
            columns.append(2.0 * np.copysign(1.0, product[:, :1]) * product[:, 1:] / delta)
        a = components[0] * basis[0] + components[1] * basis[1] + components[2] * basis[2]
        kick = attitude.apply(dL, inverse=True) + np.cross(m, a)
        angle = float(np.linalg.norm(a))
        exp_a = np.array([math.cos(0.5 * angle), *(_sinc_half(angle) * a)])  # exp([a]×)
        turned = Rotation.from_quat(_hamilton(q[None], exp_a[None])[0], scalar_first=True)
        after = EulerSolver(self.body.moments, m + kick, turned, tau)
        # The kick's size: how far it moves the attitude within the step, its momentum
        # carried by the linearized flow (the shear of a tumbler, the growth near a
        # separatrix), its rotation a as it is.
        along_basis = [float(kick @ e) for e in basis]
        moved_by = sum(column * c for column, c in zip(columns, along_basis, strict=True))
        size = float(np.linalg.norm(a)) + float(
            np.sqrt(np.max(np.einsum("ij,ij->i", moved_by, moved_by)))
        )
        self.largest = max(self.largest, h)
        return t, qs, after, size

    def run(
        self,
        start: float,
        through: EulerSolver,
        end: float,
        cap: float = math.inf,
        until: float = math.inf,
    ) -> tuple[float, EulerSolver | None, float]:
        """From ``through`` at ``start`` towards ``end``: the crossing (or inf), the run
        after the last kick (None after a crossing) and the time it reached.  A
        refinement (``until`` finite) takes steps of at most ``cap``, compares each, and
        returns at the first step's end at or past ``until`` without a crossing, for
        the run it refines to go on from there (no recursion deeper than the
        refinements of one crossing)."""
        refining = math.isfinite(until)
        m = np.asarray(through.angular_momentum(start), dtype=np.float64)
        rate = math.sqrt(max(float(m @ (m / self.body.J)), 0.0) / float(self.body.J.min()))
        self.sub = min(TURNS * 2.0 * math.pi / rate, self.period / 8.0) if rate > 0.0 else 1.0
        first = min(cap, self.period * _FIRST_ORBIT_FRACTION, self._most())
        t, h_next = start, first
        target = min(KICK_FRACTION * self.threshold, LARGEST_KICK)
        earlier: _Step | None = None  # the last step compared
        pending: list[_Step] = []  # steps made, not yet compared
        while t < end:
            h = min(h_next, end - t)
            if end - (t + h) < 0.25 * h:  # no sliver of a step at the end
                h = end - t
            nodes, qs, after, size = self.kick(through, t + 0.5 * h, h)
            while size > 2.0 * target and h > _SHORTEST_STEP:  # too large a kick: shorter
                h *= max(0.1, 0.9 * target / size)
                nodes, qs, after, size = self.kick(through, t + 0.5 * h, h)
            pending.append(_Step(t, h, through, nodes, qs, size))
            t, through = t + h, after
            waiting = sum(p.nodes.size for p in pending)
            if (
                t < end
                and not refining
                and self.compared >= ONE_STEP_AT_A_TIME
                and waiting < COMPARED_AT_ONCE
            ):
                h_next = self._next(h, size, target)
                continue
            found = self._compare(pending, earlier, end)
            earlier, pending = pending[-1], []
            h_next = min(self._next(h, size, target), cap)
            if found is not None:
                crossing, resumed, reached = found
                if math.isfinite(crossing) or resumed is None:
                    return found
                # The refinement found none up to its end: on from there.
                through, t, earlier = resumed, reached, None
                h_next = min(cap, self.period * _FIRST_ORBIT_FRACTION, self._most())
            elif refining and t >= until:
                return math.inf, through, t
        return math.inf, through, t

    def _next(self, h: float, size: float, target: float) -> float:
        """The step after one of ``h`` whose kick had ``size``: scaled to ``target`` as
        if the size went as the step's square (it grows between that and the step
        itself), at most GROWTH times h and ORBIT_FRACTION of the orbit."""
        scale = math.sqrt(target / max(size, 1e-300))
        return min(self.period * ORBIT_FRACTION, GROWTH * h, h * scale, self._most())

    def _most(self) -> float:
        """The longest step of at most MOST_NODES nodes (a fast body's step is many
        turns: its arrays, not the kick, bound it)."""
        return MOST_NODES / NODES * self.sub

    def _compare(
        self, pending: list[_Step], earlier: _Step | None, end: float
    ) -> tuple[float, EulerSolver | None, float] | None:
        """The steps ``pending`` (``earlier``: the step before them) compared with the
        free run in one call: None if none of them can hold the crossing, else what
        :meth:`run` returns.  The run compared lags the torqued one by at most the
        step's kick (its size), so a step whose angle comes within its size of the
        threshold may hold the crossing: if its kick is small enough, the first node
        at or past the threshold is bisected (none: no crossing there); if not, the
        run is searched again at an eighth of the step from the step before it."""
        nodes = np.concatenate([p.nodes for p in pending])
        self.compared += nodes.size
        angles = self.free(nodes, np.concatenate([p.qs for p in pending]))
        start = 0
        for k, step in enumerate(pending):
            stop = start + step.nodes.size
            here = angles[start:stop]
            if step.size <= ACCEPTED_LAG * self.threshold or step.h <= _SHORTEST_STEP:
                past = np.flatnonzero(here >= self.threshold)
                if past.size:
                    first = start + int(past[0])
                    low = float(nodes[first - 1]) if first > start else step.t
                    crossing = self._bisect(step.through, low, float(nodes[first]))
                    return crossing, None, crossing
            elif np.any(here >= self.threshold - step.size):
                back = pending[k - 1] if k > 0 else earlier or step
                cap = _REFINE * max(back.h, step.h)
                return self.run(back.t, back.through, end, cap, step.t + step.h)
            start = stop
        return None

    def _bisect(self, through: EulerSolver, low: float, high: float) -> float:
        """The first crossing in (low, high] on ``through``, to a millisecond."""
        while high - low > 1e-3:
            mid = 0.5 * (low + high)
            at = np.array([mid])
            if self.free(at, through.attitude_quaternion(at))[0] >= self.threshold:
                high = mid
            else:
                low = mid
        return high


def departure(
    state: State,
    start_s: float,
    end_s: float,
    free: EulerSolver,
    gradient: GravityGradient,
    period_s: float,
    threshold: float,
) -> Departure:
    """The first time in (start_s, end_s] that the motion from ``state`` (body axes) at
    ``start_s`` under ``gradient`` parts from ``free`` (the scenario's torque-free
    segment) by ``threshold`` rad (module docstring), or inf, with the torqued state
    at ``end_s``.  ``period_s``: the orbit period."""
    body = _Body(state)

    def angles(t: NDArray[np.float64], q: NDArray[np.float64]) -> NDArray[np.float64]:
        return angles_between(q, body.principal_quaternions(free.attitude_quaternion(t)))

    m, attitude = body.principal(state)
    run = _Run(body, gradient, period_s, angles, threshold)
    through = EulerSolver(body.moments, m, attitude, start_s)
    crossing, after, _ = run.run(start_s, through, end_s)
    end_state = None
    if after is not None:
        end_state = body.body(after.angular_momentum(end_s), after.attitude(end_s), state.inertia)
    return Departure(crossing, end_state, run.largest)
