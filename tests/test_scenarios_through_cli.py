"""Every file in scenarios/ runs through the command line, and its outputs hold up.

For every scenario: the CSV states its frames, units and quaternion order; the
quaternions are unit; |h_body| = |h_icrf| on every row; the inertial angular
momentum is constant between events; the kinetic energy column equals ½ ω·h.
Then, per scenario, its physics against independent references: mpmath's closed
form for the flip period, the impulse for the momentum jump, ½ m·I⁻¹m for the
energy after a deployment, the spin rate for the rotation period.
"""

import json
import math
from pathlib import Path

import numpy as np
import pytest
from reference_models import half_period_mpmath
from scipy.spatial.transform import Rotation

from attitude.cli.main import main

SCENARIOS = sorted((Path(__file__).parents[1] / "scenarios").glob("*.toml"))


def _run(path: Path, out: Path) -> tuple[np.ndarray, dict, str]:
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 0
    csv = out / "timeseries.csv"
    text = csv.read_text()
    preamble = sum(1 for line in text.splitlines() if line.startswith("#"))
    data = np.genfromtxt(
        csv, delimiter=",", skip_header=preamble, names=True, dtype=None, encoding="utf-8"
    )
    summary = json.loads((out / "summary.json").read_text())
    return data, summary, text


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    out = tmp_path_factory.mktemp("runs")
    return {path.stem: _run(path, out / path.stem) for path in SCENARIOS}


def test_there_are_example_scenarios():
    assert {p.stem for p in SCENARIOS} >= {
        "dzhanibekov_t_handle",
        "spinner_thruster_pulse",
        "boom_deployment",
        "tumbling_defunct_satellite",
    }


@pytest.mark.parametrize("name", [p.stem for p in SCENARIOS])
def test_outputs_are_consistent(runs, name):
    data, summary, text = runs[name]
    assert "scalar first" in text and "ICRF" in text and "rad/s" in text
    assert len(data) == summary["scenario"]["output"]["samples"]
    q = np.column_stack([data[f"q_body_to_icrf_{c}"] for c in "wxyz"])
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-15)
    h_icrf = np.column_stack([data[f"h_icrf_{c}_N_m_s"] for c in "xyz"])
    h_body = np.column_stack([data[f"h_body_{c}_N_m_s"] for c in "xyz"])
    ω = np.column_stack([data[f"omega_body_{c}_rad_s"] for c in "xyz"])
    G = np.linalg.norm(h_icrf, axis=1)
    np.testing.assert_allclose(np.linalg.norm(h_body, axis=1), G, rtol=1e-13)
    # The attitude carries the body momentum into the inertial one on every row.
    rotated = Rotation.from_quat(q, scalar_first=True).apply(h_body)
    np.testing.assert_allclose(rotated, h_icrf, rtol=0, atol=1e-13 * G.max())
    # The body's kinetic energy ½ω·Iω: with spinning wheels (a gyrostat) h_body is the
    # total, Iω + h_wheels.
    motions = {s["index"]: s["motion"] for s in summary["motion"]["segments"]}
    wheels = np.zeros_like(h_body)
    for loss in summary.get("guidance", {}).get("control_losses", []):
        if loss["wheels"] == "spinning":
            wheels[data["segment"] == loss["segment"]] = loss["wheel_momentum_body_N_m_s"]
    np.testing.assert_allclose(
        data["kinetic_energy_J"], 0.5 * np.sum(ω * (h_body - wheels), axis=1), rtol=1e-12
    )
    for k in np.unique(data["segment"]):
        if motions[k] in ("torqued", "guided", "slew"):
            # Under torques, or a law's controller, H_icrf changes:
            # tests/test_scenario_torques_*.py, tests/test_guided_outputs_read_back.py
            continue
        rows = h_icrf[data["segment"] == k]
        assert np.max(np.linalg.norm(rows - rows[0], axis=1)) <= 1e-13 * G.max()
    events = len(summary["scenario"]["events"])
    if "guidance" in summary:  # a slew adds a segment: the law after it
        assert len(summary["motion"]["segments"]) >= events + 1
    else:
        assert len(summary["motion"]["segments"]) == events + 1


def test_dzhanibekov_flips_every_closed_form_half_period(runs):
    data, summary, _ = runs["dzhanibekov_t_handle"]
    inertia = np.array([2.0e-5, 5.0e-5, 6.4e-5])
    m0 = inertia * np.radians([0.72, 720.0, 0.72])
    half_period = half_period_mpmath(inertia, m0)
    flips = np.array(summary["motion"]["flips"]["times_s"])
    assert len(flips) == summary["motion"]["flips"]["count"] >= 7
    np.testing.assert_allclose(np.diff(flips), half_period, rtol=1e-12)
    # The CSV shows them: ω_y changes sign between the rows around each flip.
    t, ω_y = data["t_s"], data["omega_body_y_rad_s"]
    crossings = t[1:][np.sign(ω_y[1:]) != np.sign(ω_y[:-1])]
    np.testing.assert_allclose(crossings, flips, atol=0.005 + 1e-9)


