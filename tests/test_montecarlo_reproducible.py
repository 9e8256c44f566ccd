"""The same seed gives the same table whatever the number of workers and the batch size.

Each sample draws from streams of its own, derived from (seed, sample, key): the table
of a job on one worker in one batch is the table of the same job on two workers in
batches of five, to the last bit, and each row is the one that sample gives when it is
evaluated alone in this process.  A different seed gives a different table (so the
comparison can fail).
"""

import numpy as np
from montecarlo_scenarios import write_spinner
from pandas.testing import assert_frame_equal

from attitude.files.scenario_reader import load_scenario
from attitude.montecarlo.plan import Job, evaluate_batch, plan_montecarlo
from attitude.montecarlo.simulation import simulate


def test_same_seed_same_table_on_1_and_2_workers_and_any_batch_size(tmp_path):
    mc = plan_montecarlo(load_scenario(write_spinner(tmp_path, samples=11)))
    one = simulate(mc, workers=1, batch_size=11)
    two = simulate(mc, workers=2, batch_size=5)
    assert one.execution["tasks"] == 1 and two.execution["tasks"] == 3
    assert (one.table["status"] == "ok").all()
    assert_frame_equal(one.table, two.table, check_exact=True)
    assert np.array_equal(one.envelope.counts, two.envelope.counts)

    # Sample 7 alone, in this process, is row 7.
    job = Job(mc.loaded.path, mc.loaded.document, mc.dispersions, mc.parameters, mc.metrics, 2)
    alone = evaluate_batch(job, 7, 8).rows[0]
    row = one.table.iloc[7]
    for name in mc.parameters + mc.metrics:
        assert row[name] == alone[name] or (np.isnan(row[name]) and np.isnan(alone[name])), name

    other = plan_montecarlo(load_scenario(write_spinner(tmp_path, samples=11)), seed=8)
    different = evaluate_batch(
        Job(mc.loaded.path, mc.loaded.document, other.dispersions, mc.parameters, mc.metrics, 2),
        7,
        8,
    ).rows[0]
    assert (
        different["initial_state.attitude_error_x_deg"]
        != alone["initial_state.attitude_error_x_deg"]
    )
