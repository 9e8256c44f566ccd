"""A Monte Carlo or envelope job whose table (CSV and Parquet), plots and page would
not fit on the disk of ``--out`` is refused before anything runs: exit 2, one line
naming ``--out`` and the sizes, nothing written (one rule for both jobs:
attitude.outputs.budget.check_table_fits)."""

from collections import namedtuple
from pathlib import Path

import pytest
from cli_lines import said
from envelope_scenarios import EXAMPLE

from attitude.cli.main import main

ROOT = Path(__file__).parents[1]
Usage = namedtuple("Usage", "total used free")


@pytest.mark.parametrize(
    ("argv", "what"),
    [
        (["montecarlo", str(ROOT / "scenarios" / "spinner_dispersions.toml")], "samples"),
        (["envelope", str(EXAMPLE)], "failures"),
    ],
    ids=["montecarlo", "envelope"],
)
def test_a_full_disk_refuses_the_job_and_writes_nothing(argv, what, tmp_path, capsys, monkeypatch):
    import attitude.outputs.budget as budget

    monkeypatch.setattr(budget.shutil, "disk_usage", lambda path: Usage(10**6, 10**6, 1000))
    out = tmp_path / "out"
    code = main([*argv, "--out", str(out), "--quiet"])
    lines = said(capsys.readouterr().err)
    assert code == 2, lines
    assert len(lines) == 1, lines
    assert f"--out: {out}: the job's " in lines[0] and f" {what} would take about " in lines[0]
    assert "(the outputs " in lines[0] and "and its checkpoint while it runs)" in lines[0]
    assert lines[0].endswith(("and its disk has 1 kB free", "another disk")), lines[0]
    assert not out.exists()
