"""The disk a Monte Carlo job or an envelope is checked against is within 2× of what
the writers write: never less, at most twice (issue 27; main at d285687 said
0.0051 GB for a 24-sample job that wrote 0.7 MB, and refused small disks needlessly).

The tables are a real job's rows (the spinner's samples, the example's failure
times), repeated to a thousand rows with their numbers redrawn (a relative
spread of a few tens of percent, as dispersed samples have: full-entropy floats,
which Parquet cannot shrink), written by the jobs' own writers; the checkpoint's
parts by the checkpoint itself, in batches as a job sends them.
"""

import copy

import numpy as np
import pandas
import pytest
from envelope_scenarios import with_envelope
from montecarlo_scenarios import write_spinner

from attitude import EnvelopeSettings, Wheels, load_scenario
from attitude.envelope.engine import EnvelopeResult
from attitude.envelope.engine import simulate as envelope_simulate
from attitude.envelope.plan import plan_envelope
from attitude.envelope.report import FOLDER_SIZE, write_report
from attitude.jobs.checkpoint import Checkpoint, batch_table
from attitude.montecarlo.plan import plan_montecarlo
from attitude.montecarlo.report import folder_size, write_montecarlo_report
from attitude.montecarlo.simulation import MonteCarloResult, simulate


def _grown(table: pandas.DataFrame, rows: int, index: str, seed: int = 1) -> pandas.DataFrame:
    """``table``'s rows repeated to ``rows``, numbered again, their floats redrawn."""
    grown = pandas.concat([table] * -(-rows // len(table)), ignore_index=True).iloc[:rows].copy()
    grown[index] = np.arange(rows)
    rng = np.random.default_rng(seed)
    for name in grown.columns:
        if grown[name].dtype.kind == "f" and name != index:
            grown[name] = grown[name] * rng.uniform(0.7, 1.3, rows)
    return grown


def _written(folder) -> int:
    return sum(p.stat().st_size for p in folder.rglob("*") if p.is_file())


def _checkpoint_written(tmp_path, table: pandas.DataFrame, index: str, batch: int) -> int:
    checkpoint = Checkpoint.open(
        tmp_path, "test", {}, len(table), "items", index, "test", False, print
    )
    for first in range(0, len(table), batch):
        checkpoint.add(batch_table(table.iloc[first : first + batch]), {"compute_s": 1.0})
    checkpoint.flush()
    return _written(tmp_path / ".attitude-checkpoint")


def _within_2x(estimate: int, written: int) -> None:
    assert written <= estimate <= 2 * written, (estimate, written, estimate / written)


@pytest.fixture(scope="module")
def montecarlo(tmp_path_factory):
    folder = tmp_path_factory.mktemp("mc")
    mc = plan_montecarlo(load_scenario(write_spinner(folder, samples=12)))
    return mc, simulate(mc, workers=1)


@pytest.mark.parametrize("rows", [12, 1000])
def test_the_montecarlo_estimate_against_its_writers(rows, montecarlo, tmp_path):
    mc, result = montecarlo
    table = _grown(result.table, rows, "sample")
    envelope = copy.copy(result.envelope)
    envelope.counts = result.envelope.counts * -(-rows // len(result.table))
    out = tmp_path / "out"
    write_montecarlo_report(
        MonteCarloResult(mc, table, envelope, result.nominal, result.execution), out
    )
    size = folder_size(mc)
    _within_2x(size.outputs_bytes(rows, len(mc.columns)), _written(out))

    extremes = np.random.default_rng(2).integers(0, 3600, (rows, size.checkpoint_row // 2))
    kept = table.assign(extremes=[row.astype(np.uint16).tobytes() for row in extremes])
    written = _checkpoint_written(tmp_path, kept, "sample", batch=max(1, rows // 300))
    _within_2x(size.checkpoint_bytes(rows, len(mc.columns)), written)


@pytest.fixture(scope="module")
def envelope(tmp_path_factory):
    folder = tmp_path_factory.mktemp("envelope")
    loaded = load_scenario(with_envelope(folder, "[envelope]\nevery = 600.0\nwindow = 300.0"))
    settings = EnvelopeSettings(
        window=300.0, times=(600.0, 1500.0, 3300.0), wheels=Wheels("locked", [0, 2, 0])
    )
    plan = plan_envelope(loaded, settings=settings)
    return plan, envelope_simulate(plan, workers=1)


@pytest.mark.parametrize("rows", [3, 1000])
def test_the_envelope_estimate_against_its_writers(rows, envelope, tmp_path):
    plan, result = envelope
    table = _grown(result.table, rows, "failure")
    out = tmp_path / "out"
    write_report(EnvelopeResult(plan, table, result.execution), out)
    _within_2x(FOLDER_SIZE.outputs_bytes(rows, len(plan.columns)), _written(out))
    written = _checkpoint_written(tmp_path, table, "failure", batch=max(1, rows // 300))
    _within_2x(FOLDER_SIZE.checkpoint_bytes(rows, len(plan.columns)), written)
