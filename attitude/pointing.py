"""Pointing: where the Sun, the Moon and the Earth fall on the spacecraft's body vectors.

The layer's names, importable from here; each lives in the module that holds its part:

- :mod:`attitude.pointing_spec`: what a scenario asks (:class:`BodyVector` with its
  Sun, Moon and Earth-limb constraints; :class:`PointingSpec` with the orbit, the
  interval precision, the limb's atmosphere, the LVLH Euler sequence).
- :mod:`attitude.surroundings`: the Sun, the Moon and the Earth seen from the
  spacecraft at any times, and the angles of a direction from them; both the samples
  and the search take their values from it.
- :mod:`attitude.pointing_sampling`: :func:`pointing_samples`, everything the time
  series needs at the times asked, nothing kept between calls (a stream asks chunk
  by chunk).
- :mod:`attitude.pointing_search`: :func:`pointing_analysis`, every interval and
  extremum over a span on the exact motion, its search grid, and
  :func:`check_pointing`, what a run checks before anything is sampled.

Here too: :func:`undersampling_note`, the note a run gives when its output step is
coarse for the motion (the intervals and extrema do not depend on it).

**Where the spacecraft is**: on an orbit (:class:`attitude.orbit.Orbit`: a TLE, an
OEM file, Keplerian elements), or at the Earth's centre when none is given (then only
the Sun and Moon directions are computed: no eclipse, nadir or limb).
"""

from __future__ import annotations

import math

from attitude.pointing_sampling import PointingSamples, VectorSamples, pointing_samples
from attitude.pointing_search import (
    CHUNK_POINTS,
    EXTREMA,
    MAX_SEARCH_POINTS,
    PointingAnalysis,
    SearchGrid,
    VectorAnalysis,
    check_pointing,
    pointing_analysis,
    search_grid,
)
from attitude.pointing_spec import (
    KINDS,
    BodyVector,
    PointingSpec,
    describe_lines,
    interval_precision,
)
from attitude.surroundings import SunMoonEarth, Surroundings
from attitude.trajectory import Trajectory

__all__ = [
    "CHUNK_POINTS",
    "EXTREMA",
    "KINDS",
    "MAX_SEARCH_POINTS",
    "BodyVector",
    "PointingAnalysis",
    "PointingSamples",
    "PointingSpec",
    "SearchGrid",
    "SunMoonEarth",
    "Surroundings",
    "VectorAnalysis",
    "VectorSamples",
    "check_pointing",
    "describe_lines",
    "interval_precision",
    "pointing_analysis",
    "pointing_samples",
    "search_grid",
    "undersampling_note",
]


def undersampling_note(trajectory: Trajectory, motion) -> str | None:
    """One line when the output step is more than a tenth of the shortest period of
    the motion in any segment (``motion``: :func:`attitude.motion_analysis.analyze`),
    naming the step and the period; None otherwise."""
    scenario = trajectory.scenario
    worst = None
    for index, item in enumerate(motion):
        if item.end_s < scenario.start_s or item.start_s > scenario.stop_s:
            continue
        periods = {
            "body period": item.period_s,
            "spin period": item.spin_period_s,
            "nutation period": item.nutation_period_s,
            "precession period": item.precession_period_s,
            "flip period": item.flip_period_s,
        }
        for name, period in periods.items():
            if period is not None and math.isfinite(period) and period > 0.0:
                if worst is None or period < worst[0]:
                    worst = (period, name, index)
    if worst is None or scenario.step_s <= 0.1 * worst[0]:
        return None
    period, name, index = worst
    return (
        f"output.step: {scenario.step_s:.6g} s is more than a tenth of the {period:.6g} s "
        f"{name} of segment {index}: the time series undersamples the motion (extrema and "
        "intervals are found on the exact motion regardless)"
    )
