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
search on many runs of nodes (of many failures) at once, each round of cuts one call
of the function for all: each run's cells, nodes and answer are those it has alone
(the same arithmetic, element by element).

:func:`integral` gives ∫P dt over a piece where P is smooth but for the kinks of
max(cos θ, 0): Gauss–Legendre (8 points) on cells no longer than the Lipschitz
step and :data:`_LONGEST_CELL_S`; the caller cuts the window at the shadow's edges.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from attitude.base.quaternions import rotation_rows

__all__ = [
    "as_fraction",
    "first_below",
    "first_below_many",
    "first_nodes",
    "integral",
    "mean_incidence",
    "power_fraction",
]

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
    quaternions: Callable, sun: Callable, panels: NDArray[np.float64], t: NDArray[np.float64]
) -> NDArray[np.float64]:
    """P(t) (module notes): ``quaternions(t)`` the unit attitude quaternions (n, 4),
    scalar first, body → ICRF, ``sun(t)`` the Sun's unit direction (n, 3) and the lit
    fraction (n,) or 1, ``panels`` (k, 3) unit normals in body axes."""
    direction, lit = sun(t)
    return lit * mean_incidence(quaternions(t), panels, direction)


def mean_incidence(
    q: NDArray[np.float64], panels: NDArray[np.float64], sun: NDArray[np.float64]
) -> NDArray[np.float64]:
    """(1/k) Σ_p max(cos θ_p, 0) at each of n instants: each panel's unit normal b_p
    (``panels``, (k, 3), body axes) turned to ICRF by the unit quaternions ``q`` ((n, 4),
    w, x, y, z) as R(q) b_p, the rotation matrix written row by row, against the Sun's
    unit directions ``sun`` (n, 3).  Element by element: an instant's value does not
    depend on the others computed with it."""
    rows = rotation_rows(q)
    total = np.zeros(q.shape[0])
    for b in panels:
        cosine = (rows[0][0] * b[0] + rows[0][1] * b[1] + rows[0][2] * b[2]) * sun[:, 0]
        cosine += (rows[1][0] * b[0] + rows[1][1] * b[1] + rows[1][2] * b[2]) * sun[:, 1]
        cosine += (rows[2][0] * b[0] + rows[2][1] * b[1] + rows[2][2] * b[2]) * sun[:, 2]
        # Clamped to 1: the cosine of two unit vectors, each unit within a few ulps
        # (the interpolated Sun's length is within 1e-15 of 1, measured), rounds to just
        # above 1 for a panel square to the Sun (1.0000000000000004 under the example's
        # Sun law): a rounding, not a power above full.
        total += np.clip(cosine, 0.0, 1.0)
    return total / len(panels)


def as_fraction(value: float) -> float:
    """A mean of the power fraction from :func:`integral` (a Gauss–Legendre sum of
    values within [0, 1], over the window) held within [0, 1]: the weights' sum and
    the products round, and a panel square to the Sun all window long sums to just
    above 1."""
    return min(max(value, 0.0), 1.0)


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


def first_nodes(a: float, b: float, lipschitz: float) -> NDArray[np.float64] | None:
    """The nodes :func:`first_below` starts from on [a, b] (``a`` alone for an empty
    piece), or None for a piece of more cells than a run holds (:func:`first_below`
    searches it in runs)."""
    if b <= a:
        return np.array([a])
    step = 2.0 * _SAG / lipschitz if lipschitz > 0.0 else b - a
    cells = max(1, math.ceil((b - a) / step))
    return np.linspace(a, b, cells + 1) if cells <= _CHUNK_NODES else None


def first_below_many(
    f: Callable[[NDArray[np.intp], NDArray[np.float64]], NDArray[np.float64]],
    nodes: list[NDArray[np.float64]],
    lipschitz: NDArray[np.float64],
    threshold: float,
    precision: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """:func:`first_below` on many runs of nodes at once: run i starts from
    ``nodes[i]`` (consecutive nodes of :func:`first_nodes`, one node for a piece
    reduced to its start), with the bound ``lipschitz[i]`` and ``precision[i]``;
    ``f(which, t)`` gives the function of run ``which[j]`` at ``t[j]``.  Returns each
    run's first time (NaN where f stays above ``threshold``) and f at its first node.
    The first node counts: f there at or below the threshold answers it."""
    count = len(nodes)
    found = np.full(count, np.nan)
    sizes = np.array([t.size for t in nodes], dtype=np.intp)
    which = np.repeat(np.arange(count, dtype=np.intp), sizes)
    values = f(which, np.concatenate(nodes)) if count else np.empty(0)
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.intp)
    at_start = values[starts]
    pid_parts, left_parts, right_parts, vl_parts, vr_parts = [], [], [], [], []
    for i in range(count):
        if at_start[i] <= threshold:
            found[i] = nodes[i][0]
        elif sizes[i] > 1:
            t = nodes[i]
            g = values[starts[i] : starts[i] + sizes[i]] - threshold
            pid_parts.append(np.full(t.size - 1, i, dtype=np.intp))
            left_parts.append(t[:-1])
            right_parts.append(t[1:])
            vl_parts.append(g[:-1])
            vr_parts.append(g[1:])
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
        cut = np.column_stack([left, inner, right])
        values = np.column_stack([v_left, v_inner, v_right])
        left, right = np.ravel(cut[:, :-1]), np.ravel(cut[:, 1:])
        v_left, v_right = np.ravel(values[:, :-1]), np.ravel(values[:, 1:])
        pid = np.repeat(pid, _SPLIT)
    heads = np.flatnonzero(np.concatenate([[True], pid[1:] != pid[:-1]]))
    found[pid[heads]] = left[heads]  # cut to the limit: the earliest instant it may reach
    return found, at_start


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
