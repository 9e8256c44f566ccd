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
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from attitude.trajectory import Segment, Trajectory
from attitude.vectors import basis_across

__all__ = ["SegmentMotion", "analyze"]

# Sampling of one body period for the mean precession rate: enough points per turn
# of the spin axis that the unwrapped azimuth cannot skip a turn.
_SAMPLES_PER_TURN = 32
_MAX_SAMPLES = 1_000_000


@dataclass(frozen=True)
class SegmentMotion:
    """What the motion of one segment is, in numbers (seconds, radians, body axes)."""

    start_s: float
    end_s: float
    formula: str
    period_s: float
    flip_times_s: NDArray[np.float64]
    flip_period_s: float | None
    spin_axis_body: NDArray[np.float64] | None
    nutation_min_rad: float | None
    nutation_max_rad: float | None
    nutation_period_s: float | None
    spin_period_s: float | None
    precession_period_s: float | None
    kinetic_energy_J: float
    inertial_angular_momentum_N_m_s: NDArray[np.float64]


def _mean_period_about_momentum(segment: Segment, axis_body: NDArray[np.float64]) -> float:
    """Period of the mean rotation of a body axis about H, over one period of m(t)."""
    solver = segment.solver
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


def _segment_motion(segment: Segment) -> SegmentMotion:
    solver = segment.solver
    flips = solver.flip_times(segment.start_s, segment.end_s)
    turns_over = solver.flip_times(solver.t0, solver.t0 + solver.period).size > 0
    cone = solver.spin_axis_cone()
    axis = nutation_min = nutation_max = nutation_period = spin = precession = None
    if cone is not None:
        axis, nutation_min, nutation_max = cone
        # A body axis across the spin axis, for the rotation about H.
        spin = _mean_period_about_momentum(segment, basis_across(axis)[0])
        if nutation_max > 0.0:  # else a steady spin: the spin axis lies along H
            nutation_period = solver.period / 2.0
            moments = np.sort(solver.moments_of_inertia)
            if moments[0] == moments[1] or moments[1] == moments[2]:
                precession = 2.0 * math.pi * moments[1] / solver.angular_momentum_norm
            else:
                precession = _mean_period_about_momentum(segment, axis)
    return SegmentMotion(
        start_s=segment.start_s,
        end_s=segment.end_s,
        formula=solver.formula,
        period_s=solver.period,
        flip_times_s=flips,
        flip_period_s=solver.period / 2.0 if turns_over else None,
        spin_axis_body=axis,
        nutation_min_rad=nutation_min,
        nutation_max_rad=nutation_max,
        nutation_period_s=nutation_period,
        spin_period_s=spin,
        precession_period_s=precession,
        kinetic_energy_J=solver.kinetic_energy,
        inertial_angular_momentum_N_m_s=solver.inertial_angular_momentum,
    )


def analyze(trajectory: Trajectory) -> list[SegmentMotion]:
    """The motion of each segment of ``trajectory`` (see the module docstring)."""
    return [_segment_motion(segment) for segment in trajectory.segments]
