"""The pointing searches of many windows found together (``pointing_analyses``: their
torque-free searches as one set of arrays, ``free_search.search_free_many``) against
each window searched alone (``pointing_analysis``): the same analyses, bit for bit.

The windows are the envelope's (the rigid body after a control loss at each τ, an
hour, every extremum of every body vector asked: the angles to the Sun, the Moon and
nadir, the limb angle, the incidence, so that Newton's steps, golden-section search
and the lit fraction in the penumbra are all exercised), in and out of the Earth's
shadow, with a torqued window (spinning wheels: searched on the grid, alone) among
them.  Each window's nodes, points and decisions are its own, so nothing may differ,
not even in the last bit.
"""

import functools
import math

import numpy as np
import pytest

from attitude import EnvelopeSettings, Wheels, load_scenario
from attitude.envelope.failure import _surroundings, motion_after
from attitude.envelope.plan import make_job, plan_envelope
from attitude.pointing.search import pointing_analyses, pointing_analysis

SCENARIO = "scenarios/eo_envelope.toml"
TAUS = (0.0, 10.0, 450.0, 1300.0, 2100.0, 2400.0, 3000.0, 3900.0, 4800.0)


@functools.cache
def _job(case: str):
    settings = EnvelopeSettings(
        window=3600.0, times=TAUS, wheels=Wheels(case, [0.0, 2.0, 0.0]), power_threshold=0.3
    )
    return make_job(plan_envelope(load_scenario(SCENARIO), settings=settings))[0]


def _windows(job, ks):
    trajectories = [motion_after(job, k) for k in ks]
    spans = [(float(job.seconds[k]), float(job.seconds[k]) + job.window) for k in ks]
    return trajectories, spans, _surroundings(job, trajectories[0])


def _same(a, b) -> bool:
    if isinstance(a, float) and math.isnan(a):
        return isinstance(b, float) and math.isnan(b)
    return a == b


def _assert_same(together, alone):
    assert together.shadow == alone.shadow and together.umbra == alone.umbra
    assert together.moon_hidden == alone.moon_hidden
    assert _same(together.sunlit_fraction_mean, alone.sunlit_fraction_mean)
    assert len(together.vectors) == len(alone.vectors)
    for t, a in zip(together.vectors, alone.vectors, strict=True):
        for kind in ("sun_visible", "sun_exclusion", "moon_exclusion", "earth_limb_exclusion"):
            assert getattr(t, kind) == getattr(a, kind), (t.vector.name, kind)
        assert t.blinded == a.blinded
        assert _same(t.mean_cos_incidence, a.mean_cos_incidence), t.vector.name
        assert t.extrema == a.extrema, t.vector.name


@pytest.mark.parametrize("every", [None, [("solar_array", "sun_angle")]])
def test_windows_together_against_each_alone(every):
    job = _job("locked")
    ks = list(range(job.count))
    trajectories, spans, shared = _windows(job, ks)
    together = pointing_analyses(
        trajectories, job.spec, spans, surroundings=shared, orbit=job.orbit, extrema=every
    )
    for trajectory, (a, b), found in zip(trajectories, spans, together, strict=True):
        alone = pointing_analysis(
            trajectory, job.spec, a, b, surroundings=shared, orbit=job.orbit, extrema=every
        )
        _assert_same(found, alone)
    # The windows cover the shadow and the light: else the comparison would be idle.
    assert any(found.shadow for found in together)
    assert any(not found.shadow for found in together)


def test_a_torqued_window_among_them_is_searched_alone():
    locked, spinning = _job("locked"), _job("spinning")
    trajectories, spans, shared = _windows(locked, [1, 2])
    torqued, torqued_spans, _ = _windows(spinning, [3])
    mixed = [trajectories[0], torqued[0], trajectories[1]]
    mixed_spans = [spans[0], torqued_spans[0], spans[1]]
    found = pointing_analyses(
        mixed, locked.spec, mixed_spans, surroundings=shared, orbit=locked.orbit
    )
    for trajectory, (a, b), analysis in zip(mixed, mixed_spans, found, strict=True):
        alone = pointing_analysis(
            trajectory, locked.spec, a, b, surroundings=shared, orbit=locked.orbit
        )
        _assert_same(analysis, alone)
    assert np.isfinite(found[1].vectors[0].mean_cos_incidence)
