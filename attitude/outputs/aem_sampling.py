"""Where the AEM's records go: dense enough that a reader who interpolates them as the
file declares stays within a stated tolerance of the exact attitude.

An AEM is read by interpolation between its records.  CCSDS 504.0-B-2 lets the writer
recommend how, per segment (table 4-3: ``INTERPOLATION_METHOD`` and
``INTERPOLATION_DEGREE``), but says nothing of the accuracy that results: that is the
writer's to choose.  So the records are not the CSV's output grid (a 10 s step over a
31 s spin is 0.13° off at mid-step when interpolated); each segment gets its own step,
chosen for the tolerance (1e-6 rad by default), and declares

    INTERPOLATION_METHOD = LAGRANGE
    INTERPOLATION_DEGREE = 7

read as: for an epoch t between records i and i + 1, the d + 1 = 8 consecutive records
centred on that interval (records i − 3 … i + 4), shifted to stay inside the segment;
each of Q1, Q2, Q3, QC is the Lagrange polynomial through those records (the
quaternions as written: consecutive records are in the same hemisphere), and the
result is normalized.  :func:`lagrange_quaternions` is that reading.

Why Lagrange of degree 7: the quaternion of a rotation at rate ω has components that
are sinusoids of frequency ω/2, so the error of a degree-d polynomial through records
h apart is about (ωh/2)^(d+1) · |∏(x − xᵢ)| / (d+1)!.  Degree 7 reaches 1e-6 rad with
steps of about 1.3 rad of rotation (an 8th power), where a cubic needs 0.35 rad; a
reader who also uses the rates (Orekit's Hermite with degree + 1 records) only does
better.  Higher degrees gain little more and amplify the 16-digit rounding of the
records.

Where the segments end: at every event (the rate jumps there), and at every point
inside a stretch of motion where the motion is not smooth (``Segment.breakpoints``:
a burn starting or stopping, any torque switching on or off, a guidance mode
changing).  There the rate is continuous but its derivative is not, and a polynomial
through records on both sides would be off by far more than the tolerance (8.5e-5
rad just after a burn starts, for a tolerance of 1e-6); each side is its own AEM
segment, whose first and last records are the attitude at the breakpoint.

How the step is chosen, per segment: a first guess from that bound at the body's
largest rate G/I_min, then the declared reading is carried out on test intervals and
compared with the propagated attitude, and the step is scaled by (target/error)^(1/8)
until the largest error is between a quarter and a half of the tolerance.  The test
intervals: the four at each end, where the window is off-centre, and, torque-free, up
to 2048 spread over one body period, where every phase of the motion occurs (ω(t) is
periodic in the body), and around the first flip of a separatrix segment; under
torques or a law, where nothing repeats, every interval of the segment, or 4096 spread over it
when it has more.  Each test interval is read where the interpolation error peaks,
the extremum of the node polynomial ∏(t − tᵢ) over it (:data:`PEAKS`), and at its
quarter points.

**The figure stated is measured on the file.**  While the records are written, every
interval of every segment is read as declared at that peak and compared with the
attitude there: the largest of those errors, times a margin for the rest of the
interval (:attr:`AemSegmentPlan.peak_margin`, 1 + |ω|h/18 at degree 7: about 1.07 at
the default tolerance), plus |ω| × 0.5 ns for the records' time tags, is the largest
error stated in ``summary.json`` (:attr:`AemSegmentPlan.measured_error_rad`): a
measurement over the whole file, not an estimate from samples.  A measurement beyond
the tolerance is an error, never a file.  The records themselves are exact (the
solver's), and written to 1 ns: a time tag rounded by up to 0.5 ns costs ω × 0.5 ns,
which is why a tolerance below that is refused.  ``tests/test_aem_meets_its_tolerance.py``
and ``tests/test_aem_of_a_torqued_run_read_back_by_ccsds_ndm_py.py`` read the written
files back with an independent parser, interpolate them as declared inside every
interval, and check them against the tolerance and the stated figure.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from typing import BinaryIO

import numpy as np
from numpy.typing import NDArray

from attitude.base.errors import InputError
from attitude.environment.epoch_texts import EpochTexts
from attitude.environment.timescales import SAME_INSTANT_S
from attitude.outputs.aem_writer import AemWriter
from attitude.trajectory.guided import GuidedMotion
from attitude.trajectory.motion import SegmentMotion
from attitude.trajectory.torqued import TorquedMotion
from attitude.trajectory.trajectory import Segment, Trajectory

__all__ = [
    "DEFAULT_TOLERANCE_RAD",
    "INTERPOLATION_DEGREE",
    "INTERPOLATION_METHOD",
    "PEAKS",
    "AemPlan",
    "AemSegmentPlan",
    "lagrange_quaternions",
    "plan_aem",
    "write_planned_aem",
]

DEFAULT_TOLERANCE_RAD = 1e-6
INTERPOLATION_METHOD = "LAGRANGE"
INTERPOLATION_DEGREE = 7
# Beyond this, interpolating an attitude means little; below the floor, 16 digits do
# not hold it.
MAX_TOLERANCE_RAD = 0.1
MIN_TOLERANCE_RAD = 1e-12
# The step is tuned until the largest error tested lies in [¼, ½] of the tolerance.
_TARGET = 0.5
_TEST_INTERVALS = 2048
_TORQUED_TEST_INTERVALS = 4096
_END_INTERVALS = 4
_MAX_ITERATIONS = 12
# Time tags are written to 1 ns (half of it is the rounding), and records closer than
# this would repeat one.
_TIME_TAG_S = 0.5e-9
_MIN_STEP_S = 2e-9


def _peaks(degree: int) -> NDArray[np.float64]:
    """For each interval j of a window of degree + 1 evenly spaced nodes 0 … degree,
    the fraction of the interval (from node j) where |∏(x − i)| is largest."""
    fractions = np.linspace(0.0, 1.0, 20001)
    nodes = np.arange(degree + 1.0)
    peaks = []
    for j in range(degree):
        x = j + fractions
        product = np.abs(np.prod(x[:, None] - nodes[None, :], axis=1))
        peaks.append(fractions[int(np.argmax(product))])
    return np.array(peaks)


# PEAKS[d][j]: where the interpolation error of degree d peaks in the window's interval
# j (the error of a polynomial through smooth data is f^(d+1)(ξ)/(d+1)! times the node
# polynomial, whose extremum this is): ½ in the centred interval, off-centre at the ends.
class _Peaks(dict):
    """PEAKS, each degree computed when first asked for (not at import: 30 ms)."""

    def __missing__(self, degree: int) -> NDArray[np.float64]:
        self[degree] = peaks = _peaks(degree)
        return peaks


PEAKS: dict[int, NDArray[np.float64]] = _Peaks()


@dataclass(frozen=True)
class AemSegmentPlan:
    """The records of one AEM segment: ``count`` epochs evenly spaced over
    [start_s, end_s] (TT seconds since the epoch), and the interpolation declared.

    ``started_by``: what happens at ``start_s`` when the segment starts inside a
    stretch of motion (a breakpoint: a torque switching), else None.
    ``measured_error_rad``: set when the records are written (module docstring).
    """

    segment: int  # index of the trajectory segment
    start_s: float
    end_s: float
    count: int
    degree: int | None  # INTERPOLATION_DEGREE (None: a single record)
    tested_error_rad: float  # the largest error found when choosing the step
    time_tag_rad: float = 0.0  # |ω| × (0.5 ns + float spacing): the time tags' rounding
    started_by: str | None = None
    measured_error_rad: float | None = None
    rate_rad_s: float = 0.0  # the bound on |ω| the step was guessed from
    # Predicted, not planned: `attitude check` past its budget (plan_aem(budget_s=)).
    predicted: bool = False

    @property
    def peak_margin(self) -> float:
        """How much the error may exceed its value at an interval's peak elsewhere in
        it: the error is the node polynomial times a divided difference of the
        quaternion, f^(d+1)(ξ)/(d+1)!, whose components turn at |ω|/2 or less, so
        across half an interval it changes by at most |ω| h / (2 (d + 2)) of itself
        (to first order): 1 plus that."""
        degree = self.degree if self.degree is not None else 1
        return 1.0 + self.rate_rad_s * self.step_s / (2.0 * (degree + 2))

    @property
    def step_s(self) -> float:
        return (self.end_s - self.start_s) / max(self.count - 1, 1)

    def seconds(self, first: int, stop: int) -> NDArray[np.float64]:
        """The epochs of records first … stop − 1, TT seconds since the scenario epoch."""
        k = np.arange(first, min(stop, self.count), dtype=np.float64)
        τ = self.start_s + k * self.step_s
        if stop >= self.count and self.count > 1:
            τ[-1] = self.end_s  # the last record is the segment's end, exactly
        return τ


@dataclass(frozen=True)
class AemPlan:
    """The AEM's segments and the tolerance they were sampled for."""

    tolerance_rad: float
    segments: list[AemSegmentPlan]

    @property
    def records(self) -> int:
        return sum(item.count for item in self.segments)

    @property
    def predicted(self) -> int:
        """How many segments are predicted (check past its budget), not planned."""
        return sum(item.predicted for item in self.segments)

    def describe(self, exact: bool) -> str:
        """The plan in one line for ``attitude check`` (``exact``: the motion is closed
        form, not propagated)."""
        steps = [item.step_s for item in self.segments]
        about = "about " if self.predicted else ""
        line = (
            f"{about}{self.records} records (a record every {min(steps):.4g} to "
            f"{max(steps):.4g} s), {INTERPOLATION_METHOD} interpolation within "
            f"{self.tolerance_rad:g} rad of the {'exact' if exact else 'propagated'} attitude"
        )
        if self.predicted:
            planned = len(self.segments) - self.predicted
            line += (
                f"; {planned} of its {len(self.segments)} segments planned within check's "
                "budget, the others' records predicted from their steps (the run plans them)"
            )
        return line

    @property
    def measured_error_rad(self) -> float | None:
        """The largest error measured while writing (None before)."""
        found = [item.measured_error_rad for item in self.segments]
        if not found or any(value is None for value in found):
            return None
        return max(value for value in found if value is not None)


