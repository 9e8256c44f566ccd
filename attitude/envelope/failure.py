"""One control loss: the motion after it and its metrics, on the exact motion.

For a failure at τ the body starts from the nominal state (the law's or the slew's
attitude and rate, read on the nominal timeline) with the wheels' momentum h, through
the exact hand-off (:func:`attitude.trajectory.handoff.hand_off_states` for every τ at
once; :func:`~attitude.trajectory.handoff.hand_off` for one): the closed-form rigid
body (locked wheels, no torque), or the splitting with the exact gyroscopic flow
(spinning wheels) and the scenario's torques.  That motion, one segment over
[τ, τ + window], is searched by the exact pointing search
(:func:`attitude.pointing.search.pointing_analysis`: torque-free segments on the
motion's structure, others with rigorous rate bounds) against the surroundings of the
whole job, built once per process and shared by every τ
(:func:`attitude.pointing.shared_surroundings.shared_surroundings`).  A task's failures
are searched together (:func:`attitude.pointing.search.pointing_analyses`: their
torque-free searches as one set of arrays) and their power searches too
(:func:`_power_search`); each row is the same, bit for bit, as the failure's alone
(:func:`failure_metrics`), whatever the task it runs in.

The metrics (columns of the table; times in s after τ; ``inf``: not within the window):

- ``{vector}_{exclusion}_s``: the first violation of each exclusion of each body vector
  (``sun_exclusion``, ``moon_exclusion``, ``earth_limb_exclusion``; 0 when violated at τ),
  and ``{vector}_blinded_s``, the first of them;
- ``{panel}_least_sun_angle_deg``: the least angle between each panel's normal and the
  Sun over the window;
- ``power_at_loss``, ``power_mean``: the panels' power fraction at τ and its mean over
  the window (:mod:`attitude.envelope.power`: the energy the panels collect, as a
  fraction of full power over the window), ``power_lost_s``: the first time it is at or
  below the threshold (eclipses included: the Earth's shadow takes the power to 0);
- ``rate_at_loss_deg_s``, ``rate_max_deg_s``, ``rate_max_at_s``: the body rate |ω| just
  after the loss (with locked wheels, I⁻¹(I ω_law + h): their momentum passes to the
  body), and its largest over the window, on the motion
  (:func:`attitude.trajectory.rates.largest_rate`);
- ``flips``, ``first_flip_s``: the body's flips (Джанибеков) within the window;
- ``first_violation_s``: the least of the exclusion times (the first instant any body
  vector is blinded).
"""

from __future__ import annotations

import contextlib
import math
import time
import weakref
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.envelope.power import (
    as_fraction,
    first_below,
    first_below_many,
    first_nodes,
    integral,
    mean_incidence,
    power_fraction,
)
from attitude.jobs.failures import TaskError
from attitude.pointing.search import (
    OrbitIntervals,
    PointingAnalysis,
    pointing_analyses,
    pointing_analysis,
)
from attitude.pointing.shared_surroundings import SharedSurroundings, shared_surroundings
from attitude.pointing.spec import PointingSpec
from attitude.scenario.events import State
from attitude.scenario.modes import Wheels
from attitude.scenario.scenario import Scenario
from attitude.solver.euler_solver import EulerSolver
from attitude.trajectory.handoff import hand_off
from attitude.trajectory.rates import largest_rate
from attitude.trajectory.segments import Segment
from attitude.trajectory.torqued import TorquedMotion
from attitude.trajectory.trajectory import Trajectory

__all__ = ["BatchResult", "EnvelopeJob", "evaluate_batch", "failure_metrics", "metric_names"]

EXCLUSIONS = ("sun_exclusion", "moon_exclusion", "earth_limb_exclusion")


def metric_names(spec: PointingSpec) -> list[str]:
    """The table's metric columns for ``spec``'s body vectors (module notes)."""
    names = []
    for vector in spec.body_vectors:
        exclusions = vector.exclusions
        names += [f"{vector.name}_{e}_s" for e in exclusions]
        if exclusions:
            names.append(f"{vector.name}_blinded_s")
    panels = [v.name for v in spec.body_vectors if v.kind == "panel"]
    names += [f"{p}_least_sun_angle_deg" for p in panels]
    if panels:
        names += ["power_at_loss", "power_mean", "power_lost_s"]
    names += ["rate_at_loss_deg_s", "rate_max_deg_s", "rate_max_at_s", "flips", "first_flip_s"]
    names.append("first_violation_s")
    return names


