"""Intervals where a condition holds, with their ends refined on the exact solution.

A condition is a continuous function f(τ) of TT seconds since the epoch, true where
f > 0 (for a Sun exclusion cone: cos(Sun angle) − cos(half angle)).  It is sampled
on a search grid finer than the motion's fastest time scale, then every sign
change is refined by bisection, all of them at once (vectorized), until the
bracket is narrower than the stated precision: the ends do not depend on the
output step.  Conditions combine as interval sets (``difference``), e.g. "the Sun is
in the tracker's cone and the spacecraft is not in umbra".

A condition that becomes true and false again between two search samples is missed;
the search step (see ``attitude.pointing``) is chosen so that no Sun crossing of a
body vector can hide that way.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["Interval", "difference", "find_intervals", "total_duration"]


@dataclass(frozen=True)
class Interval:
    """[start_s, end_s] in TT seconds since the scenario epoch.

    ``starts_before``/``ends_after``: the condition already held at the start of the
    searched span, or still holds at its end (the interval is cut by the span).
    """

    start_s: float
    end_s: float
    starts_before: bool = False
    ends_after: bool = False

    @property
    def duration_s(self) -> float:
        return self.end_s - self.start_s


def _refine(
    f: Callable[[NDArray[np.float64]], NDArray[np.float64]],
    a: NDArray[np.float64],
    b: NDArray[np.float64],
    inside_at_a: NDArray[np.bool_],
    precision_s: float,
) -> NDArray[np.float64]:
    """The sign changes of f in the brackets [a, b], to ``precision_s`` (bisection)."""
    a, b = a.copy(), b.copy()
    while a.size and np.max(b - a) > precision_s:
        mid = 0.5 * (a + b)
        if np.all((mid == a) | (mid == b)):
            break  # the brackets are one float wide: no finer time exists
        same_as_a = (f(mid) > 0.0) == inside_at_a
        a = np.where(same_as_a, mid, a)
        b = np.where(same_as_a, b, mid)
    return 0.5 * (a + b)


def find_intervals(
    f: Callable[[NDArray[np.float64]], NDArray[np.float64]],
    grid_s: NDArray[np.float64],
    precision_s: float,
    grid_values: NDArray[np.float64] | None = None,
) -> list[Interval]:
    """The intervals of [grid[0], grid[-1]] where f > 0, ends refined to ``precision_s``.

    ``f`` takes and returns arrays (vectorized); ``grid_s`` is the increasing search
    grid, TT seconds; ``grid_values``, if given, is f on the grid (when several
    conditions share the costly part of f, the caller computes it once).
    """
    grid_s = np.asarray(grid_s, dtype=np.float64)
    inside = (f(grid_s) if grid_values is None else grid_values) > 0.0
    change = np.flatnonzero(inside[1:] != inside[:-1])
    crossings = _refine(f, grid_s[change], grid_s[change + 1], inside[change], precision_s)
    entering = ~inside[change]
    intervals = []
    start, starts_before = (grid_s[0], True) if inside[0] else (None, False)
    for time, enters in zip(crossings, entering, strict=True):
        if enters:
            start, starts_before = time, False
        else:
            intervals.append(Interval(float(start), float(time), starts_before, False))
            start = None
    if start is not None:
        intervals.append(Interval(float(start), float(grid_s[-1]), starts_before, True))
    return intervals


def difference(a: list[Interval], b: list[Interval]) -> list[Interval]:
    """The parts of the intervals ``a`` outside the intervals ``b`` (sorted, disjoint)."""
    out = []
    for interval in a:
        pieces = [interval]
        for cut in b:
            next_pieces = []
            for piece in pieces:
                if cut.end_s <= piece.start_s or cut.start_s >= piece.end_s:
                    next_pieces.append(piece)
                    continue
                if cut.start_s > piece.start_s:
                    next_pieces.append(
                        Interval(piece.start_s, cut.start_s, piece.starts_before, False)
                    )
                if cut.end_s < piece.end_s:
                    next_pieces.append(Interval(cut.end_s, piece.end_s, False, piece.ends_after))
            pieces = next_pieces
        out.extend(pieces)
    return out


def total_duration(intervals: list[Interval]) -> float:
    """The summed length of ``intervals``, seconds."""
    return float(sum(interval.duration_s for interval in intervals))
