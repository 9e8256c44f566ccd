"""A long job says what it is doing and how long it takes (issue 27).

- `attitude check` of a Monte Carlo file and of an envelope gives the job's time: a
  sample or a failure timed now, times their count, over the cores (main at d285687
  gave none; `check` answers within its budget: an item not timed within it is said
  so).
- The envelope after its bar: main went silent from the bar's end to `done` (for a
  year of failure times, minutes of CSV and of the figure's legend searching 200 000
  points for the emptiest corner); now a line for each step of the writing.
"""

import re

from cli_lines import progress_lines
from envelope_scenarios import with_envelope
from montecarlo_scenarios import write_spinner

from attitude.cli.main import main

TIME = re.compile(
    r"^  time        (about \S+ (s|min|h) of CPU \(\S+ s a (sample|failure), timed now\), about "
    r"\S+ (s|min|h) on this machine's \d+ cores?|not timed: a (sample|failure) took more than)"
)


def test_check_of_a_montecarlo_job_gives_its_time(tmp_path, capsys):
    assert main(["check", str(write_spinner(tmp_path, samples=300)), "--quiet"]) == 0
    lines = [line for line in capsys.readouterr().out.splitlines() if line.startswith("  time")]
    assert len(lines) == 1 and TIME.match(lines[0]), lines
    assert " a sample, timed now" in lines[0] or "a sample took more than" in lines[0]


def test_the_envelope_says_each_step_after_its_bar_and_check_gives_its_time(tmp_path, capsys):
    table = (
        "[envelope]\ntimes = [600.0, 2400.0]\nwindow = 300.0\n"
        'wheels = { case = "locked", momentum = [0.0, 2.0, 0.0] }'
    )
    scenario = with_envelope(tmp_path, table)
    assert main(["check", str(scenario), "--quiet"]) == 0
    lines = [line for line in capsys.readouterr().out.splitlines() if line.startswith("  time")]
    assert len(lines) == 1 and TIME.match(lines[0]), lines

    assert main(["envelope", str(scenario), "--out", str(tmp_path / "out"), "--workers", "1"]) == 0
    err = capsys.readouterr().err
    after = err.split("] 2/2 failures", 1)[1]
    stages = [line.split("] ", 1)[1] for line in progress_lines(after)]
    assert stages[:4] == [
        "writing envelope.parquet and envelope.csv (2 rows of 21 columns)",
        "the worst failure times (summary.json)",
        "drawing the metrics against the failure time (2 failure times)",
        "writing report.html",
    ], stages
    assert stages[4].startswith("done: "), stages
