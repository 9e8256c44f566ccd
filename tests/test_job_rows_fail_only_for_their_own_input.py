"""A job's row says `failed` only for a reason of the sample's own input; the machine's
free memory and a bug of ours are never science rows (issue 27).

Against a real Dask cluster whose worker is a thread of this process (a `LocalCluster`
with `processes=False`, reached through its scheduler's address as an external one
is), so that what the test plants reaches the worker:

- the workers' host short of memory (`available_memory_bytes` says 244 MB on the
  worker threads): main at d285687 made samples `failed` with "244 MB is available"
  and exited 0, a table that depended on the machine; now the same table, to the last
  bit, as with all the memory there is (the nominal's memory is checked once, before
  the job);
- an exception no input explains in one sample (a ZeroDivisionError planted in its
  metrics): main made it a row "internal error: ..." and exited 0; now exit 3, one
  line naming the sample, no traceback, and the previous outputs untouched.  The same
  through the job run in this process (`--workers 1`, no cluster).
"""

import logging
import threading

import pytest
from cli_lines import said
from montecarlo_scenarios import write_spinner
from pandas.testing import assert_frame_equal

import attitude.montecarlo.plan as plan_module
import attitude.outputs.budget as budget
from attitude.cli.main import main
from attitude.files.scenario_reader import load_scenario
from attitude.montecarlo.plan import plan_montecarlo
from attitude.montecarlo.simulation import simulate


@pytest.fixture(scope="module")
def threaded_cluster():
    """A scheduler and one worker thread in this process: (the scheduler's address)."""
    from distributed import LocalCluster

    with LocalCluster(
        n_workers=1,
        threads_per_worker=1,
        processes=False,
        protocol="tcp",
        host="127.0.0.1",
        dashboard_address="127.0.0.1:0",
        silence_logs=logging.CRITICAL,
    ) as cluster:
        yield cluster.scheduler_address


def _on_a_worker() -> bool:
    return threading.current_thread() is not threading.main_thread()


def test_a_host_short_of_memory_changes_no_row(tmp_path, monkeypatch, threaded_cluster):
    mc = plan_montecarlo(load_scenario(write_spinner(tmp_path, samples=4)))
    plenty = simulate(mc, workers=1, batch_size=2).table
    real = budget.available_memory_bytes
    monkeypatch.setattr(
        budget, "available_memory_bytes", lambda: 244e6 if _on_a_worker() else real()
    )
    short = simulate(mc, scheduler=threaded_cluster, batch_size=2).table
    assert (short["status"] == "ok").all(), short["error"].tolist()
    assert_frame_equal(short, plenty, check_exact=True)


def _plant_a_bug(monkeypatch, on_worker_thread: bool) -> None:
    """Sample metrics that raise ZeroDivisionError on their third call (sample 2)."""
    real = plan_module.sample_metrics
    calls = []

    def metrics(plan):
        if _on_a_worker() == on_worker_thread:
            calls.append(1)
            if len(calls) == 3:
                raise ZeroDivisionError("planted")
        return real(plan)

    monkeypatch.setattr(plan_module, "sample_metrics", metrics)


@pytest.mark.parametrize("where", ["scheduler", "this process"])
def test_a_bug_in_a_sample_is_exit_3_naming_it_and_no_row(
    where, tmp_path, capsys, monkeypatch, threaded_cluster
):
    scenario = write_spinner(tmp_path, samples=4)
    out = tmp_path / "results"
    assert main(["montecarlo", str(scenario), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    capsys.readouterr()
    _plant_a_bug(monkeypatch, on_worker_thread=where == "scheduler")
    options = ["--scheduler", threaded_cluster] if where == "scheduler" else ["--workers", "1"]
    argv = ["montecarlo", str(scenario), "--out", str(out), "--batch-size", "1", "--quiet"]
    code = main([*argv, *options])
    err = capsys.readouterr().err
    assert code == 3, err
    lines = said(err)
    assert len(lines) == 1 and "Traceback" not in err, err
    assert lines[0].startswith(
        "attitude: error: internal error: sample 2: ZeroDivisionError: planted (a bug"
    ), lines[0]
    # The samples before it are kept for --resume, the previous outputs untouched.
    assert lines[0].endswith("the same command with --resume continues the job"), lines[0]
    assert {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()} == before
