"""The least (or greatest) value of a function over a span, found on the function itself.

The function f(τ) of TT seconds (a Sun angle on the exact attitude, say) is known
on a search grid whose step comes from the motion (see ``attitude.pointing``): fine
enough that between two grid points f has at most one turning point.  Every grid
point that is a local minimum brackets a minimum of f, [τ_{k−1}, τ_{k+1}], and inside
each bracket f is unimodal, so golden-section search (Kiefer 1953; Press et al.,
*Numerical Recipes*, 3rd ed., §10.2) narrows it to the stated time precision without
derivatives, through kinks too (the angle between two directions has one where they
meet, at 0).  All brackets are narrowed at once, one vectorized call of f per step.

Most brackets cannot hold the answer, and are dropped as soon as that is proven: f
changes at most at a rate ``lipschitz`` (rad/s for an angle: the vector's fastest
turn plus the geometry's), so between two evaluated points g apart where f is fp and
fq, f is at least (fp + fq − lipschitz·g)/2, where the two steepest descents meet.
A bracket whose bound is above the best value found so far, or within ``tolerance``
of it (it could improve it by less than that), is dropped.  Brackets whose minima
tie to within ``tolerance`` (a spinner in a fixed Sun) stop there: any of them is the
answer.  The result does not depend on the output step; it depends on the search grid
only through which brackets exist.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["Extremum", "Problem", "least", "least_in_brackets", "least_of_each"]

_GOLDEN = (np.sqrt(5.0) - 1.0) / 2.0  # 0.618...


@dataclass(frozen=True)
class Extremum:
    """A value of a function and the time (TT s since the epoch) where it is reached."""

    time_s: float
    value: float


@dataclass(frozen=True)
class Problem:
    """One function to minimize over the grid: its values there, a bound on its rate
    of change (inf: none), and the best value of an earlier part of the span (or None)."""

    grid_values: NDArray[np.float64]
    lipschitz: float
    incumbent: Extremum | None = None


def least(
    f: Callable[[NDArray[np.float64]], NDArray[np.float64]],
    grid_s: NDArray[np.float64],
    grid_values: NDArray[np.float64],
    lipschitz: float,
    tolerance: float,
    precision_s: float,
    incumbent: Extremum | None = None,
) -> Extremum:
    """The least value of ``f`` over [grid_s[0], grid_s[-1]], refined on ``f`` itself.

    ``f``: vectorized, from TT seconds to values; ``grid_values``: f on ``grid_s``;
    ``lipschitz``: a bound on |df/dτ| (inf: no pruning); ``tolerance``: in f's units,
    the improvement not worth a bracket (see the module notes); ``precision_s``: the
    width to which a bracket is narrowed.  ``incumbent``: the best of an earlier part
    of the span, which brackets here must beat (returned when none does).  For the
    greatest value, pass −f and negate the result.
    """
    found = least_of_each(
        lambda τ: {"f": f(τ)},
        grid_s,
        {"f": Problem(np.asarray(grid_values, dtype=np.float64), lipschitz, incumbent)},
        tolerance,
        precision_s,
    )
    return found["f"]


def _lowest(fp, fq, width, lipschitz: float):
    """The least value a function of rate at most ``lipschitz`` can take between two
    points ``width`` apart where it is fp and fq: its two slopes meet at
    (fp + fq − lipschitz · width) / 2 (no lower than the lesser of them when the
    points are one; −inf for an unbounded rate)."""
    with np.errstate(invalid="ignore"):
        meet = 0.5 * (fp + fq - lipschitz * width)
    return np.where(width > 0.0, meet, np.minimum(fp, fq))


class _Brackets:
    """The golden-section brackets of one problem: a < x1 < x2 < b and f there."""

    def __init__(
        self,
        a: NDArray[np.float64],
        b: NDArray[np.float64],
        fa: NDArray[np.float64],
        fb: NDArray[np.float64],
        x1: NDArray[np.float64],
        x2: NDArray[np.float64],
    ) -> None:
        self.a, self.b, self.fa, self.fb, self.x1, self.x2 = a, b, fa, fb, x1, x2
        # f at x1 and x2, and which of them the last step moved: unknown until the
        # first take().
        self.f1: NDArray[np.float64] | None = None
        self.f2: NDArray[np.float64] | None = None
        self.lower: NDArray[np.bool_] | None = None

    def _interior(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """f at x1 and x2 (after the first take())."""
        if self.f1 is None or self.f2 is None:
            raise RuntimeError("the brackets' interior values are not taken yet")
        return self.f1, self.f2

    def points(self) -> NDArray[np.float64]:
        """Where f is needed next."""
        if self.lower is None:
            return np.concatenate([self.x1, self.x2])
        return np.where(self.lower, self.x1, self.x2)

    def take(self, values: NDArray[np.float64]) -> None:
        """f at :meth:`points`; then move each bracket one golden step."""
        if self.lower is None:
            n = self.x1.size
            self.f1, self.f2 = values[:n], values[n:]
        else:
            f1, f2 = self._interior()
            self.f1 = np.where(self.lower, values, f1)
            self.f2 = np.where(self.lower, f2, values)

    def step(self) -> None:
        """Keep the sub-bracket that holds the lesser interior point; place the new point."""
        f1, f2 = self._interior()
        lower = f1 <= f2
        self.b = np.where(lower, self.x2, self.b)
        self.fb = np.where(lower, f2, self.fb)
        self.a = np.where(lower, self.a, self.x1)
        self.fa = np.where(lower, self.fa, f1)
        kept_x, kept_f = np.where(lower, self.x1, self.x2), np.where(lower, f1, f2)
        new_x = np.where(
            lower, self.b - _GOLDEN * (self.b - self.a), self.a + _GOLDEN * (self.b - self.a)
        )
        self.x1 = np.where(lower, new_x, kept_x)
        self.x2 = np.where(lower, kept_x, new_x)
        self.f1 = np.where(lower, np.nan, kept_f)
        self.f2 = np.where(lower, kept_f, np.nan)
        self.lower = lower

    def best(self) -> tuple[float, float] | None:
        x = np.concatenate([self.x1, self.x2])
        y = np.concatenate(self._interior())
        if y.size == 0:
            return None
        i = int(np.nanargmin(y))
        return float(x[i]), float(y[i])

    def keep(self, best: float, lipschitz: float, tolerance: float, precision_s: float) -> bool:
        """Drop the brackets that cannot beat ``best`` by more than ``tolerance`` and those
        narrower than ``precision_s``; True while any is left."""
        f1, f2 = self._interior()
        bound = np.minimum.reduce(
            [
                _lowest(self.fa, f1, self.x1 - self.a, lipschitz),
                _lowest(f1, f2, self.x2 - self.x1, lipschitz),
                _lowest(f2, self.fb, self.b - self.x2, lipschitz),
            ]
        )
        alive = (bound < best - tolerance) & (self.b - self.a > precision_s)
        for name in ("a", "b", "fa", "fb", "x1", "x2", "f1", "f2"):
            setattr(self, name, getattr(self, name)[alive])
        return bool(alive.any())


def least_of_each(
    evaluate: Callable[[NDArray[np.float64]], dict[str, NDArray[np.float64]]],
    grid_s: NDArray[np.float64],
    problems: dict[str, Problem],
    tolerance: float,
    precision_s: float,
) -> dict[str, Extremum]:
    """:func:`least` for several functions of the same time at once: ``evaluate(τ)``
    gives every function's values at τ (a dict by name), and each golden step calls it
    once for the brackets of all of them."""
    grid_s = np.asarray(grid_s, dtype=np.float64)
    n = grid_s.size
    best: dict[str, Extremum] = {}
    brackets: dict[str, _Brackets] = {}
    for name, problem in problems.items():
        values = problem.grid_values
        i = int(np.argmin(values))
        best[name] = Extremum(float(grid_s[i]), float(values[i]))
        if problem.incumbent is not None and problem.incumbent.value <= best[name].value:
            best[name] = problem.incumbent
        if n < 2:
            continue
        # Local minima of the grid (ends included; a plateau's first point) and their
        # brackets.
        left = np.concatenate([[np.inf], values[:-1]])
        right = np.concatenate([values[1:], [np.inf]])
        k = np.flatnonzero((values < left) & (values <= right))
        lo, hi = np.maximum(k - 1, 0), np.minimum(k + 1, n - 1)
        bound = np.minimum(
            _lowest(values[lo], values[k], grid_s[k] - grid_s[lo], problem.lipschitz),
            _lowest(values[k], values[hi], grid_s[hi] - grid_s[k], problem.lipschitz),
        )
        keep = bound < best[name].value - tolerance
        keep |= k == i  # the grid's own best is always refined
        k = k[keep]
        if k.size == 0:
            continue
        lo, hi = np.maximum(k - 1, 0), np.minimum(k + 1, n - 1)
        a, b = grid_s[lo], grid_s[hi]
        brackets[name] = _Brackets(
            a, b, values[lo], values[hi], b - _GOLDEN * (b - a), a + _GOLDEN * (b - a)
        )
    return _narrow(evaluate, brackets, best, problems, tolerance, precision_s)


def least_in_brackets(
    evaluate: Callable[[NDArray[np.float64]], dict[str, NDArray[np.float64]]],
    brackets: dict[str, tuple[NDArray[np.float64], ...]],
    problems: dict[str, Problem],
    best: dict[str, Extremum],
    tolerance: float,
    precision_s: float,
) -> dict[str, Extremum]:
    """:func:`least_of_each` on brackets found otherwise (by
    :mod:`attitude.pointing.free_search`, from bounds between nodes): ``brackets[name]``
    is (a, b, f(a), f(b)), arrays of the brackets' ends and of f there; ``best``: the
    least value known of each (every evaluated point, and the incumbent).  Each bracket
    is narrowed by golden-section search, and dropped on ``problems[name].lipschitz``
    as in :func:`least_of_each`; ``problems[name].grid_values`` is not used."""
    out = dict(best)
    narrowing: dict[str, _Brackets] = {}
    for name, (a, b, fa, fb) in brackets.items():
        if a.size:
            narrowing[name] = _Brackets(a, b, fa, fb, b - _GOLDEN * (b - a), a + _GOLDEN * (b - a))
    return _narrow(evaluate, narrowing, out, problems, tolerance, precision_s)


def _narrow(evaluate, brackets: dict[str, _Brackets], best, problems, tolerance, precision_s):
    """Golden-section steps on every bracket at once, one call of ``evaluate`` a step,
    until none is left (each dropped on its bound, or narrower than ``precision_s``)."""
    while brackets:
        names = list(brackets)
        points = [brackets[name].points() for name in names]
        values = evaluate(np.concatenate(points))
        start = 0
        for name, x in zip(names, points, strict=True):
            bracket = brackets[name]
            bracket.take(values[name][start : start + x.size])
            start += x.size
            found = bracket.best()
            if found is not None and found[1] < best[name].value:
                best[name] = Extremum(*found)
            bracket_alive = bracket.keep(
                best[name].value, problems[name].lipschitz, tolerance, precision_s
            )
            if bracket_alive:
                bracket.step()
            else:
                del brackets[name]
    return best
