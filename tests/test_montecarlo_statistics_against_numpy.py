"""statistics.json and the Sun-angle envelopes against numpy on the table itself.

- Each metric's mean, standard deviation (ddof 1) and percentiles equal numpy's on the
  column of samples.parquet, over the samples that ran.
- The one-sided 99 % bounds: the rank r is the largest whose confidence, the binomial
  tail P(Binomial(n, 0.01) ≥ r) summed here term by term with exact integers, is at
  least 95 %; the bound is the r-th largest (smallest) value of the column.  Below 299
  samples there is none, and the confidence of the extreme value is 1 − 0.99ⁿ.
- The envelopes: every sample's Sun angle, recomputed in this process from its emitted
  document, reduced to its extremes in each time bin and rounded to 0.05°, gives per
  bin the percentiles numpy's inverted_cdf gives on those values.
"""

from fractions import Fraction
from math import comb

import numpy as np
import pytest
from montecarlo_scenarios import write_spinner

from attitude.files.scenario_reader import load_scenario, scenario_from_document
from attitude.montecarlo.dispersions import draw_sample
from attitude.montecarlo.metrics import ANGLE_STEP_DEG, sample_metrics
from attitude.montecarlo.plan import plan_montecarlo
from attitude.montecarlo.report import statistics
from attitude.montecarlo.simulation import simulate
from attitude.montecarlo.statistics import PERCENTILES, describe, order_statistic_rank
from attitude.report.plan import plan_run


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    path = write_spinner(tmp_path_factory.mktemp("job"), samples=24)
    return simulate(plan_montecarlo(load_scenario(path)), workers=2)


def _exact_confidence(n: int, r: int) -> Fraction:
    """P(Binomial(n, 1/100) ≥ r), in exact rationals."""
    p = Fraction(1, 100)
    return 1 - sum(comb(n, k) * p**k * (1 - p) ** (n - k) for k in range(r))


def test_metrics_statistics_equal_numpy_on_the_table(result):
    stats = statistics(result)
    ok = result.table[result.table["status"] == "ok"]
    assert len(ok) == 24
    checked = 0
    for name, entry in stats["metrics"].items():
        values = ok[name].to_numpy(float)
        values = values[np.isfinite(values)]
        assert entry["n"] == values.size
        if values.size < 2:
            continue
        assert entry["mean"] == np.mean(values)
        assert entry["std"] == np.std(values, ddof=1)
        assert entry["min"] == values.min() and entry["max"] == values.max()
        for p in PERCENTILES:
            assert entry["percentiles"][str(p)] == np.percentile(values, p)
        assert entry["upper_bound_99"]["value"] is None  # 24 samples: no 95 % bound
        assert entry["upper_bound_99"]["confidence"] == pytest.approx(1 - 0.99**24, rel=1e-12)
        checked += 1
    assert checked >= 20
    assert "star_tracker_sun_angle_min_deg" in stats["metrics"]
    assert stats["categories"]["segment1_motion"] == {"periodic": 24}


@pytest.mark.parametrize("n", [299, 300, 1000, 4321, 10000])
def test_order_statistic_rank_against_the_exact_binomial_tail(n):
    r, confidence = order_statistic_rank(n)
    assert _exact_confidence(n, r) >= Fraction(95, 100) > _exact_confidence(n, r + 1)
    assert confidence == pytest.approx(float(_exact_confidence(n, r)), rel=1e-9)


def test_bounds_are_the_order_statistics_of_the_column():
    values = np.random.default_rng(3).lognormal(size=1000)
    entry = describe(values)
    ordered = np.sort(values)
    r = entry["upper_bound_99"]["rank_from_top"]
    assert r == 5 and entry["lower_bound_99"]["rank_from_bottom"] == 5
    assert entry["upper_bound_99"]["value"] == ordered[-r]
    assert entry["lower_bound_99"]["value"] == ordered[r - 1]
    # The 99th percentile of this sample lies below its bound, the 1st above its bound.
    assert entry["upper_bound_99"]["value"] >= np.percentile(values, 99)
    assert entry["lower_bound_99"]["value"] <= np.percentile(values, 1)
    assert describe(values[:298])["upper_bound_99"]["value"] is None


def test_envelopes_equal_numpy_on_each_samples_recomputed_extremes(result):
    mc = result.plan
    seconds = mc.plan.scenario.output_seconds()
    bins = result.envelope.counts.shape[2]
    low = np.empty((24, 2, bins))
    high = np.empty((24, 2, bins))
    for k in range(24):
        sample = draw_sample(mc.dispersions, mc.loaded.document, k)
        loaded = scenario_from_document(mc.loaded.path, sample.document)
        _, angles = sample_metrics(plan_run(loaded.scenario, loaded.pointing))
        for b in range(bins):
            start, stop = (b * seconds.size) // bins, ((b + 1) * seconds.size) // bins
            low[k, :, b] = angles[:, start:stop].min(axis=1)
            high[k, :, b] = angles[:, start:stop].max(axis=1)
    steps = np.rint(np.stack([low, high], axis=2) / ANGLE_STEP_DEG)  # (samples, v, 2, bins)
    expected = np.percentile(steps, PERCENTILES, axis=0, method="inverted_cdf")
    got = result.envelope.percentiles_deg(PERCENTILES) / ANGLE_STEP_DEG
    assert np.array_equal(np.rint(got), expected)
