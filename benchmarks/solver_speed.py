"""Benchmark: the speed of ``EulerSolver`` as ratios to ``scipy.special.ellipj``, in one run.

The targets of issue 9, each timed side by side with its peer (the machine is shared:
absolute times move with the load, which is printed; ratios are what carry over):

1. ``attitude(t)`` at ``--samples`` (1e6) samples, per sample, against ``ellipj`` on as
   many points, in every regime: far from the separatrix, within |Δ2|/G² = 1e-10 of it,
   the Dzhanibekov case of the docs (mc = 2e-6), symmetric tops (I1 = I2 and I2 = I3),
   and mc below 2^-128 (the kernels' ln-mc regime);
2. ``angular_momentum(t)`` and ``angular_velocity(t)``, the same way;
3. one scalar ``attitude(t)`` call against one scalar ``ellipj`` call, with what
   scipy's ``Rotation`` construction alone costs;
4. ``attitude_quaternion(t)`` against ``attitude(t)``, timed side by side in every
   regime, and the peak memory of each per sample (tracemalloc: every numpy
   allocation is traced), with what it holds besides its output;
5. the cost per sample of ``attitude_quaternion`` from 1e3 to ``--largest`` (1e7)
   samples: flat if nothing falls off a cliff (BLAS threads, cache).

    python -m benchmarks.solver_speed
    python -m benchmarks.solver_speed --quick     # 2e5 samples, fewer repeats

Results go to stdout and to benchmarks/results/solver_speed.json.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
import tracemalloc
from pathlib import Path

import numpy as np
from scipy import special
from scipy.spatial.transform import Rotation

from attitude import EulerSolver
from benchmarks.free_flow import _best_per_call
from benchmarks.trajectory_sampling import _best

RESULTS = Path(__file__).parent / "results"
ATTITUDE0 = Rotation.from_euler("ZYX", [10.0, 20.0, 30.0], degrees=True)


def _near_separatrix(inertia: np.ndarray, δ2: float) -> np.ndarray:
    """A unit momentum with Δ2/G² = δ2 exactly up to rounding (x1² = 0.3 of the way)."""
    I1, I2, I3 = inertia
    a, b = (I1 - I2) / I1, (I3 - I2) / I3
    x1_2 = 0.3 * (1.0 - δ2 / b) / (1.0 - a / b)
    x3_2 = (δ2 - a * x1_2) / b
    return np.sqrt([x1_2, 1.0 - x1_2 - x3_2, x3_2])


# name: (moments, body momentum), moments in the user's order
CASES: dict[str, tuple[np.ndarray, np.ndarray]] = {
    "far (generic)": (np.array([3.0, 1.0, 2.0]), np.array([0.6, -0.5, 0.4])),
    "separatrix 1e-10": (
        np.array([1.0, 2.0, 3.0]),
        _near_separatrix(np.array([1.0, 2.0, 3.0]), 1e-10),
    ),
    "Dzhanibekov (mc 2e-6)": (
        np.array([100.0, 200.0, 300.0]),
        np.array([100.0, 200.0, 300.0]) * np.array([1e-3, 1.0, 1e-3]),
    ),
    "symmetric I1 = I2": (np.array([2.0, 2.0, 5.0]), np.array([0.3, 0.4, 0.5])),
    "symmetric I2 = I3": (np.array([2.0, 5.0, 5.0]), np.array([0.3, 0.4, 0.5])),
    "mc < 2^-128 (ln mc)": (np.array([1.0, 2.0, 3.0]), np.array([1e-30, 1.0, 2e-30])),
}


def _peak_bytes(function) -> int:
    tracemalloc.start()
    function()
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return peak


def _paired(ours, peer, repeats: int) -> tuple[float, float]:
    """Best times of ``ours`` and ``peer``, run alternately so that both see the load."""
    best_ours = best_peer = np.inf
    for _ in range(repeats):
        best_ours = min(best_ours, _best(ours, 1))
        best_peer = min(best_peer, _best(peer, 1))
    return best_ours, best_peer


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=1_000_000)
    parser.add_argument("--largest", type=int, default=10_000_000)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args(argv)
    if args.quick:
        args.samples, args.largest, args.repeats = 200_000, 1_000_000, 3
    N = args.samples
    rng = np.random.default_rng(9)
    t = np.linspace(0.0, 3600.0, N)
    u = rng.uniform(-3.0, 3.0, N)
    m = rng.uniform(0.0, 1.0, N)
    ellipj = lambda: special.ellipj(u, m)  # noqa: E731
    load = [os.getloadavg()[0]]
    report: dict = {
        "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
        "machine": f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores",
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": __import__("scipy").__version__,
        "samples": N,
        "regimes": {},
    }
    print(f"{N} samples; ratios to scipy.special.ellipj on {N} points in the same run")
    header = ("regime", "formula", "mc", "attitude", "quaternion", "momentum", "velocity", "q/att")
    print("{:24s} {:>7s} {:>9s} {:>9s} {:>10s} {:>9s} {:>9s} {:>6s}".format(*header))
    for name, (inertia, momentum) in CASES.items():
        solver = EulerSolver(inertia, momentum, ATTITUDE0)
        solver.attitude(t[:2000])  # warm up
        row = {"formula": solver.formula, "mc": solver.mc}
        for key, call in (
            ("attitude", lambda: solver.attitude(t)),  # noqa: B023
            ("attitude_quaternion", lambda: solver.attitude_quaternion(t)),  # noqa: B023
            ("angular_momentum", lambda: solver.angular_momentum(t)),  # noqa: B023
            ("angular_velocity", lambda: solver.angular_velocity(t)),  # noqa: B023
        ):
            ours, peer = _paired(call, ellipj, args.repeats)
            row[key] = {
                "ns_per_sample": ours / N * 1e9,
                "ellipj_ns_per_point": peer / N * 1e9,
                "ratio_to_ellipj": ours / peer,
            }
        # the two attitude outputs against each other, alternately
        quaternion, rotation = _paired(
            lambda: solver.attitude_quaternion(t),  # noqa: B023
            lambda: solver.attitude(t),  # noqa: B023
            2 * args.repeats,
        )
        row["quaternion_over_attitude"] = quaternion / rotation
        report["regimes"][name] = row
        load.append(os.getloadavg()[0])
        print(
            f"{name:24s} {row['formula']:>7s} {row['mc']:9.2g} "
            + " ".join(
                f"{row[k]['ratio_to_ellipj']:9.2f}x"
                for k in ("attitude", "attitude_quaternion", "angular_momentum")
            )
            + f" {row['angular_velocity']['ratio_to_ellipj']:8.2f}x"
            + f" {row['quaternion_over_attitude']:6.3f}"
        )
    ns = [row["attitude"]["ellipj_ns_per_point"] for row in report["regimes"].values()]
    print(f"  (ellipj: {min(ns):.0f} to {max(ns):.0f} ns a point across the runs)")

    # ------------------------------------------------------------ one scalar call
    name = "Dzhanibekov (mc 2e-6)"
    solver = EulerSolver(*CASES[name], ATTITUDE0)
    repeats = 4 * args.repeats
    scalar_ellipj = _best_per_call(lambda: special.ellipj(0.7, 0.3), repeats)
    scalar = {}
    for regime, (inertia, momentum) in CASES.items():
        s = EulerSolver(inertia, momentum, ATTITUDE0)
        scalar[regime] = _best_per_call(lambda: s.attitude(1234.5), repeats) / scalar_ellipj  # noqa: B023
    q = solver.attitude_quaternion(1234.5)
    from_quat = _best_per_call(lambda: Rotation.from_quat(q, scalar_first=True), repeats)
    report["scalar"] = {
        "ellipj_us": scalar_ellipj * 1e6,
        "attitude_ratio_to_ellipj": scalar,
        "rotation_from_quat_us": from_quat * 1e6,
        "rotation_from_quat_ratio_to_ellipj": from_quat / scalar_ellipj,
    }
    print(f"\none scalar attitude(t) call / one scalar ellipj call ({scalar_ellipj * 1e6:.2f} µs):")
    for regime, ratio in scalar.items():
        print(f"  {regime:24s} {ratio:6.1f}x")
    print(
        f"  (Rotation.from_quat of one quaternion alone: {from_quat * 1e6:.1f} µs, "
        f"{from_quat / scalar_ellipj:.1f}x)"
    )

    # ------------------------------------------------------------ memory per sample
    memory = {}
    for key, call in (
        ("attitude", lambda: solver.attitude(t)),
        ("attitude_quaternion", lambda: solver.attitude_quaternion(t)),
        ("angular_momentum", lambda: solver.angular_momentum(t)),
    ):
        memory[key] = _peak_bytes(call) / N
    beyond = {
        key: memory[key] * N - width * 8 * N
        for key, width in (("attitude", 4), ("attitude_quaternion", 4), ("angular_momentum", 3))
    }
    report["peak_bytes_per_sample"] = memory
    report["peak_bytes_beyond_the_output"] = beyond
    print(
        f"\npeak memory per sample ({name}, {N} samples, tracemalloc; attitude: the "
        "first array call, with its table build): "
        + ", ".join(f"{k} {v:.1f} B" for k, v in memory.items())
        + "\n  besides the output (32 B a quaternion, 24 B a vector): "
        + ", ".join(f"{k} {v / 2**20:.2f} MiB" for k, v in beyond.items())
    )

    # ------------------------------------------------------------ flat cost per sample
    sizes = [
        n for n in (1_000, 10_000, 32_768, 100_000, 1_000_000, 10_000_000) if n <= args.largest
    ]
    flat = {}
    print("\nattitude_quaternion per sample across sizes (ns, and / ellipj on as many points):")
    for n in sizes:
        tn = np.linspace(0.0, 3600.0, n)
        un, mn = u[: min(n, N)], m[: min(n, N)]
        if n > N:
            un, mn = np.resize(u, n), np.resize(m, n)
        reps = max(args.repeats, min(200, 2_000_000 // n))
        ours, peer = _paired(
            lambda: solver.attitude_quaternion(tn),  # noqa: B023
            lambda: special.ellipj(un, mn),  # noqa: B023
            reps,
        )
        flat[n] = {"ns_per_sample": ours / n * 1e9, "ratio_to_ellipj": ours / peer}
        print(f"  {n:9d} {ours / n * 1e9:8.1f} ns {ours / peer:6.2f}x")
    per = [v["ns_per_sample"] for v in flat.values()]
    report["sizes"] = flat
    report["largest_over_smallest_per_sample_cost_1e4_up"] = max(per[1:]) / min(per[1:])

    # the BLAS cliff itself, for the record: (n,4)@(4,4) per row
    M = rng.normal(size=(4, 4))
    cliff = {}
    for n in (16_384, 32_768, 131_072):
        A = rng.normal(size=(n, 4))
        cliff[n] = _best(lambda: A @ M, 20) / n * 1e9  # noqa: B023
    report["numpy_n_by_4_matmul_ns_per_row"] = cliff
    print(
        "  (numpy (n,4)@(4,4), ns a row: "
        + ", ".join(f"{k}: {v:.1f}" for k, v in cliff.items())
        + ")"
    )

    load.append(os.getloadavg()[0])
    report["load_average_1min"] = load
    print(f"\nload average (1 min) during the run: {min(load):.2f} to {max(load):.2f}")
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "solver_speed.json").write_text(json.dumps(report, indent=2) + "\n")
    return report


if __name__ == "__main__":
    main()
