"""Intervals where a condition holds, with their ends refined on the exact solution.

A condition is a continuous function f(τ) of TT seconds since the epoch, true where
f > 0 (for a Sun exclusion cone: cos(Sun angle) − cos(half angle)).  It is sampled
on a search grid finer than the motion's fastest time scale, then every sign
change is refined (regula falsi, then bisection if needed), all of them at once
(vectorized), until the bracket is narrower than the stated precision: the ends do not depend on the
output step.  Conditions combine as interval sets (``difference``, ``union``), e.g.
"the Sun is in the tracker's cone and the spacecraft is not in umbra", or "the tracker
is blinded by the Sun, the Moon or the limb".  A long span is searched in
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
    "append_across",
    "difference",
    "find_all_intervals",
    "find_intervals",
    "isolate",
    "join",
    "total_duration",
    "union",
]


@dataclass(frozen=True, slots=True)
class Interval:
    """[start_s, end_s] in TT seconds since the scenario epoch.

    ``starts_before``/``ends_after``: the condition already held at the start of the
    searched span, or still holds at its end (the interval is cut by the span).
    Slots: a month of a spinner's Sun visibility windows is close to a million
    intervals, about 120 bytes each in a list (160 with a ``__dict__``).
    """

    start_s: float
    end_s: float
    starts_before: bool = False
    ends_after: bool = False

    @property
    def duration_s(self) -> float:
        return self.end_s - self.start_s


def _refine(
    f: Callable[[NDArray[np.float64], NDArray[np.intp]], NDArray[np.float64]],
    a: NDArray[np.float64],
    b: NDArray[np.float64],
    inside_at_a: NDArray[np.bool_],
    precision_s: float,
    fa: NDArray[np.float64] | None = None,
    fb: NDArray[np.float64] | None = None,
    estimate: NDArray[np.float64] | None = None,
) -> NDArray[np.float64]:
    """The sign changes of f in the brackets [a, b], to ``precision_s``.

    ``f(τ, which)``: f at one time for each of the brackets ``which`` (indices), all at
    once; a bracket closed to ``precision_s`` is not evaluated again.  With f at the
    ends (``fa``, ``fb``), two steps of regula falsi (the conditions are smooth: from a
    grid step it lands well within the precision of the crossing) and then f at
    0.49 ``precision_s`` on either side of its estimate, which closes the bracket with
    four calls of f where bisection takes eight; a bracket not closed that way (a
    kink, a flat end) goes on by bisection (Press et al., *Numerical Recipes*, 3rd
    ed., §9.2).  With an ``estimate`` of each crossing (the root of a cubic through the
    ends' values and slopes: :mod:`attitude.pointing.free_search`), the regula falsi is
    skipped and the probes go either side of it.  Each bracket's result depends on its
    own evaluations only."""
    a, b = a.copy(), b.copy()
    if estimate is not None and a.size:
        x = np.where(np.isfinite(estimate), estimate, 0.5 * (a + b))
        _probe(f, a, b, inside_at_a, precision_s, x)
    elif fa is not None and fb is not None and a.size:
        fa, fb = np.asarray(fa, dtype=np.float64).copy(), np.asarray(fb, dtype=np.float64).copy()
        for _ in range(2):
            which = np.flatnonzero(b - a > precision_s)
            if which.size == 0:
                break
            with np.errstate(divide="ignore", invalid="ignore"):
                x = (a * fb - b * fa) / (fb - fa)
            x = np.where(np.isfinite(x) & (x > a) & (x < b), x, 0.5 * (a + b))[which]
            fx = f(x, which)
            same_as_a = (fx > 0.0) == inside_at_a[which]
            a[which] = np.where(same_as_a, x, a[which])
            fa[which] = np.where(same_as_a, fx, fa[which])
            b[which] = np.where(same_as_a, b[which], x)
            fb[which] = np.where(same_as_a, fb[which], fx)
        with np.errstate(divide="ignore", invalid="ignore"):
            x = (a * fb - b * fa) / (fb - fa)
        x = np.where(np.isfinite(x), x, 0.5 * (a + b))
        _probe(f, a, b, inside_at_a, precision_s, x)
    while True:
        which = np.flatnonzero(b - a > precision_s)
        if which.size == 0:
            break
        mid = 0.5 * (a[which] + b[which])
        if np.all((mid == a[which]) | (mid == b[which])):
            break  # the brackets are one float wide: no finer time exists
        same_as_a = (f(mid, which) > 0.0) == inside_at_a[which]
        a[which] = np.where(same_as_a, mid, a[which])
        b[which] = np.where(same_as_a, b[which], mid)
    return 0.5 * (a + b)


def _probe(f, a, b, inside_at_a, precision_s: float, x) -> None:
    """Close the brackets [a, b] (in place) with f at 0.49 ``precision_s`` either side of
    the estimates ``x``, where that lands inside them."""
    for probe in (x - 0.49 * precision_s, x + 0.49 * precision_s):
        probe = np.clip(probe, a, b)
        which = np.flatnonzero((b - a > precision_s) & (probe > a) & (probe < b))
        if which.size == 0:
            continue
        same_as_a = (f(probe[which], which) > 0.0) == inside_at_a[which]
        a[which] = np.where(same_as_a, probe[which], a[which])
        b[which] = np.where(same_as_a, b[which], probe[which])


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
    lipschitz: dict[str, float] | None = None,
) -> dict[str, list[Interval]]:
    """:func:`find_intervals` for several conditions at once: ``evaluate(τ)`` gives
    every condition's function at τ (a dict by name; > 0 where it holds), and each
    refinement step calls it once for the crossings of all of them.  ``grid_values``:
    each condition's function on the grid.  With ``lipschitz`` (a bound on |df/dτ| of
    each condition), no interval is missed however short: see :func:`isolate`."""
    grid_s = np.asarray(grid_s, dtype=np.float64)
    if lipschitz is not None:
        grid_s, grid_values = isolate(evaluate, grid_s, grid_values, lipschitz)
    names = list(grid_values)
    inside = {name: np.asarray(grid_values[name]) > 0.0 for name in names}
    changes = {name: np.flatnonzero(inside[name][1:] != inside[name][:-1]) for name in names}
    owner = np.concatenate(
        [np.full(changes[name].size, k, dtype=np.intp) for k, name in enumerate(names)]
    )
    index = np.concatenate([changes[name] for name in names]).astype(np.intp)
    at_a = np.concatenate([inside[name][changes[name]] for name in names]).astype(bool)

    def f(τ: NDArray[np.float64], which: NDArray[np.intp]) -> NDArray[np.float64]:
        """Each crossing's own condition at its time τ (crossings ``which``)."""
        values = evaluate(τ)
        out = np.empty(τ.size)
        owners = owner[which]
        for k, name in enumerate(names):
            mine = owners == k
            out[mine] = values[name][mine]
        return out

    ends = [
        np.concatenate([np.asarray(grid_values[name])[changes[name] + k] for name in names])
        for k in (0, 1)
    ]
    crossings = _refine(f, grid_s[index], grid_s[index + 1], at_a, precision_s, *ends)
    found = {}
    for k, name in enumerate(names):
        mine = owner == k
        found[name] = _assemble(grid_s, inside[name], crossings[mine], ~at_a[mine])
    return found


