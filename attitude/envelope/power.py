"""The panels' sunlit power after a loss, and the first time it falls below a threshold.

The power fraction of the panels p (body vectors of kind ``panel``) is

    P(t) = λ(t) · (1/n) Σ_p max(cos θ_p(t), 0),

θ_p the angle between the panel's normal and the Sun, λ the lit fraction of the Sun's
disc (0 in umbra, between 0 and 1 in penumbra: :mod:`attitude.pointing.eclipse`):
1 when every panel faces the Sun squarely in full light.

:func:`first_below` finds the first time P ≤ c on [a, b] without a grid that could miss
a dip: P is Lipschitz, |P'| ≤ L with L = λ_max + (1/n) Σ_p max|θ_p'| (each angle's rate
bound from the search, :meth:`attitude.pointing.search.SearchGrid.vector_angle_rate_bound`,
and the lit fraction's, :attr:`~attitude.pointing.search.SearchGrid.fraction_rate_bound`,
which counts only inside the Earth's shadow), so on a cell [t₀, t₁] of width h,
P ≥ (P(t₀) + P(t₁) − L h)/2.  A cell whose bound exceeds c is settled; the others, in
time order up to the first node where P ≤ c, are cut into 16 parts until the first is narrower
than the precision: its left end is the first instant P can reach c (an early answer
by at most the precision, never a late one).  :func:`first_below_many` runs that
search for many pieces (of many failures) at once, each round of cuts one call of the
function for every piece: the same cells, nodes and answer as :func:`first_below` on
each piece alone (the same arithmetic, element by element).

:func:`integral` gives ∫P dt over a piece where P is smooth but for the kinks of
max(cos θ, 0): Gauss–Legendre (8 points) on cells no longer than the Lipschitz
step and :data:`_LONGEST_CELL_S`; the caller cuts the window at the shadow's edges.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

__all__ = ["first_below", "first_below_many", "integral", "power_fraction"]

# The first nodes are spaced so that the Lipschitz bound sags at most this much
# between two of them (a power fraction), and a run of nodes holds at most this many.
_SAG = 0.05
_CHUNK_NODES = 8192
# The integral's cells: at most this long (s), and Gauss–Legendre points in each.
_LONGEST_CELL_S = 30.0
_GAUSS_POINTS = 8
# An open cell is cut into this many parts a round (one call of the function for all
# of them: a cell of 30 s reaches 1 ms in 4 rounds, where halving takes 15), and at
# most this many rounds (a cell of a week cut 20 times is 5e-19 s wide).
_SPLIT = 16
_MAX_HALVINGS = 20


def power_fraction(
    attitude: Callable, sun: Callable, panels: NDArray[np.float64], t: NDArray[np.float64]
) -> NDArray[np.float64]:
    """P(t) (module notes): ``attitude(t)`` the body → ICRF Rotation, ``sun(t)`` the
    Sun's unit direction (n, 3) and the lit fraction (n,) or 1, ``panels`` (k, 3) unit
    normals in body axes."""
    rotation = attitude(t)
    direction, lit = sun(t)
    cosines = np.stack([np.einsum("ij,ij->i", rotation.apply(p), direction) for p in panels])
    return lit * np.mean(np.maximum(cosines, 0.0), axis=0)


def first_below(
    f: Callable[[NDArray[np.float64]], NDArray[np.float64]],
    a: float,
    b: float,
    lipschitz: float,
    threshold: float,
    precision: float,
) -> float | None:
    """The first t in [a, b] where ``f`` (vectorized, |f'| ≤ ``lipschitz``) may reach
    ``threshold``, within ``precision`` (s), or None if f stays above it (module notes)."""
    if f(np.array([a]))[0] <= threshold:
        return a
    if b <= a:
        return None
    step = 2.0 * _SAG / lipschitz if lipschitz > 0.0 else b - a
    cells = max(1, math.ceil((b - a) / step))
    chunk = max(1, math.ceil(cells / math.ceil(cells / _CHUNK_NODES)))
    edges = np.linspace(a, b, cells + 1)
    for start in range(0, cells, chunk):
        t = edges[start : start + chunk + 1]
        found = _first_in(lambda x: f(x) - threshold, t, lipschitz, precision)
        if found is not None:
            return found
    return None


def first_below_many(
    f: Callable[[NDArray[np.intp], NDArray[np.float64]], NDArray[np.float64]],
    a: NDArray[np.float64],
    b: NDArray[np.float64],
    lipschitz: NDArray[np.float64],
    threshold: float,
    precision: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """:func:`first_below` on each piece [a_i, b_i] (bound ``lipschitz[i]``, precision
    ``precision[i]``) at once: ``f(which, t)`` gives the function of piece ``which[j]``
    at ``t[j]``.  Returns the first times (NaN where f stays above ``threshold``) and
    f(a_i).  A piece of more than :data:`_CHUNK_NODES` cells is searched alone, by
    :func:`first_below`."""
    count = a.size
    found = np.full(count, np.nan)
    at_start = np.empty(count)
    # Round 0: every piece's first nodes (its start alone if it is empty or searched
    # alone), in one call.
    edges: list[NDArray[np.float64]] = []
    for i in range(count):
        lo, hi, slope = float(a[i]), float(b[i]), float(lipschitz[i])
        if hi <= lo:
            edges.append(np.array([lo]))
            continue
        step = 2.0 * _SAG / slope if slope > 0.0 else hi - lo
        cells = max(1, math.ceil((hi - lo) / step))
        edges.append(np.linspace(lo, hi, cells + 1) if cells <= _CHUNK_NODES else np.array([lo]))
    sizes = np.array([e.size for e in edges], dtype=np.intp)
    which = np.repeat(np.arange(count, dtype=np.intp), sizes)
    values = f(which, np.concatenate(edges)) if count else np.empty(0)
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.intp)
    at_start[:] = values[starts]
    pid_parts, left_parts, right_parts, vl_parts, vr_parts = [], [], [], [], []
    for i in range(count):
        if at_start[i] <= threshold:
            found[i] = a[i]
        elif sizes[i] > 1:
            t = edges[i]
            g = values[starts[i] : starts[i] + sizes[i]] - threshold
            pid_parts.append(np.full(t.size - 1, i, dtype=np.intp))
            left_parts.append(t[:-1])
            right_parts.append(t[1:])
            vl_parts.append(g[:-1])
            vr_parts.append(g[1:])
        elif b[i] > a[i]:  # more cells than a run holds: alone, in runs
            alone = first_below(
                _one(f, i),
                float(a[i]),
                float(b[i]),
                float(lipschitz[i]),
                threshold,
                float(precision[i]),
            )
            found[i] = np.nan if alone is None else alone
    if not pid_parts:
        return found, at_start
    pid = np.concatenate(pid_parts)
    left, right = np.concatenate(left_parts), np.concatenate(right_parts)
    v_left, v_right = np.concatenate(vl_parts), np.concatenate(vr_parts)
    fractions = np.arange(1, _SPLIT) / _SPLIT
    for _ in range(_MAX_HALVINGS):
        # Each piece's cells up to its first node where f ≤ c (as _first_in).
        index = np.arange(pid.size)
        first_low = np.full(count, pid.size)
        low = v_right <= 0.0
        np.minimum.at(first_low, pid[low], index[low])
        keep = index <= first_low[pid]
        keep &= 0.5 * (v_left + v_right - lipschitz[pid] * (right - left)) <= 0.0
        pid, left, right = pid[keep], left[keep], right[keep]
        v_left, v_right = v_left[keep], v_right[keep]
        if pid.size == 0:
            return found, at_start
        heads = np.flatnonzero(np.concatenate([[True], pid[1:] != pid[:-1]]))
        narrow = heads[right[heads] - left[heads] <= precision[pid[heads]]]
        if narrow.size:
            found[pid[narrow]] = left[narrow]
            done = np.zeros(count, dtype=bool)
            done[pid[narrow]] = True
            keep = ~done[pid]
            pid, left, right = pid[keep], left[keep], right[keep]
            v_left, v_right = v_left[keep], v_right[keep]
            if pid.size == 0:
                return found, at_start
        inner = left[:, None] + (right - left)[:, None] * fractions[None, :]
        v_inner = (f(np.repeat(pid, _SPLIT - 1), inner.ravel()) - threshold).reshape(inner.shape)
        nodes = np.column_stack([left, inner, right])
        values = np.column_stack([v_left, v_inner, v_right])
        left, right = np.ravel(nodes[:, :-1]), np.ravel(nodes[:, 1:])
        v_left, v_right = np.ravel(values[:, :-1]), np.ravel(values[:, 1:])
        pid = np.repeat(pid, _SPLIT)
    heads = np.flatnonzero(np.concatenate([[True], pid[1:] != pid[:-1]]))
    found[pid[heads]] = left[heads]  # cut to the limit: the earliest instant it may reach
    return found, at_start


def _one(f, i: int) -> Callable[[NDArray[np.float64]], NDArray[np.float64]]:
    """Piece ``i``'s function of :func:`first_below_many` alone."""

    def g(t: NDArray[np.float64]) -> NDArray[np.float64]:
        return f(np.full(t.size, i, dtype=np.intp), t)

    return g


def _first_in(g, t, lipschitz: float, precision: float) -> float | None:
    """The first cell of nodes ``t`` where g = f − c may reach 0, cut down to
    ``precision``: its left end, or None."""
    v = g(t)
    left, right, v_left, v_right = t[:-1], t[1:], v[:-1], v[1:]
    for _ in range(_MAX_HALVINGS):
        below = np.flatnonzero(v_right <= 0.0)
        last = below[0] + 1 if below.size else left.size
        left, right, v_left, v_right = left[:last], right[:last], v_left[:last], v_right[:last]
        open_ = 0.5 * (v_left + v_right - lipschitz * (right - left)) <= 0.0
        left, right, v_left, v_right = left[open_], right[open_], v_left[open_], v_right[open_]
        if left.size == 0:
            return None
        if right[0] - left[0] <= precision:
            return float(left[0])
        # Each open cell cut into _SPLIT equal parts, all evaluated in one call.
        fractions = np.arange(1, _SPLIT) / _SPLIT
        inner = left[:, None] + (right - left)[:, None] * fractions[None, :]
        v_inner = g(inner.ravel()).reshape(inner.shape)
        nodes = np.column_stack([left, inner, right])
        values = np.column_stack([v_left, v_inner, v_right])
        left, right = np.ravel(nodes[:, :-1]), np.ravel(nodes[:, 1:])
        v_left, v_right = np.ravel(values[:, :-1]), np.ravel(values[:, 1:])
    return float(left[0])  # cut to the limit: the earliest instant it may reach


def integral(
    f: Callable[[NDArray[np.float64]], NDArray[np.float64]],
    a: float,
    b: float,
    lipschitz: float,
) -> float:
    """∫_a^b f dt (module notes)."""
    if b <= a:
        return 0.0
    step = min(2.0 * _SAG / lipschitz if lipschitz > 0.0 else b - a, _LONGEST_CELL_S)
    cells = max(1, math.ceil((b - a) / step))
    x, w = np.polynomial.legendre.leggauss(_GAUSS_POINTS)
    edges = np.linspace(a, b, cells + 1)
    half = 0.5 * np.diff(edges)
    t = (edges[:-1] + half)[:, None] + half[:, None] * x[None, :]
    values = f(t.ravel()).reshape(t.shape)
    return float(np.sum(half * (values @ w)))