@dataclass(frozen=True, eq=False)
class EnvelopeJob:
    """What every task needs (scattered once to each worker).

    ``scenario``: the job's span (the epoch, the orbit, the spacecraft; its stop covers
    the last window) without events; ``spec``: the pointing, with the orbit;
    ``seconds``: the failure instants τ; ``quaternions`` (scalar last, scipy's order,
    body → ICRF) and ``momenta`` (N m s, body axes): the hand-off states there, and the nominal
    rates ``angular_velocities`` (rad/s, body axes);
    ``wheels``; ``torques``: (start, stop, model) of the torques acting on the free
    body; ``step``: the splitting's step (None: the exact solver); ``order``;
    ``orbit``: the eclipses and the Moon behind the Earth over the whole span, found
    once and cut to each window (None at the Earth's centre).
    """

    scenario: Scenario
    spec: PointingSpec
    seconds: NDArray[np.float64]
    quaternions: NDArray[np.float64]
    momenta: NDArray[np.float64]
    angular_velocities: NDArray[np.float64]
    wheels: Wheels
    window: float
    threshold: float
    torques: tuple[tuple[float, float, Any], ...]
    step: float | None
    order: int
    columns: tuple[str, ...]
    orbit: OrbitIntervals | None = None

    @property
    def count(self) -> int:
        return int(self.seconds.size)


@dataclass
class BatchResult:
    """The rows of failures ``first`` to ``stop − 1``, and the CPU they took (s)."""

    rows: list[dict[str, Any]]
    compute_s: float


def motion_after(job: EnvelopeJob, k: int) -> Trajectory:
    """The motion after failure ``k``: one segment over [τ, τ + window]."""
    τ = float(job.seconds[k])
    end = τ + job.window
    attitude = Rotation.from_quat(job.quaternions[k])
    axes = job.scenario.spacecraft.principal_axes
    state = State(attitude, job.momenta[k], axes)
    acting = [model for a, b, model in job.torques if a < end and b > τ]
    spinning = job.wheels.case == "spinning"
    if not spinning and not acting:
        # Locked wheels: the momentum already holds h; the exact rigid body.
        solver: Any = hand_off(attitude, job.angular_velocities[k], axes, τ, job.wheels)
    else:
        assert job.step is not None
        h = job.wheels.momentum_vector if spinning else None
        solver = TorquedMotion(state, τ, end, acting, job.step, job.order, h)
    return Trajectory(job.scenario, [Segment(τ, end, solver, state)])


def _first(intervals, τ: float) -> float:
    if not intervals:
        return math.inf
    first = intervals[0]
    return 0.0 if first.starts_before else max(first.start_s - τ, 0.0)


def _surroundings(job: EnvelopeJob, trajectory: Trajectory) -> SharedSurroundings:
    """The job's shared surroundings in this process: looked up once per job (the
    lookup hashes the orbit), then kept with it."""
    found = _SURROUNDINGS.get(job)
    if found is None:
        found = shared_surroundings(trajectory, job.spec, 0.0, job.scenario.stop_s)
        _SURROUNDINGS[job] = found
    return found


# Each job's shared surroundings in this process, for as long as the job lives.
_SURROUNDINGS: weakref.WeakKeyDictionary[EnvelopeJob, SharedSurroundings] = (
    weakref.WeakKeyDictionary()
)


@dataclass
class _Power:
    """What the power search of one failure needs: its motion's attitude quaternions
    (scalar first, body → ICRF), the panels' normals, the window cut at the shadow's
    edges (:func:`_pieces`), its precision; ``row`` receives ``power_at_loss`` and
    ``power_lost_s``."""

    row: dict[str, Any]
    τ: float
    quaternions: Any
    normals: NDArray[np.float64]
    pieces: list[tuple[float, float, float, bool]]
    precision: float


def failure_metrics(job: EnvelopeJob, k: int) -> dict[str, Any]:
    """The metrics of failure ``k`` (module notes), as one row of the table."""
    row, power = _structure(job, k)
    if power is not None:
        _power_search(_SURROUNDINGS[job], [power], job.threshold)
    return row


def _extrema(job: EnvelopeJob) -> list[tuple[str, str]]:
    """The extrema the rows need: each panel's least Sun angle."""
    return [(v.name, "sun_angle") for v in job.spec.body_vectors if v.kind == "panel"]


def _structure(job: EnvelopeJob, k: int) -> tuple[dict[str, Any], _Power | None]:
    """Failure ``k``'s row but for the power search's two columns, and that search."""
    τ = float(job.seconds[k])
    trajectory = motion_after(job, k)
    shared = _surroundings(job, trajectory)
    analysis = pointing_analysis(
        trajectory,
        job.spec,
        τ,
        τ + job.window,
        surroundings=shared,
        orbit=job.orbit,
        extrema=_extrema(job),
    )
    return _row(job, k, trajectory, analysis, shared)