def isolate(
    evaluate: Callable[[NDArray[np.float64]], dict[str, NDArray[np.float64]]],
    grid_s: NDArray[np.float64],
    grid_values: dict[str, NDArray[np.float64]],
    lipschitz: dict[str, float],
) -> tuple[NDArray[np.float64], dict[str, NDArray[np.float64]]]:
    """The grid with points added until no condition can change sign twice between
    two neighbours unseen: with |df/dτ| ≤ L, f cannot reach 0 between points h apart
    where it is fa and fb of one sign if |fa| + |fb| > L h (the two steepest slopes
    from the ends meet before 0).  Every step between points where that is not proved
    is halved, all at once, one call of ``evaluate`` a round, down to the spacing of
    floats there (4 ulps): an interval between two points closer than that is below
    what a time in seconds resolves.  Returns the grid and each condition's values."""
    values = {name: np.asarray(v, dtype=np.float64) for name, v in grid_values.items()}
    while grid_s.size > 1:
        width = np.diff(grid_s)
        resolvable = width > 4.0 * np.spacing(np.maximum(abs(grid_s[:-1]), abs(grid_s[1:])))
        unproved = np.zeros(width.size, dtype=bool)
        for name, rate in lipschitz.items():
            f = values[name]
            same = (f[:-1] > 0.0) == (f[1:] > 0.0)
            with np.errstate(invalid="ignore"):
                unproved |= same & ~(np.abs(f[:-1]) + np.abs(f[1:]) > rate * width)
        split = np.flatnonzero(unproved & resolvable)
        if split.size == 0:
            break
        middle = 0.5 * (grid_s[split] + grid_s[split + 1])
        more = evaluate(middle)
        order = np.argsort(np.concatenate([grid_s, middle]), kind="stable")
        grid_s = np.concatenate([grid_s, middle])[order]
        values = {
            name: np.concatenate([values[name], np.asarray(more[name], dtype=np.float64)])[order]
            for name in values
        }
    return grid_s, values


