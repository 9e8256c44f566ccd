"""The command line tunes Python's garbage collector only in its own process.

``attitude ...`` (``main()`` reading the process's own arguments) collects less often
and freezes what is left before its exit (``attitude.cli.main``); ``main([...])``
called from a Python session must leave that session's collector as it found it:
the same thresholds and nothing frozen.  Compared against ``gc``'s own state before
the call, and, for the command, against the interpreter's defaults in a fresh process.
"""

import gc
import json
import subprocess
import sys
from pathlib import Path

from attitude.cli.main import main

ROOT = Path(__file__).parents[1]
SCENARIO = ROOT / "scenarios" / "dzhanibekov_t_handle.toml"


def test_main_called_from_a_session_leaves_its_collector_alone(capsys):
    thresholds, frozen = gc.get_threshold(), gc.get_freeze_count()
    assert main(["check", str(SCENARIO), "--quiet"]) == 0
    assert gc.get_threshold() == thresholds
    assert gc.get_freeze_count() == frozen
    assert gc.isenabled()


def test_the_command_collects_less_and_freezes_before_its_exit():
    code = (
        "import gc, json, sys\n"
        "default = gc.get_threshold()\n"
        "from attitude.cli.main import main\n"
        f"sys.argv = ['attitude', 'check', {str(SCENARIO)!r}, '--quiet']\n"
        "status = main()\n"
        "print(json.dumps([status, default, gc.get_threshold(), gc.get_freeze_count(),"
        " gc.isenabled()]))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True
    )
    last = done.stdout.splitlines()[-1]  # after what `check` prints
    status, default, (young, middle, old), frozen, enabled = json.loads(last)
    assert status == 0
    assert [young, middle] == default[:2]  # the young generations as Python has them
    assert old == 100 and old > default[2]  # full collections rarer than Python's 10
    assert frozen > 0 and enabled  # what was left frozen before the exit; still collecting