@contextlib.contextmanager
def _refusals_or_bugs(job: EnvelopeJob, k: int) -> Iterator[None]:
    """An exception of the block that is neither a refusal of failure ``k``'s own
    motion (:class:`InputError`: its row says so) nor the machine's (a memory error)
    raised as a :class:`TaskError` naming the failure: a bug, never a row."""
    try:
        yield
    except (InputError, MemoryError):
        raise
    except Exception as exc:
        raise TaskError.of(exc, f"failure {k} (τ = {float(job.seconds[k]):g} s)") from exc


def _structures(job: EnvelopeJob, ks: list[int]) -> list[Any]:
    """:func:`_structure` of failures ``ks``, their pointing searches together
    (:func:`attitude.pointing.search.pointing_analyses`: each the same, bit for bit, as
    alone): for each, its (row, power search), or the refusal (:class:`InputError`)
    of its motion.  If the searches together are refused, each is searched alone (to
    name the one); any other exception is a bug (:func:`_refusals_or_bugs`)."""
    out: list[Any] = [None] * len(ks)
    motions = []
    for j, k in enumerate(ks):
        try:
            with _refusals_or_bugs(job, k):
                motions.append((j, k, motion_after(job, k)))
        except InputError as exc:
            out[j] = exc
    if not motions:
        return out
    shared = _surroundings(job, motions[0][2])
    try:
        analyses = pointing_analyses(
            [trajectory for _, _, trajectory in motions],
            job.spec,
            [(float(job.seconds[k]), float(job.seconds[k]) + job.window) for _, k, _ in motions],
            surroundings=shared,
            orbit=job.orbit,
            extrema=_extrema(job),
        )
    except Exception:  # a refusal or a bug: each alone says which failure's, and which
        for j, k, _ in motions:
            try:
                with _refusals_or_bugs(job, k):
                    out[j] = _structure(job, k)
            except InputError as exc:
                out[j] = exc
        return out
    for (j, k, trajectory), analysis in zip(motions, analyses, strict=True):
        try:
            with _refusals_or_bugs(job, k):
                out[j] = _row(job, k, trajectory, analysis, shared)
        except InputError as exc:
            out[j] = exc
    return out


def _row(
    job: EnvelopeJob,
    k: int,
    trajectory: Trajectory,
    analysis: PointingAnalysis,
    shared: SharedSurroundings,
) -> tuple[dict[str, Any], _Power | None]:
    """Failure ``k``'s row from its pointing ``analysis``, but for the power search's
    two columns, and that search."""
    τ = float(job.seconds[k])
    end = τ + job.window
    row: dict[str, Any] = {}
    firsts = []
    for item in analysis.vectors:
        name = item.vector.name
        exclusions = item.vector.exclusions
        for e in exclusions:
            row[f"{name}_{e}_s"] = _first(getattr(item, e), τ)
            firsts.append(row[f"{name}_{e}_s"])
        if exclusions:
            row[f"{name}_blinded_s"] = _first(item.blinded, τ)
    panels = [item for item in analysis.vectors if item.vector.kind == "panel"]
    for item in panels:
        row[f"{item.vector.name}_least_sun_angle_deg"] = math.degrees(
            item.extrema["sun_angle"][0].value
        )
    segment = trajectory.segments[0]
    power = None
    if panels:
        normals = np.array([item.vector.vector for item in panels])
        grid = analysis.grid
        turning = float(np.mean([grid.vector_angle_rate_bound(i.vector.name) for i in panels]))
        row["power_at_loss"] = math.nan  # filled by the power search (_power_search)
        pieces = _pieces(analysis, τ, end, turning, grid.fraction_rate_bound)
        if isinstance(segment.solver, EulerSolver):
            # The free search integrates the incidence exactly on each cell's quintic.
            row["power_mean"] = float(np.mean([i.mean_cos_incidence for i in panels]))
        else:  # the grid search's trapezoid is coarse: Gauss–Legendre between the edges
            energy = sum(
                integral(_power_in(shared, segment.solver, normals, shadow), a, b, lip)
                for a, b, lip, shadow in pieces
            )
            row["power_mean"] = as_fraction(energy / job.window)  # the quadrature's rounding
        row["power_lost_s"] = math.nan
        quaternions = segment.solver.attitude_quaternion
        power = _Power(row, τ, quaternions, normals, pieces, analysis.precision_s)
    # The body's rate just after the loss: the law's with spinning wheels, I⁻¹(Iω + h)
    # with locked ones (their momentum passes to the body).
    rate0 = float(np.linalg.norm(trajectory.angular_velocity(np.array([τ, τ]))[0]))
    rate, at = largest_rate(segment, τ, end)
    row["rate_at_loss_deg_s"] = math.degrees(rate0)
    row["rate_max_deg_s"] = math.degrees(max(rate, rate0))
    row["rate_max_at_s"] = at - τ if rate > rate0 else 0.0
    flips = segment.solver.flip_times(τ, end)
    row["flips"] = len(flips)
    row["first_flip_s"] = float(flips[0] - τ) if len(flips) else math.inf
    row["first_violation_s"] = min(firsts, default=math.inf)
    return row, power


