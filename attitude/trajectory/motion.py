"""Flips, spin, precession and nutation of a trajectory, per segment, from the closed form.

For each segment of torque-free motion:

- **flips** (the Джанибеков effect): the times at which the body turns over, exactly
  (``EulerSolver.flip_times``), and the flip period, half the period of m(t);
- **spin axis and nutation**: in case (i) the body angular momentum circulates
  about the axis of least inertia, in case (ii) about the axis of greatest inertia;
  the angle between that *spin axis* and the angular momentum H oscillates between
  the closed-form bounds arccos(B/G) and arccos(B√mc/G) with period T/2
  (``EulerSolver.spin_axis_cone``).  It is constant for a symmetric body;
- **spin period**: the mean period of the body's rotation about H, what a ground
  observer of a tumbling body measures (e.g. by laser ranging): the azimuth about
  H of a body axis across the spin axis advances by 2π per spin period;
- **precession period**: the mean period of the spin axis circling H.  For a
  symmetric body it is 2π I⊥/G exactly (Landau & Lifshitz, Mechanics, §33); None
  for a steady spin, whose spin axis lies along H.
Mean rates are measured on the closed-form attitude over one period T of m(t),
after which the body's orientation relative to H repeats up to a rotation about H.

Segments without a period are stated as what they are (``SegmentMotion.motion``):

- ``"steady spin"``: m is fixed in the body (a sphere, a spin exactly about a
  principal axis, the intermediate one included, or m in the plane of two equal
  moments), so ω ∥ m and the body turns about H at |ω| = 2T/G: the spin period is
  2π/|ω|, and there are no flips, no nutation, no precession;
- ``"separatrix"``: m on the separatrix (Δ2 = 0) but not at the intermediate axis:
  no period; m leaves the intermediate axis and returns to it asymptotically, so the
  body turns over at most once (at u = 0) and nothing repeats;
- ``"rest"``: G = 0;
- ``"torqued"``: a segment under torques (``attitude.trajectory.torqued``): no period and
  no closed form; its energy and momentum are given at its start, and its flips are
  located on the propagated motion (:meth:`TorquedMotion.flip_times`), the momentum
  crossing from one side of the intermediate axis to the other as the closed form
  defines a flip.  When they are not located (``attitude check`` leaves them to the
  run), ``flip_count`` is None and ``flips_note`` says why: never a count that was not
  computed; ``"gyrostat"``: a body with spinning wheels and no torque, likewise;
- ``"guided"`` and ``"slew"``: a segment under an attitude law or a slew
  (``attitude.trajectory.guided``): the attitude is the law's, not a motion of its own;
  no flips; its energy and momentum (I·ω) are given at its start.
Flips are counted from the closed form without listing them all: at most
:data:`LISTED_FLIPS` flip times are kept (a day of a fast tumbler has millions).

Each segment's largest body rate over its part of the output span, and when it is
first reached, are found on the motion (``attitude.trajectory.rates``), not on the
output grid.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from attitude.base.vectors import basis_across
from attitude.solver.euler_solver import EulerSolver
from attitude.trajectory.guided import GuidedMotion
from attitude.trajectory.rates import largest_rate
from attitude.trajectory.torqued import TorquedMotion
from attitude.trajectory.trajectory import Segment, Trajectory

__all__ = [
    "LISTED_FLIPS",
    "NOT_LOCATED",
    "SegmentMotion",
    "analyze",
    "largest_rate_of",
    "undersampling_note",
]

# Sampling of one body period for the mean precession rate: enough points per turn
# of the spin axis that the unwrapped azimuth cannot skip a turn.
_SAMPLES_PER_TURN = 32
_MAX_SAMPLES = 1_000_000
# The flip times kept per segment; beyond, flips are counted, not listed.
LISTED_FLIPS = 10_000


@dataclass(frozen=True)
class SegmentMotion:
    """What the motion of one segment is, in numbers (seconds, radians, body axes)."""

    start_s: float
    end_s: float
    formula: str
    motion: str  # "periodic", "steady spin", "separatrix", "rest", "torqued", "gyrostat",
    # "guided" or "slew"
    period_s: float  # inf when the motion has no period
    flip_count: int | None  # None: not located (flips_note says why)
    flip_times_s: NDArray[np.float64]  # the first LISTED_FLIPS of them
    flip_period_s: float | None
    spin_axis_body: NDArray[np.float64] | None
    nutation_min_rad: float | None
    nutation_max_rad: float | None
    nutation_period_s: float | None
    spin_period_s: float | None
    precession_period_s: float | None
    kinetic_energy_J: float
    inertial_angular_momentum_N_m_s: NDArray[np.float64]
    angular_momentum_norm_N_m_s: float  # G, with no overflow of the squares
    # The largest |ω| over the segment's part of the output span, and when first
    # reached (None: the segment lies outside it, or the rate was not searched).
    max_rate_rad_s: float | None = None
    max_rate_at_s: float | None = None
    flips_note: str | None = None


def _free_solver(segment: Segment) -> EulerSolver:
    """The segment's exact torque-free solver (the analyses below need its invariants)."""
    if not isinstance(segment.solver, EulerSolver):
        raise TypeError(f"segment from {segment.start_s} s is not torque-free")
    return segment.solver