def check_tolerance(tolerance_rad: float, name: str = "aem_tolerance") -> float:
    """``tolerance_rad`` if it is a usable AEM tolerance, else :class:`InputError`."""
    if not (MIN_TOLERANCE_RAD <= tolerance_rad <= MAX_TOLERANCE_RAD):
        raise InputError(
            f"{tolerance_rad:g} rad is outside [{MIN_TOLERANCE_RAD:g}, "
            f"{MAX_TOLERANCE_RAD:g}] rad (16-digit records hold 1e-15; beyond 0.1 rad an "
            "interpolated attitude means little)",
            key=name,
            value=tolerance_rad,
        )
    return float(tolerance_rad)


def _window(count: int, interval: NDArray[np.intp], degree: int) -> NDArray[np.intp]:
    """First record of the degree + 1 records centred on each interval (i, i + 1)."""
    first = interval - (degree - 1) // 2
    return np.clip(first, 0, count - degree - 1)


def lagrange_quaternions(
    record_s: NDArray[np.float64],
    quaternions: NDArray[np.float64],
    t_s: NDArray[np.float64],
    degree: int = INTERPOLATION_DEGREE,
) -> NDArray[np.float64]:
    """The declared reading: Lagrange interpolation of degree ``degree`` of each
    quaternion component over the records centred on t's interval, normalized.

    ``record_s``: the records' epochs (increasing), ``quaternions``: (n, 4) in the same
    hemisphere from one record to the next, ``t_s``: where to interpolate, within
    [record_s[0], record_s[-1]].
    """
    count = record_s.size
    degree = min(degree, count - 1)
    interval = np.clip(np.searchsorted(record_s, t_s, side="right") - 1, 0, count - 2)
    nodes = _window(count, interval, degree)[:, None] + np.arange(degree + 1)
    return _lagrange(record_s[nodes], quaternions[nodes], t_s)


