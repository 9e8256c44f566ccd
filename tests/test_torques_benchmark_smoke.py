"""Smoke test of ``python -m benchmarks.torques_vs_peers``, not the benchmark itself.

One short problem through the benchmark's own code paths (the attitude ladder, scipy
at matching accuracy, Basilisk reported as skipped), and its Jacobi integral on a state
where it is known in closed form.
"""

from __future__ import annotations

import math
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:  # benchmarks/ is not installed: import it from the clone
    sys.path.insert(0, str(ROOT))

from benchmarks import torques_vs_peers as bench  # noqa: E402


def test_a_short_tumbler_through_the_benchmark():
    problem = replace(bench.TUMBLER, name="smoke", span=120.0, steps=(40.0, 20.0), checks=3)
    lines = []
    out = bench.single(problem, "Basilisk made absent", lines.append)
    assert out["basilisk"] == {"skipped": "Basilisk made absent"}
    assert [row["step"] for row in out["attitude"]] == [40.0, 20.0]
    assert all(row["error"] < 1e-3 and row["flows"] > 0 for row in out["attitude"])
    matched = out["vs_scipy"]
    assert matched["scipy_error"] <= matched["attitude_error"] and matched["speedup"] > 0.0
    report = {
        "machine": bench._machine(),
        "load": {"min": 0.0, "mean": 0.0, "max": 0.0},
        "free_flow": "any",
        "single": [out],
    }
    assert "scipy DOP853" in bench._markdown(report)


def test_the_largest_step_whose_smaller_steps_all_pass():
    ladder = [
        {"step": 50.0, "error": 1e-7},  # a lucky step beyond a failing one is not taken
        {"step": 40.0, "error": 1e-5},
        {"step": 30.0, "error": 1e-7},
        {"step": 20.0, "error": 1e-8},
    ]
    assert bench._cheapest(ladder, 1e-6)["step"] == 30.0
    assert bench._cheapest(ladder, 1e-9) is None


def test_jacobi_integral_of_a_body_turning_with_the_local_vertical():
    """Pitch axis on the orbit normal, rate −n about it, at rest in the LVLH frame.

    T = ½ Iy n², V = (μ/2r³)(3 Iz − tr I) with the yaw axis z on the nadir, and
    n ĥ·H = −n (−Iy n) = Iy n², so J = −½ Iy n² + V.
    """
    inertia = np.array([150.0, 200.0, 100.0])
    # LVLH at t = 0 on the benchmark's orbit (r along +x, h along +z): x_b = +y, y_b = −z,
    # z_b = −x (nadir); body → inertial columns.
    matrix = np.array([[0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
    q = Rotation.from_matrix(matrix).as_quat(scalar_first=True)[None, :]
    ω = np.array([[0.0, -bench.N, 0.0]])
    r = bench.position(np.array([0.0]))
    value = bench.jacobi(inertia, q, ω, r)[0]
    potential = 0.5 * bench.MU / bench.RADIUS**3 * (3 * inertia[2] - inertia.sum())
    assert math.isclose(value, -0.5 * inertia[1] * bench.N**2 + potential, rel_tol=1e-12)
