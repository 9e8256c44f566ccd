"""Statistics of a Monte Carlo table: percentiles, moments, and distribution-free bounds.

For each metric (a column of the per-sample table, over the samples that ran and gave
a finite value): the mean, the standard deviation (``ddof=1``), the extremes, the
percentiles :data:`PERCENTILES` (numpy's default, linear interpolation), and the
one-sided 99 % bounds from order statistics.

The bounds assume nothing about the distribution (Wilks, S. S., "Determination of
sample sizes for setting tolerance limits", Ann. Math. Statist. 12(1), 91-96, 1941,
doi:10.1214/aoms/1177731788).  For n independent samples of a continuous quantity
with p-quantile q_p, the r-th largest value X₍ₙ₋ᵣ₊₁₎ is at least q_p unless fewer
than r samples fall above q_p, so

    P(X₍ₙ₋ᵣ₊₁₎ ≥ q_p) = P(Binomial(n, 1 − p) ≥ r),

whatever the distribution.  The upper bound is the r-th largest value for the largest
r whose confidence is at least :data:`CONFIDENCE`; the lower bound is the r-th
smallest, the same way.  With p = 0.99 and 95 % confidence, n = 299 is the smallest
count for which the largest value will do (1 − 0.99²⁹⁹ = 0.9504); with 1,000 samples
it is the 5th largest (0.971), with 10,000 the 84th (0.954).  Below 299 samples no
order statistic reaches 95 %: the bound is given as null, with the confidence that
the extreme value does reach.

The percentile envelopes of the Sun angle over time come from histograms
(:func:`histogram_percentiles`): each worker reduces its samples to the extremes in
each time bin, quantized, and the histograms add up exactly in any order.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "CONFIDENCE",
    "COVERAGE",
    "PERCENTILES",
    "describe",
    "histogram_percentiles",
    "order_statistic_rank",
]

PERCENTILES = (1, 5, 50, 95, 99)
COVERAGE = 0.99
CONFIDENCE = 0.95


def order_statistic_rank(
    n: int, coverage: float = COVERAGE, confidence: float = CONFIDENCE
) -> tuple[int | None, float]:
    """(r, its confidence): the r-th largest of ``n`` samples bounds the ``coverage``
    quantile from above with that confidence, for the largest such r (the tightest
    bound); (None, the confidence of the largest sample) if even r = 1 falls short.
    By symmetry the r-th smallest bounds the 1 − coverage quantile from below."""
    sf, ppf = _binomial_sf_ppf()
    tail = 1.0 - coverage
    if n < 1:
        return None, 0.0
    if sf(0, n, tail) < confidence:
        return None, float(sf(0, n, tail))
    # sf(r - 1) = P(B ≥ r) falls as r grows: the first k with cdf(k) > 1 − confidence
    # fails, so r = k is the last that holds (checked on either side for rounding).
    r = max(1, int(ppf(1.0 - confidence, n, tail)))
    while r > 1 and sf(r - 1, n, tail) < confidence:
        r -= 1
    while r < n and sf(r, n, tail) >= confidence:
        r += 1
    return r, float(sf(r - 1, n, tail))


def _binomial_sf_ppf() -> tuple[Any, Any]:
    """The binomial law's survival function and quantile (k, n, p): the ufuncs that
    ``scipy.stats.binom`` evaluates (Boost's), taken from scipy.special without
    importing scipy.stats (about 1 s of a job's start); ``binom`` itself where a scipy
    does not have them."""
    try:
        from scipy.special import _ufuncs

        return _ufuncs._binom_sf, _ufuncs._binom_ppf
    except (ImportError, AttributeError):  # another scipy
        from scipy.stats import binom

        return binom.sf, binom.ppf


def _ordinal(r: int) -> str:
    suffix = "th" if 10 <= r % 100 <= 20 else {1: "st", 2: "nd", 3: "rd"}.get(r % 10, "th")
    return f"{r}{suffix}"


def describe(values: NDArray[np.float64]) -> dict[str, Any]:
    """The statistics of one metric (NaN and infinite values are left out and counted)."""
    values = np.asarray(values, dtype=float)
    finite = values[np.isfinite(values)]  # in sample order: the sums as numpy does them
    n = int(finite.size)
    entry: dict[str, Any] = {"n": n, "not_finite": int(values.size - n)}
    if n == 0:
        return entry
    entry.update(
        mean=float(np.mean(finite)),
        std=float(np.std(finite, ddof=1)) if n > 1 else None,
        min=float(np.min(finite)),
        max=float(np.max(finite)),
        percentiles={str(p): float(np.percentile(finite, p)) for p in PERCENTILES},
    )
    finite = np.sort(finite)
    r, confidence = order_statistic_rank(n)
    percent = f"{100 * COVERAGE:g} %"
    if r is None:
        note = (
            f"{n} samples: no order statistic bounds the {percent} quantile with "
            f"{100 * CONFIDENCE:g} % confidence (299 samples are needed); the extreme "
            f"value does with {100 * confidence:.1f} %"
        )
        entry["upper_bound_99"] = {"value": None, "confidence": confidence, "note": note}
        entry["lower_bound_99"] = {"value": None, "confidence": confidence, "note": note}
        return entry
    entry["upper_bound_99"] = {
        "value": float(finite[n - r]),
        "order_statistic": f"the {_ordinal(r)} largest of {n}",
        "rank_from_top": r,
        "confidence": confidence,
        "meaning": f"at least {percent} of cases lie at or below it, with this confidence",
    }
    entry["lower_bound_99"] = {
        "value": float(finite[r - 1]),
        "order_statistic": f"the {_ordinal(r)} smallest of {n}",
        "rank_from_bottom": r,
        "confidence": confidence,
        "meaning": f"at least {percent} of cases lie at or above it, with this confidence",
    }
    return entry


def histogram_percentiles(
    counts: NDArray[np.integer], percentiles: tuple[float, ...] = PERCENTILES
) -> NDArray[np.float64]:
    """Percentiles of histogrammed values, as bin indices: ``counts[..., a]`` is the
    number of values equal to a.  For each percentile p, the smallest a with at least
    ceil(n p / 100) values ≤ a (numpy's ``inverted_cdf`` on the values themselves);
    NaN where a histogram is empty.  Shape: ``(len(percentiles), *counts.shape[:-1])``."""
    cumulative = np.cumsum(counts, axis=-1)
    n = cumulative[..., -1]
    out = np.full((len(percentiles), *n.shape), np.nan)
    for i, p in enumerate(percentiles):
        need = np.maximum(1, np.ceil(n * (p / 100.0)))
        index = np.argmax(cumulative >= need[..., None], axis=-1).astype(float)
        out[i] = np.where(n > 0, index, np.nan)
    return out
