"""Every hostile file in tests/hostile/ ends in exit 0, or exit 2 with one line that
names the key holding the bad value.

Each file is copied into a folder of the user's (beside a thesis, a data file and
the orbit and attitude files that the hostile scenarios name) and run through
`attitude check --out` and `attitude run --out` a new folder (the disk is the one
check that needs the folder), then `attitude run --out` the user's folder itself.
After each: exit 0 (stderr holds only
one-line warnings or notes, and the outputs are there) or exit 2 (exactly one line on
stderr and no output folder); never a traceback; `check` and `run` agree; and every
file of the user's is byte for byte as it was.

A refusal names the key that holds the bad value, as the file's author means it
(:data:`KEYS`, one entry per file, read from what each file tries): on the line of
`check` and of `run` (``FILE: KEY: reason``), and as data, ``InputError.key``, from
the library path that both commands take.
"""

import shutil
import warnings
from pathlib import Path

import pytest
from cli_lines import said

from attitude.base.errors import InputError
from attitude.cli.main import main
from attitude.files.scenario_reader import load_scenario
from attitude.outputs.budget import check_fits
from attitude.report.plan import plan_run

ACCEPTED = "accepted"
# The key that holds each file's bad value (None: the file is not a TOML document at
# all), or ACCEPTED.  A new hostile file needs its entry.
KEYS = {
    "aem_and_quaternion": "initial_state",  # two attitudes: the table that holds both
    "aem_eme2000": ACCEPTED,
    "aem_garbage": "initial_state.aem",
    "aem_outside": "initial_state.aem",
    "atmosphere_1e9_m": "pointing.earth_limb_atmosphere_height",
    "bad_vector_name": "pointing.body_vectors[0].name",
    "bare_angle": "pointing.body_vectors[0].sun_exclusion_half_angle",
    "binary": None,
    "booleans_as_moments": "spacecraft.principal_moments",
    "burn_1e30_with_accuracy": "torques.burns[0].torque",
    "dispersions_bare_angle": "dispersions.initial_state.attitude.sigma",
    "dispersions_event_that_is_not_there": "dispersions.events[0]",
    "dispersions_seed_negative": "dispersions.seed",
    "dispersions_sigma_inf": "dispersions.initial_state.angular_velocity.sigma",
    "dispersions_trillion_samples": "dispersions.samples",
    "duplicate_key": None,  # not TOML: tomllib says where (line 17), not which key
    "duration_10_to_400": "output.duration",
    "duration_inf": "output.duration",
    "duration_nan": "output.duration",
    "duration_negative_zero": "output.duration",
    "empty": "scenario",
    "epoch_1850": "scenario.epoch",
    "epoch_2060": "scenario.epoch",
    "euler_sequence_repeated": "pointing.lvlh_euler_sequence",
    "event_after_the_end": "events[0].offset",
    "fast_tumbler_year_with_pointing": "output.duration",
    "gravity_gradient_oem_ends_early": "pointing.oem",
    "huge_momentum": ACCEPTED,
    "hundred_billion_samples": "output.step",
    "hz": "initial_state.angular_velocity",
    "intermediate_axis": ACCEPTED,
    "interval_precision_1e-13": ACCEPTED,
    "keplerian_1e30_m": "pointing.keplerian.semi_major_axis",
    "keplerian_bare_inclination": "pointing.keplerian.inclination",
    "keplerian_hyperbolic": "pointing.keplerian.eccentricity",
    "keplerian_inside_earth": "pointing.keplerian.semi_major_axis",
    "keplerian_nan": "pointing.keplerian.eccentricity",
    "keplerian_raan_1e20_deg": "pointing.keplerian.raan",
    "leap_second_that_never_was": "scenario.epoch",
    "limb_in_seconds": "pointing.body_vectors[0].earth_limb_exclusion_angle",
    "limb_without_orbit": "pointing.body_vectors[0].earth_limb_exclusion_angle",
    "long_name": ACCEPTED,
    "lvlh_frame_without_attitude": "initial_state.frame",
    "lvlh_without_orbit": "initial_state.frame",
    "many_events": ACCEPTED,
    "moment_10_to_400": "spacecraft.principal_moments",
    "moon_bare_angle": "pointing.body_vectors[0].moon_exclusion_half_angle",
    "nested_deep": None,
    "newline_in_name": "scenario.name",
    "non_ascii_name": ACCEPTED,
    "oem_dev_zero": "pointing.oem",
    "oem_faster_than_light": "pointing.oem",
    "oem_folder": "pointing.oem",
    "oem_garbage": "pointing.oem",
    "oem_itrf": "pointing.oem",
    "oem_light_years": "pointing.oem",
    "oem_missing": "pointing.oem",
    "oem_outside_span": "pointing.oem",
    "omega_1e200": "initial_state.angular_velocity",
    "path_in_name": ACCEPTED,
    "rest": ACCEPTED,
    "runaway_burn": "torques.burns[0].torque",
    "second_60": "scenario.epoch",
    "separatrix": ACCEPTED,
    "separatrix_after_reset": ACCEPTED,
    "seven_tib": "output.step",
    "slew_bare_rate": "events[0].slew.max_rate",
    "spacecraft_name_blank": "spacecraft.name",
    "span_across_2053": "output.duration",
    "sphere": ACCEPTED,
    "step_5e-324": "output.step",
    "string_duration": "output.duration",
    "strings_vector": "initial_state.angular_velocity",
    "tensor_not_positive": "spacecraft.inertia_tensor",
    "tiny_momentum": ACCEPTED,
    "tle_checksum": "pointing.tle",
    "tle_decades_away": "pointing.tle",
    "tle_mean_motion_tiny": "pointing.tle",
    "tle_not_ascii": "pointing.tle",
    "tle_short": "pointing.tle",
    "tle_swapped": "pointing.tle",
    "two_orbits": "pointing",  # two orbits: the table that holds both
    "unknown_table": "torques.gravity",
    "utf16": None,
    "year_0001": ACCEPTED,
    "year_10000": "output.duration",
}

