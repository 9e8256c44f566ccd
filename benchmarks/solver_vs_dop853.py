"""Benchmark: EulerSolver against scipy DOP853 on the same span, in one run.

Times ``attitude(t)`` and ``angular_momentum(t)`` for N samples (default 1e6) over
the span, and the same span integrated with ``solve_ivp(DOP853, rtol=1e-13,
atol=1e-15)`` (Euler's equations and the quaternion kinematics) with output at the
same N times; reports time per sample, the ratio DOP853 / ours, the peak memory of
our evaluation, and how far apart the two answers end up.

    python -m benchmarks.solver_vs_dop853                # 1e6 samples over one hour
    python -m benchmarks.solver_vs_dop853 --span 86400   # over a day (DOP853: minutes)

Results go to stdout and to benchmarks/results/solver_vs_dop853.json.
"""

from __future__ import annotations

import argparse
import json
import platform
import time
import tracemalloc
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from attitude import EulerSolver
from benchmarks.peer_scipy import euler_rhs

RESULTS = Path(__file__).parent / "results"


def _best_of(repeats, function):
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        result = function()
        best = min(best, time.perf_counter() - start)
    return best, result


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=1_000_000)
    parser.add_argument("--span", type=float, default=3600.0, help="seconds")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args(argv)

    # The Dzhanibekov case of the peer benchmarks: I = diag(100, 200, 300) kg m²,
    # ω0 = (1e-3, 1, 1e-3) rad/s, close to the separatrix (|Δ2|/G² ≈ 5e-6).
    inertia = np.array([100.0, 200.0, 300.0])
    ω0 = np.array([1e-3, 1.0, 1e-3])
    attitude0 = Rotation.from_euler("ZYX", [10.0, 20.0, 30.0], degrees=True)
    t = np.linspace(0.0, args.span, args.samples)

    construction, solver = _best_of(
        args.repeats, lambda: EulerSolver.from_angular_velocity(inertia, ω0, attitude0)
    )
    solver.attitude(t[:1000])  # warm up
    momentum_time, m = _best_of(args.repeats, lambda: solver.angular_momentum(t))
    attitude_time, attitude = _best_of(args.repeats, lambda: solver.attitude(t))

    tracemalloc.start()
    solver.attitude(t)
    _, peak_bytes = tracemalloc.get_traced_memory()
    tracemalloc.stop()

    y0 = np.concatenate([inertia * ω0, attitude0.as_quat(scalar_first=True)])
    start = time.perf_counter()
    solution = solve_ivp(
        euler_rhs,
        (0.0, args.span),
        y0,
        method="DOP853",
        t_eval=t,
        rtol=1e-13,
        atol=1e-15,
        args=(1.0 / inertia,),
    )
    dop853_time = time.perf_counter() - start
    m_ref = solution.y[:3].T
    attitude_ref = Rotation.from_quat(solution.y[3:].T, scalar_first=True)
    G = np.linalg.norm(inertia * ω0)

    report = {
        "machine": f"{platform.processor() or platform.machine()}, {platform.system()}",
        "python": platform.python_version(),
        "numpy": np.__version__,
        "case": {"inertia": inertia.tolist(), "omega0": ω0.tolist(), "span_s": args.span},
        "samples": args.samples,
        "solver_formula": solver.formula,
        "solver_mc": solver.mc,
        "construction_us": construction * 1e6,
        "angular_momentum_ns_per_sample": momentum_time / args.samples * 1e9,
        "attitude_ns_per_sample": attitude_time / args.samples * 1e9,
        "attitude_peak_memory_bytes_per_sample": peak_bytes / args.samples,
        "dop853_s": dop853_time,
        "dop853_ns_per_sample": dop853_time / args.samples * 1e9,
        "dop853_function_evaluations": int(solution.nfev),
        "ratio_dop853_over_attitude": dop853_time / attitude_time,
        "ratio_dop853_over_angular_momentum": dop853_time / momentum_time,
        "max_momentum_difference_relative": float(np.max(np.linalg.norm(m - m_ref, axis=1)) / G),
        "max_attitude_difference_rad": float(np.max((attitude.inv() * attitude_ref).magnitude())),
    }
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "solver_vs_dop853.json").write_text(json.dumps(report, indent=2) + "\n")
    print(
        f"{args.samples} samples over {args.span:g} s, formula {solver.formula}, mc {solver.mc:.3g}"
    )
    print(f"  attitude(t)          {report['attitude_ns_per_sample']:8.0f} ns/sample")
    print(f"  angular_momentum(t)  {report['angular_momentum_ns_per_sample']:8.0f} ns/sample")
    print(f"  peak memory          {report['attitude_peak_memory_bytes_per_sample']:8.0f} B/sample")
    dop853_ns = report["dop853_ns_per_sample"]
    print(f"  DOP853 (rtol 1e-13)  {dop853_ns:8.0f} ns/sample ({dop853_time:.1f} s)")
    print(f"  ratio DOP853 / attitude(t)          {report['ratio_dop853_over_attitude']:8.1f}")
    print(
        f"  ratio DOP853 / angular_momentum(t)  {report['ratio_dop853_over_angular_momentum']:8.1f}"
    )
    print(
        "  difference (DOP853's own error near the separatrix dominates): "
        f"momentum {report['max_momentum_difference_relative']:.1e}, "
        f"attitude {report['max_attitude_difference_rad']:.1e} rad"
    )
    return report


if __name__ == "__main__":
    main()
