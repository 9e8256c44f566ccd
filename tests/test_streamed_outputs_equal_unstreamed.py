"""A run streamed in chunks writes what one chunk over the whole grid writes.

The reference is the same run with a single chunk: the grid evaluated at once, as
before streaming.  Streamed with chunks of 100 epochs (the thruster pulse falls on a
chunk's first epoch), 7 (it falls inside one) and 1 (every epoch is a chunk), the
time series (CSV and Parquet) and the AEM are equal byte for byte (but for the AEM's
creation date), and the summary and the intervals are the same bytes: the pointing's
intervals and extrema are searched on the exact motion over the whole span, whatever
the output grid's chunks.
"""

import json
import re
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from attitude.files.scenario_reader import load_scenario
from attitude.outputs.formats import OutputChoice
from attitude.report.plan import plan_run
from attitude.report.run import write_report

ROOT = Path(__file__).parents[1]


def _spinner(tmp_path: Path) -> Path:
    text = (ROOT / "scenarios" / "spinner_thruster_pulse.toml").read_text()
    for pattern, value in (
        (r"(?m)^duration = .*$", "duration = 300.0"),
        (r"(?m)^step = .*$", "step = 1.0"),
        (r"(?m)^offset = .*$", "offset = 100.0"),
    ):
        text, count = re.subn(pattern, value, text, count=1)
        assert count == 1
    path = tmp_path / "spinner.toml"
    path.write_text(text)
    return path


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("streamed")
    loaded = load_scenario(_spinner(folder))
    outputs = OutputChoice(("csv", "parquet", "aem", "report"))
    made = {}
    for chunk in (10**9, 100, 7, 1):
        out = folder / f"chunk-{chunk}"
        plan = plan_run(loaded.scenario, loaded.pointing, outputs)
        write_report(
            loaded.scenario, out, loaded.pointing, "spinner.toml", plan=plan, chunk_samples=chunk
        )
        made[chunk] = out
    return made


def _without_creation_date(path: Path) -> str:
    return re.sub(r"(?m)^CREATION_DATE = .*$", "", path.read_text())


@pytest.mark.parametrize("chunk", [100, 7, 1])
def test_the_time_series_and_the_aem_are_the_same_bytes(runs, chunk):
    whole, streamed = runs[10**9], runs[chunk]
    assert (streamed / "timeseries.csv").read_bytes() == (whole / "timeseries.csv").read_bytes()
    table, reference = (pq.read_table(p / "timeseries.parquet") for p in (streamed, whole))
    assert table.equals(reference) and table.schema.metadata == reference.schema.metadata
    assert _without_creation_date(streamed / "attitude.aem") == _without_creation_date(
        whole / "attitude.aem"
    )


def _intervals(path: Path) -> list[tuple[str, str, float, float]]:
    rows = []
    for line in path.read_text().splitlines():
        if line.startswith(("#", "kind,")):
            continue
        kind, vector, _, _, start, end, *_ = line.split(",")
        rows.append((kind, vector, float(start), float(end)))
    return rows


@pytest.mark.parametrize("chunk", [100, 7, 1])
def test_the_summary_and_the_intervals_are_the_same(runs, chunk):
    whole, streamed = runs[10**9], runs[chunk]
    a = json.loads((whole / "summary.json").read_text())
    b = json.loads((streamed / "summary.json").read_text())
    assert a == b
    assert len(_intervals(whole / "intervals.csv")) > 10
    assert (streamed / "intervals.csv").read_bytes() == (whole / "intervals.csv").read_bytes()


def test_the_grid_in_chunks_is_the_grid(tmp_path):
    """Scenario.output_seconds(first, stop), chunk by chunk, gives the whole grid's
    values, the odd stop included; the whole grid is the definition's: start, then the
    step (to 1e-12 of it), the last gap no longer than a step, stop last, and as many
    epochs as output_count counts without building them."""
    text = (ROOT / "scenarios" / "boom_deployment.toml").read_text()
    text = re.sub(r"(?m)^step = .*$", "step = 0.37", text)
    path = Path(__file__).parent / "hostile" / "rest.toml"
    for source in (text, path.read_text()):
        tmp = tmp_path / "grid.toml"
        tmp.write_text(source)
        scenario = load_scenario(tmp).scenario
        whole = scenario.output_seconds()
        assert whole.size == scenario.output_count()
        assert whole[0] == scenario.start_s
        assert abs(whole[-1] - scenario.stop_s) <= 1e-9 * scenario.step_s
        gaps = np.diff(whole)
        assert np.allclose(gaps[:-1], scenario.step_s, rtol=1e-12, atol=0.0)
        assert 0.0 < gaps[-1] <= scenario.step_s * (1 + 1e-12)
        for chunk in (1, 3, 1000, whole.size):
            pieces = [
                scenario.output_seconds(first, first + chunk)
                for first in range(0, whole.size, chunk)
            ]
            assert np.array_equal(np.concatenate(pieces), whole)
