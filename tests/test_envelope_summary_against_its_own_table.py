"""The envelope's summary (``worst_per_metric``) against the table it summarizes, and
the power fraction within [0, 1].

The failures are those of the example's charging mode (the Sun law with the array on
the Sun, where the array's least Sun angle is 0 at every τ but the ones in the
Earth's shadow) and its imaging mode before, with locked wheels and a window too short
for any flip or any power loss in sunlight:

- a panel's least Sun angle is best at 0 (the panel square to the Sun): its worst τ
  is where it is greatest, not where it is 0, as the summary said;
- a metric that is ``inf`` (not within the window: ``null`` in summary.json) at every τ
  has no worst τ: ``tau_s`` and ``value`` are null, where the summary named the first τ;
- ``power_at_loss`` was 1.0000000000000004 with the array square to the Sun (the
  cosine of two unit vectors, rounded): a fraction is within [0, 1].
"""

import functools
import json

import numpy as np
import pandas

from attitude import EnvelopeSettings, Wheels, load_scenario
from attitude.envelope.engine import EnvelopeResult
from attitude.envelope.failure import evaluate_batch
from attitude.envelope.plan import make_job, plan_envelope
from attitude.envelope.report import _least_is_worst, summary
from attitude.report.summaries import to_json

SCENARIO = "scenarios/eo_envelope.toml"
TAUS = (2400.0, 2700.0, 3300.0, 3500.0, 3700.0, 4300.0, 4400.0, 4700.0)


@functools.cache
def _result() -> EnvelopeResult:
    settings = EnvelopeSettings(
        window=60.0, times=TAUS, wheels=Wheels("locked", [0.0, 0.0, 0.0]), power_threshold=0.3
    )
    plan = plan_envelope(load_scenario(SCENARIO), settings=settings)
    job, epochs, modes = make_job(plan)
    rows = evaluate_batch(job, 0, job.count).rows
    for row in rows:
        row["epoch_utc"], row["mode"] = epochs[row["failure"]], modes[row["failure"]]
    table = pandas.DataFrame(rows, columns=plan.columns)
    execution = {"scheduler": "in process", "compute_s": 0.0, "wall_s": 0.0}
    return EnvelopeResult(plan, table, execution)


def test_each_metrics_worst_is_the_worst_of_its_column():
    result = _result()
    table = result.table
    assert (table["status"] == "ok").all()
    stated = json.loads(json.dumps(summary(result)))["worst_per_metric"]
    for name, entry in stated.items():
        column = table[name].to_numpy(dtype=float)
        known = column[np.isfinite(column)]
        if known.size == 0:
            assert entry == {"tau_s": None, "value": None}, name
            continue
        worst = known.min() if _least_is_worst(name) else known.max()
        assert entry["value"] == worst, name
        first = table["tau_s"][column == worst].min()  # the earliest of ties
        assert entry["tau_s"] == first, name


def test_a_panels_worst_is_the_sun_furthest_from_it():
    result = _result()
    angles = result.table["solar_array_least_sun_angle_deg"].to_numpy(dtype=float)
    assert angles.min() < 1e-9 and angles.max() > 10.0  # square to the Sun, and not
    entry = summary(result)["worst_per_metric"]["solar_array_least_sun_angle_deg"]
    assert entry["value"] == angles.max()


def test_a_metric_not_within_the_window_at_any_tau_names_no_tau():
    result = _result()
    assert np.isinf(result.table["first_flip_s"].to_numpy(dtype=float)).all()
    stated = to_json(summary(result))["worst_per_metric"]
    assert stated["first_flip_s"] == {"tau_s": None, "value": None}


def test_the_power_fraction_is_within_zero_and_one():
    table = _result().table
    for name in ("power_at_loss", "power_mean"):
        values = table[name].to_numpy(dtype=float)
        assert np.all((values >= 0.0) & (values <= 1.0)), (name, values.tolist())
    assert table["power_at_loss"].max() == 1.0  # the array square to the Sun, in light