def _sun(shared: SharedSurroundings, t: NDArray[np.float64], shadow: bool):
    """The Sun's direction and the lit fraction at ``t``: outside the Earth's shadow
    the lit fraction is 1 (only the Sun's direction is needed there, from the
    interpolated targets)."""
    if shadow:
        around = shared.at(t)
        return around.sun_direction, around.sunlit_fraction
    return shared.targets(t).sun, 1.0


def _power_in(shared: SharedSurroundings, solver, normals, shadow: bool):
    """P(t) of one motion, for the integral of a torqued motion."""

    def power(t):
        t = np.asarray(t, dtype=float)
        return power_fraction(
            solver.attitude_quaternion, lambda x: _sun(shared, x, shadow), normals, t
        )

    return power


# The power search takes a piece's nodes in runs of at most this many cells, the next
# run only if the power stays above the threshold over the previous one: in the
# Earth's shadow the lit fraction's rate makes the nodes about a second apart, and the
# power falls to 0 in the umbra, within the first run or two of a shadow piece.
_RUN_CELLS = 256


def _power_search(shared: SharedSurroundings, items: list[_Power], threshold: float) -> None:
    """``power_at_loss`` and ``power_lost_s`` of many failures at once
    (:func:`attitude.envelope.power.first_below_many`): the first run of nodes of
    every failure's window together (with the instant of the loss), then the next run
    of those not yet below the threshold, and so on through the pieces of the window;
    each round evaluates the Sun and the lit fraction for every failure's points in
    one call, and each failure's attitude once.  Each failure's points and their order
    are those it has alone, so its row is the same bit for bit whatever the batch.
    A piece of more cells than :func:`~attitude.envelope.power.first_below` takes in
    one run is searched by it, for its failure alone."""
    stages = [_stages(item) for item in items]
    for item in items:
        item.row["power_lost_s"] = math.inf
    waiting = list(range(len(items)))
    level = 0
    while waiting:
        # (failure, nodes, bound on |P'|, in the shadow): the instant of the loss (its
        # power, the lit fraction counted) first, then stage ``level`` of each window.
        runs = [(i, np.array([items[i].τ]), 0.0, True) for i in waiting] if level == 0 else []
        alone: list[tuple[int, float, float, float, bool]] = []
        for i in waiting:
            if level < len(stages[i]):
                stage = stages[i][level]
                (runs if isinstance(stage[0], np.ndarray) else alone).append((i, *stage))
        if not runs and not alone:
            break
        found_at: dict[int, float] = {}
        for i, a, b, lipschitz, dark in alone:
            first = first_below(
                _one(_batch_power(shared, items, np.array([i]), np.array([dark]))),
                a,
                b,
                lipschitz,
                threshold,
                items[i].precision,
            )
            found_at[i] = math.nan if first is None else first
        if runs:
            owners = np.array([r[0] for r in runs], dtype=np.intp)
            found, at_start = first_below_many(
                _batch_power(shared, items, owners, np.array([r[3] for r in runs], dtype=bool)),
                [r[1] for r in runs],
                np.array([r[2] for r in runs]),
                threshold,
                np.array([items[r[0]].precision for r in runs]),
            )
            first_stage = 0
            if level == 0:
                first_stage = len(waiting)
                for j, i in enumerate(waiting):
                    items[i].row["power_at_loss"] = float(at_start[j])
            for j in range(first_stage, len(runs)):
                found_at[int(owners[j])] = float(found[j])
        still = []
        for i in waiting:
            if i in found_at and not math.isnan(found_at[i]):
                items[i].row["power_lost_s"] = found_at[i] - items[i].τ
            elif level + 1 < len(stages[i]):
                still.append(i)
        waiting = still
        level += 1


