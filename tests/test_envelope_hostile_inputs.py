"""Bad ``[envelope]`` tables: `check` and `envelope` each exit 2 with one line naming
the file, the key and the value, before anything runs (one reading of the table:
attitude.envelope.plan.plan_envelope), and write nothing."""

import pytest
from cli_lines import said
from envelope_scenarios import EXAMPLE, with_envelope

from attitude import EnvelopeSettings, InputError
from attitude.cli.main import main

CASES = {
    "step_zero": ("every = 0.0\nwindow = 600.0", "envelope.every: must be positive"),
    "step_negative": ("every = -10.0\nwindow = 600.0", "envelope.every: must be positive"),
    "window_zero": ("every = 60.0\nwindow = 0.0", "envelope.window: the window after each"),
    "window_absurd": ("every = 60.0\nwindow = 1e12", "envelope.window: the window after each"),
    "window_nan": ("every = 60.0\nwindow = nan", "envelope.window: expected finite numbers"),
    "both_ways": (
        "every = 60.0\ntimes = [10.0]\nwindow = 600.0",
        "envelope.every: give the failure times as every",
    ),
    "neither": ("window = 600.0", "envelope.every: give the failure times as every"),
    "tau_before_epoch": (
        "times = [-5.0, 10.0]\nwindow = 600.0",
        "envelope.times: -5 s is outside the nominal timeline",
    ),
    "tau_after_timeline": (
        "times = [1e6]\nwindow = 600.0",
        "envelope.times: 1e+06 s is outside the nominal timeline",
    ),
    "times_text": ('times = ["noon"]\nwindow = 600.0', "envelope.times: expected"),
    "millions_of_failures": (
        "every = 1e-3\nwindow = 600.0",
        "envelope.every: 0.001 s over the 6600 s timeline is 6,600,001 failure times",
    ),
    "beyond_budget": (
        "every = 1.0\nwindow = 600000.0",
        "envelope.window: 6,601 failures of 600000 s each",
    ),
    "absurd_wheels": (
        'every = 600.0\nwindow = 600.0\nwheels = { case = "spinning", momentum = [0.0, 1e9, 0.0] }',
        "envelope.wheels.momentum",
    ),
    "wheels_case": (
        'every = 600.0\nwindow = 600.0\nwheels = { case = "free", momentum = [0.0, 1.0, 0.0] }',
        "envelope.wheels.case: expected one of locked, spinning",
    ),
    "threshold_above_one": (
        "every = 600.0\nwindow = 600.0\npower_threshold = 2.0",
        "envelope.power_threshold: a fraction of the panels' full power, in (0, 1], got 2.0",
    ),
    "misspelt_key": ("every = 600.0\nwindow = 600.0\nwindw = 5.0", "envelope.windw: unknown key"),
    "not_a_table": (None, "envelope: expected a table"),
}


@pytest.mark.parametrize("case", CASES)
@pytest.mark.parametrize("command", ["check", "envelope"])
def test_bad_envelope_exits_2_with_one_line(case, command, tmp_path, capsys):
    body, expected = CASES[case]
    if body is None:  # a top-level key, before the file's first table
        path = with_envelope(tmp_path, "")
        path.write_text("envelope = 5\n" + path.read_text())
    else:
        path = with_envelope(tmp_path, f"[envelope]\n{body}")
    out = tmp_path / "out"
    argv = [command, str(path), "--quiet"]
    if command == "envelope":
        argv += ["--out", str(out), "--workers", "1"]
    code = main(argv)
    err = said(capsys.readouterr().err)
    assert code == 2, err
    assert len(err) == 1, err
    assert err[0].startswith(f"attitude: error: eo.toml: {expected}"), err[0]
    assert not out.exists()


def test_a_scenario_without_laws_has_no_envelope(tmp_path, capsys):
    source = EXAMPLE.parent / "dzhanibekov_t_handle.toml"  # a free body throughout
    path = tmp_path / "free.toml"
    path.write_text(source.read_text() + "\n[envelope]\nevery = 1.0\nwindow = 10.0\n")
    code = main(["check", str(path), "--quiet"])
    err = said(capsys.readouterr().err)
    assert code == 2 and len(err) == 1, err
    assert "envelope: an envelope of control losses needs a nominal timeline" in err[0]


def test_settings_refused_in_python_name_their_key():
    with pytest.raises(InputError, match="window: the window after each loss"):
        EnvelopeSettings(window=-1.0, every=10.0)
    with pytest.raises(InputError, match="power_threshold"):
        EnvelopeSettings(window=10.0, every=10.0, power_threshold=0.0)
