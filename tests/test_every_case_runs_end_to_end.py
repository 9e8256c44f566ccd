"""Every case of the free rigid body runs through `attitude run`: summary, plots, report.

The segments without a period (a sphere, a body at rest, a steady spin about the
intermediate axis, a state exactly on the separatrix, also one reached by an
attitude reset late in a run) each run: the summary says what the motion is (no
period, no flips, steady or asymptotic), and the time series agrees with an independent DOP853
integration of Euler's equations from the same state (tests/reference_models.py).
"""

import json
import math

import numpy as np
import pytest
from csv_read_back import read_csv
from reference_models import integrate_dop853
from scipy.spatial.transform import Rotation

from attitude.cli.main import main

TEMPLATE = """
[scenario]
name = "{name}"
epoch = "2027-03-01T12:00:00"

[spacecraft]
name = "body"
principal_moments = {moments}

[initial_state]
quaternion = [0.9238795325112867, 0.0, 0.3826834323650898, 0.0]
{rate}

{events}

[output]
duration = 20.0
step = 0.25
"""

CASES = {
    "sphere": ([5.0, 5.0, 5.0], "angular_velocity = [0.01, 0.2, 0.01]", "", "steady spin"),
    "rest": ([10.0, 20.0, 25.0], "angular_velocity = [0.0, 0.0, 0.0]", "", "rest"),
    "intermediate axis": (
        [10.0, 20.0, 25.0],
        "angular_velocity = [0.0, 0.2, 0.0]",
        "",
        "steady spin",
    ),
    "separatrix": ([1.0, 2.0, 2.25], "angular_momentum = [1.0, 2.0, 3.0]", "", "separatrix"),
    "separatrix after a reset": (
        [1.0, 2.0, 2.25],
        "angular_momentum = [0.5, 0.1, 3.0]",
        '[[events]]\ntype = "attitude_reset"\noffset = 15.0\nangular_momentum = [1.0, -2.0, 3.0]',
        "separatrix",
    ),
}


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("cases")
    results = {}
    for case, (moments, rate, events, _) in CASES.items():
        path = folder / f"{case.replace(' ', '_')}.toml"
        path.write_text(TEMPLATE.format(name=case, moments=moments, rate=rate, events=events))
        out = folder / path.stem
        assert main(["run", str(path), "--out", str(out), "--quiet"]) == 0, case
        results[case] = (out, json.loads((out / "summary.json").read_text()))
    return results


@pytest.mark.parametrize("case", list(CASES))
def test_the_run_writes_every_output(runs, case):
    out, _ = runs[case]
    for name in ("timeseries.csv", "summary.json", "attitude.aem", "report.html"):
        assert (out / name).stat().st_size > 0
    for name in ("angular_velocity.png", "polhode.png"):
        assert (out / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "polhode.png" in (out / "report.html").read_text()


@pytest.mark.parametrize("case", list(CASES))
def test_the_summary_says_what_the_motion_is(runs, case):
    _, summary = runs[case]
    segment = summary["motion"]["segments"][-1]
    motion = CASES[case][3]
    assert segment["motion"] == motion
    assert segment["body_period_s"] is None  # no period: null, not a number, not inf
    assert segment["flip_period_s"] is None
    assert segment["precession_period_s"] is None and segment["nutation_period_s"] is None
    if motion == "steady spin":
        assert segment["flip_count"] == 0
        ω = np.array([0.01, 0.2, 0.01]) if case == "sphere" else np.array([0.0, 0.2, 0.0])
        assert segment["spin_period_s"] == pytest.approx(2 * math.pi / np.linalg.norm(ω))
    if motion == "rest":
        assert segment["spin_period_s"] is None and segment["angular_momentum_norm_N_m_s"] == 0
    if motion == "separatrix":
        assert segment["flip_count"] <= 1
        assert "asymptotically" in segment["motion_description"]


@pytest.mark.parametrize("case", list(CASES))
def test_the_time_series_agrees_with_numerical_integration(runs, case):
    out, summary = runs[case]
    data = read_csv(out / "timeseries.csv")
    moments = np.array(CASES[case][0])
    last = summary["motion"]["segments"][-1]
    inside = data["t_s"] >= last["start_s"]
    t = data["t_s"][inside] - last["start_s"]
    h = np.column_stack([data[f"h_body_{c}_N_m_s"] for c in "xyz"])[inside]
    q = np.column_stack([data[f"q_body_to_icrf_{c}"] for c in "wxyz"])[inside]
    m_ref, attitude_ref = integrate_dop853(
        moments, h[0], Rotation.from_quat(q[0], scalar_first=True), t
    )
    scale = max(np.linalg.norm(h[0]), 1.0)
    np.testing.assert_allclose(h, m_ref, atol=1e-9 * scale)
    error = (Rotation.from_quat(q, scalar_first=True) * attitude_ref.inv()).magnitude()
    assert np.max(error) < 1e-9
    # The flips the summary counts are the sign changes of the intermediate component
    # (a change from exactly 0 to 0 is not one).
    m2 = np.sign(h[:, 1])
    changes = int(np.sum(m2[1:] * m2[:-1] < 0))
    assert last["flip_count"] == changes
