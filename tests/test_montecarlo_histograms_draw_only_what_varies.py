"""The Monte Carlo histograms draw a metric's spread only beyond its stated precision.

Interval ends are refined to ``interval_precision`` (1 ms in the example): two samples
with the same eclipses report totals that differ by root finding's noise, a fraction of
a millisecond.  ``histograms.png`` must not draw that noise as if the eclipse time
varied (it did: a histogram of ``eclipse_total_s`` spread over 0.3 ms).  A table built
here, with the example's plan, holds such noise beside metrics that do vary; the checks
are against the numbers put in.
"""

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from attitude.files.scenario_reader import load_scenario
from attitude.montecarlo.report import _histogram_columns, drawn_spread, stated_precision
from attitude.outputs.formats import OutputChoice
from attitude.report.plan import plan_run

EXAMPLE = Path(__file__).parents[1] / "scenarios" / "spinner_dispersions.toml"


@pytest.fixture(scope="module")
def mc():
    loaded = load_scenario(EXAMPLE)
    plan = plan_run(loaded.scenario, loaded.pointing, OutputChoice(("csv",)), horizon=False)
    metrics = [
        "eclipse_count",
        "eclipse_total_s",
        "umbra_total_s",
        "star_tracker_sun_exclusion_count",
        "star_tracker_sun_exclusion_total_s",
        "star_tracker_sun_exclusion_longest_s",
        "star_tracker_sun_angle_min_deg",
        "flip_count",
        "max_rate_deg_s",
    ]
    return SimpleNamespace(plan=plan, metrics=metrics, loaded=loaded)


def _table(rng, n=300):
    noise = rng.uniform(-4e-4, 4e-4, n)  # within one end's refinement (1 ms)
    return pd.DataFrame(
        {
            "status": ["ok"] * n,
            "eclipse_count": np.full(n, 2),
            "eclipse_total_s": 1382.1234 + noise,
            "umbra_total_s": 1337.5 + rng.uniform(-4e-4, 4e-4, n),
            "star_tracker_sun_exclusion_count": np.full(n, 3),
            # Varies for real: by seconds.
            "star_tracker_sun_exclusion_total_s": 120.0 + rng.normal(0.0, 5.0, n),
            "star_tracker_sun_exclusion_longest_s": 45.0 + rng.uniform(-3e-4, 3e-4, n),
            "star_tracker_sun_angle_min_deg": 30.0 + rng.normal(0.0, 1.0, n),
            "flip_count": np.zeros(n, dtype=int),
            "max_rate_deg_s": 30.0 + rng.normal(0.0, 0.2, n),
        }
    )


def test_noise_within_the_stated_precision_gets_no_histogram(mc):
    table = _table(np.random.default_rng(23))
    chosen = _histogram_columns(mc, table)
    assert "eclipse_total_s" not in chosen
    assert "umbra_total_s" not in chosen
    assert "star_tracker_sun_exclusion_longest_s" not in chosen
    assert "star_tracker_sun_exclusion_total_s" in chosen
    assert "star_tracker_sun_angle_min_deg" in chosen


def test_the_stated_precisions(mc):
    table = _table(np.random.default_rng(1))
    assert mc.plan.pointing.interval_precision_s == 1e-3
    assert stated_precision("eclipse_total_s", mc, table) == pytest.approx(2e-3)
    assert stated_precision("umbra_total_s", mc, table) == pytest.approx(2e-3)
    assert stated_precision("star_tracker_sun_exclusion_total_s", mc, table) == pytest.approx(3e-3)
    assert stated_precision("star_tracker_sun_exclusion_longest_s", mc, table) == 1e-3
    assert stated_precision("star_tracker_sun_angle_min_deg", mc, table) is None


def test_a_spread_is_drawn_rounded_to_its_precision():
    values = np.array([10.0004, 10.0011, 12.5002, np.nan])
    np.testing.assert_allclose(drawn_spread(values, 1e-3), [10.0, 10.001, 12.5])
    assert drawn_spread(np.array([5.0004, 5.0006]), 1e-3) is None  # one step apart
    assert drawn_spread(np.array([1.0, 1.0]), None) is None
    np.testing.assert_array_equal(drawn_spread(np.array([1.0, 2.0]), None), [1.0, 2.0])
