"""Bad [dispersions] tables and options: exit 2 and one line naming the file, the key
and the value, the same from `check`, `run` and `montecarlo`, before anything runs.

`check` and `run` read the table through the path `montecarlo` uses
(attitude.montecarlo.job.plan_montecarlo), so what one refuses, all refuse.
"""

import pytest
from cli_lines import said
from montecarlo_scenarios import SPINNER

from attitude.cli.main import main

GOOD = """
[dispersions]
seed = 7
samples = 10
"""

# name: (text after [dispersions] seed/samples, or a whole [dispersions] table; the
# expected start of the message after "attitude: error: spinner.toml: ")
CASES = {
    "bare_angle": (
        '[dispersions.initial_state]\nattitude = { distribution = "normal", sigma = 2.0 }',
        "dispersions.initial_state.attitude.sigma: an angle needs its unit",
    ),
    "negative_sigma": (
        '[dispersions.spacecraft]\nprincipal_moments = { distribution = "normal", '
        "relative_sigma = -0.1 }",
        "dispersions.spacecraft.principal_moments.relative_sigma: must be positive",
    ),
    "relative_above_one": (
        '[dispersions.spacecraft]\nprincipal_moments = { distribution = "uniform", '
        "relative_half_width = 1.5 }",
        "dispersions.spacecraft.principal_moments.relative_half_width: is a fraction",
    ),
    "unknown_law": (
        '[dispersions.spacecraft]\nprincipal_moments = { distribution = "gaussian", '
        "relative_sigma = 0.1 }",
        "dispersions.spacecraft.principal_moments.distribution: expected one of normal, "
        "uniform, truncated_normal, got 'gaussian'",
    ),
    "uniform_with_sigma": (
        '[dispersions.spacecraft]\nprincipal_moments = { distribution = "uniform", '
        "relative_sigma = 0.1 }",
        "dispersions.spacecraft.principal_moments.relative_sigma: unknown key; expected one of",
    ),
    "absolute_moments": (
        '[dispersions.spacecraft]\nprincipal_moments = { distribution = "normal", sigma = 5 }',
        "dispersions.spacecraft.principal_moments.sigma: unknown key; expected one of",
    ),
    "truncation_zero": (
        '[dispersions.initial_state]\nattitude = { distribution = "truncated_normal", '
        'sigma = { value = 1, unit = "deg" }, truncation = 0.0 }',
        "dispersions.initial_state.attitude.truncation: is in σ and must be between",
    ),
    "rotation_beyond_180_deg": (
        '[dispersions.initial_state]\nattitude = { distribution = "normal", '
        'sigma = { value = 500, unit = "deg" } }',
        "dispersions.initial_state.attitude.sigma: must be at most 180 deg",
    ),
    "nan_sigma": (
        "[dispersions.events]\n",  # replaced below: an array of tables is needed
        "",
    ),
    "rate_hz": (
        '[dispersions.initial_state]\nangular_velocity = { distribution = "normal", '
        'sigma = { value = 0.1, unit = "Hz" } }',
        "dispersions.initial_state.angular_velocity.sigma: unit 'Hz' is ambiguous",
    ),
    "rate_two_numbers": (
        '[dispersions.initial_state]\nangular_velocity = { distribution = "normal", '
        "sigma = [0.1, 0.2] }",
        "dispersions.initial_state.angular_velocity.sigma: expected 3 numbers, got [0.1, 0.2]",
    ),
    "other_rate_key": (
        '[dispersions.initial_state]\nangular_momentum = { distribution = "normal", sigma = 1.0 }',
        "dispersions.initial_state.angular_momentum: the initial state gives angular_velocity",
    ),
    "event_out_of_range": (
        '[[dispersions.events]]\nevent = 3\ntime = { distribution = "normal", sigma = 1.0 }',
        "dispersions.events[0].event: must be between 0 and 0, got 3",
    ),
    "event_twice": (
        "[[dispersions.events]]\nevent = 0\n[[dispersions.events]]\nevent = 0",
        "dispersions.events[1].event: events[0] is dispersed twice",
    ),
    "event_time_in_string": (
        '[[dispersions.events]]\nevent = 0\ntime = { distribution = "normal", sigma = "1 s" }',
        "dispersions.events[0].time.sigma: expected a number, got '1 s'",
    ),
    "tle_without_tle": (
        '[dispersions.pointing]\ntle_epoch = { distribution = "normal", sigma = 1.0 }',
        "dispersions.pointing.tle_epoch: the scenario has no [pointing] tle",
    ),
    "misspelt_key": (
        "sample = 3",
        "dispersions.sample: unknown key; expected one of: seed, samples",
    ),
}
CASES["nan_sigma"] = (
    '[[dispersions.events]]\nevent = 0\ntime = { distribution = "normal", sigma = nan }',
    "dispersions.events[0].time.sigma: expected finite numbers, got nan",
)

# Whole tables: the seed and the sample count.
TABLES = {
    "samples_zero": ("[dispersions]\nseed = 1\nsamples = 0", "dispersions.samples: must be"),
    "samples_too_many": (
        "[dispersions]\nseed = 1\nsamples = 1000000000000",
        "dispersions.samples: must be between 1 and 10,000,000, got 1000000000000",
    ),
    "samples_float": (
        "[dispersions]\nseed = 1\nsamples = 1e3",
        "dispersions.samples: expected a whole number, got 1000.0",
    ),
    "samples_bool": (
        "[dispersions]\nseed = 1\nsamples = true",
        "dispersions.samples: expected a whole number, got True",
    ),
    "seed_negative": ("[dispersions]\nseed = -1\nsamples = 3", "dispersions.seed: must be"),
    "seed_string": (
        '[dispersions]\nseed = "7"\nsamples = 3',
        "dispersions.seed: expected a whole number, got '7'",
    ),
    "seed_missing": ("[dispersions]\nsamples = 3", "dispersions.seed: missing key"),
    "not_a_table": ("dispersions = 5", "dispersions: expected a table, got 5"),  # at the top
}


