"""When a ground site sees the spacecraft: its elevation, and the intervals above a
minimum elevation, found on the law's own geometry (not on an output grid).

A law tracking a ground site is defined whether or not the site is above the
horizon (it then points through the Earth); these functions tell the later layers when
it is, so that a run can say "never visible in the span" rather than track silently.

:func:`visible_intervals` samples the elevation's *rate* every ``step`` seconds (30 s
by default: the elevation of a site seen from low orbit has one maximum per pass,
and its extrema are tens of minutes apart), finds every maximum by root-finding the
rate (``scipy.optimize.brentq``), and then every crossing of the minimum elevation
between a maximum above it and the neighbouring minima or span ends.  A pass whose
highest elevation exceeds the minimum is found however short it is, as long as two
extrema of the elevation are not within one ``step``.
"""

from __future__ import annotations

from itertools import pairwise

import numpy as np
from numpy.typing import ArrayLike, NDArray

from attitude.base.errors import InputError
from attitude.base.quantities import as_si_scalar
from attitude.laws.align_constrain import AlignConstrainLaw, BoundLaw
from attitude.laws.directions import GroundSite, Opposite

__all__ = ["elevation", "ground_site", "visible_intervals"]


def ground_site(bound: BoundLaw) -> GroundSite:
    """The ground site a bound law points at (primary or secondary direction)."""
    law = bound.law
    if isinstance(law, AlignConstrainLaw):
        for candidate in (law.primary, law.secondary):
            inner = candidate.inner if isinstance(candidate, Opposite) else candidate
            if isinstance(inner, GroundSite):
                return inner
    raise InputError(f"{bound.key}: the {law.name} law points at no ground site")


def elevation(
    bound: BoundLaw, seconds: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The spacecraft's elevation above the site's horizon (rad) and its rate (rad/s)
    at TT seconds (see :meth:`attitude.laws.directions.GroundSite.elevation`)."""
    return ground_site(bound).elevation(bound.at(seconds))


def visible_intervals(
    bound: BoundLaw, min_elevation: float = 0.0, step: float = 30.0
) -> list[tuple[float, float]]:
    """The intervals [start, stop] (TT seconds) of the bound span where the spacecraft
    stands at least ``min_elevation`` (radians or an angle Quantity) above the site's
    horizon.  An empty list: the site never sees it in the span."""
    site = ground_site(bound)
    floor = as_si_scalar(min_elevation, "angle", "min_elevation")
    step = as_si_scalar(step, "time", "step")
    if not step > 0.0:
        raise InputError(f"step must be positive, got {step}")
    start, stop = bound.inputs.start_s, bound.inputs.stop_s
    count = max(int(np.ceil((stop - start) / step)), 1) + 1
    grid = np.linspace(start, stop, count)
    _, rate = site.elevation(bound.at(grid))
    from scipy.optimize import brentq  # here: a run without a ground site never needs it

    def rate_at(t: float) -> float:
        return float(site.elevation(bound.at([t]))[1][0])

    def above(t: float) -> float:
        return float(site.elevation(bound.at([t]))[0][0]) - floor

    # The extrema: the span's ends and every sign change of the rate.
    extrema = [start]
    for k in np.flatnonzero(np.sign(rate[:-1]) * np.sign(rate[1:]) < 0):
        extrema.append(brentq(rate_at, grid[k], grid[k + 1], xtol=1e-9, rtol=1e-15))
    extrema.append(stop)
    heights = [above(t) for t in extrema]
    intervals: list[tuple[float, float]] = []
    for (a, ha), (b, hb) in pairwise(zip(extrema, heights, strict=True)):
        # Between consecutive extrema the elevation is monotonic: at most one crossing.
        if ha >= 0.0 and hb >= 0.0:
            piece = (a, b)
        elif ha < 0.0 and hb < 0.0:
            continue
        else:
            crossing = brentq(above, a, b, xtol=1e-9, rtol=1e-15)
            piece = (crossing, b) if hb >= 0.0 else (a, crossing)
        if intervals and abs(intervals[-1][1] - piece[0]) <= 1e-9:
            intervals[-1] = (intervals[-1][0], piece[1])
        else:
            intervals.append(piece)
    return intervals
