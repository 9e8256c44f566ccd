"""The eclipses and the Moon behind the Earth found once over a long span and cut to a
window (``orbit_intervals``, ``pointing_analysis(orbit=...)``: the envelope's windows
share them) against the search of that window alone; and an analysis asked for a few
extrema against the full analysis.

A window's own search finds each interval end to the interval precision, so the cut
intervals agree with it to twice that, with the same flags (starting before the
window, ending after it); the lit fraction's mean agrees to the quadrature's rounding,
also for windows whose ends fall inside a penumbra (integrated again over the part
within)."""

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from attitude import (
    BodyVector,
    InitialState,
    KeplerianOrbit,
    PointingSpec,
    Scenario,
    Spacecraft,
    pointing_analysis,
    propagate,
)
from attitude.pointing.search import orbit_intervals
from attitude.pointing.spec import interval_precision

EPOCH = "2025-05-01T10:00:00"
SPAN_S = 4 * 3600.0
WINDOW_S = 1800.0
KINDS = ("shadow", "umbra", "moon_hidden")


@pytest.fixture(scope="module")
def case():
    orbit = KeplerianOrbit(
        EPOCH,
        7_078_137.0,
        0.001,
        math.radians(98.2),
        math.radians(170.0),
        0.0,
        mean_anomaly=0.0,
        j2=True,
    )
    scenario = Scenario(
        "a slow tumbler on a sun-synchronous orbit",
        Spacecraft("box", [820.0, 1040.0, 610.0]),
        EPOCH,
        InitialState(Rotation.identity(), angular_velocity=[0.001, 0.002, -0.0015]),
        duration=SPAN_S,
        orbit=orbit,
    )
    spec = PointingSpec(
        body_vectors=[
            BodyVector("tracker", [0.0, -0.6, -0.8], math.radians(30.0), kind="star_tracker"),
            BodyVector("array", [0.0, 0.0, -1.0], kind="panel"),
        ],
        orbit=orbit,
    )
    trajectory = propagate(scenario)
    return trajectory, spec, orbit_intervals(trajectory, spec, 0.0, SPAN_S)


def _windows(timeline) -> list[float]:
    """Window starts: inside an umbra, inside a penumbra (the window's start and, for
    the one ending there, its end cut it), and at the span's start."""
    umbra = timeline.intervals["umbra"][1]
    penumbra = [piece for piece, _ in timeline.penumbra_unlit if not piece.starts_before]
    middle = 0.5 * (penumbra[1].start_s + penumbra[1].end_s)
    return [0.0, 0.5 * (umbra.start_s + umbra.end_s), middle, middle - WINDOW_S]


def test_cut_intervals_against_the_window_search(case):
    trajectory, spec, timeline = case
    precision = interval_precision(spec, SPAN_S)[0]
    assert all(timeline.intervals[kind] for kind in ("shadow", "umbra"))
    for start in _windows(timeline):
        stop = start + WINDOW_S
        cut = pointing_analysis(trajectory, spec, start, stop, orbit=timeline)
        alone = pointing_analysis(trajectory, spec, start, stop)
        for kind in KINDS:
            a, b = getattr(cut, kind), getattr(alone, kind)
            assert len(a) == len(b), (start, kind)
            for x, y in zip(a, b, strict=True):
                assert (x.starts_before, x.ends_after) == (y.starts_before, y.ends_after)
                assert abs(x.start_s - y.start_s) <= 2 * precision
                assert abs(x.end_s - y.end_s) <= 2 * precision
        assert cut.sunlit_fraction_mean == pytest.approx(alone.sunlit_fraction_mean, abs=1e-9)
        for x, y in zip(cut.vectors, alone.vectors, strict=True):
            assert len(x.sun_exclusion) == len(y.sun_exclusion)
            for i, j in zip(x.sun_exclusion, y.sun_exclusion, strict=True):
                assert abs(i.start_s - j.start_s) <= 2 * precision
                assert abs(i.end_s - j.end_s) <= 2 * precision


def test_a_window_outside_the_timeline_is_refused(case):
    trajectory, spec, _ = case
    short = orbit_intervals(trajectory, spec, 0.0, 600.0)
    with pytest.raises(ValueError, match="do not serve"):
        pointing_analysis(trajectory, spec, 0.0, 1200.0, orbit=short)


def test_a_few_extrema_against_the_full_analysis(case):
    trajectory, spec, timeline = case
    start = _windows(timeline)[2]
    full = pointing_analysis(trajectory, spec, start, start + WINDOW_S, orbit=timeline)
    few = pointing_analysis(
        trajectory, spec, start, start + WINDOW_S, orbit=timeline, extrema=[("array", "sun_angle")]
    )
    array_full, array_few = full.vectors[1], few.vectors[1]
    assert set(array_few.extrema) == {"sun_angle"}
    assert few.vectors[0].extrema == {}
    for got, want in zip(
        array_few.extrema["sun_angle"], array_full.extrema["sun_angle"], strict=True
    ):
        assert got.value == pytest.approx(want.value, abs=1e-9)
    assert array_few.mean_cos_incidence == pytest.approx(array_full.mean_cos_incidence, abs=1e-12)
    assert array_few.sun_visible == array_full.sun_visible
    assert np.isfinite(array_few.mean_cos_incidence)