def _assemble(
    grid_s: NDArray[np.float64],
    inside: NDArray[np.bool_],
    crossings: NDArray[np.float64],
    entering: NDArray[np.bool_],
) -> list[Interval]:
    """The intervals from the crossings (in time order) and whether each enters."""
    intervals = []
    start: float | None = float(grid_s[0]) if inside[0] else None
    starts_before = bool(inside[0])
    for time, enters in zip(crossings, entering, strict=True):
        if enters:
            start, starts_before = float(time), False
        else:
            if start is None:
                raise ValueError(f"an exit at {time} s without an entry before it")
            intervals.append(Interval(start, float(time), starts_before, False))
            start = None
    if start is not None:
        intervals.append(Interval(float(start), float(grid_s[-1]), starts_before, True))
    return intervals


def difference(a: list[Interval], b: list[Interval]) -> list[Interval]:
    """The parts of the intervals ``a`` outside the intervals ``b`` (each sorted and
    disjoint), in one sweep: O(len(a) + len(b))."""
    if not b:
        return list(a)
    out = []
    first = 0  # the first cut that can still overlap an interval of a
    for interval in a:
        while first < len(b) and b[first].end_s <= interval.start_s:
            first += 1
        start, starts_before = interval.start_s, interval.starts_before
        covered = False  # a cut reaches the interval's end
        for cut in b[first:]:
            if cut.start_s >= interval.end_s:
                break
            if cut.start_s > start:
                out.append(Interval(start, cut.start_s, starts_before, False))
            if cut.end_s >= interval.end_s:
                covered = True
                break
            start, starts_before = max(start, cut.end_s), False
        if not covered:
            out.append(Interval(start, interval.end_s, starts_before, interval.ends_after))
    return out


def union(*lists: list[Interval]) -> list[Interval]:
    """The time covered by any of the interval ``lists`` (each sorted and disjoint), as
    sorted disjoint intervals: overlapping or touching intervals merge into one.

    A merged interval starts before the span if its first piece does, and ends after
    it if a piece that reaches its end does."""
    pieces = sorted(
        (interval for intervals in lists for interval in intervals),
        key=lambda i: (i.start_s, not i.starts_before),
    )
    out: list[Interval] = []
    for piece in pieces:
        if out and piece.start_s <= out[-1].end_s:
            last = out[-1]
            if piece.end_s > last.end_s:
                out[-1] = Interval(last.start_s, piece.end_s, last.starts_before, piece.ends_after)
            elif piece.end_s == last.end_s and piece.ends_after and not last.ends_after:
                out[-1] = Interval(last.start_s, last.end_s, last.starts_before, True)
        else:
            out.append(piece)
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


def append_across(intervals: list[Interval], more: list[Interval], boundary_s: float) -> None:
    """:func:`join` across a boundary where the condition's value may jump (an event
    that resets the attitude): an interval of ``more`` that starts at the boundary
    without one of ``intervals`` continuing it started there, not before the span."""
    continued = bool(intervals) and intervals[-1].ends_after and intervals[-1].end_s == boundary_s
    if more and more[0].starts_before and more[0].start_s == boundary_s and not continued:
        first = more[0]
        more = [Interval(first.start_s, first.end_s, False, first.ends_after), *more[1:]]
    join(intervals, more, boundary_s)


def total_duration(intervals: list[Interval]) -> float:
    """The summed length of ``intervals``, seconds."""
    return float(sum(interval.duration_s for interval in intervals))
