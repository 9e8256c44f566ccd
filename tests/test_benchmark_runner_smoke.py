"""Smoke test of the peer benchmarks (``python -m benchmarks``), not the benchmark itself.

Runs the runner on a 20 s case with this package and scipy only: Basilisk and Orekit
must come out as skipped with a reason (they are optional; when installed they are
made to look absent, so that this test stays small).  Also checks, without the peers
installed, each convention conversion on a known rotation, and the independent
reference on FRB 903's printed example.
"""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:  # benchmarks/ is not installed: import it from the clone
    sys.path.insert(0, str(ROOT))

from benchmarks import peer_basilisk, peer_orekit, reference  # noqa: E402
from benchmarks.__main__ import DATA, main, reference_code_hash  # noqa: E402
from benchmarks.cases import CASES, delta2_over_G2  # noqa: E402

QUARTER_TURN_Z = Rotation.from_rotvec([0.0, 0.0, np.pi / 2])  # body → inertial


def test_runner_on_a_tiny_case_reports_skipped_peers(tmp_path, monkeypatch):
    for module, package in ((peer_basilisk, "Basilisk"), (peer_orekit, "orekit_jpype")):
        if importlib.util.find_spec(package) is not None:
            monkeypatch.setattr(module, "availability", lambda p=package: f"{p}: made absent")
    report = main(["--cases", "smoke", "--no-cache", "--out", str(tmp_path)])

    stored = json.loads((tmp_path / "peers.json").read_text())
    markdown = (tmp_path / "peers.md").read_text()
    for name in ("basilisk", "orekit"):
        assert stored["peers"][name]["status"] == "skipped"
        assert stored["peers"][name]["reason"]
        assert f"{name}: **skipped**" in markdown
    (case,) = report["cases"]
    rows = {r["label"]: r for r in case["rows"]}
    ours = rows["attitude (closed form)"]
    assert ours["status"] == "ok" and ours["samples"] == 21
    assert ours["worst_error_rad"] < 1e-11  # against the 40-digit Jadczyk reference
    assert ours["time_ratio"] == 1.0
    dop853 = rows["scipy DOP853 rtol 1e-12"]
    assert dop853["status"] == "ok" and dop853["time_ratio"] > 0
    assert dop853["worst_error_rad"] < 1e-6
    assert rows["scipy DOP853 rtol 1e-6"]["error_ratio"] > 1.0
    skipped = [r for r in case["rows"] if r["status"] == "skipped"]
    assert {r["peer"] for r in skipped} == {"basilisk", "orekit"}
    assert all(r["reason"] for r in skipped)
    assert "| attitude (closed form) |" in markdown


