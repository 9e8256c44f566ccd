"""`check` and `run` say on stderr what they are doing from their first second, on a
clock that starts with their process.

`check` used to print nothing until it ended, and `run` nothing until its planning
was done (150 s for a one-day torqued CubeSat on a loaded machine), its clock started
then, so that `done` stated less than the wall time.  Read against the kernel's own
record of when the process started (psutil's create_time): each line's time is that
process's age when it was written, no more (never ahead of the kernel's clock), and
not a planning's length less (the last line, `done`, within a second of the age at
which it was read).  The stages come in the order they are done, the planning's
before the sampling; `--quiet` says nothing.
"""

import re
import subprocess
import sys
import time
from pathlib import Path

import psutil
from signal_dispositions import defaults

ROOT = Path(__file__).parents[1]
SCENARIO = ROOT / "scenarios" / "tumbler_gravity_gradient_burn.toml"  # seconds of planning
LINE = re.compile(r"^\[ *(\d+\.\d) s\] (.*)$")


def _command(*args: str) -> tuple[list[tuple[float, float, str]], str, int]:
    """Run ``attitude ARGS``: its progress lines as (age of the process when read,
    time the line states, text), its stdout, its exit status."""
    process = subprocess.Popen(
        [sys.executable, "-m", "attitude", *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=defaults,
    )
    created = psutil.Process(process.pid).create_time()
    lines = []
    for line in process.stderr:
        age = time.time() - created
        found = LINE.match(line.rstrip("\n"))
        assert found, line  # nothing but progress lines
        lines.append((age, float(found.group(1)), found.group(2)))
    out = process.stdout.read()
    return lines, out, process.wait(timeout=300)


def _stages(lines) -> list[str]:
    return [text.split(" ")[0] for _, _, text in lines]


def _on_the_process_clock(lines) -> None:
    for age, stated, text in lines:
        assert stated <= age + 0.15, (stated, age, text)  # 0.1 s rounding, 10 ms ticks
    age, stated, text = lines[-1]
    assert stated >= age - 1.0, (stated, age, text)  # not a planning's length short


def test_check_says_each_stage_as_it_starts():
    lines, out, code = _command("check", str(SCENARIO))
    assert code == 0 and ": OK" in out
    stages = _stages(lines)
    assert stages[0] == "reading" and lines[0][1] < lines[-1][1]
    expected = ["reading", "propagating", "analysing", "checking", "choosing"]
    assert [s for s in stages if s in expected] == expected, stages
    # The step for the accuracy is chosen on the run's error estimate, while propagating.
    propagating = next(text for _, _, text in lines if text.startswith("propagating"))
    assert "error estimate" in propagating and "1e-06 rad" in propagating, propagating
    _on_the_process_clock(lines)


def test_run_says_its_planning_before_it_samples_and_done_states_the_wall_time(tmp_path):
    out = tmp_path / "out"
    lines, _, code = _command("run", str(SCENARIO), "--out", str(out), "--formats", "csv")
    assert code == 0 and (out / "timeseries.csv").is_file()
    stages = _stages(lines)
    assert stages[0] == "reading" and stages[-1] == "done:", stages
    assert stages.index("propagating") < stages.index("analysing") < stages.index("sampling")
    _on_the_process_clock(lines)


def test_quiet_says_nothing(tmp_path):
    lines, out, code = _command("check", str(SCENARIO), "--quiet")
    assert code == 0 and ": OK" in out and lines == []
