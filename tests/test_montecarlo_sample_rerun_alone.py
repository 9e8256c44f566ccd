"""A sample re-run alone, as an ordinary scenario through `attitude run`, gives its row.

`attitude montecarlo FILE --out DIR` runs the job on a local Dask cluster;
`attitude montecarlo FILE --sample K --emit-scenario DIR2` writes sample K as a
scenario file; `attitude run` on that file writes summary.json.  Every metric of row K
of samples.csv (as written, read back) equals the number summary.json holds, exactly;
and the emitted file holds the drawn values of row K (the impulse, the event's offset,
the rate, the moments; the attitude as the nominal turned by the recorded error).
"""

import csv
import json
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from montecarlo_scenarios import write_spinner
from scipy.spatial.transform import Rotation

from attitude.cli.main import main
from attitude.files.scenario_reader import load_scenario

SAMPLES = 8


@pytest.fixture(scope="module")
def job(tmp_path_factory):
    folder = tmp_path_factory.mktemp("job")
    scenario = write_spinner(folder, samples=SAMPLES)
    code = main(
        ["montecarlo", str(scenario), "--out", str(folder / "mc"), "--workers", "2", "--quiet"]
    )
    assert code == 0
    return scenario, folder, _read_table(folder / "mc" / "samples.csv")


def _cell(text: str) -> float | str:
    try:
        return float(text)
    except ValueError:
        return text


def _read_table(path: Path) -> list[dict[str, float | str]]:
    """samples.csv as written, each number read by Python's float, which gives the
    text's own double (pandas' default parser was an ulp off it before pandas 3.1)."""
    with open(path, newline="", encoding="utf-8") as stream:
        return [{k: _cell(v) for k, v in row.items()} for row in csv.DictReader(stream)]


def _summary_values(summary: dict) -> dict:
    """The metrics as summary.json of `attitude run` states them (docs/scenarios.md)."""
    values = {
        "flip_count": summary["motion"]["flips"]["count"],
        "max_rate_deg_s": summary["extrema"]["max_rate_deg_s"],
    }
    for k, s in enumerate(summary["motion"]["segments"]):
        for key, name in (
            ("motion", "motion"),
            ("body_period_s", "body_period_s"),
            ("flip_count", "flip_count"),
            ("flip_period_s", "flip_period_s"),
            ("nutation_angle_min_deg", "nutation_min_deg"),
            ("nutation_angle_max_deg", "nutation_max_deg"),
            ("nutation_period_s", "nutation_period_s"),
            ("spin_period_s", "spin_period_s"),
            ("precession_period_s", "precession_period_s"),
            ("kinetic_energy_J", "kinetic_energy_J"),
            ("angular_momentum_norm_N_m_s", "angular_momentum_norm_N_m_s"),
        ):
            values[f"segment{k}_{name}"] = s[key]
    for v, entry in summary["pointing"]["body_vectors"].items():
        # Every extremum the summary gives (found on the exact motion), by its own key.
        for key, value in entry.items():
            if key.endswith(("_min_deg", "_max_deg", "_min", "_max")):
                values[f"{v}_{key}"] = value
        values[f"{v}_sun_visible_s"] = entry["sun_visible"]["total_s"]
        values[f"{v}_mean_cos_incidence"] = entry["mean_cos_incidence"]
        for constraint in ("sun_exclusion", "moon_exclusion", "earth_limb_exclusion"):
            if constraint in entry:
                for total in ("count", "total_s", "longest_s"):
                    values[f"{v}_{constraint}_{total}"] = entry[constraint][total]
    return values


@pytest.mark.parametrize("k", [0, SAMPLES - 3])
def test_sample_k_emitted_and_run_alone_reproduces_its_row(job, k, tmp_path, capsys):
    scenario, _, table = job
    emitted = tmp_path / "emitted"
    assert (
        main(["montecarlo", str(scenario), "--sample", str(k), "--emit-scenario", str(emitted)])
        == 0
    )
    path = emitted / f"sample_{k}.toml"
    assert capsys.readouterr().out.strip() == str(path)
    assert main(["run", str(path), "--out", str(tmp_path / "run"), "--quiet"]) == 0
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    row = table[k]
    assert row["sample"] == k and row["status"] == "ok"
    values = _summary_values(summary)
    # 2, 11 per segment (2); per vector the least and greatest Sun angle, Moon angle and
    # incidence, the Sun-visible time and the mean incidence (8), and the tracker's Sun
    # exclusion (3).
    assert len(values) == 43
    for name, value in values.items():
        if value is None:  # a quantity the motion does not have: null in JSON, empty in CSV
            assert row[name] == "", name
        elif isinstance(value, str):
            assert row[name] == value, name
        else:
            assert float(row[name]) == value, (name, row[name], value)  # exactly
    # The extrema's times: TT seconds in the row, the epoch as text in summary.json.
    scenario = load_scenario(path).scenario
    for v, entry in summary["pointing"]["body_vectors"].items():
        for key, value in entry.items():
            if key.endswith("_at"):
                assert scenario.format_epoch(float(row[f"{v}_{key}_s"])) == value, key

    document = tomllib.loads(path.read_text())
    assert "dispersions" not in document
    event = document["events"][0]
    assert event["offset"] == row["events[0].offset_s"]
    assert event["impulse"] == [row[f"events[0].impulse_{c}_N_m_s"] for c in "xyz"]
    rate = document["initial_state"]["angular_velocity"]
    assert rate == [row[f"initial_state.angular_velocity_{c}_rad_s"] for c in "xyz"]
    moments = np.linalg.eigvalsh(np.array(document["spacecraft"]["inertia_tensor"]))
    drawn = sorted(row[f"spacecraft.moment_{i}_kg_m2"] for i in (1, 2, 3))
    assert np.allclose(moments, drawn, rtol=1e-13, atol=0)
    nominal = Rotation.from_quat(
        [0.9238795325112867, 0.0, 0.3826834323650898, 0.0], scalar_first=True
    )
    error = np.radians([row[f"initial_state.attitude_error_{c}_deg"] for c in "xyz"])
    expected = (nominal * Rotation.from_rotvec(error)).as_quat(scalar_first=True)
    q = np.array(document["initial_state"]["quaternion"])
    assert min(np.max(np.abs(q - expected)), np.max(np.abs(q + expected))) < 1e-14
    assert math.isclose(
        math.degrees(np.linalg.norm(error)), row["initial_state.attitude_error_deg"]
    )