def _mean_period_about_momentum(segment: Segment, axis_body: NDArray[np.float64]) -> float:
    """Period of the mean rotation of a body axis about H, over one period of m(t)."""
    solver = _free_solver(segment)
    G = solver.angular_momentum_norm
    h = solver.inertial_angular_momentum / G
    period = solver.period
    turns = period * G / np.min(solver.moments_of_inertia) / (2.0 * math.pi)  # upper bound
    count = int(min(_MAX_SAMPLES, max(1024, _SAMPLES_PER_TURN * turns)))
    t = solver.t0 + np.linspace(0.0, period, count + 1)
    axis = solver.attitude(t).apply(axis_body)
    u, v = basis_across(h)
    azimuth = np.unwrap(np.arctan2(axis @ v, axis @ u))
    advance = abs(azimuth[-1] - azimuth[0])
    return math.inf if advance == 0.0 else 2.0 * math.pi * period / advance


def _is_steady(segment: Segment) -> bool:
    """True if m is fixed in the body: ω = I⁻¹m is parallel to m (then dm/dt = m × ω = 0
    and m stays), tested exactly in principal axes, as the solver sees the state."""
    solver = _free_solver(segment)
    if solver.formula == "steady":
        return True
    if solver.formula == "rest":
        return False
    axes = segment.state.inertia
    m = segment.state.angular_momentum
    if not axes.is_diagonal:
        m = axes.body_to_principal.apply(m)
    ω = m / axes.moments
    return not np.any(np.cross(m, ω))


def _steady_spin_period(segment: Segment) -> float | None:
    """2π/|ω| for a steady spin (ω = I⁻¹m ∥ m: the body turns about H at |ω| = 2T/G),
    with m scaled first so that neither |m|² nor T can underflow or overflow; None if
    |ω| is below the float range (m of 1e-300 N m s)."""
    m = segment.state.angular_momentum
    scale = float(np.max(np.abs(m)))
    ω = np.linalg.solve(segment.state.inertia.tensor, m / scale)
    rate = scale * float(np.linalg.norm(ω))
    return 2.0 * math.pi / rate if rate > 0.0 and math.isfinite(2.0 * math.pi / rate) else None


def _flips(segment: Segment) -> tuple[int, NDArray[np.float64], float | None]:
    """(count, the first LISTED_FLIPS flip times, flip period) over the segment.

    In cases (i) and (ii) the flips come every half period T/2 when the body turns
    over; their number over a long segment is counted from the first one, not by
    listing them (the solver's ``flip_times`` lists every one).
    """
    solver = _free_solver(segment)
    start, end = segment.start_s, segment.end_s
    if solver.formula not in ("i", "ii"):
        flips = solver.flip_times(start, end)  # the separatrix: at most one
        return int(flips.size), flips, None
    half = solver.period / 2.0
    first = solver.flip_times(solver.t0, solver.t0 + solver.period)
    if first.size == 0:
        return 0, np.empty(0), None  # m2 changes sign in a nutation, not a flip
    if (end - start) / half < LISTED_FLIPS:
        flips = solver.flip_times(start, end)
        return int(flips.size), flips, half
    # Flips at first[0] + j T/2 for every integer j: count those in [start, end].
    count = math.floor((end - first[0]) / half) - math.ceil((start - first[0]) / half) + 1
    listed = solver.flip_times(start, start + (LISTED_FLIPS - 0.5) * half)
    return count, listed[:LISTED_FLIPS], half


# Why a torqued segment's flips are not located, when they are not.
NOT_LOCATED = "not located by `attitude check`: the run locates them on its propagated motion"


def _torqued_motion(
    segment: Segment, solver: TorquedMotion | GuidedMotion, locate: bool
) -> SegmentMotion:
    """A segment under torques (or with spinning wheels): its state at the start, its
    flips located on the propagated motion (when ``locate``); no period or cone.  Under
    a law or a slew: its state at the start, no flips (the law holds the attitude)."""
    guided = isinstance(solver, GuidedMotion)
    locate = locate or guided
    flips = solver.flip_times(segment.start_s, segment.end_s) if locate else np.empty(0)
    return SegmentMotion(
        start_s=segment.start_s,
        end_s=segment.end_s,
        formula=solver.formula,
        motion=solver.formula,
        period_s=math.inf,
        flip_count=int(flips.size) if locate else None,
        flips_note=None if locate else NOT_LOCATED,
        flip_times_s=flips[:LISTED_FLIPS],
        flip_period_s=None,
        spin_axis_body=None,
        nutation_min_rad=None,
        nutation_max_rad=None,
        nutation_period_s=None,
        spin_period_s=None,
        precession_period_s=None,
        kinetic_energy_J=solver.initial_kinetic_energy,
        inertial_angular_momentum_N_m_s=solver.initial_inertial_angular_momentum,
        angular_momentum_norm_N_m_s=float(np.linalg.norm(segment.state.angular_momentum)),
    )


