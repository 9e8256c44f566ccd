"""Intervals where a condition holds, with their ends refined on the exact solution.

A condition is a continuous function f(τ) of TT seconds since the epoch, true where
f > 0 (for a Sun exclusion cone: cos(Sun angle) − cos(half angle)).  It is sampled
on a search grid finer than the motion's fastest time scale, then every sign
change is refined by bisection, all of them at once (vectorized), until the
bracket is narrower than the stated precision: the ends do not depend on the
output step.  Conditions combine as interval sets (``difference``), e.g. "the Sun is
in the tracker's cone and the spacecraft is not in umbra".  A long span is searched in
chunks (bounded memory); ``join`` puts the pieces of an interval cut by a chunk's end
back together.

A condition that becomes true and false again between two search samples is missed;
the search step (see ``attitude.pointing``) is chosen so that no Sun crossing of a
body vector can hide that way.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "Interval",
    "difference",
    "find_all_intervals",
    "find_intervals",
    "join",
    "total_duration",
]


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
    """The sign changes of f in the brackets [a, b], to ``precision_s`` (bisection).

    ``f`` takes the midpoints of all brackets at once (one value per bracket)."""
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
    values = f(grid_s) if grid_values is None else grid_values
    return find_all_intervals(lambda τ: {"f": f(τ)}, grid_s, precision_s, {"f": values})["f"]


def find_all_intervals(
    evaluate: Callable[[NDArray[np.float64]], dict[str, NDArray[np.float64]]],
    grid_s: NDArray[np.float64],
    precision_s: float,
    grid_values: dict[str, NDArray[np.float64]],
) -> dict[str, list[Interval]]:
    """:func:`find_intervals` for several conditions at once: ``evaluate(τ)`` gives
    every condition's function at τ (a dict by name; > 0 where it holds), and each
    bisection step calls it once for the crossings of all of them.  ``grid_values``:
    each condition's function on the grid."""
    grid_s = np.asarray(grid_s, dtype=np.float64)
    names = list(grid_values)
    inside = {name: np.asarray(grid_values[name]) > 0.0 for name in names}
    changes = {name: np.flatnonzero(inside[name][1:] != inside[name][:-1]) for name in names}
    owner = np.concatenate(
        [np.full(changes[name].size, k, dtype=np.intp) for k, name in enumerate(names)]
    )
    index = np.concatenate([changes[name] for name in names]).astype(np.intp)
    at_a = np.concatenate([inside[name][changes[name]] for name in names]).astype(bool)

    def f(τ: NDArray[np.float64]) -> NDArray[np.float64]:
        values = evaluate(τ)
        out = np.empty(τ.size)
        for k, name in enumerate(names):
            mine = owner == k
            out[mine] = values[name][mine]
        return out

    crossings = _refine(f, grid_s[index], grid_s[index + 1], at_a, precision_s)
    found = {}
    for k, name in enumerate(names):
        mine = owner == k
        found[name] = _assemble(grid_s, inside[name], crossings[mine], ~at_a[mine])
    return found


def _assemble(grid_s, inside, crossings, entering) -> list[Interval]:
    """The intervals from the crossings (in time order) and whether each enters."""
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
    """The parts of the intervals ``a`` outside the intervals ``b`` (each sorted and
    disjoint), in one sweep: O(len(a) + len(b))."""
    out = []
    first = 0  # the first cut that can still overlap an interval of a
    for interval in a:
        while first < len(b) and b[first].end_s <= interval.start_s:
            first += 1
        start, starts_before = interval.start_s, interval.starts_before
        for cut in b[first:]:
            if cut.start_s >= interval.end_s:
                break
            if cut.start_s > start:
                out.append(Interval(start, cut.start_s, starts_before, False))
            if cut.end_s >= interval.end_s:
                start = None
                break
            start, starts_before = max(start, cut.end_s), False
        if start is not None:
            out.append(Interval(start, interval.end_s, starts_before, interval.ends_after))
    return out


def join(intervals: list[Interval], more: list[Interval], boundary_s: float) -> None:
    """Append ``more`` (the intervals of the next chunk, which starts at ``boundary_s``)
    to ``intervals``, joining an interval cut at the boundary with its continuation."""
    if (
        intervals
        and more
        and intervals[-1].ends_after
        and more[0].starts_before
        and intervals[-1].end_s == boundary_s == more[0].start_s
    ):
        last = intervals.pop()
        intervals.append(
            Interval(last.start_s, more[0].end_s, last.starts_before, more[0].ends_after)
        )
        more = more[1:]
    elif intervals and intervals[-1].ends_after and intervals[-1].end_s == boundary_s:
        last = intervals.pop()  # the condition ended exactly at the boundary
        intervals.append(Interval(last.start_s, last.end_s, last.starts_before, False))
    intervals.extend(more)


def total_duration(intervals: list[Interval]) -> float:
    """The summed length of ``intervals``, seconds."""
    return float(sum(interval.duration_s for interval in intervals))