def test_spinner_pulse_jumps_the_momentum_and_starts_a_nutation(runs):
    data, summary, _ = runs["spinner_thruster_pulse"]
    t = data["t_s"]
    q = np.column_stack([data[f"q_body_to_icrf_{c}"] for c in "wxyz"])
    h_icrf = np.column_stack([data[f"h_icrf_{c}_N_m_s"] for c in "xyz"])
    at = np.flatnonzero(np.isclose(t, 600.0))[0]  # the post-event row at the pulse epoch
    expected = Rotation.from_quat(q[at], scalar_first=True).apply([18.0, 0.0, 0.0])
    G = np.linalg.norm(h_icrf[at])
    np.testing.assert_allclose(h_icrf[at] - h_icrf[at - 1], expected, atol=1e-13 * G)
    before, after = summary["motion"]["segments"]
    assert before["nutation_angle_max_deg"] == 0.0 and before["precession_period_s"] is None
    assert before["spin_period_s"] == pytest.approx(12.0, rel=1e-9)  # 5 rpm
    # The nutation angle between body z and H, measured on the CSV rows after the pulse.
    z = Rotation.from_quat(q[at:], scalar_first=True).apply([0.0, 0.0, 1.0])
    h = h_icrf[at:] / np.linalg.norm(h_icrf[at:], axis=1)[:, None]
    angle = np.degrees(np.arccos(np.clip(np.sum(z * h, axis=1), -1, 1)))
    assert angle.min() == pytest.approx(after["nutation_angle_min_deg"], abs=2e-4)
    assert angle.max() == pytest.approx(after["nutation_angle_max_deg"], abs=2e-4)
    # Near-symmetric oblate spinner: precession about H at nearly G/I⊥.
    G = np.linalg.norm(h_icrf[-1])
    assert after["precession_period_s"] == pytest.approx(2 * math.pi * 875.0 / G, rel=0.01)


def test_boom_deployment_conserves_momentum_and_takes_energy(runs):
    data, summary, _ = runs["boom_deployment"]
    t = data["t_s"]
    at = np.flatnonzero(np.isclose(t, 300.0))[0]
    h_icrf = np.column_stack([data[f"h_icrf_{c}_N_m_s"] for c in "xyz"])
    np.testing.assert_allclose(h_icrf[at], h_icrf[at - 1], rtol=1e-13)
    h_body = np.column_stack([data[f"h_body_{c}_N_m_s"] for c in "xyz"])
    deployed = np.array([[324.575, -54.0, -45.0], [-54.0, 1421.875, -2.25], [-45.0, -2.25, 1492.7]])
    expected_T = 0.5 * h_body[at] @ np.linalg.solve(deployed, h_body[at])
    assert data["kinetic_energy_J"][at] == pytest.approx(expected_T, rel=1e-13)
    before, after = summary["motion"]["segments"]
    assert before["kinetic_energy_J"] == pytest.approx(
        0.5 * 410.0 * (2 * math.pi / 6) ** 2, rel=1e-13
    )
    assert after["kinetic_energy_J"] < before["kinetic_energy_J"] / 3
    assert before["spin_period_s"] == pytest.approx(6.0, rel=1e-9)  # 10 rpm
    assert after["spin_period_s"] > 3 * before["spin_period_s"]
    assert after["nutation_angle_max_deg"] > 1.0  # the spin axis is no longer principal


def test_tumbler_spin_period_is_consistent_with_its_input_rate(runs):
    """A consistency check of the scenario with the spin-period analysis, not of physics.

    The scenario's initial rate (|ω0| = 2.672 deg/s) was chosen to give the apparent
    period that laser ranging measured for Envisat, 134.74 s on 2013-09-25 (Kucharski et
    al., IEEE Trans. Geosci. Remote Sens. 52 (2014) 7651-7657).  So agreeing with
    134.7 s says that the analysis returns the period the input was built for, with a
    small nutation; it does not confirm the value independently.  The spin-period
    analysis itself is checked against the symmetric top's closed form in
    test_spin_period_against_symmetric_top.py.
    """
    _, summary, _ = runs["tumbling_defunct_satellite"]
    [segment] = summary["motion"]["segments"]
    assert summary["motion"]["flips"]["count"] == 0
    input_period_s = 360.0 / math.hypot(0.05, 0.08, 2.67)  # the scenario's ω0, deg/s
    assert segment["spin_period_s"] == pytest.approx(input_period_s, rel=0.002)
    assert segment["spin_period_s"] == pytest.approx(134.74, rel=0.002)
    assert 0.0 < segment["nutation_angle_min_deg"] < segment["nutation_angle_max_deg"] < 5.0


def test_check_describes_every_scenario(capsys):
    for path in SCENARIOS:
        assert main(["check", str(path)]) == 0
        assert f"{path}: OK" in capsys.readouterr().out