def _lagrange(
    x: NDArray[np.float64], q: NDArray[np.float64], t: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Lagrange interpolation at t[i] through the nodes x[i] (m, k) of values q[i]
    (m, k, 4), normalized.  The nodes are scaled to [0, 1] per window: the weights are
    then ratios of numbers near 1, well conditioned."""
    scale = x[:, -1:] - x[:, :1]
    u = (x - x[:, :1]) / scale
    v = ((t - x[:, 0]) / scale[:, 0])[:, None]
    k = x.shape[1]
    weights = np.ones_like(u)
    for m in range(k):
        other = np.arange(k) != m
        weights[:, other] *= (v - u[:, m : m + 1]) / (u[:, other] - u[:, m : m + 1])
    result = np.einsum("ij,ijk->ik", weights, q)
    return result / np.linalg.norm(result, axis=1, keepdims=True)


def _angle(a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """Rotation angle between unit quaternions a and ±b (4 asin(|a − b|/2), b's sign
    chosen nearest a): exact for small angles, unlike acos of the dot product."""
    sign = np.where(np.einsum("ij,ij->i", a, b) < 0.0, -1.0, 1.0)[:, None]
    return 4.0 * np.arcsin(np.minimum(1.0, 0.5 * np.linalg.norm(a - sign * b, axis=1)))


def _same_hemisphere(q: NDArray[np.float64]) -> NDArray[np.float64]:
    """Each row of (..., k, 4) flipped to the hemisphere of the row before it."""
    dots = np.einsum("...ij,...ij->...i", q[..., 1:, :], q[..., :-1, :])
    steps = np.where(dots < 0.0, -1.0, 1.0)
    signs = np.concatenate([np.ones((*steps.shape[:-1], 1)), np.cumprod(steps, axis=-1)], -1)
    return q * signs[..., None]


def _read_errors(
    solver,
    index: NDArray[np.intp],
    record_s: NDArray[np.float64],
    record_q: NDArray[np.float64],
    interval: NDArray[np.intp],
    count: int,
    degree: int,
    fractions: tuple[str, ...] = ("peak",),
) -> NDArray[np.float64]:
    """The error of the declared reading in each of ``interval`` (indices of records
    i, i + 1 of a segment of ``count``), where ``record_s``/``record_q`` hold the
    records of the increasing indices ``index`` (every one the windows need), at the
    peak of the node polynomial and, if asked, at the quarter points: one value per
    interval."""
    first = _window(count, interval, degree)
    nodes = np.searchsorted(index, first[:, None] + np.arange(degree + 1))
    x = record_s[nodes]
    q = _same_hemisphere(record_q[nodes])
    j = interval - first
    spots = []
    if "peak" in fractions:
        spots.append(PEAKS[degree][j])
    if "quarters" in fractions:
        spots += [np.full(interval.shape, 0.25), np.full(interval.shape, 0.75)]
    worst = np.zeros(interval.shape)
    for fraction in spots:
        left = x[np.arange(len(interval)), j]
        right = x[np.arange(len(interval)), j + 1]
        t = left + fraction * (right - left)
        worst = np.maximum(worst, _angle(_lagrange(x, q, t), solver.attitude_quaternion(t)))
    return worst


def _tested_error(
    segment: Segment,
    start_s: float,
    end_s: float,
    count: int,
    degree: int,
    intervals: NDArray[np.intp],
) -> float:
    """The largest error of the declared reading of ``count`` even records over
    [start_s, end_s] in the test ``intervals``, each record evaluated once."""
    step = (end_s - start_s) / (count - 1)
    first = _window(count, intervals, degree)
    needed = np.unique(first[:, None] + np.arange(degree + 1))
    τ = start_s + needed * step
    τ[needed == count - 1] = end_s
    q = segment.solver.attitude_quaternion(τ)
    errors = _read_errors(
        segment.solver, needed, τ, q, intervals, count, degree, ("peak", "quarters")
    )
    return float(np.max(errors))


def _test_intervals(
    segment: Segment,
    motion: SegmentMotion,
    start_s: float,
    end_s: float,
    count: int,
    rng: np.random.Generator,
) -> NDArray[np.intp]:
    """The intervals tested (module docstring): the end ones; torque-free, one body
    period (every phase of ω(t) occurs in it; without a period, the start) and around
    the first flip; under torques, every interval, or _TORQUED_TEST_INTERVALS spread
    over the segment."""
    intervals = count - 1
    step = (end_s - start_s) / intervals
    picked = [np.arange(min(_END_INTERVALS, intervals))]
    picked.append(np.arange(max(0, intervals - _END_INTERVALS), intervals))
    if isinstance(segment.solver, TorquedMotion | GuidedMotion):  # nothing repeats
        if intervals <= _TORQUED_TEST_INTERVALS:
            picked.append(np.arange(intervals))
        else:
            picked.append(rng.integers(0, intervals, _TORQUED_TEST_INTERVALS))
        return np.unique(np.concatenate(picked))
    span = max(64.0 * step, motion.period_s if math.isfinite(motion.period_s) else 0.0)
    windows = [(start_s, min(end_s, start_s + span))]
    flips = motion.flip_times_s
    flips = flips[(flips >= start_s) & (flips <= end_s)]
    if flips.size:
        windows.append((max(start_s, flips[0] - 32.0 * step), min(end_s, flips[0] + span)))
    for low, high in windows:
        a = int(np.clip((low - start_s) // step, 0, intervals - 1))
        b = int(np.clip(np.ceil((high - start_s) / step), a + 1, intervals))
        if b - a <= _TEST_INTERVALS:
            picked.append(np.arange(a, b))
        else:
            picked.append(rng.integers(a, b, _TEST_INTERVALS))
    return np.unique(np.concatenate(picked))


def _largest_rate(segment: Segment) -> float:
    """The segment's largest body rate bound, G / I_min (rad/s)."""
    solver = segment.solver
    G = solver.angular_momentum_norm
    return G / float(np.min(solver.moments_of_inertia)) if G > 0.0 else 0.0


def _time_tags_error(index: int, segment: Segment, end_s: float, tolerance_rad: float) -> float:
    """The attitude error (rad) of rounding a record's time to the AEM's 1 ns time
    tag at the segment's largest rate; refused when it takes half the tolerance."""
    rate = _largest_rate(segment)
    time_tags = rate * (_TIME_TAG_S + float(np.spacing(max(abs(end_s), 1.0))))
    if time_tags >= 0.5 * tolerance_rad:
        # The rate's fault, and the key that set it (a runaway burn, a state's absurd
        # rate), when even the default tolerance cannot be met; else the tolerance's
        # (no key here: the caller's name for it).
        if time_tags >= 0.5 * DEFAULT_TOLERANCE_RAD:
            raise InputError(
                f"segment {index} turns at up to {rate:.3g} rad/s: {time_tags:.2g} rad in the "
                f"rounding of an AEM's 1 ns time tag, more than its {tolerance_rad:g} rad "
                "tolerance allows: give a slower motion",
                key=segment.rate_key,
            )
        raise InputError(
            f"{tolerance_rad:g} rad is finer than 1 ns time tags allow for "
            f"segment {index}, which turns at up to {rate:.3g} rad/s ({time_tags:.2g} rad in "
            "the rounding of a time tag): give a larger tolerance"
        )
    return time_tags


def check_time_tags(
    trajectory: Trajectory,
    start_s: float,
    stop_s: float,
    tolerance_rad: float = DEFAULT_TOLERANCE_RAD,
    name: str = "aem_tolerance",
) -> None:
    """Refuse, as :func:`plan_aem` would, a segment too fast for 1 ns time tags to
    meet ``tolerance_rad``, from the segments' rate bounds alone: a run checks this
    before the motion's analysis, which takes minutes on such a motion."""
    tolerance_rad = check_tolerance(tolerance_rad, name)
    for index, segment in enumerate(trajectory.segments):
        if min(segment.end_s, stop_s) - max(segment.start_s, start_s) <= SAME_INSTANT_S:
            continue
        if _largest_rate(segment) == 0.0:
            continue
        for start, end, _ in _pieces(segment, start_s, stop_s):
            if int((end - start) / _MIN_STEP_S) + 1 <= 2:
                continue  # constant in the file: no interpolation to spoil
            try:
                _time_tags_error(index, segment, end, tolerance_rad)
            except InputError as exc:
                raise (exc if exc.key else exc.located(key=name)) from None


def _plan_segment(
    index: int,
    segment: Segment,
    motion: SegmentMotion,
    start_s: float,
    end_s: float,
    tolerance_rad: float,
    started_by: str | None,
) -> AemSegmentPlan:
    length = end_s - start_s
    most = max(2, int(length / _MIN_STEP_S) + 1)  # records ≥ 2 ns apart
    rate = _largest_rate(segment)
    degree = INTERPOLATION_DEGREE
    if rate == 0.0 or most <= 2:  # at rest: constant
        return AemSegmentPlan(index, start_s, end_s, 2, 1, 0.0, 0.0, started_by, None, rate)
    time_tags = _time_tags_error(index, segment, end_s, tolerance_rad)
    target = _TARGET * tolerance_rad - time_tags
    step = _first_step(rate, target, degree)
    rng = np.random.default_rng(index)
    accepted = None
    for _ in range(_MAX_ITERATIONS):
        count = min(max(math.ceil(length / step) + 1, degree + 1), most)
        degree_here = min(degree, count - 1)
        intervals = _test_intervals(segment, motion, start_s, end_s, count, rng)
        error = _tested_error(segment, start_s, end_s, count, degree_here, intervals)
        if error <= target:
            accepted = AemSegmentPlan(
                index, start_s, end_s, count, degree_here, error, time_tags, started_by, None, rate
            )
            if error >= 0.5 * target or count <= degree + 1:
                break
        elif count >= most:
            break
        ratio = (target / error) ** (1.0 / (degree_here + 1)) if error > 0.0 else 2.0
        step = (length / (count - 1)) * float(np.clip(0.95 * ratio, 0.25, 2.0))
    if accepted is None:
        raise InputError(
            f"{tolerance_rad:g} rad cannot be met in segment {index} with records "
            f"1 ns apart (the last try was {error:.2g} rad off): give a larger tolerance"
        )
    return accepted


def _first_step(rate: float, target: float, degree: int) -> float:
    """The first guess of a segment's step: a uniform rotation at the largest rate,
    end-interval constant (module notes)."""
    constant = 528.0 / math.factorial(degree + 1)  # max |∏(x − i)|, x in the first interval
    return (2.0 / rate) * (target / (4.0 * constant)) ** (1.0 / (degree + 1))


def _predicted_segment(
    index: int,
    segment: Segment,
    start_s: float,
    end_s: float,
    tolerance_rad: float,
    started_by: str | None,
    ratio: float,
) -> AemSegmentPlan:
    """A segment's records as :func:`_plan_segment` would choose them, predicted: its
    first guess scaled by ``ratio``, the least ratio of chosen to first step among the
    segments planned (the most records).  The records it would refuse, 1 ns apart, are
    refused before from the rate bound (:func:`check_time_tags`: a step that short
    needs a rate whose time tags miss any tolerance)."""
    length = end_s - start_s
    most = max(2, int(length / _MIN_STEP_S) + 1)
    rate = _largest_rate(segment)
    if rate == 0.0 or most <= 2:
        return AemSegmentPlan(index, start_s, end_s, 2, 1, 0.0, 0.0, started_by, None, rate)
    time_tags = _time_tags_error(index, segment, end_s, tolerance_rad)
    step = ratio * _first_step(rate, _TARGET * tolerance_rad - time_tags, INTERPOLATION_DEGREE)
    count = min(max(math.ceil(length / step) + 1, INTERPOLATION_DEGREE + 1), most)
    degree = min(INTERPOLATION_DEGREE, count - 1)
    return AemSegmentPlan(
        index, start_s, end_s, count, degree, math.nan, time_tags, started_by, None, rate, True
    )


def _ratio(item: AemSegmentPlan, tolerance_rad: float) -> float | None:
    """A planned segment's chosen step over its first guess (None: nothing guessed, or
    a segment shorter than a window of records, whose step says nothing of the rest)."""
    if item.rate_rad_s == 0.0 or item.degree is None or item.count <= INTERPOLATION_DEGREE + 1:
        return None
    target = _TARGET * tolerance_rad - item.time_tag_rad
    return item.step_s / _first_step(item.rate_rad_s, target, INTERPOLATION_DEGREE)


def _pieces(
    segment: Segment, start_s: float, stop_s: float
) -> list[tuple[float, float, str | None]]:
    """The segment's stretch within [start_s, stop_s] cut at its breakpoints: (start,
    end, what happens at start when it is a breakpoint)."""
    a, b = max(segment.start_s, start_s), min(segment.end_s, stop_s)
    cuts = [(a, None)] + [
        (point.time_s, point.what)
        for point in segment.breakpoints()
        if a + SAME_INSTANT_S < point.time_s < b - SAME_INSTANT_S
    ]
    ends = [t for t, _ in cuts[1:]] + [b]
    return [(t, end, what) for (t, what), end in zip(cuts, ends, strict=True)]


def plan_aem(
    trajectory: Trajectory,
    motion: list[SegmentMotion],
    start_s: float,
    stop_s: float,
    tolerance_rad: float = DEFAULT_TOLERANCE_RAD,
    name: str = "aem_tolerance",
    budget_s: float | None = None,
) -> AemPlan:
    """The AEM's segments over [start_s, stop_s]: one per stretch of smooth motion,
    between events and breakpoints, each sampled for ``tolerance_rad`` (see the
    module docstring).

    A segment ends with its own (pre-event) state at the next event's epoch and the
    next one starts with the post-event state there: the attitude is continuous but
    the rate jumps, and a reader must not interpolate across.  At a breakpoint both
    segments hold the same state; the rate's derivative jumps there.

    ``budget_s``: `attitude check`'s CPU budget (s): the segments after it is spent
    (at least one planned) are predicted from their rate bounds and the planned ones'
    steps (:func:`_predicted_segment`, ``AemSegmentPlan.predicted``): a thousand burns
    make two thousand segments, tens of seconds to plan.  Such a plan is never written.
    """
    tolerance_rad = check_tolerance(tolerance_rad, name)
    started = time.process_time()
    plans: list[AemSegmentPlan] = []
    ratios: list[float] = []
    for index, (segment, item) in enumerate(zip(trajectory.segments, motion, strict=True)):
        if min(segment.end_s, stop_s) - max(segment.start_s, start_s) <= SAME_INSTANT_S:
            continue  # before the output span, or a zero-length stretch between events
        for start, end, what in _pieces(segment, start_s, stop_s):
            spent = budget_s is not None and time.process_time() - started > budget_s
            try:
                if spent and ratios:
                    plans.append(
                        _predicted_segment(
                            index, segment, start, end, tolerance_rad, what, min(ratios)
                        )
                    )
                    continue
                plans.append(_plan_segment(index, segment, item, start, end, tolerance_rad, what))
            except InputError as exc:  # the tolerance's, unless it names the rate's key
                raise (exc if exc.key else exc.located(key=name)) from None
            ratio = _ratio(plans[-1], tolerance_rad)
            if ratio is not None:
                ratios.append(ratio)
    return AemPlan(tolerance_rad, plans)


def write_planned_aem(
    stream: BinaryIO,
    trajectory: Trajectory,
    plan: AemPlan,
    texts: EpochTexts,
    *,
    object_name: str,
    object_id: str,
    comments: tuple[str, ...] = (),
    chunk_records: int = 16384,
) -> AemPlan:
    """The AEM of ``plan`` into the binary ``stream``, written as it is computed: a
    segment per stretch of smooth motion, its records ``chunk_records`` at a time, each
    declaring the interpolation it was sampled for (:data:`INTERPOLATION_METHOD`).

    Returns ``plan`` with each segment's error measured on the records written
    (``measured_error_rad``: module docstring); a measurement beyond the tolerance
    raises :class:`RuntimeError` (the sampling failed: a bug, not the user's).

    ``texts``: the epoch texts of the scenario's time scale; ``comments``: the
    header's first comment lines (a statement of the sampling's accuracy follows them).
    """
    scenario = trajectory.scenario
    writer = AemWriter(
        stream,
        object_name=object_name,
        object_id=object_id,
        time_scale=scenario.time_scale,
        comments=(
            *comments,
            f"sampled so that {INTERPOLATION_METHOD} interpolation as declared (each of "
            "Q1..QC over the degree + 1 records",
            f"centred on the interval, normalized) stays within {plan.tolerance_rad:g} "
            "rad of the exact attitude",
        ),
    )
    if plan.predicted:
        raise RuntimeError("an AEM plan predicted past check's budget is not written")
    measured: list[AemSegmentPlan] = []
    for item in plan.segments:
        segment = trajectory.segments[item.segment]
        ends = texts(np.array([item.start_s, item.end_s]))
        writer.begin_segment(
            ends[0].decode("ascii"),
            ends[1].decode("ascii"),
            interpolation=None if item.degree is None else (INTERPOLATION_METHOD, item.degree),
            comments=(
                f"motion segment {item.segment}",
                *(
                    (f"started by {segment.event.kind}",)
                    if segment.event and item.start_s == segment.start_s
                    else ()
                ),
                *((f"starts where {item.started_by}",) if item.started_by else ()),
                f"a record every {item.step_s:.6g} s",
            ),
        )
        worst = 0.0
        degree = item.degree if item.degree is not None else 1
        for first in range(0, item.count, chunk_records):
            stop = min(first + chunk_records, item.count)
            # The chunk's records, and the neighbours the windows of its intervals use.
            low, high = max(0, first - degree), min(item.count, stop + degree)
            τ = item.seconds(low, high)
            # One record is evaluated as a pair (see attitude.outputs.csv.sample).
            pair = np.repeat(τ, 2) if τ.size == 1 else τ
            q = segment.solver.attitude_quaternion(pair)[: τ.size]
            ω = segment.solver.angular_velocity(pair)[: τ.size]
            own = slice(first - low, stop - low)
            writer.write_records(texts(τ[own]), q[own], ω[own])
            interval = np.arange(first, min(stop, item.count - 1))
            if interval.size and item.count > 1:
                index = np.arange(low, high)
                found = _read_errors(segment.solver, index, τ, q, interval, item.count, degree)
                worst = max(worst, float(np.max(found)))
        writer.end_segment()
        bound = worst * item.peak_margin + item.time_tag_rad
        if bound > plan.tolerance_rad:
            raise RuntimeError(
                f"attitude.aem segment {len(measured)}: the declared reading is {bound:.3g} rad "
                f"off the attitude, measured on the records written, beyond the "
                f"{plan.tolerance_rad:g} rad it was sampled for"
            )
        measured.append(replace(item, measured_error_rad=bound))
    writer.close()
    return replace(plan, segments=measured)