def _with_rate(item: SegmentMotion, segment: Segment, span: tuple[float, float] | None):
    """``item`` with its largest rate over ``span`` ∩ the segment (None: no rate)."""
    if span is None:
        return item
    a, b = max(segment.start_s, span[0]), min(segment.end_s, span[1])
    if b < a:
        return item
    rate, at = largest_rate(segment, a, b)
    return dataclasses.replace(item, max_rate_rad_s=rate, max_rate_at_s=at)


def _segment_motion(segment: Segment, locate: bool) -> SegmentMotion:
    if isinstance(segment.solver, TorquedMotion | GuidedMotion):
        return _torqued_motion(segment, segment.solver, locate)
    solver = _free_solver(segment)
    count, flips, flip_period = _flips(segment)
    axis = nutation_min = nutation_max = nutation_period = spin = precession = None
    steady = solver.formula == "steady" or _is_steady(segment)
    if steady:
        count, flips, flip_period = 0, np.empty(0), None
        spin = _steady_spin_period(segment)
    cone = solver.spin_axis_cone()
    if cone is not None:
        axis, nutation_min, nutation_max = cone
        if not steady:
            # A body axis across the spin axis, for the rotation about H.
            spin = _mean_period_about_momentum(segment, basis_across(axis)[0])
        if nutation_max > 0.0:  # else a steady spin: the spin axis lies along H
            nutation_period = solver.period / 2.0
            moments = np.sort(solver.moments_of_inertia)
            if moments[0] == moments[1] or moments[1] == moments[2]:
                precession = 2.0 * math.pi * moments[1] / solver.angular_momentum_norm
            else:
                precession = _mean_period_about_momentum(segment, axis)
    if solver.formula == "rest":
        motion = "rest"
    elif steady or (cone is not None and nutation_max == 0.0):
        motion = "steady spin"
    elif solver.formula == "iii":
        motion = "separatrix"
    else:
        motion = "periodic"
    return SegmentMotion(
        start_s=segment.start_s,
        end_s=segment.end_s,
        formula=solver.formula,
        motion=motion,
        period_s=solver.period if motion == "periodic" else math.inf,
        flip_count=count,
        flip_times_s=flips,
        flip_period_s=flip_period,
        spin_axis_body=axis,
        nutation_min_rad=nutation_min,
        nutation_max_rad=nutation_max,
        nutation_period_s=nutation_period,
        spin_period_s=spin,
        precession_period_s=precession,
        kinetic_energy_J=solver.kinetic_energy,
        inertial_angular_momentum_N_m_s=solver.inertial_angular_momentum,
        angular_momentum_norm_N_m_s=solver.angular_momentum_norm,
    )


def analyze(trajectory: Trajectory, locate: bool = True) -> list[SegmentMotion]:
    """The motion of each segment of ``trajectory`` (see the module docstring).

    ``locate``: locate the flips and the largest rate of the segments under torques
    on their propagated motion, and the largest rate of every segment (``attitude
    check`` does not: it leaves them to the run, and says so).
    """
    scenario = trajectory.scenario
    span = (scenario.start_s, scenario.stop_s) if locate else None
    return [
        _with_rate(_segment_motion(segment, locate), segment, span)
        for segment in trajectory.segments
    ]


def largest_rate_of(motion: list[SegmentMotion]) -> tuple[float, float] | None:
    """The largest body rate over the output span (rad/s) and when it is first
    reached (TT s), from :func:`analyze`'s segments; None if not searched."""
    found = [
        (item.max_rate_rad_s, item.max_rate_at_s)
        for item in motion
        if item.max_rate_rad_s is not None and item.max_rate_at_s is not None
    ]
    if not found:
        return None
    top = max(rate for rate, _ in found)
    return top, min(at for rate, at in found if rate == top)


def undersampling_note(trajectory: Trajectory, motion) -> str | None:
    """One line when the output step is more than a tenth of the shortest period of
    the motion in any segment (``motion``: :func:`analyze`),
    naming the step and the period; None otherwise."""
    scenario = trajectory.scenario
    worst = None
    for index, item in enumerate(motion):
        if item.end_s < scenario.start_s or item.start_s > scenario.stop_s:
            continue
        periods = {
            "body period": item.period_s,
            "spin period": item.spin_period_s,
            "nutation period": item.nutation_period_s,
            "precession period": item.precession_period_s,
            "flip period": item.flip_period_s,
        }
        for name, period in periods.items():
            if period is not None and math.isfinite(period) and period > 0.0:
                if worst is None or period < worst[0]:
                    worst = (period, name, index)
    if worst is None or scenario.step_s <= 0.1 * worst[0]:
        return None
    period, name, index = worst
    return (
        f"output.step: {scenario.step_s:.6g} s is more than a tenth of the {period:.6g} s "
        f"{name} of segment {index}: the time series undersamples the motion (extrema and "
        "intervals are found on the exact motion regardless)"
    )