def _refused(capsys, argv) -> list[str]:
    code = main(argv)
    err = said(capsys.readouterr().err)
    assert code == 2, err
    assert len(err) == 1, err
    return err


@pytest.mark.parametrize("case", [*CASES, *TABLES])
def test_bad_dispersions_exit_2_with_one_line_from_every_command(case, tmp_path, capsys):
    if case in CASES:
        text, expected = CASES[case]
        text = SPINNER + GOOD + text + "\n"
    else:
        text, expected = TABLES[case]
        text = text + "\n" + SPINNER if case == "not_a_table" else SPINNER + text + "\n"
    path = tmp_path / "spinner.toml"
    path.write_text(text)
    out = tmp_path / "out"
    check = _refused(capsys, ["check", str(path)])
    run = _refused(capsys, ["run", str(path), "--out", str(out), "--quiet"])
    montecarlo = _refused(capsys, ["montecarlo", str(path), "--out", str(out), "--quiet"])
    assert check == run == montecarlo
    assert check[0].startswith(f"attitude: error: spinner.toml: {expected}"), check[0]
    assert not out.exists()


@pytest.mark.parametrize(
    ("options", "expected"),
    [
        (["--samples", "0"], "--samples: must be between 1 and 10,000,000, got 0"),
        (["--seed", "-3"], "--seed: must be between 0 and 9,223,372,036,854,775,807, got -3"),
        (
            ["--seed", str(2**70)],
            f"--seed: must be between 0 and 9,223,372,036,854,775,807, got {2**70}",
        ),
        (["--workers", "0"], "spinner.toml: --workers: expected 1 to"),
        (["--batch-size", "0"], "spinner.toml: --batch-size: expected 1 to 10, got 0"),
        (["--sample", "10", "--emit-scenario", "{tmp}/e"], "spinner.toml: --sample: expected"),
        (["--sample", "1"], "spinner.toml: --sample: K goes with --emit-scenario DIR"),
        (["--scheduler", "tcp://localhost"], "spinner.toml: --scheduler 'tcp://localhost': not a"),
        (["--scheduler", "nonsense://x:1"], "spinner.toml: --scheduler 'nonsense://x:1': not a"),
    ],
)
def test_bad_options_exit_2_with_one_line(options, expected, tmp_path, capsys):
    path = tmp_path / "spinner.toml"
    path.write_text(SPINNER + GOOD)
    options = [o.replace("{tmp}", str(tmp_path)) for o in options]
    out = (
        []
        if "--emit-scenario" in options or "--sample" in options
        else ["--out", str(tmp_path / "o")]
    )
    err = _refused(capsys, ["montecarlo", str(path), *out, "--quiet", *options])
    assert err[0].startswith(f"attitude: error: {expected}"), err[0]
    assert not (tmp_path / "o").exists() and not (tmp_path / "e").exists()


def test_a_scenario_without_dispersions_is_refused_by_montecarlo(tmp_path, capsys):
    path = tmp_path / "spinner.toml"
    path.write_text(SPINNER)
    err = _refused(capsys, ["montecarlo", str(path), "--out", str(tmp_path / "o")])
    assert err[0].startswith("attitude: error: spinner.toml: dispersions: missing table: add one")


def test_the_users_folder_is_refused_for_the_report_and_for_emitted_samples(tmp_path, capsys):
    user = tmp_path / "user"
    user.mkdir()
    path = user / "spinner.toml"
    path.write_text(SPINNER + GOOD)
    (user / "thesis.tex").write_text("months of work\n")
    before = {p.name: p.read_bytes() for p in user.iterdir()}
    for options in (["--out", str(user)], ["--sample", "1", "--emit-scenario", str(user)]):
        err = _refused(capsys, ["montecarlo", str(path), "--quiet", *options])
        assert "the folder holds files that attitude did not write" in err[0], err
        # The option that named the folder, not --out for both.
        assert err[0].startswith(f"attitude: error: {options[-2]} {user}: "), err
    assert {p.name: p.read_bytes() for p in user.iterdir()} == before


@pytest.mark.parametrize("seed", [-1, 2**63, 2**70])
def test_the_seed_has_one_rule_in_the_file_and_on_the_command_line(seed, tmp_path, capsys):
    """--seed 2**70 was accepted while the file's seed refused it."""
    path = tmp_path / "spinner.toml"
    path.write_text(SPINNER + GOOD.replace("seed = 7", f"seed = {seed}"))
    from_file = _refused(capsys, ["montecarlo", str(path), "--out", str(tmp_path / "o")])
    path.write_text(SPINNER + GOOD)
    options = ["--out", str(tmp_path / "o"), "--seed", str(seed)]
    from_option = _refused(capsys, ["montecarlo", str(path), *options])
    reason = f"must be between 0 and 9,223,372,036,854,775,807, got {seed}"
    assert from_file == [f"attitude: error: spinner.toml: dispersions.seed: {reason}"]
    assert from_option == [f"attitude: error: --seed: {reason}"]
    assert not (tmp_path / "o").exists()