def _one(f):
    """``f`` of :func:`_batch_power` for its one piece."""

    def power(t: NDArray[np.float64]) -> NDArray[np.float64]:
        return f(np.zeros(t.size, dtype=np.intp), t)

    return power


def _stages(item: _Power) -> list[tuple]:
    """The window's pieces as the power search takes them, in time order: runs of at
    most _RUN_CELLS cells of a piece's nodes (nodes, bound, in the shadow), or a piece
    searched alone (a, b, bound, in the shadow)."""
    stages: list[tuple] = []
    for a, b, lipschitz, dark in item.pieces:
        nodes = first_nodes(a, b, lipschitz)
        if nodes is None:
            stages.append((a, b, lipschitz, dark))
            continue
        cells = max(nodes.size - 1, 1)
        for start in range(0, cells, _RUN_CELLS):
            stages.append((nodes[start : start + _RUN_CELLS + 1], lipschitz, dark))
    return stages


def _batch_power(shared: SharedSurroundings, items: list[_Power], owners, darks):
    """P at times of many pieces (``owners``: each piece's failure, ``darks``: whether
    it lies in the Earth's shadow): the Sun for all points in one call, each failure's
    attitude at its points in one call, the incidences of all in one pass (element by
    element: a point's value does not depend on the others)."""

    def f(which: NDArray[np.intp], t: NDArray[np.float64]) -> NDArray[np.float64]:
        whose, dark = owners[which], darks[which]
        direction = np.empty((t.size, 3))
        lit = np.ones(t.size)
        if np.any(dark):
            direction[dark], lit[dark] = _sun(shared, t[dark], True)
        if not np.all(dark):
            direction[~dark] = _sun(shared, t[~dark], False)[0]
        q = np.empty((t.size, 4))
        for i in np.unique(whose):
            mine = whose == i
            q[mine] = items[int(i)].quaternions(t[mine])
        # Every failure of a task has the job's panels.
        return lit * mean_incidence(q, items[0].normals, direction)

    return f


def _pieces(analysis, τ: float, end: float, turning: float, fraction_rate: float):
    """[τ, end] cut at the shadow's edges, each piece with its bound on |P'|: outside
    the Earth's shadow the lit fraction is 1, and only the panels' turning bounds it;
    within a shadow the lit fraction's rate adds to it."""
    pieces: list[tuple[float, float, float, bool]] = []
    cursor = τ
    for shadow in analysis.shadow:
        a, b = max(shadow.start_s, τ), min(shadow.end_s, end)
        if b < a:
            continue
        if a > cursor:
            pieces.append((cursor, a, turning, False))
        pieces.append((a, b, turning + fraction_rate, True))
        cursor = b
    if cursor < end:
        pieces.append((cursor, end, turning, False))
    return pieces


def evaluate_batch(job: EnvelopeJob, first: int, stop: int) -> BatchResult:
    """Failures ``first`` to ``stop − 1`` of ``job``, each a row (runs on a worker).  A
    failure whose motion is refused (an :class:`InputError`) is a row with its error;
    the job goes on.  Any other exception ends the task (:func:`_refusals_or_bugs`).

    The pointing searches of the batch run together (:func:`_structures`), and so do
    its power searches (:func:`_power_search`); each row is the same bit for bit as
    :func:`failure_metrics` gives it alone."""
    started = time.process_time()
    rows = []
    searches: list[_Power] = []
    ks = list(range(first, stop))
    for k, found in zip(ks, _structures(job, ks), strict=True):
        row: dict[str, Any] = {"failure": k, "tau_s": float(job.seconds[k])}
        if isinstance(found, InputError):  # a refused motion is this failure's row
            _failed(row, job, found)
        else:
            metrics, power = found
            row.update(metrics, status="ok", error="")
            if power is not None:
                power.row = row
                searches.append(power)
        rows.append(row)
    if searches:
        try:
            _power_search(_SURROUNDINGS[job], searches, job.threshold)
        except Exception:  # find which failure's search is refused: each alone
            for power in searches:
                try:
                    with _refusals_or_bugs(job, power.row["failure"]):
                        _power_search(_SURROUNDINGS[job], [power], job.threshold)
                except InputError as exc:
                    _failed(power.row, job, exc)
    return BatchResult(rows, time.process_time() - started)


def _failed(row: dict[str, Any], job: EnvelopeJob, exc: BaseException) -> None:
    row.update({name: math.nan for name in job.columns}, status="failed", error=_text(exc))


def _text(exc: BaseException) -> str:
    text = " ".join(str(exc).split())
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__