def test_basilisk_mrp_on_a_quarter_turn_about_z():
    # After +90° about z, Basilisk holds σ_BN = tan(π/8) ẑ; the inertial x axis is −y_B.
    sigma = np.array([0.0, 0.0, np.tan(np.pi / 8)])
    bn = peer_basilisk.mrp_to_dcm_bn(sigma)
    np.testing.assert_allclose(bn @ [1.0, 0.0, 0.0], [0.0, -1.0, 0.0], atol=1e-15)
    q = peer_basilisk.mrp_to_quaternion(sigma)[0]
    np.testing.assert_allclose(q, QUARTER_TURN_Z.as_quat(scalar_first=True), atol=1e-15)
    rotation = Rotation.from_quat(q, scalar_first=True)
    np.testing.assert_allclose(rotation.apply([1.0, 0.0, 0.0]), [0.0, 1.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(rotation.as_matrix(), bn.T, atol=1e-15)  # ours is [NB] = [BN]ᵀ


def test_basilisk_mrp_round_trip_and_shadow_set():
    r = Rotation.from_euler("ZYX", [170.0, -40.0, 75.0], degrees=True)
    q = r.as_quat(scalar_first=True)
    q = q if q[0] >= 0 else -q
    sigma = peer_basilisk.quaternion_to_mrp(q)
    assert np.linalg.norm(sigma) <= 1.0
    np.testing.assert_allclose(peer_basilisk.mrp_to_quaternion(sigma)[0], q, atol=1e-15)
    shadow = -sigma / (sigma @ sigma)  # Basilisk switches to it when |σ| > 1
    np.testing.assert_allclose(peer_basilisk.mrp_to_quaternion(shadow)[0], q, atol=1e-14)
    np.testing.assert_allclose(peer_basilisk.mrp_to_dcm_bn(sigma), r.as_matrix().T, atol=1e-14)


def test_orekit_quaternion_against_hipparchus_apply_to():
    # Hipparchus' documented case: Rotation(+K, +90°, VECTOR_OPERATOR) stores
    # q = (√½, 0, 0, −√½), and its applyTo(X) = +Y.
    c = np.sqrt(0.5)
    np.testing.assert_allclose(
        peer_orekit.hipparchus_apply_to([c, 0.0, 0.0, -c], [1.0, 0.0, 0.0]), [0, 1, 0], atol=1e-15
    )
    # Attitude.getRotation() maps inertial to body: for our body → inertial R, its
    # applyTo(v_N) must be R⁻¹ v_N, with the four numbers passed through unchanged.
    for r in (QUARTER_TURN_Z, Rotation.from_euler("ZYX", [10.0, 20.0, 30.0], degrees=True)):
        q = r.as_quat(scalar_first=True)
        hipparchus = peer_orekit.quaternion_to_hipparchus(q)
        for v in np.eye(3):
            np.testing.assert_allclose(
                peer_orekit.hipparchus_apply_to(hipparchus, v), r.inv().apply(v), atol=1e-15
            )
        back = peer_orekit.hipparchus_to_quaternion(-np.asarray(hipparchus))[0]
        np.testing.assert_allclose(back, q if q[0] >= 0 else -q, atol=1e-16)
    # After a quarter turn about z the inertial x axis is −y_B, as for Basilisk's [BN].
    np.testing.assert_allclose(
        peer_orekit.hipparchus_apply_to(QUARTER_TURN_Z.as_quat(scalar_first=True), [1, 0, 0]),
        [0.0, -1.0, 0.0],
        atol=1e-15,
    )


def test_reference_reproduces_frb903_example():
    angle, component = reference.validate_frb903()
    assert component < 1e-9  # FRB 903 printed it with its quadrature option (~8e-10)
    assert angle < 2e-9


def test_case_three_is_at_the_requested_distance_from_the_separatrix():
    assert delta2_over_G2(CASES["near_separatrix_1h"]) == pytest.approx(-1e-10, rel=1e-6)
    assert delta2_over_G2(CASES["dzhanibekov_1h"]) > 0  # the two sides of the separatrix


def test_cached_references_come_from_the_current_reference_code():
    """benchmarks/data/*.npz are keyed on the code of benchmarks/reference.py: a change to
    that code without regenerating them fails here (the runner would recompute them)."""
    files = [DATA / f"reference_{name}.npz" for name in CASES]  # not the torques one
    assert all(path.exists() for path in files)
    for path in files:
        meta = json.loads(str(np.load(path, allow_pickle=False)["meta"]))
        assert meta["reference_code_sha256"] == reference_code_hash(), path.name


def test_reference_code_hash_follows_the_code_not_the_prose(tmp_path):
    source = Path(reference.__file__).read_text(encoding="utf-8")
    assert "\nDPS = 40\n" in source
    original = reference_code_hash(Path(reference.__file__))
    prose = tmp_path / "prose.py"
    prose.write_text(
        source.replace('"""The independent', '"""Reworded: the independent', 1).replace(
            "\nDPS = 40\n", "\n# a new comment\n\nDPS = 40  # and another\n", 1
        ),
        encoding="utf-8",
    )
    code = tmp_path / "code.py"
    code.write_text(source.replace("\nDPS = 40\n", "\nDPS = 41\n", 1), encoding="utf-8")
    assert reference_code_hash(prose) == original
    assert reference_code_hash(code) != original
