"""Samples of scenarios on an orbit, with attitudes in an orbit frame or from an AEM file.

- A sample evaluated by a Monte Carlo task (``evaluate_batch``, in this process) and the
  same sample emitted and run alone by ``attitude run`` give the same numbers, exactly,
  on an orbit: the Moon, nadir and Earth-limb extrema, the three exclusions and the
  eclipses, all found on the exact motion.
- An attitude given in LVLH is dispersed in LVLH (R' = R exp(δ), R body → LVLH), and the
  sample's ICRF attitude is the nominal's turned by exp(δ) in body axes (scipy).
- A file the scenario names (an AEM) is read from the sample written into another
  folder: its path is written absolute.
"""

import json
import shutil
import tomllib
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from attitude.cli.main import main
from attitude.files.scenario_reader import load_scenario
from attitude.montecarlo.plan import Job, evaluate_batch, plan_montecarlo

ROOT = Path(__file__).parents[1]
HOSTILE = Path(__file__).parent / "hostile"

DISPERSIONS = """
[dispersions]
seed = 11
samples = 4

[dispersions.spacecraft]
principal_moments = { distribution = "normal", relative_sigma = 0.05 }

[dispersions.initial_state]
attitude = { distribution = "normal", sigma = { value = 3.0, unit = "deg" } }
"""


def _cubesat(folder: Path) -> Path:
    """The nadir-pointing CubeSat (attitude in LVLH, Keplerian orbit, Sun, Moon and limb
    exclusions), over 4,000 s: a Sun exclusion from 807 s, an eclipse from 3,595 s."""
    text = (ROOT / "scenarios" / "nadir_cubesat_star_tracker.toml").read_text()
    text = text.replace("duration = 11400.0", "duration = 4000.0")
    assert "duration = 4000.0" in text
    path = folder / "cubesat.toml"
    path.write_text(text + DISPERSIONS)
    return path


def _emit(path: Path, k: int, folder: Path, capsys) -> Path:
    assert main(["montecarlo", str(path), "--sample", str(k), "--emit-scenario", str(folder)]) == 0
    capsys.readouterr()
    return folder / f"sample_{k}.toml"


def test_a_sample_on_an_orbit_gives_what_attitude_run_gives(tmp_path, capsys):
    path = _cubesat(tmp_path)
    mc = plan_montecarlo(load_scenario(path))
    k = 2
    batch = evaluate_batch(Job.of(mc), k, k + 1)
    (row,) = batch.rows
    assert row["status"] == "ok", row["error"]
    emitted = _emit(path, k, tmp_path / "emitted", capsys)
    assert main(["run", str(emitted), "--out", str(tmp_path / "run"), "--quiet"]) == 0
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    pointing = summary["pointing"]
    expected = {
        "eclipse_count": pointing["eclipses"]["shadow"]["count"],
        "eclipse_total_s": pointing["eclipses"]["shadow"]["total_s"],
        "umbra_total_s": pointing["eclipses"]["umbra"]["total_s"],
        "sunlit_fraction": pointing["eclipses"]["sunlit_fraction_of_span"],
        "moon_behind_earth_total_s": pointing["moon_behind_earth"]["total_s"],
        "max_rate_deg_s": summary["extrema"]["max_rate_deg_s"],
    }
    for v, entry in pointing["body_vectors"].items():
        for key, value in entry.items():
            if key.endswith(("_min_deg", "_max_deg", "_min", "_max")):
                expected[f"{v}_{key}"] = value
        for constraint in ("sun_exclusion", "moon_exclusion", "earth_limb_exclusion"):
            if constraint in entry:
                for total in ("count", "total_s", "longest_s"):
                    expected[f"{v}_{constraint}_{total}"] = entry[constraint][total]
    # The orbit's quantities are there: nadir and limb extrema, the three exclusions.
    assert "star_tracker_earth_limb_angle_min_deg" in expected
    assert "star_tracker_earth_limb_exclusion_total_s" in expected
    assert "star_tracker_moon_exclusion_count" in expected
    assert expected["eclipse_count"] >= 1  # the eclipse that starts at 3,595 s
    assert expected["star_tracker_sun_exclusion_count"] >= 1
    assert set(expected) <= set(mc.metrics)
    for name, value in expected.items():
        assert row[name] == value, (name, row[name], value)  # exactly


def test_an_attitude_in_lvlh_is_dispersed_in_lvlh(tmp_path, capsys):
    path = _cubesat(tmp_path)
    nominal = load_scenario(path).scenario.initial_state.attitude  # body -> ICRF
    emitted = _emit(path, 1, tmp_path / "emitted", capsys)
    document = tomllib.loads(emitted.read_text())
    state = document["initial_state"]
    assert state["frame"] == "lvlh"
    table = plan_montecarlo(load_scenario(path))
    from attitude.montecarlo.dispersions import draw_sample

    drawn = draw_sample(table.dispersions, table.loaded.document, 1).parameters
    δ = np.radians([drawn[f"initial_state.attitude_error_{c}_deg"] for c in "xyz"])
    # The nominal body -> LVLH is the identity: the sample's is exp(δ) itself.
    in_lvlh = Rotation.from_quat(state["quaternion"], scalar_first=True)
    assert np.allclose(in_lvlh.as_rotvec(), δ, rtol=0, atol=1e-15)
    # In ICRF: the nominal attitude turned by exp(δ) in body axes.
    sample = load_scenario(emitted).scenario.initial_state.attitude
    expected = nominal * Rotation.from_rotvec(δ)
    assert (sample * expected.inv()).magnitude() < 1e-12


def test_an_aem_named_by_the_scenario_is_found_from_the_emitted_sample(tmp_path, capsys):
    source = tmp_path / "mission"
    source.mkdir()
    shutil.copy(HOSTILE / "aem_eme2000.aem", source)
    text = (HOSTILE / "aem_eme2000.toml").read_text()
    rate_only = DISPERSIONS.split("[dispersions.initial_state]")[0]
    path = source / "sat.toml"
    path.write_text(text + rate_only)
    emitted = _emit(path, 0, tmp_path / "elsewhere", capsys)
    document = tomllib.loads(emitted.read_text())
    assert Path(document["initial_state"]["aem"]) == (source / "aem_eme2000.aem").absolute()
    assert main(["run", str(emitted), "--out", str(tmp_path / "run"), "--quiet"]) == 0
    read_there = load_scenario(emitted).scenario.initial_state.attitude
    read_here = load_scenario(path).scenario.initial_state.attitude
    assert np.array_equal(read_there.as_quat(), read_here.as_quat())  # the same file, read

    # With the attitude dispersed, the AEM's attitude is written as its ICRF quaternion.
    path.write_text(text + DISPERSIONS)
    emitted = _emit(path, 0, tmp_path / "elsewhere2", capsys)
    state = tomllib.loads(emitted.read_text())["initial_state"]
    assert "aem" not in state and "frame" not in state
    assert main(["run", str(emitted), "--out", str(tmp_path / "run2"), "--quiet"]) == 0
