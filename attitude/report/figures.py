"""What the report's figures show, sampled from the exact motion, and where they zoom.

The output grid is the user's choice and may alias the motion (a 10 s step over a 31 s
spin); the figures of the motion do not use it:

- The angular velocity is drawn per pixel column from the exact solution.  ω(t) is
  periodic in the body with the body period T, so a column longer than T holds its
  whole range, taken once per segment from 4096 samples of one period; a shorter one
  is sampled at 512 points per turn (or per T, if shorter; at most 4096 a column):
  extremes within 2e-5 of the amplitude.  A steady spin is constant.  Under torques
  the columns hold the segment's survey (``TorquedMotion.survey``: 32 samples a turn
  at the largest rate, the samples its flips and largest rate were found on), so the
  figure propagates nothing: extremes within about 0.5 % of the nutation's amplitude.
- The polhode is each segment's momentum over one body period (2049 samples, the
  whole closed curve), or over the segment when it is shorter or has no period (the
  separatrix, sampled densely around its flip): a nutation of exactly 60° is drawn at
  exactly 60°.
- Zoom panels sample the exact motion (and the pointing) at 1500 points over a window
  around something that happens: the first event for the rates, the first Sun
  exclusion for the Sun angles, the first eclipse entry for the eclipses; the first
  flip or the first turns when nothing happens.

The Sun-angle and eclipse envelopes are the output grid's own samples (what the time
series holds), gathered while the series is streamed.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from attitude.report.plots import PIXEL_COLUMNS, Envelope, Zoom
from attitude.trajectory.motion import SegmentMotion
from attitude.trajectory.torqued import TorquedMotion
from attitude.trajectory.trajectory import Trajectory

__all__ = [
    "ZOOM_POINTS",
    "angular_velocity_envelope",
    "eclipse_zoom",
    "polhode_paths",
    "rate_zoom",
    "sun_angle_zoom",
]

ZOOM_POINTS = 1500
_PERIOD_SAMPLES = 4096
_PER_TURN = 512
_MAX_PER_COLUMN = 4096
_POLHODE_SAMPLES = 2049


def _turn_s(solver) -> float:
    """The time of a turn at the body's largest rate, G/I_min (inf at rest)."""
    G = solver.angular_momentum_norm
    return math.inf if G == 0.0 else 2.0 * math.pi * float(np.min(solver.moments_of_inertia)) / G


def _pieces(trajectory: Trajectory, motion: list[SegmentMotion], start_s: float, stop_s: float):
    """(index, segment, motion, a, b): the segments' stretches within [start_s, stop_s]."""
    for k, (segment, item) in enumerate(zip(trajectory.segments, motion, strict=True)):
        a, b = max(segment.start_s, start_s), min(segment.end_s, stop_s)
        if b > a:
            yield k, segment, item, a, b


