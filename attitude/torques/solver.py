"""Attitude under external torques: splitting with the exact free flow (``TorquedSolver``).

The equations of a rigid body under a torque Γ(t, R, ω),

    dm/dt = m × ω + Γ,   dq/dt = ½ q ⊗ (0, ω),   ω = I⁻¹ m   (body axes),

are split into the free rigid body, whose flow is exact (:mod:`attitude.solver.free_flow`,
after Celledoni, Fassò, Säfström and Zanna, whose paper's title names this use), and
the kick dm/dt = Γ with the attitude and the clock frozen, exact for any torque that
does not depend on ω (see :mod:`attitude.torques.models`).  A composition of the two
(:mod:`attitude.torques.splitting`) gives a method whose error is proportional to the torque,
not to the spin, and which is the exact solver when the torque vanishes.  For
gravity gradient each map is a Poisson map, so the energy-like integrals (the Jacobi
integral on a circular orbit) stay bounded instead of drifting.

Time dependence (an orbit) is carried by the free flow: the clock advances with the
flows, and a kick evaluates the torque at the clock reached so far, t_k + c_j h.  The
splitting of this autonomous extended system keeps the method's order.  Steps end at
every breakpoint of the torques (a burn's start and stop).

Dense output: the state at any t between grid points t_k ≤ t < t_{k+1} is one step of
the same method of size t − t_k from the state at t_k, so it has the method's order
(not the free flow from the last kick, which would be first order in the torque).

The grid is computed as far as it is asked for and kept: a later evaluation at an
earlier time costs one partial step.

References: see :mod:`attitude.torques.splitting` and :mod:`attitude.torques.models`.
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.base.quantities import as_si_array, as_si_scalar, as_vector3
from attitude.solver.euler_solver import EulerSolver
from attitude.solver.free_flow import UnitBatch, advance_floats
from attitude.solver.inertia import principal_axes
from attitude.torques.gyrostat import Gyroscope
from attitude.torques.models import (
    GravityGradient,
    PrincipalFrame,
    Torque,
    as_torque_list,
    merged_constant_torques,
)
from attitude.torques.splitting import Composition, composition

__all__ = [
    "ACCURACY_RANGE_RAD",
    "MAX_STEPS",
    "StepChoice",
    "StepPrediction",
    "TorquedSolver",
    "angles_between",
    "departure_time",
    "error_growth",
    "first_crossing",
    "next_search_step",
    "propagate_batch",
    "search_start_step",
]

# Steps computed per call of the torques' time functions (orbit positions, vectorized).
_CHUNK_STEPS = 512
# Dense-output evaluations are done in slices of this many times.
_DENSE_CHUNK = 8192
# A step may exceed the nominal one by this fraction rather than leave a sliver
# before a breakpoint.
_SLIVER = 1e-6
# More steps than this in one request (hours of computing) is refused as a mistake.
_MAX_REQUEST_STEPS = 1e8
# The compiled loop's start-up (numba's import and its cached machine code loaded: about
# 0.3 s of CPU) is the cost of some 8 000 steps of the Python loop (35 µs each), which
# computes the same states bit for bit.  A process takes its first PYTHON_LOOP_STEPS
# steps in Python and the rest compiled (paying the start when it is sure to need
# more): an hour's validity horizon never starts numba, a day's pays its start once and
# at most 0.15 s for the steps taken in Python first (a rent-or-buy rule: never more
# than twice the cheaper choice in hindsight).
PYTHON_LOOP_STEPS = 4096
_python_steps = 0  # steps this process took by the Python loop in place of the compiled one
# A step search that would try a step with more than this many steps over its span is
# refused (each try runs the span twice): torques that turn the body faster and faster
# (a runaway spin-up) would otherwise halve the step for hours before failing.  At 8
# free flows a step and tens of µs a flow, 1e7 steps are about an hour of computing.
# The scenario's run-level search (attitude.trajectory.steps) has the same cap.
MAX_STEPS = 1e7
# The accuracies a step search can meet (rad): below 1e-12 the Richardson estimate is
# rounding (16-digit states), and the search would shrink the step until it gives up
# at MAX_STEPS; beyond 0.1 rad an estimate from a linear error model means
# nothing.  The scenario's ``[torques] accuracy`` has the same range.
ACCURACY_RANGE_RAD = (1e-12, 0.1)
# The body must turn by less than this fraction of a turn in the spacing of float
# seconds at the time reached (as ``attitude.trajectory`` requires of a scenario):
# beyond, the free flow's phase is rounding, and a torque of 1e300 N m would spin the
# momentum past the float range within a step.
_RESOLVED_FRACTION_OF_A_TURN = 1e-3


# ----------------------------------------------------------------- the step engine


class _Engine:
    """Advances states by steps of one composition: exact kicks, exact free flows.

    A state is (m, q, pending): the body momentum and the attitude quaternion in
    principal axes as tuples of components (floats for one state, arrays of N values
    for a batch), and ``pending``, a free flow (s) still owed.  Flows are not applied
    until a kick needs the state, so that the last flow of a step and the first of the
    next are one call (a method that starts and ends with a flow costs one flow less
    per step).  The state at a grid point is F(pending)(m, q).
    """

    def __init__(
        self,
        method: Composition,
        torques: list[Torque],
        frame: PrincipalFrame,
        moments: NDArray[np.float64],
        gyroscope: Gyroscope | None = None,
    ) -> None:
        self.method = method
        self.gyroscope = gyroscope  # spinning wheels: the gyroscopic flow (torques.gyrostat)
        self.torques = torques
        self.frame = frame
        self.moments = moments  # (3,) or (N, 3), for advance()
        self.moment_floats: tuple[float, float, float] | None = (
            (float(moments[0]), float(moments[1]), float(moments[2]))
            if moments.shape == (3,)
            else None
        )
        self.rk4 = any(t.depends_on_angular_velocity for t in torques)
        self.clock = method.kick_clock
        self.kicks = [j for j, b in enumerate(method.kicks) if b != 0.0]
        self.flows = 0  # free-flow calls made (for benchmarks)
        self.unit_batch: UnitBatch | None = None  # the batch's free flow (see flow)
        # One rigid spacecraft under gravity gradient alone: steps by the compiled loop
        # (which has no gyroscopic flow: spinning wheels take the Python loop).
        self.compiled = (
            self.moment_floats is not None
            and gyroscope is None
            and len(torques) == 1
            and isinstance(torques[0], GravityGradient)
        )

    # ---- the two maps

    def flow(self, m, q, dt):
        """The exact free flow over dt (float, or array for a batch)."""
        self.flows += 1
        if self.moment_floats is not None and isinstance(m[0], float):  # one spacecraft
            return advance_floats(self.moment_floats, m, q, dt)
        m_array = np.stack(np.broadcast_arrays(*m), axis=-1)
        n = m_array.shape[0]
        if self.unit_batch is None or self.unit_batch.inertia.shape[0] != n:
            # The moments stay from flow to flow: what depends on them alone, once.
            self.unit_batch = UnitBatch(np.broadcast_to(self.moments, (n, 3)))
        # Every argument at its full (N, ...) shape: the free flow need not broadcast.
        # Straight to the flow: its states come from the last step, checked there.
        m_new, q_new = self.unit_batch.advance(
            m_array,
            np.stack(np.broadcast_arrays(*q), axis=-1),
            np.broadcast_to(np.asarray(dt, dtype=np.float64), (n,)),
        )
        # Components as contiguous rows: the kicks' arithmetic runs on them.
        return tuple(np.ascontiguousarray(m_new.T)), tuple(np.ascontiguousarray(q_new.T))

    def torque(self, data, m, q):
        I1, I2, I3 = self.frame.moments
        if self.gyroscope is None:
            ω = (m[0] / I1, m[1] / I2, m[2] / I3)
        else:
            ω = self.gyroscope.body_rate(m, self.frame.moments)
        total = (0.0, 0.0, 0.0)
        for model, row in zip(self.torques, data, strict=True):
            torque = model.principal_torque(row, q, ω, self.frame)
            total = (total[0] + torque[0], total[1] + torque[1], total[2] + torque[2])
        return total

    def kick(self, data, m, q, w):
        """m after the kick of duration w (s) at frozen attitude and clock."""
        k1 = self.torque(data, m, q)
        if not self.rk4:  # Γ does not depend on m: the kick is exact
            return (m[0] + w * k1[0], m[1] + w * k1[1], m[2] + w * k1[2])
        # Classical Runge–Kutta on dm/dt = Γ(t, R, I⁻¹m), R and t frozen.
        h2 = 0.5 * w
        k2 = self.torque(data, tuple(m[i] + h2 * k1[i] for i in range(3)), q)
        k3 = self.torque(data, tuple(m[i] + h2 * k2[i] for i in range(3)), q)
        k4 = self.torque(data, tuple(m[i] + w * k3[i] for i in range(3)), q)
        return tuple(m[i] + w / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]) for i in range(3))

    def kick_and_turn(self, data, m, q, w):
        """(m, q) after the kick of duration w: the torques' kick, and with spinning
        wheels the gyroscopic rotation G around it, G(w/2) T(w) G(w/2) (attitude.torques
        .gyrostat)."""
        gyroscope = self.gyroscope
        if gyroscope is None:
            return self.kick(data, m, q, w), q
        if not self.torques:
            return gyroscope.turn(m, q, w)
        m, q = gyroscope.turn(m, q, 0.5 * w)
        m = self.kick(data, m, q, w)
        return gyroscope.turn(m, q, 0.5 * w)

    # ---- one step

    def compiled_steps(self, m, q, pending, sizes, data, largest, out_m, out_q, out_p) -> int:
        """Steps of ``sizes`` from (m, q, pending) by the compiled loop
        (:mod:`attitude.torques.compiled_steps`) into the ``out_*`` rows, stopping before
        a state beyond ``largest`` (|m1| + |m2| + |m3|, N m s); the number done (0 when
        this engine has no compiled loop)."""
        global _python_steps
        if not self.compiled:
            return 0
        if _python_steps < PYTHON_LOOP_STEPS:  # numba's start not yet worth paying
            _python_steps += len(sizes)
            return 0
        from attitude.torques.compiled_steps import gravity_gradient_steps

        method = self.method
        done = gravity_gradient_steps(
            np.asarray(method.flows, dtype=np.float64),
            np.asarray(method.kicks, dtype=np.float64),
            np.asarray(self.moment_floats, dtype=np.float64),
            np.array([*m, *q, pending], dtype=np.float64),
            np.ascontiguousarray(sizes, dtype=np.float64),
            np.ascontiguousarray(data[0], dtype=np.float64),
            float(largest),
            out_m,
            out_q,
            out_p,
        )
        self.flows += int(done) * sum(1 for b in method.kicks if b != 0.0)
        return int(done)

    def step(self, m, q, pending, h, data_by_kick):
        """One step of size h (float or array); data_by_kick[j]: per torque, its row."""
        a, b = self.method.flows, self.method.kicks
        s = len(a)
        for j in range(s + 1):
            if b[j] != 0.0:
                if _nonzero(pending):
                    m, q = self.flow(m, q, pending)
                    pending = 0.0
                m, q = self.kick_and_turn(data_by_kick[j], m, q, b[j] * h)
            if j < s:
                pending = pending + a[j] * h
        return m, q, pending

    def time_data(self, t_start: NDArray, h: NDArray) -> list[NDArray]:
        """Per torque, its time data at every active kick: arrays (K, kicks, width)."""
        clock = self.clock[self.kicks]
        t = t_start[:, None] + clock[None, :] * h[:, None]
        t_mid = np.broadcast_to((t_start + 0.5 * h)[:, None], t.shape)
        out = []
        for model in self.torques:
            data = model.time_data(t.ravel(), np.ascontiguousarray(t_mid).ravel())
            out.append(np.asarray(data, dtype=np.float64).reshape((*t.shape, model.data_width)))
        return out

    def rows_for_step(self, data: list, k: int):
        """data_by_kick for step k of a chunk: rows as tuples of floats."""
        rows: list = [None] * len(self.method.kicks)
        for column, j in enumerate(self.kicks):
            rows[j] = [tuple(d[k][column]) for d in data]
        return rows

    def rows_for_batch(self, data: list[NDArray]):
        """data_by_kick for one step of N states at once: rows as tuples of arrays."""
        rows: list = [None] * len(self.method.kicks)
        for column, j in enumerate(self.kicks):
            rows[j] = [tuple(d[:, column, i] for i in range(d.shape[-1])) for d in data]
        return rows

    def partial_steps(self, m, q, pending, t_start, h):
        """States advanced by a step h from t_start (each its own, or shared), synchronized."""
        data = self.time_data(np.atleast_1d(t_start), np.atleast_1d(h))
        m, q, pending = self.step(m, q, pending, h, self.rows_for_batch(data))
        if _nonzero(pending):
            m, q = self.flow(m, q, pending)
        return m, q


def largest_momentum(moments: NDArray[np.float64], t: float) -> float:
    """The largest |m| (N m s) a state may have at time t (s): the body then turns at
    |ω| ≤ |m|/I_min, by at most a thousandth of a turn in the spacing of floats at t
    (``_RESOLVED_FRACTION_OF_A_TURN``).  Compared with |m1| + |m2| + |m3| ≥ |m|, which
    cannot overflow."""
    rate = 2.0 * math.pi * _RESOLVED_FRACTION_OF_A_TURN / float(np.spacing(max(abs(t), 1.0)))
    return rate * float(np.min(moments))


def _refuse_runaway(m, moments: NDArray[np.float64], t: float) -> None:
    """The InputError of a state past :func:`largest_momentum` (or not finite)."""
    components = np.abs(np.stack(np.broadcast_arrays(*m), axis=-1))
    largest = float(np.max(components)) if np.all(np.isfinite(components)) else math.inf
    raise InputError(
        f"the torques spin the body up to {largest / float(np.min(moments)):.3g} rad/s or "
        f"more (a momentum component of {largest:.3g} N m s) by t = {t:.6g} s, faster than "
        "float seconds can follow there: a torque that large has no meaningful attitude "
        "(check its magnitude)"
    )


def _nonzero(pending) -> bool:
    if isinstance(pending, float):
        return pending != 0.0
    return bool(np.any(pending != 0.0))


def _grid_steps(t_from: float, t_to: float, step: float, breakpoints: NDArray, limit: int):
    """Start times and sizes of the next steps from t_from, at most ``limit``, up to t_to.

    Steps are ``step`` long, except the last one before a breakpoint, which ends on it
    (shorter, or longer by at most a sliver rather than leave one).
    """
    starts: list[float] = []
    sizes: list[float] = []
    t = t_from
    while len(starts) < limit and t < t_to:
        later = int(
            np.searchsorted(breakpoints, t, side="right")
        )  # bisection: linear in breakpoints
        end = float(breakpoints[later]) if later < breakpoints.size else math.inf
        to_end = max(1, math.ceil((end - t) / step - _SLIVER)) if math.isfinite(end) else None
        wanted = max(1, math.ceil((t_to - t) / step))
        count = min(limit - len(starts), wanted, to_end or wanted)
        seg_starts = t + step * np.arange(count)
        seg_sizes = np.full(count, step)
        if count == to_end:  # the segment's last step lands on the breakpoint
            seg_sizes[-1] = end - seg_starts[-1]
        starts.extend(seg_starts.tolist())
        sizes.extend(seg_sizes.tolist())
        t = end if count == to_end else float(seg_starts[-1] + step)
    return np.array(starts), np.array(sizes)


# ----------------------------------------------------------------- the step search
# One search for a step that meets an error target, shared by TorquedSolver(accuracy=)
# and the scenario's run-level search (attitude.trajectory.steps), which estimate the
# error differently (one solver from its start; the whole run) but move alike.


def search_start_step(rate: float, torques: Iterable[Torque], t: float) -> float:
    """Where a step search starts: a quarter turn at ``rate`` (rad/s), at most a
    twentieth of the period of the orbit of any gravity gradient among ``torques``
    (its position at TT ``t``), 60 s with neither."""
    candidates = [2.0 * math.pi / rate / 4.0] if rate > 0.0 else []
    for torque in torques:
        if isinstance(torque, GravityGradient):  # the one torque with an orbit period
            radius = float(np.linalg.norm(torque.position(np.array([t]))[0]))
            candidates.append(2.0 * math.pi * math.sqrt(radius**3 / torque.mu) / 20.0)
    return min(candidates, default=60.0)


def next_search_step(
    step: float,
    error: float,
    accuracy: float,
    order: int,
    span: float,
    good: float | None,
    bad: float,
) -> float | None:
    """The step search's next try after ``step`` gave the estimate ``error``, or None
    when the search is done.  ``good``: the largest step that met ``accuracy`` so far
    (None: none yet); ``bad``: the smallest that missed it (inf: none yet).

    The error model C h^p (p = ``order``) aims at half the accuracy, moving at most
    8× down (and at least to 0.8 of the step) or 4× up a try, never past half the
    ``span``; once a passing and a failing step bracket the answer, it bisects in
    log h until they are within a factor 1.25."""
    factor = (0.5 * accuracy / max(error, 1e-300)) ** (1.0 / order)
    if good is not None and math.isfinite(bad):
        if bad / good < 1.25:
            return None
        return math.sqrt(good * bad)
    if good is not None:
        if factor < 1.25 or step >= 0.5 * span:
            return None
        return min(0.5 * span, step * min(4.0, factor))
    return step * min(0.8, max(0.125, factor))


# The exponent k of a search's error e(t) ~ t^k, fitted where a try was cut short.
GROWTH_RANGE = (1.0, 3.0)


def error_growth(times: Iterable[float], worst: Iterable[float], until: float) -> float:
    """k of e(t) ~ t^k over [until/4, until], from the largest estimate ``worst[i]`` up to
    each time ``times[i]`` (s from the search's start), within :data:`GROWTH_RANGE`:
    how a try cut short by `attitude check`'s budget is extrapolated over its span,
    e(span) = e(until) (span/until)^k (attitude.trajectory.steps explains the choice)."""
    t = np.asarray(list(times), dtype=np.float64)
    e = list(worst)
    if t.size == 0 or until <= 0.0:
        return GROWTH_RANGE[0]
    index = int(np.searchsorted(t, 0.25 * until, side="right")) - 1
    early = e[index] if index >= 0 else 0.0
    late = e[-1]
    if not (early > 0.0 and math.isfinite(late) and late > early):
        return GROWTH_RANGE[0]
    k = math.log(late / early) / math.log(until / float(t[index]))
    return float(np.clip(k, *GROWTH_RANGE))


# ----------------------------------------------------------------- the solver


@dataclass(frozen=True)
class StepChoice:
    """How a step was chosen from an accuracy: the estimate and the runs behind it.

    ``step``: the step adopted (s); ``error_estimate``: the estimated worst attitude
    error (rad) over [t0, t0 + span]: the largest angle between the runs at ``step``
    and ``2·step``, over ``checks`` times spread over the span, divided by 2^p − 1
    (Richardson, p the classical order; conservative when the error falls faster, as
    for the near-integrable methods).  ``tried``: (step, estimate) of every pair run;
    the step adopted is within a factor 1.25 of the largest that passed.
    """

    step: float
    error_estimate: float
    accuracy: float
    span: float
    tried: tuple[tuple[float, float], ...] = field(default=())
    checks: int = 0
    cpu_s: float = 0.0  # the search's CPU time (time.process_time)


@dataclass(frozen=True)
class StepPrediction:
    """A step search cut by a budget of CPU time (:meth:`TorquedSolver.predict_step`,
    for `attitude check`): its tries up to the cut are the search's own, and what lies
    beyond is predicted.

    ``step``: the step the search will end near, from the error model C h^p with a
    margin of 2 (at most the cut try's); ``cut_step``: the try the budget cut;
    ``predicted_error``: that try's estimate over the span, extrapolated from
    ``until`` (s covered from t0) as t^``growth`` and bounded below by the earlier
    tries scaled as h^p; ``tried``: (step, estimate) of every try, the last predicted;
    ``cpu_s``: spent here, ``tries_cpu_s`` of it by the tries that finished;
    ``cpu_per_step``: of one grid step, measured; ``search_cpu_s``: what the whole
    search will take, predicted: the tries that finished here, the cut one finished
    (1.5 runs of the span: the step and twice it) and two more tries at ``step``.
    """

    step: float
    cut_step: float
    predicted_error: float
    until: float
    growth: float
    accuracy: float
    span: float
    tried: tuple[tuple[float, float], ...]
    cpu_s: float
    tries_cpu_s: float
    cpu_per_step: float

    @property
    def search_cpu_s(self) -> float:
        finish = 1.5 * self.span / self.cut_step * self.cpu_per_step
        more = 2.0 * 1.5 * self.span / self.step * self.cpu_per_step
        return self.tries_cpu_s + finish + more


class _Propagation:
    """The grid of one step size: states at t_k, extended on demand."""

    def __init__(self, engine: _Engine, t0: float, m0, q0, step: float, breakpoints):
        self.engine = engine
        self.step = step
        self.breakpoints = breakpoints
        self._t = [np.array([t0])]
        self._m = [np.array([m0])]
        self._q = [np.array([q0])]
        self._pending = [np.array([0.0])]
        self._state = (tuple(m0), tuple(q0), 0.0)
        self.t_end = t0
        self.count = 0  # steps computed so far
        self._arrays: tuple[NDArray[np.float64], ...] | None = None

    def extend_to(self, t_max: float, whole: bool = False) -> None:
        """Compute the grid's steps that end by ``t_max`` (``whole``: also the step
        that straddles it).  The dense output reaches ``t_max`` from the last of them
        by a partial step: the straddling one would evaluate the torques past ``t_max``
        (past an orbit file that ends there) for no state asked."""
        e = self.engine
        if (t_max - self.t_end) / self.step > _MAX_REQUEST_STEPS:
            raise InputError(
                f"t = {t_max:g} s is {(t_max - self.t_end) / self.step:.3g} steps of "
                f"{self.step:g} s ahead: more than {_MAX_REQUEST_STEPS:g} steps; use a larger step "
                "or a shorter span"
            )
        while self.t_end < t_max:
            starts, sizes = _grid_steps(
                self.t_end, t_max, self.step, self.breakpoints, _CHUNK_STEPS
            )
            beyond = np.flatnonzero(starts + sizes > t_max) if not whole else np.empty(0)
            if beyond.size:
                starts, sizes = starts[: beyond[0]], sizes[: beyond[0]]
                if starts.size == 0:
                    return
            arrays = e.time_data(starts, sizes)
            m, q, pending = self._state
            K = len(starts)
            out_m, out_q, out_p = np.empty((K, 3)), np.empty((K, 4)), np.empty(K)
            largest = largest_momentum(e.moments, float(starts[-1] + sizes[-1]))
            done = e.compiled_steps(m, q, pending, sizes, arrays, largest, out_m, out_q, out_p)
            if done:
                m, q = tuple(out_m[done - 1].tolist()), tuple(out_q[done - 1].tolist())
                pending = float(out_p[done - 1])
            data = [d.tolist() for d in arrays] if done < K else []
            for k in range(done, K):
                m, q, pending = e.step(m, q, pending, float(sizes[k]), e.rows_for_step(data, k))
                norm = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
                if not (abs(m[0]) + abs(m[1]) + abs(m[2]) <= largest and norm > 0.0):
                    _refuse_runaway(m, e.moments, float(starts[k] + sizes[k]))
                q = (q[0] / norm, q[1] / norm, q[2] / norm, q[3] / norm)
                out_m[k], out_q[k], out_p[k] = m, q, pending
            self._state = (m, q, pending)
            self._t.append(starts + sizes)
            self._m.append(out_m)
            self._q.append(out_q)
            self._pending.append(out_p)
            self.t_end = float(starts[-1] + sizes[-1])
            self.count += K
            self._arrays = None
            if beyond.size:
                return

    def arrays(self):
        if self._arrays is None:
            self._arrays = tuple(
                np.concatenate(x) for x in (self._t, self._m, self._q, self._pending)
            )
            self._t, self._m, self._q, self._pending = ([a] for a in self._arrays)
        return self._arrays

    def states(self, t: NDArray[np.float64]) -> tuple[NDArray, NDArray]:
        """Principal-axes momentum (n, 3) and quaternion (n, 4) at the times t (n,)."""
        if t.size == 0:
            return np.zeros((0, 3)), np.zeros((0, 4))
        self.extend_to(float(np.max(t)))
        grid_t, grid_m, grid_q, grid_pending = self.arrays()
        k = np.clip(np.searchsorted(grid_t, t, side="right") - 1, 0, len(grid_t) - 1)
        h = t - grid_t[k]
        m, q = self.engine.partial_steps(
            tuple(grid_m[k].T), tuple(grid_q[k].T), grid_pending[k], grid_t[k], h
        )
        m_array = np.stack(m, axis=-1)
        size = np.sum(np.abs(m_array), axis=-1)
        if not np.all(size <= largest_momentum(self.engine.moments, float(np.max(t)))):
            # Refused as the grid refuses it, at the end of the step that runs away,
            # whatever time was asked first: check and run ask different ones.
            self.extend_to(float(np.max(t)), whole=True)
            _refuse_runaway(m, self.engine.moments, float(np.max(t)))
        q_array = np.stack(q, axis=-1)
        q_array /= np.linalg.norm(q_array, axis=-1, keepdims=True)
        return m_array, q_array


class TorquedSolver:
    """Attitude of a rigid body under external torques, by splitting with the exact free flow.

    ``inertia``: 3 principal moments along the body axes, in any order, or a 3×3 tensor
    in body axes (kg m²); ``angular_momentum``: body axes at ``t0`` (N m s);
    ``attitude``: body → inertial at ``t0`` (``Rotation``, default identity); ``t0``: s.
    ``torques``: a list of :class:`~attitude.torques.models.GravityGradient`,
    :class:`~attitude.torques.models.ConstantTorque`, :class:`~attitude.torques.models.UserTorque`
    (a bare callable ``torque(t, attitude, angular_velocity)`` is taken as the last).

    The method: ``order`` 2 (Strang), 4 (the default: ABA(10,6,4) of Blanes et al. 2013,
    whose error is O(εh¹⁰ + ε²h⁶ + ε³h⁴) for a torque ε times smaller than the free
    dynamics), or 6 (SRKN₁₁ᵇ of Blanes & Moan 2002, best when the torque is not
    small, e.g. a gravity-gradient-stabilized body; needs torques independent of ω);
    or ``method``, a name of :data:`attitude.torques.splitting.COMPOSITIONS`.

    The step: ``step`` (s, default 5 s), or ``accuracy`` (rad) with ``span`` (s): the
    step is then chosen so that the estimated attitude error over [t0, t0 + span] is
    within the accuracy, and ``step_choice`` reports the estimate.

    ``wheel_momentum``: the momentum h (body axes, N m s) of wheels spinning at a
    constant speed relative to the body: the body is then a gyrostat
    (:mod:`attitude.torques.gyrostat`: the gyroscopic term is a third exact flow of the
    splitting, with or without torques), ``angular_momentum`` is the spacecraft's total,
    M = Iω + h, and :meth:`angular_velocity` gives ω = I⁻¹(M − h).  Order 6 is refused
    with it.

    With no torque and no wheels the solver is
    :class:`~attitude.solver.euler_solver.EulerSolver` itself.  Times t ≥ t0 only.
    Outputs: :meth:`attitude`, :meth:`angular_momentum`, :meth:`angular_velocity`,
    :meth:`attitude_quaternion`, as for ``EulerSolver``.
    """

    def __init__(
        self,
        inertia: ArrayLike,
        angular_momentum: ArrayLike,
        attitude: Rotation | None = None,
        t0: float = 0.0,
        torques: Any = (),
        step: float | None = None,
        order: int | None = None,
        *,
        method: str | None = None,
        accuracy: float | None = None,
        span: float | None = None,
        wheel_momentum: ArrayLike | None = None,
    ) -> None:
        self._free = EulerSolver(inertia, angular_momentum, attitude, t0)  # validates all three
        self._t0 = self._free.t0
        self._torques = as_torque_list(torques)
        self.method = composition(4 if order is None and method is None else order, method)
        wheels = (
            None
            if wheel_momentum is None
            else as_vector3(wheel_momentum, "angular_momentum", "wheel_momentum")
        )
        if wheels is not None and self.method.needs_rkn:
            raise InputError(
                f"method {self.method.name!r} (order {self.method.order}) keeps its order only "
                "without a gyroscopic term; spinning wheels allow order 2 or 4"
            )
        # The exact solver alone: no torque and no wheels.
        self._exact = not self._torques and wheels is None
        if self.method.needs_rkn and any(t.depends_on_angular_velocity for t in self._torques):
            raise InputError(
                f"method {self.method.name!r} (order {self.method.order}) needs torques that do "
                "not depend on the angular velocity; a UserTorque with "
                "depends_on_angular_velocity=True allows order 2 or 4"
            )
        axes = principal_axes(inertia)
        self._moments = axes.moments.copy()
        m_body = as_vector3(angular_momentum, "angular_momentum", "angular_momentum")
        attitude = self._free.initial_attitude
        if axes.is_diagonal:
            self._principal_to_body = None
            m0, R0 = m_body, attitude
        else:
            self._principal_to_body = axes.body_to_principal.inv()
            m0 = axes.body_to_principal.apply(m_body)
            R0 = attitude * self._principal_to_body
        frame = PrincipalFrame(
            tuple(float(v) for v in self._moments),
            None if self._principal_to_body is None else self._principal_to_body.as_matrix(),
        )
        self._wheels_principal: NDArray[np.float64] | None = None
        gyroscope = None
        if wheels is not None:
            h = wheels if axes.is_diagonal else axes.body_to_principal.apply(wheels)
            self._wheels_principal = np.asarray(h, dtype=np.float64)
            gyroscope = Gyroscope(
                tuple(float(v) for v in h), tuple(float(v) for v in self._moments)
            )
        # Every ConstantTorque in one model: a kick costs the same for 1 burn or 1000.
        self._engine = _Engine(
            self.method, merged_constant_torques(self._torques), frame, self._moments, gyroscope
        )
        self._m0 = tuple(float(v) for v in m0)
        self._q0 = tuple(R0.as_quat(scalar_first=True).tolist())
        self._breakpoints = np.array(
            sorted({b for t in self._torques for b in t.breakpoints if b > self._t0})
        )
        self.step_choice: StepChoice | None = None
        if accuracy is not None and not self._exact:
            if step is not None:
                raise InputError("give either step or accuracy, not both")
            self._propagation = self._choose_step(accuracy, span)
        else:  # (an accuracy without torques: the exact solver needs no step)
            step = 5.0 if step is None else as_si_scalar(step, "time", "step")
            if not step > 0.0:
                raise InputError(f"step must be positive (s), got {step}")
            self._propagation = self._new_propagation(step)

    # ----------------------------------------------------------------- the step

    def _new_propagation(self, step: float) -> _Propagation:
        return _Propagation(self._engine, self._t0, self._m0, self._q0, step, self._breakpoints)

    def _choose_step(self, accuracy: Any, span: Any) -> _Propagation:
        """Step and half step over the span, until the Richardson estimate meets the accuracy."""
        choice, propagation = self._search(accuracy, span, None)
        assert isinstance(choice, StepChoice) and propagation is not None
        self.step_choice = choice
        return propagation

    def predict_step(
        self, accuracy: Any, span: Any, budget_s: float
    ) -> StepChoice | StepPrediction:
        """The search that ``accuracy=`` and ``span=`` make, within ``budget_s`` of CPU
        time: its :class:`StepChoice` when it ends within the budget, else a
        :class:`StepPrediction` from its tries so far (the same tries, cut where the
        budget ran out).  Refuses what the search would refuse, and a predicted step
        of more than :data:`MAX_STEPS` steps over the span.  The solver itself is
        unchanged (its step stays the one it was made with)."""
        return self._search(accuracy, span, budget_s)[0]

    def _search(
        self, accuracy: Any, span: Any, budget_s: float | None
    ) -> tuple[StepChoice | StepPrediction, _Propagation | None]:
        """The step search of ``accuracy`` over ``span``; with ``budget_s``, cut when the
        CPU time spent passes it (:meth:`predict_step`)."""
        accuracy = as_si_scalar(accuracy, "angle", "accuracy")
        low, high = ACCURACY_RANGE_RAD
        if not low <= accuracy <= high:
            raise InputError(
                f"accuracy must be between {low:g} and {high:g} rad (below, the estimate "
                f"is rounding; above, it means nothing), got {accuracy!r} rad"
            )
        if span is None:
            raise InputError("an accuracy needs span=, the duration (s) it is to hold over")
        span = as_si_scalar(span, "time", "span")
        if not span > 0.0:
            raise InputError(f"span must be positive (s), got {span}")
        p = self.method.order
        scale = 2.0**p - 1.0
        checks = self._t0 + span * np.linspace(1.0 / 32.0, 1.0, 32)
        started = time.process_time()

        def estimate(step: float) -> tuple[float, _Propagation, tuple | None]:
            """Richardson estimate of the error of the run at ``step`` (from 2 step), and
            (checks compared, their running largest estimate, the steps taken, the CPU
            time of the try) when the budget cut it."""
            fine = self._new_propagation(step)
            coarse = self._new_propagation(2.0 * step)
            if budget_s is None:
                difference = np.max(
                    angles_between(coarse.states(checks)[1], fine.states(checks)[1])
                )
                return float(difference) / scale, fine, None
            begun = time.process_time()
            worst, envelope = 0.0, []
            for i in range(checks.size):  # in time order: the grids grow as they are read
                at = checks[i : i + 1]
                angle = float(angles_between(coarse.states(at)[1], fine.states(at)[1])[0])
                worst = max(worst, angle / scale)
                envelope.append(worst)
                if i + 1 < checks.size and time.process_time() - started > budget_s:
                    cost = time.process_time() - begun
                    return worst, fine, (i + 1, envelope, fine.count + coarse.count, cost)
            return worst, fine, None

        # Search on the adopted step s, within a factor 1.25 of the largest that passes:
        # the error model C s^p to move, bisection (in log s) once bracketed.
        step = min(0.5 * span, 0.5 * self._initial_step())
        good: tuple[float, float, _Propagation] | None = None
        bad = math.inf
        tried: list[tuple[float, float]] = []
        for _ in range(10):
            if span / step > MAX_STEPS:
                raise self._too_many_steps(accuracy, span, step, tried)
            error, propagation, cut = estimate(step)
            if cut is not None:
                return self._prediction(accuracy, span, step, error, cut, tried, started), None
            tried.append((step, error))
            if error <= accuracy:
                if good is None or step > good[0]:
                    good = (step, error, propagation)
            else:
                bad = min(bad, step)
            following = next_search_step(
                step, error, accuracy, p, span, None if good is None else good[0], bad
            )
            if following is None:
                break
            step = following
        if good is None:
            raise InputError(
                f"{accuracy:g} rad over {span:g} s not reached: the estimate was "
                f"{tried[-1][1]:.3g} rad at a step of {tried[-1][0]:.3g} s",
                key="accuracy",
                value=accuracy,
            )
        step, error, propagation = good
        cpu = time.process_time() - started
        choice = StepChoice(step, error, accuracy, span, tuple(tried), len(checks), cpu)
        return choice, propagation

    def _too_many_steps(
        self, accuracy: float, span: float, step: float, tried: list[tuple[float, float]]
    ) -> InputError:
        last = f"; the estimate was {tried[-1][1]:.3g} rad at {tried[-1][0]:.3g} s" if tried else ""
        return InputError(
            f"{accuracy:g} rad over {span:g} s would need a step below "
            f"{step:.3g} s, more than {MAX_STEPS:g} steps{last}: give a step, "
            "a looser accuracy or a shorter span",
            key="accuracy",
            value=accuracy,
        )

    def _prediction(
        self,
        accuracy: float,
        span: float,
        step: float,
        error: float,
        cut: tuple,
        tried: list[tuple[float, float]],
        started: float,
    ) -> StepPrediction:
        """The search cut at the try of ``step`` after ``cut[0]`` checks: its estimate
        extrapolated over the span, bounded below by the finished tries scaled as h^p,
        and the step that meets the accuracy with a margin of 2 (as
        attitude.trajectory.steps predicts the run-level search)."""
        count, envelope, steps, cost = cut
        p = self.method.order
        times = [float(x) for x in (np.linspace(1.0 / 32.0, 1.0, 32)[:count] * span)]
        until = times[-1]
        growth = error_growth(times, envelope, until)
        predicted = max(
            [error * (span / until) ** growth] + [e * (step / h) ** p for h, e in tried if e > 0.0]
        )
        needed = step * min(1.0, (0.5 * accuracy / max(predicted, 1e-300)) ** (1.0 / p))
        tried = [*tried, (step, predicted)]
        if span / needed > MAX_STEPS:
            raise self._too_many_steps(accuracy, span, needed, tried)
        per_step = cost / steps if steps else 0.0
        spent = time.process_time() - started
        return StepPrediction(
            needed,
            step,
            predicted,
            until,
            growth,
            accuracy,
            span,
            tuple(tried),
            spent,
            spent - cost,
            per_step,
        )

    def _initial_step(self) -> float:
        """:func:`search_start_step` at the initial rate (the gyroscopic turn's too)."""
        ω = float(np.linalg.norm(self._principal_rate(np.asarray(self._m0))))
        if self._engine.gyroscope is not None:  # the gyroscopic turn, too
            ω = max(ω, float(self._engine.gyroscope.speed))
        return search_start_step(ω, self._torques, self._t0)

    # ----------------------------------------------------------------- evaluation

    def _principal_states(self, t: Any) -> tuple[NDArray, NDArray, tuple[int, ...]]:
        τ = as_si_array(t, "time", "t")
        if np.any(τ < self._t0):
            raise InputError(
                f"t must be at or after t0 = {self._t0} s (the torqued solver propagates "
                f"forward), got {float(np.min(τ))}"
            )
        flat = τ.ravel()
        m = np.empty((flat.size, 3))
        q = np.empty((flat.size, 4))
        for start in range(0, flat.size, _DENSE_CHUNK):
            part = slice(start, start + _DENSE_CHUNK)
            m[part], q[part] = self._propagation.states(flat[part])
        return m, q, τ.shape

    def _principal_rate(self, m: NDArray) -> NDArray:
        """ω = I⁻¹(M − h) in principal axes (h = 0 without wheels)."""
        if self._wheels_principal is not None:
            m = m - self._wheels_principal
        return m / self._moments

    def _body_quaternions(self, q_principal: NDArray) -> NDArray:
        """Body → inertial quaternions (scalar first) from principal → inertial ones."""
        if self._principal_to_body is None:
            return q_principal
        R = Rotation.from_quat(q_principal, scalar_first=True) * self._principal_to_body.inv()
        return R.as_quat(scalar_first=True)

    def _to_body(self, v: NDArray) -> NDArray:
        return v if self._principal_to_body is None else self._principal_to_body.apply(v)

    def states(self, t: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Body-frame angular momentum (N m s) and attitude quaternions body → inertial,
        scalar first, at ``t``, from one evaluation: shapes ``np.shape(t) + (3,)``, ``+ (4,)``."""
        if self._exact:
            return self._free.angular_momentum(t), self._free.attitude_quaternion(t)
        m, q, shape = self._principal_states(t)
        return self._to_body(m).reshape((*shape, 3)), self._body_quaternions(q).reshape((*shape, 4))

    def angular_momentum(self, t: ArrayLike) -> NDArray[np.float64]:
        """Body-frame angular momentum at ``t`` (N m s), shape ``np.shape(t) + (3,)``."""
        if self._exact:
            return self._free.angular_momentum(t)
        m, _, shape = self._principal_states(t)
        return self._to_body(m).reshape((*shape, 3))

    def angular_velocity(self, t: ArrayLike) -> NDArray[np.float64]:
        """Body-frame angular velocity at ``t`` (rad/s), shape ``np.shape(t) + (3,)``."""
        if self._exact:
            return self._free.angular_velocity(t)
        m, _, shape = self._principal_states(t)
        return self._to_body(self._principal_rate(m)).reshape((*shape, 3))

    def attitude_quaternion(self, t: ArrayLike, scalar_first: bool = True) -> NDArray[np.float64]:
        """Attitude at ``t``, body → inertial, unit quaternions of shape ``np.shape(t) + (4,)``.

        Scalar first (w, x, y, z) by default.
        """
        if self._exact:
            return self._free.attitude_quaternion(t, scalar_first)
        _, q, shape = self._principal_states(t)
        q = self._body_quaternions(q).reshape((*shape, 4))
        return q if scalar_first else q[..., [1, 2, 3, 0]]

    def attitude(self, t: ArrayLike) -> Rotation:
        """Rotation body → inertial at ``t``: one for a scalar, a stack for a 1-D array."""
        if self._exact:
            return self._free.attitude(t)
        if np.ndim(t) > 1:
            raise InputError(f"t must be a scalar or a 1-D array for attitude(), got {np.shape(t)}")
        return Rotation.from_quat(self.attitude_quaternion(t), scalar_first=True)

    # ----------------------------------------------------------------- properties

    @property
    def t0(self) -> float:
        return self._t0

    @property
    def step(self) -> float:
        """The step (s) of the grid (every step but those cut at a breakpoint)."""
        return self._propagation.step

    @property
    def order(self) -> int:
        return self.method.order

    @property
    def wheel_momentum(self) -> NDArray[np.float64] | None:
        """The spinning wheels' momentum h, body axes (N m s), or None."""
        h = self._wheels_principal
        return None if h is None else np.asarray(self._to_body(h), dtype=np.float64)

    @property
    def torques(self) -> tuple[Torque, ...]:
        return tuple(self._torques)

    def grid_invariants(self, t_end: float) -> tuple[NDArray, NDArray, NDArray]:
        """The grid up to ``t_end``: its times (s), |m| (N m s) and kinetic energy (J).

        Both quantities are those of the states at the grid points: the free flow
        conserves them, so a flow still owed there (see ``_Engine``) does not change them.
        With wheels the energy is the body's, ½ ω·Iω with ω = I⁻¹(M − h), which the free
        flow changes: it is then taken at the grid points after the owed flow.
        """
        self._propagation.extend_to(float(t_end))
        t, m, _, _ = self._propagation.arrays()
        keep = t <= t_end
        t, m = t[keep], m[keep]
        if self._wheels_principal is not None:
            m = self._propagation.states(t)[0]
        ω = self._principal_rate(m)
        return t, np.linalg.norm(m, axis=-1), 0.5 * np.sum(ω * ω * self._moments, axis=-1)

    @property
    def steps_computed(self) -> int:
        """Grid steps propagated so far (the grid is extended as far as it is asked for)."""
        return self._propagation.count

    @property
    def free_flows(self) -> int:
        """Free-flow calls made so far (the cost unit of the method)."""
        return self._engine.flows

    def __repr__(self) -> str:
        return (
            f"TorquedSolver(inertia={self._moments.tolist()}, t0={self._t0}, "
            f"torques={self._torques!r}, method={self.method.name!r}, step={self.step:g} s)"
        )


# ----------------------------------------------------------------- many spacecraft


def propagate_batch(
    inertia: ArrayLike,
    angular_momentum: ArrayLike,
    attitude: Rotation | None = None,
    t0: float = 0.0,
    times: ArrayLike = (),
    torques: Any = (),
    step: float = 5.0,
    order: int | None = None,
    *,
    method: str | None = None,
    wheel_momentum: ArrayLike | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """N spacecraft advanced together under the same torque models, states at ``times``.

    For dispersion studies: every kick and every free flow acts on all N states at
    once (vectorized), and the time-dependent part of the torques (the orbit position)
    is computed once for all.  ``inertia``: principal moments along the body axes,
    (3,) shared or (N, 3) dispersed, kg m² (body axes = principal axes here: a full
    tensor is diagonalized by the caller, as ``attitude.solver.inertia.principal_axes`` does);
    ``angular_momentum``: (N, 3), body axes, N m s; ``attitude``: a stack of N
    rotations body → inertial at ``t0`` (or one, or None for the identity);
    ``times``: increasing, ≥ ``t0``, s.  The orbit is shared: spacecraft on different
    orbits are different batches.

    ``wheel_momentum``: wheels spinning at constant speed relative to each body, their
    momentum h (body axes, N m s), (3,) shared or (N, 3): gyrostats
    (:mod:`attitude.torques.gyrostat`), whose ``angular_momentum`` is the total M = Iω + h.

    Returns (momentum, quaternions): body-frame momentum (T, N, 3) and attitude
    quaternions body → inertial, scalar first, (T, N, 4), at each of the T times.
    The same grid and dense output as :class:`TorquedSolver` with the same step.
    """
    inertia = as_si_array(inertia, "moment_of_inertia", "inertia")
    m = as_si_array(angular_momentum, "angular_momentum", "angular_momentum")
    if m.ndim != 2 or m.shape[1] != 3:
        raise InputError(f"angular_momentum must have shape (N, 3), got {m.shape}")
    n = m.shape[0]
    if inertia.shape not in ((3,), (n, 3)) or not np.all(inertia > 0.0):
        raise InputError(
            f"inertia must be 3 positive moments or shape ({n}, 3), got {inertia.shape}"
        )
    if attitude is None:
        q = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    else:
        q = np.broadcast_to(attitude.as_quat(scalar_first=True), (n, 4)).copy()
    t0 = as_si_scalar(t0, "time", "t0")
    times = as_si_array(times, "time", "times")
    if times.ndim != 1 or np.any(np.diff(times) < 0.0) or (times.size and times[0] < t0):
        raise InputError("times must be a 1-D increasing array at or after t0")
    step = as_si_scalar(step, "time", "step")
    if not step > 0.0:
        raise InputError(f"step must be positive (s), got {step}")
    torques = as_torque_list(torques)
    chosen = composition(4 if order is None and method is None else order, method)
    frame = PrincipalFrame(tuple(inertia[..., i] for i in range(3)))
    gyroscope = None
    if wheel_momentum is not None:
        h = as_si_array(wheel_momentum, "angular_momentum", "wheel_momentum")
        if h.shape not in ((3,), (n, 3)):
            raise InputError(f"wheel_momentum must have shape (3,) or ({n}, 3), got {h.shape}")
        if chosen.needs_rkn:
            raise InputError(
                f"method {chosen.name!r} (order {chosen.order}) keeps its order only without "
                "a gyroscopic term; spinning wheels allow order 2 or 4"
            )
        h = np.broadcast_to(h, (n, 3))
        gyroscope = Gyroscope(tuple(h[:, i] for i in range(3)), frame.moments)
    engine = _Engine(chosen, merged_constant_torques(torques), frame, inertia, gyroscope)
    breakpoints = np.array(sorted({b for t in torques for b in t.breakpoints if b > t0}))

    out_m = np.empty((times.size, n, 3))
    out_q = np.empty((times.size, n, 4))
    state = (tuple(m.T), tuple(q.T), 0.0)

    def output(i: int, t_start: float) -> None:
        m_i, q_i = engine.partial_steps(*state, t_start, float(times[i] - t_start))
        out_m[i] = np.stack(np.broadcast_arrays(*m_i), axis=-1)
        q_i = np.stack(np.broadcast_arrays(*q_i), axis=-1)
        out_q[i] = q_i / np.linalg.norm(q_i, axis=-1, keepdims=True)

    i, t = 0, t0
    while i < times.size:
        starts, sizes = _grid_steps(t, float(times[-1]), step, breakpoints, _CHUNK_STEPS)
        if starts.size == 0:  # the remaining times are at the end of the grid
            output(i, t)
            i += 1
            continue
        data = [d.tolist() for d in engine.time_data(starts, sizes)]
        largest = largest_momentum(inertia, float(starts[-1] + sizes[-1]))
        for k in range(starts.size):
            while i < times.size and times[i] < starts[k] + sizes[k]:
                output(i, float(starts[k]))
                i += 1
            state = engine.step(*state, float(sizes[k]), engine.rows_for_step(data, k))
            m_k = state[0]
            if not np.all(np.abs(m_k[0]) + np.abs(m_k[1]) + np.abs(m_k[2]) <= largest):
                _refuse_runaway(m_k, inertia, float(starts[k] + sizes[k]))
        t = float(starts[-1] + sizes[-1])
    return out_m, out_q


# ----------------------------------------------------------------- validity of torque-free


def departure_time(
    inertia: ArrayLike,
    angular_momentum: ArrayLike,
    attitude: Rotation | None,
    t0: float,
    torques: Any,
    horizon: float,
    threshold: float = math.radians(1.0),
    **solver_options: Any,
) -> float:
    """How long (s after t0) until the torques move the attitude ``threshold`` (rad) away
    from the torque-free motion, or ``math.inf`` if not within ``horizon`` (s).

    The validity horizon of a torque-free propagation: the torqued solver runs
    alongside :class:`EulerSolver` from the same state; their attitudes are compared
    every step, and the first crossing is refined by bisection on the dense output
    (to a millisecond).  A departure shorter than a step between two samples can be
    missed.  ``solver_options`` go to :class:`TorquedSolver` (step, order, ...).
    """
    horizon = as_si_scalar(horizon, "time", "horizon")
    threshold = as_si_scalar(threshold, "angle", "threshold")
    if not (horizon > 0.0 and threshold > 0.0):
        raise InputError(f"horizon and threshold must be positive, got {horizon}, {threshold}")
    torqued = TorquedSolver(inertia, angular_momentum, attitude, t0, torques, **solver_options)
    free = EulerSolver(inertia, angular_momentum, attitude, t0)

    def angle(t):
        return angles_between(torqued.attitude_quaternion(t), free.attitude_quaternion(t))

    crossing = first_crossing(angle, torqued.t0, torqued.t0 + horizon, torqued.step, threshold)
    return crossing - torqued.t0


def first_crossing(angle, start: float, end: float, sample: float, threshold: float) -> float:
    """The first time in (start, end] at which ``angle(t)`` (t an array) reaches
    ``threshold``, or ``math.inf``: sampled every ``sample`` s, 1000 samples at a time
    (computing no further than needed), then refined by bisection to a millisecond."""
    while start < end:
        t = np.minimum(start + sample * np.arange(1, 1001), end)
        beyond = np.flatnonzero(angle(t) >= threshold)
        if beyond.size:
            high = float(t[beyond[0]])
            low = float(t[beyond[0] - 1]) if beyond[0] > 0 else start
            while high - low > 1e-3:
                mid = 0.5 * (low + high)
                if angle(np.array([mid]))[0] >= threshold:
                    high = mid
                else:
                    low = mid
            return high
        start = float(t[-1])
    return math.inf


def angles_between(qa: NDArray, qb: NDArray) -> NDArray:
    """Rotation angles (rad) between quaternion stacks, without cancellation near 0."""
    diff = np.minimum(np.linalg.norm(qa - qb, axis=-1), np.linalg.norm(qa + qb, axis=-1))
    return 4.0 * np.arcsin(np.minimum(1.0, 0.5 * diff))