HOSTILE = sorted((Path(__file__).parent / "hostile").glob("*.toml"))
# The OEM and AEM files the hostile scenarios read (beside them, as a user keeps them).
COMPANIONS = sorted(
    p for p in (Path(__file__).parent / "hostile").iterdir() if p.suffix in (".oem", ".aem")
)


def _snapshot(folder: Path) -> dict[str, bytes]:
    return {
        str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()
    }


def _call(capsys, argv) -> tuple[int, list[str], str]:
    code = main(argv)
    captured = capsys.readouterr()
    assert "Traceback" not in captured.err and "Traceback" not in captured.out
    return code, said(captured.err), captured.out


def test_there_are_hostile_files():
    assert len(HOSTILE) >= 40
    assert sorted(KEYS) == [p.stem for p in HOSTILE]  # every file says what it expects


UNREAD = "<an error's text, which nothing may read a key from>"


def _library_error(scenario: Path, out: Path, monkeypatch) -> InputError | None:
    """The error of the path `check --out` and `run` take, as the library raises it,
    with every InputError's text made unreadable meanwhile: a key found by parsing a
    message, or a reason built from one, would show it."""
    with warnings.catch_warnings(), monkeypatch.context() as patch:
        warnings.simplefilter("ignore")
        patch.setattr(InputError, "__str__", lambda self: UNREAD)
        try:
            loaded = load_scenario(scenario)
            plan = plan_run(loaded.scenario, loaded.pointing, loaded.outputs, horizon=False)
            if "dispersions" in loaded.document:
                from attitude.montecarlo.plan import plan_montecarlo

                plan_montecarlo(loaded, plan)
            check_fits(plan.budget, out)
        except InputError as exc:
            return exc
    return None


@pytest.mark.parametrize("path", HOSTILE, ids=[p.stem for p in HOSTILE])
def test_a_hostile_file_ends_cleanly(path, tmp_path, capsys, monkeypatch):
    user = tmp_path / "user"
    user.mkdir()
    scenario = user / path.name
    shutil.copyfile(path, scenario)
    for companion in COMPANIONS:
        shutil.copyfile(companion, user / companion.name)
    (user / "thesis.tex").write_text("months of work\n")
    (user / "data.csv").write_text("t,x\n0,1\n")
    before = _snapshot(user)

    out = tmp_path / "out"
    checked, check_err, _ = _call(capsys, ["check", str(scenario), "--out", str(out)])
    ran, run_err, _ = _call(capsys, ["run", str(scenario), "--out", str(out), "--quiet"])
    assert checked == ran, (check_err, run_err)  # check refuses whatever run refuses
    assert ran in (0, 2), run_err
    key = KEYS[path.stem]
    assert (ran == 0) == (key == ACCEPTED), run_err
    if ran == 2:
        assert len(check_err) == 1 and check_err == run_err, (check_err, run_err)
        error = _library_error(scenario, out, monkeypatch)
        assert error is not None and error.key == key, (key, error and error.key, str(error))
        assert UNREAD not in error.reason, error.reason
        assert error.file in (None, path.name)  # the reader's errors name it; the CLI adds it
        assert check_err[0].endswith(error.reason)  # the line is the data, joined
        named = f"{path.name}: {key}: " if key else f"{path.name}: "
        assert check_err[0].startswith(f"attitude: error: {named}"), check_err
        assert not out.exists()
    else:
        assert all(line.startswith(("attitude: warning: ", "attitude: note: ")) for line in run_err)
        assert (out / "attitude-manifest.json").is_file() and (out / "report.html").is_file()
    assert _snapshot(user) == before

    # The user's own folder as the output folder: refused, nothing touched.
    code, err, _ = _call(capsys, ["run", str(scenario), "--out", str(user), "--quiet"])
    assert code == 2 and len(err) == 1, err
    assert _snapshot(user) == before


def test_a_runaway_burn_is_refused_before_its_motion_is_analysed(tmp_path, capsys):
    """The AEM's time-tag limit follows from the segments' rate bounds: `run` refuses
    the runaway burn at the stage `check` does, before the analysis of 1.5e5 rad/s
    (flips and the largest rate over 120 000 turns), which would take minutes."""
    scenario = tmp_path / "runaway_burn.toml"
    shutil.copyfile(Path(__file__).parent / "hostile" / "runaway_burn.toml", scenario)
    code = main(["run", str(scenario), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2
    assert "choosing the AEM" not in err and "analysing the motion" not in err, err
    assert "1 ns time tag" in err