def angular_velocity_envelope(
    trajectory: Trajectory,
    motion: list[SegmentMotion],
    start_s: float,
    stop_s: float,
    columns: int = PIXEL_COLUMNS,
) -> Envelope:
    """The body angular velocity's range (rad/s, series x, y, z) in each pixel column of
    [start_s, stop_s], from the exact solution (see the module docstring)."""
    envelope = Envelope(start_s, stop_s, ("x", "y", "z"), columns, keep=0)
    edges = envelope.edges
    for _, segment, item, a, b in _pieces(trajectory, motion, start_s, stop_s):
        solver = segment.solver
        if isinstance(solver, TorquedMotion):
            # The survey the flips and the largest rate were found on: no new propagation.
            for t, _, ω in solver.survey():
                inside = (t >= a) & (t <= b)
                envelope.add(t[inside], {axis: ω[inside, i] for i, axis in enumerate("xyz")})
            continue
        period = item.period_s
        # Closed columns: a segment starting on an edge also ends the column before.
        first = max(int(np.searchsorted(edges, a, side="left")) - 1, 0)
        last = int(envelope.column(np.array([b]))[0])
        low = np.maximum(edges[first : last + 1], a)
        high = np.minimum(edges[first + 1 : last + 2], b)
        if item.motion in ("steady spin", "rest"):
            dense = np.ones(low.size, dtype=bool)  # ω is constant: two samples say it all
            per_piece = np.full(low.size, 2)
        else:
            fastest = min(period, _turn_s(solver))
            whole = math.isfinite(period) & (high - low >= period)
            dense = ~whole
            per_piece = np.clip(np.ceil((high - low) / fastest * _PER_TURN) + 1, 2, _MAX_PER_COLUMN)
            if np.any(whole):
                τ = segment.start_s + np.linspace(0.0, period, _PERIOD_SAMPLES)
                ω = solver.angular_velocity(τ)
                pair = np.repeat(0.5 * (low[whole] + high[whole]), 2)
                envelope.add(
                    pair,
                    {
                        axis: np.tile([ω[:, i].min(), ω[:, i].max()], pair.size // 2)
                        for i, axis in enumerate("xyz")
                    },
                )
        if np.any(dense):
            counts = per_piece[dense].astype(int)
            starts, stops = low[dense], high[dense]
            fraction = np.concatenate([np.linspace(0.0, 1.0, n) for n in counts])
            τ = np.repeat(starts, counts) + fraction * np.repeat(stops - starts, counts)
            ω = solver.angular_velocity(τ)
            column = np.repeat(np.arange(first, last + 1)[dense], counts)
            envelope.add(τ, {axis: ω[:, i] for i, axis in enumerate("xyz")}, column)
    return envelope


def polhode_paths(
    trajectory: Trajectory, motion: list[SegmentMotion], start_s: float, stop_s: float
) -> list[tuple[int, NDArray[np.float64]]]:
    """Each segment's body angular momentum, densely over one body period (or over its
    stretch of [start_s, stop_s] when shorter or without a period)."""
    paths = []
    for k, segment, item, a, b in _pieces(trajectory, motion, start_s, stop_s):
        period = item.period_s
        if math.isfinite(period) and b - a > period:
            τ = a + np.linspace(0.0, period, _POLHODE_SAMPLES)
        else:
            τ = np.linspace(a, b, _POLHODE_SAMPLES)
            flips = item.flip_times_s[(item.flip_times_s >= a) & (item.flip_times_s <= b)]
            if flips.size:  # the separatrix: its one turn-over, densely
                turn = _turn_s(segment.solver)
                near = flips[0] + np.linspace(-4.0 * turn, 4.0 * turn, _POLHODE_SAMPLES)
                τ = np.unique(np.concatenate([τ, near[(near >= a) & (near <= b)]]))
        paths.append((k, segment.solver.angular_momentum(τ)))
    return paths


def _window(
    center_s: float, length_s: float, start_s: float, stop_s: float, before: float = 1 / 3
) -> NDArray[np.float64]:
    """ZOOM_POINTS times over a window of ``length_s`` with ``center_s`` a third of the
    way in, moved (and shortened) to lie within [start_s, stop_s]."""
    length = min(length_s, stop_s - start_s)
    low = min(max(center_s - before * length, start_s), stop_s - length)
    return np.linspace(low, low + length, ZOOM_POINTS)


def _period_of(item: SegmentMotion, segment) -> float:
    """A period that shows the motion: nutation, spin, body period, or a turn."""
    for value in (item.nutation_period_s, item.spin_period_s, item.period_s):
        if value is not None and math.isfinite(value) and value > 0.0:
            return float(value)
    return _turn_s(segment.solver)


def rate_zoom(
    trajectory: Trajectory,
    motion: list[SegmentMotion],
    start_s: float,
    stop_s: float,
    events_s: Sequence[float],
) -> Zoom | None:
    """Around the first event in the span, else the first flip, else the first three
    periods; None if the span is no longer than that."""
    inside = [t for t in events_s if start_s < t < stop_s]
    flips = np.concatenate([m.flip_times_s for m in motion]) if motion else np.empty(0)
    flips = flips[(flips > start_s) & (flips < stop_s)]
    k = int(trajectory.segment_index(np.array([inside[0] if inside else start_s]))[0])
    length = 3.0 * _period_of(motion[k], trajectory.segments[k])
    if inside:
        center, what = inside[0], f"the first event, at +{inside[0]:.6g} s"
    elif flips.size:
        center, what = float(flips[0]), f"the first flip, at +{float(flips[0]):.6g} s"
    else:
        center, what = start_s, "the first turns"
    if not math.isfinite(length) or length >= 0.5 * (stop_s - start_s):
        return None
    τ = _window(center, length, start_s, stop_s, 0.0 if center == start_s else 1 / 3)
    ω = trajectory.angular_velocity(τ)
    return Zoom(
        τ,
        {axis: ω[:, i] for i, axis in enumerate("xyz")},
        f"Zoom: {what} (exact motion, {ZOOM_POINTS} points)",
        marks_s=[center] if inside or flips.size else [],
    )


def sun_angle_zoom(
    trajectory: Trajectory,
    motion: list[SegmentMotion],
    start_s: float,
    stop_s: float,
    sun_angles_deg: Callable[[NDArray[np.float64]], dict[str, NDArray[np.float64]]],
    sun_exclusions_s: Sequence[tuple[float, float]],
    shadow_s: Sequence[tuple[float, float]],
    events_s: Sequence[float],
) -> Zoom | None:
    """Around the first Sun exclusion, else the first eclipse entry, else the first
    event, else the first turns; ``sun_angles_deg(τ)`` gives each vector's Sun angle."""
    candidates = [
        (sun_exclusions_s[0][0], "the first Sun exclusion") if sun_exclusions_s else None,
        (shadow_s[0][0], "the first eclipse entry") if shadow_s else None,
        next(((t, "the first event") for t in events_s if start_s < t < stop_s), None),
    ]
    found = next((c for c in candidates if c is not None), None)
    center = found[0] if found else start_s
    k = int(trajectory.segment_index(np.array([min(max(center, start_s), stop_s)]))[0])
    length = 3.0 * _period_of(motion[k], trajectory.segments[k])
    if found and sun_exclusions_s and found[1] == "the first Sun exclusion":
        length = max(length, 3.0 * (sun_exclusions_s[0][1] - sun_exclusions_s[0][0]))
    if not math.isfinite(length) or length >= 0.5 * (stop_s - start_s):
        return None
    τ = _window(center, length, start_s, stop_s, 1 / 3 if found else 0.0)
    what = f"{found[1]}, at +{center:.6g} s" if found else "the first turns"
    return Zoom(
        τ,
        sun_angles_deg(τ),
        f"Zoom: {what} (exact motion, {ZOOM_POINTS} points)",
        marks_s=[center] if found else [],
        shaded_s=[(a, b) for a, b in shadow_s if b >= τ[0] and a <= τ[-1]],
    )


def eclipse_zoom(
    start_s: float,
    stop_s: float,
    sunlit_fraction: Callable[[NDArray[np.float64]], NDArray[np.float64]],
    shadow_s: Sequence[tuple[float, float]],
    umbra_s: Sequence[tuple[float, float]],
) -> Zoom | None:
    """The first eclipse entry: from a minute before the shadow to a minute into the
    umbra (or two minutes into the shadow, if it has none)."""
    entries = [(a, b) for a, b in shadow_s if a > start_s]
    if not entries:
        return None
    entry = entries[0][0]
    umbra = [a for a, _ in umbra_s if a >= entry]
    end = (umbra[0] if umbra else entry) + (60.0 if umbra else 120.0)
    low, high = max(start_s, entry - 60.0), min(stop_s, end)
    τ = np.linspace(low, high, ZOOM_POINTS)
    return Zoom(
        τ,
        {"sunlit": sunlit_fraction(τ)},
        f"Zoom: the first eclipse entry, at +{entry:.6g} s (penumbra, then umbra)",
        marks_s=[entry, *umbra[:1]],
    )
