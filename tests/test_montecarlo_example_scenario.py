"""The Monte Carlo example, scenarios/spinner_dispersions.toml, is checked and runs.

`attitude check` accepts it and describes its seven dispersions; its first samples,
evaluated in this process as a worker would, run to a row with every metric; their
smallest Sun angles on the star tracker differ by degrees, not tens (a degree of
attitude error and a few percent of inertia cannot move it further).
"""

from pathlib import Path

import numpy as np

from attitude.cli.main import main
from attitude.files.scenario_reader import load_scenario
from attitude.montecarlo.plan import Job, evaluate_batch, plan_montecarlo

EXAMPLE = Path(__file__).parents[1] / "scenarios" / "spinner_dispersions.toml"


def test_check_describes_the_dispersions(capsys):
    assert main(["check", str(EXAMPLE)]) == 0
    out = capsys.readouterr().out
    assert "dispersions 300 samples, seed 2027" in out
    assert "events[0].impulse_direction: normal σ 2 deg" in out


def test_the_first_samples_run_to_full_rows():
    mc = plan_montecarlo(load_scenario(EXAMPLE))
    job = Job.of(mc)
    result = evaluate_batch(job, 0, 2)
    assert [row["status"] for row in result.rows] == ["ok", "ok"]
    assert result.extremes.shape == (2, 3, 2, 200)
    for row in result.rows:
        assert set(mc.parameters + mc.metrics) <= set(row)
        assert 0.0 < row["eclipse_total_s"] < 3600.0
    nominal = evaluate_batch(job, 0, 0)  # no samples: an empty batch is fine
    assert nominal.rows == [] and nominal.extremes.shape == (0, 3, 2, 0)
    minima = [row["star_tracker_sun_angle_min_deg"] for row in result.rows]
    assert np.ptp(minima) < 10.0
