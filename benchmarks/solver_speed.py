"""Benchmark: the speed of ``EulerSolver`` as ratios to ``scipy.special.ellipj``, in one run.

Every figure is CPU time (``time.process_time``: what the process itself spent, which a
loaded machine inflates far less than wall clock), the best of short windows, each
timed alternately with its peer after both were warmed up, and printed with the
peer's own cost beside the ratio.  The peer is ``scipy.special.ellipj``: one scalar call
for the per-call figures, a call on as many points for the per-sample ones.  In every
regime: far from the separatrix, within |Δ2|/G² = 1e-10 of it, the Dzhanibekov case of
the docs (mc = 2e-6), exactly on it (case iii), symmetric tops (I1 = I2 and I2 = I3),
and mc below 2^-128 (the kernels' ln-mc regime).

1. construction: ``EulerSolver(inertia, momentum, attitude)`` (three moments; and a
   full tensor), and a fresh solver with one ``attitude(t)``: what building one solver
   per sample costs;
2. one scalar ``attitude(t)``, ``attitude_quaternion(t)`` and ``angular_momentum(t)``;
3. ``attitude(t)``, ``attitude_quaternion(t)``, ``angular_momentum(t)`` and
   ``angular_velocity(t)`` at ``--samples`` (1e6) times, per sample, against
   ``ellipj`` on as many points;
4. the table of ψ's periodic part: what the first call of a fresh solver costs with it
   and without it, at sizes around the threshold, and where it starts to pay;
5. many states × many times: ``EulerSolverBatch`` against one ``EulerSolver`` per
   state, per state and per sample;
6. the cost per sample of ``attitude_quaternion`` from 1e3 to ``--largest`` (1e7)
   samples (flat if nothing falls off a cliff), and the peak memory per sample.

    python -m benchmarks.solver_speed
    python -m benchmarks.solver_speed --quick     # 2e5 samples, fewer repeats

Sections 4 and 5 use the solver's internals and the batch: they are skipped on a
commit that has neither, so that the same script times an older commit (run it with
``PYTHONPATH`` at that commit's tree).  Results go to stdout and to
benchmarks/results/solver_speed.json.
"""

from __future__ import annotations

import argparse
import json
import os
import time
import tracemalloc
from pathlib import Path

import numpy as np
from scipy import special
from scipy.spatial.transform import Rotation

from attitude import EulerSolver
from benchmarks.free_flow import _cpu_best, _machine_line, _paired_per_call

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
    "on the separatrix (iii)": (np.array([2.0, 3.0, 6.0]), np.array([1.0, 0.7, -1.0])),
    "Dzhanibekov (mc 2e-6)": (
        np.array([100.0, 200.0, 300.0]),
        np.array([100.0, 200.0, 300.0]) * np.array([1e-3, 1.0, 1e-3]),
    ),
    "symmetric I1 = I2": (np.array([2.0, 2.0, 5.0]), np.array([0.3, 0.4, 0.5])),
    "symmetric I2 = I3": (np.array([2.0, 5.0, 5.0]), np.array([0.3, 0.4, 0.5])),
    "mc < 2^-128 (ln mc)": (np.array([1.0, 2.0, 3.0]), np.array([1e-30, 1.0, 2e-30])),
}
TENSOR = np.array([[3.0, 0.1, 0.2], [0.1, 2.0, 0.05], [0.2, 0.05, 1.0]])


def _peak_bytes(function) -> int:
    tracemalloc.start()
    function()
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return peak


def _paired_best(ours, peer, repeats: int) -> tuple[float, float]:
    """Best CPU times of one call of ``ours`` and ``peer``, run alternately."""
    best_ours = best_peer = np.inf
    for _ in range(repeats):
        best_ours = min(best_ours, _cpu_best(ours, 1))
        best_peer = min(best_peer, _cpu_best(peer, 1))
    return best_ours, best_peer


def _one_call_section(report: dict, repeats: int) -> None:
    """Sections 1 and 2: construction and one time, against one scalar ellipj call."""
    scalar_ellipj = lambda: special.ellipj(0.7, 0.3)  # noqa: E731
    rows = {}
    print(
        "\none call, CPU time / one scalar ellipj call (its own µs in brackets):\n"
        f"{'regime':24s} {'EulerSolver()':>15s} {'+attitude(t)':>14s} {'attitude(t)':>13s} "
        f"{'quaternion':>11s} {'momentum':>9s}"
    )
    for name, (inertia, momentum) in CASES.items():
        solver = EulerSolver(inertia, momentum, ATTITUDE0)
        solver.attitude(1234.5)
        row = {}
        for key, call in (
            ("construction", lambda: EulerSolver(inertia, momentum, ATTITUDE0)),  # noqa: B023
            (
                "construction_and_one_attitude",
                lambda: EulerSolver(inertia, momentum, ATTITUDE0).attitude(1234.5),  # noqa: B023
            ),
            ("attitude", lambda: solver.attitude(1234.5)),  # noqa: B023
            ("attitude_quaternion", lambda: solver.attitude_quaternion(1234.5)),  # noqa: B023
            ("angular_momentum", lambda: solver.angular_momentum(1234.5)),  # noqa: B023
        ):
            ours, peer = _paired_per_call(call, scalar_ellipj, repeats)
            row[key] = {"us": ours * 1e6, "ellipj_us": peer * 1e6, "ratio_to_ellipj": ours / peer}
        rows[name] = row
        print(
            f"{name:24s} "
            + " ".join(
                f"{row[k]['ratio_to_ellipj']:{w}.1f}x"
                for k, w in (
                    ("construction", 8),
                    ("construction_and_one_attitude", 13),
                    ("attitude", 12),
                    ("attitude_quaternion", 10),
                    ("angular_momentum", 8),
                )
            )
            + f"  [{row['construction']['ellipj_us']:.2f} µs]"
        )
    ours, peer = _paired_per_call(
        lambda: EulerSolver(TENSOR, [0.3, -0.2, 0.5], ATTITUDE0), scalar_ellipj, repeats
    )
    report["one_call"] = rows
    report["construction_from_a_tensor"] = {
        "us": ours * 1e6,
        "ellipj_us": peer * 1e6,
        "ratio_to_ellipj": ours / peer,
    }
    print(
        f"{'tensor (eigh)':24s} {ours / peer:8.1f}x  (construction from a full tensor) "
        f"[{peer * 1e6:.2f} µs]"
    )
    q = np.array([0.1, 0.2, 0.3, np.sqrt(0.86)])
    ours, peer = _paired_per_call(
        lambda: Rotation.from_quat(q, scalar_first=True), scalar_ellipj, repeats
    )
    report["rotation_from_quat"] = {"us": ours * 1e6, "ratio_to_ellipj": ours / peer}
    print(
        f"  (scipy's Rotation.from_quat of one quaternion alone: {ours / peer:.1f}x, "
        f"{ours * 1e6:.2f} µs)"
    )


def _arrays_section(report: dict, t: np.ndarray, u: np.ndarray, m: np.ndarray, repeats: int):
    """Section 3: 1e6 samples against ellipj on as many points."""
    N = t.size
    ellipj = lambda: special.ellipj(u, m)  # noqa: E731
    print(f"\n{N} samples, CPU time / ellipj on {N} points (ellipj's own ns a point in brackets):")
    header = ("regime", "formula", "mc", "attitude", "quaternion", "momentum", "velocity")
    print("{:24s} {:>7s} {:>9s} {:>14s} {:>14s} {:>14s} {:>14s}".format(*header))
    for name, (inertia, momentum) in CASES.items():
        solver = EulerSolver(inertia, momentum, ATTITUDE0)
        solver.attitude(t)  # warm up (and build the table where there is one)
        row: dict = {"formula": solver.formula, "mc": solver.mc}
        for key, call in (
            ("attitude", lambda: solver.attitude(t)),  # noqa: B023
            ("attitude_quaternion", lambda: solver.attitude_quaternion(t)),  # noqa: B023
            ("angular_momentum", lambda: solver.angular_momentum(t)),  # noqa: B023
            ("angular_velocity", lambda: solver.angular_velocity(t)),  # noqa: B023
        ):
            ours, peer = _paired_best(call, ellipj, repeats)
            row[key] = {
                "ns_per_sample": ours / N * 1e9,
                "ellipj_ns_per_point": peer / N * 1e9,
                "ratio_to_ellipj": ours / peer,
            }
        report["arrays"][name] = row
        print(
            f"{name:24s} {row['formula']:>7s} {row['mc']:9.2g} "
            + " ".join(
                f"{row[k]['ratio_to_ellipj']:6.2f}x [{row[k]['ellipj_ns_per_point']:3.0f} ns]"
                for k in ("attitude", "attitude_quaternion", "angular_momentum", "angular_velocity")
            )
        )


def _table_section(report: dict, repeats: int) -> None:
    """Section 4: a fresh solver's first call with the table (built in the call) and
    without it, at sizes around the threshold."""
    try:
        from attitude.solver import backends
    except ImportError:
        print("\n(the table section needs attitude.solver.backends: skipped)")
        return
    sizes = (2048, 4096, 6144, 8192, 12288, 16384, 32768)
    threshold = backends.TABLE_MIN_SAMPLES
    print(
        "\nthe table: a fresh solver's first attitude_quaternion call, CPU ms, with the table "
        f"(built in the call) / without (the formula); the threshold is {threshold} samples"
    )
    print(f"{'regime':24s} " + " ".join(f"{n:>12d}" for n in sizes) + "   pays from")
    table: dict = {}
    for name in ("far (generic)", "separatrix 1e-10", "Dzhanibekov (mc 2e-6)"):
        inertia, momentum = CASES[name]
        row = {}
        for n in sizes:
            tn = np.linspace(0.0, 3600.0, n)

            def first_call(tabulate: bool, tn=tn) -> None:
                solver = EulerSolver(inertia, momentum, ATTITUDE0)  # noqa: B023
                saved = backends.TABLE_MIN_SAMPLES
                backends.TABLE_MIN_SAMPLES = 1 if tabulate else 10**12
                try:
                    solver.attitude_quaternion(tn)
                finally:
                    backends.TABLE_MIN_SAMPLES = saved

            with_table, without = _paired_best(
                lambda f=first_call: f(True), lambda f=first_call: f(False), repeats
            )
            row[n] = {"with_table_ms": with_table * 1e3, "formula_ms": without * 1e3}
        pays = next((n for n in sizes if row[n]["with_table_ms"] < row[n]["formula_ms"]), None)
        table[name] = {"sizes": row, "pays_from": pays}
        print(
            f"{name:24s} "
            + " ".join(f"{row[n]['with_table_ms']:5.2f}/{row[n]['formula_ms']:5.2f}" for n in sizes)
            + f"   {pays}"
        )
    report["table"] = {"threshold": threshold, "regimes": table}


def _batch_section(report: dict, repeats: int) -> None:
    """Section 5: N states × T times through EulerSolverBatch, against one EulerSolver
    per state (built and evaluated), and against ellipj on N T points."""
    try:
        from attitude import EulerSolverBatch
    except ImportError:
        print("\n(EulerSolverBatch is not in this commit: section skipped)")
        return
    rng = np.random.default_rng(5)
    rows = {}
    print(
        "\nmany states x many times: CPU µs a state (construction and evaluation), "
        "EulerSolverBatch / one EulerSolver per state, and ns a sample / ellipj"
    )
    print(
        f"{'states x times':>16s} {'batch µs/state':>15s} {'solvers µs/state':>17s} "
        f"{'batch/solvers':>14s} {'ns/sample':>10s} {'/ellipj':>8s} [ellipj ns/pt]"
    )
    for states, times in ((100, 1), (1000, 1), (1000, 10), (100, 100), (10, 1000), (1000, 100)):
        inertia = np.sort(rng.uniform(1.0, 10.0, (states, 3)), axis=1)
        momentum = rng.normal(size=(states, 3))
        attitude = Rotation.random(states, random_state=3)
        t = np.linspace(0.0, 600.0, times)
        u, mpar = rng.uniform(-3.0, 3.0, states * times), rng.uniform(0.0, 1.0, states * times)

        def batch() -> None:
            EulerSolverBatch(inertia, momentum, attitude).attitude_quaternion(t)  # noqa: B023

        def solvers() -> None:
            for k in range(states):  # noqa: B023
                EulerSolver(inertia[k], momentum[k], attitude[k]).attitude_quaternion(t)  # noqa: B023

        ours, one_by_one = _paired_best(batch, solvers, repeats)
        _, peer = _paired_best(batch, lambda: special.ellipj(u, mpar), repeats)  # noqa: B023
        samples = states * times
        rows[f"{states}x{times}"] = {
            "batch_us_per_state": ours / states * 1e6,
            "solvers_us_per_state": one_by_one / states * 1e6,
            "batch_ns_per_sample": ours / samples * 1e9,
            "ellipj_ns_per_point": peer / samples * 1e9,
            "batch_over_ellipj": ours / peer,
        }
        print(
            f"{states:>8d} x {times:<5d} {ours / states * 1e6:15.1f} "
            f"{one_by_one / states * 1e6:17.1f} {ours / one_by_one:14.3f} "
            f"{ours / samples * 1e9:10.0f} {ours / peer:7.2f}x [{peer / samples * 1e9:.0f}]"
        )
    report["batch"] = rows


def _sizes_section(report: dict, u, m, largest: int, samples: int, repeats: int) -> None:
    """Section 6: per-sample cost across sizes, and the peak memory per sample."""
    solver = EulerSolver(*CASES["Dzhanibekov (mc 2e-6)"], ATTITUDE0)
    sizes = [n for n in (1_000, 10_000, 32_768, 100_000, 1_000_000, 10_000_000) if n <= largest]
    flat = {}
    print(
        "\nattitude_quaternion per sample across sizes (Dzhanibekov; CPU ns, / ellipj on as "
        "many points, [ellipj ns a point]):"
    )
    for n in sizes:
        tn = np.linspace(0.0, 3600.0, n)
        un, mn = np.resize(u, n), np.resize(m, n)
        solver.attitude_quaternion(tn)
        reps = max(repeats, min(200, 2_000_000 // n))
        ours, peer = _paired_best(
            lambda: solver.attitude_quaternion(tn),  # noqa: B023
            lambda: special.ellipj(un, mn),  # noqa: B023
            reps,
        )
        flat[n] = {
            "ns_per_sample": ours / n * 1e9,
            "ellipj_ns_per_point": peer / n * 1e9,
            "ratio_to_ellipj": ours / peer,
        }
        print(f"  {n:9d} {ours / n * 1e9:8.1f} ns {ours / peer:6.2f}x [{peer / n * 1e9:.0f}]")
    report["sizes"] = flat

    t = np.linspace(0.0, 3600.0, samples)
    fresh = EulerSolver(*CASES["Dzhanibekov (mc 2e-6)"], ATTITUDE0)
    memory = {}
    for key, call in (
        ("attitude", lambda: fresh.attitude(t)),
        ("attitude_quaternion", lambda: fresh.attitude_quaternion(t)),
        ("angular_momentum", lambda: fresh.angular_momentum(t)),
    ):
        memory[key] = _peak_bytes(call) / samples
    report["peak_bytes_per_sample"] = memory
    print(
        f"\npeak memory per sample (Dzhanibekov, {samples} samples, tracemalloc; attitude: "
        "the first array call, with its table build): "
        + ", ".join(f"{k} {v:.1f} B" for k, v in memory.items())
    )


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=1_000_000)
    parser.add_argument("--largest", type=int, default=10_000_000)
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--quick", action="store_true")
    parser.add_argument(
        "--sections", default="1,3,4,5,6", help="comma-separated sections (1 covers 1 and 2)"
    )
    args = parser.parse_args(argv)
    if args.quick:
        args.samples, args.largest, args.repeats = 200_000, 1_000_000, 3
    sections = {int(s) for s in args.sections.split(",")}
    N = args.samples
    rng = np.random.default_rng(9)
    t = np.linspace(0.0, 3600.0, N)
    u = rng.uniform(-3.0, 3.0, N)
    m = rng.uniform(0.0, 1.0, N)
    load = [os.getloadavg()[0]]
    report: dict = {
        "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
        "machine": _machine_line(),
        "clock": "CPU (time.process_time), best of alternated windows",
        "samples": N,
        "arrays": {},
    }
    print(f"{report['machine']}; {report['clock']}; load average {load[0]:.2f}")
    if 1 in sections:
        _one_call_section(report, 4 * args.repeats)
        load.append(os.getloadavg()[0])
    if 3 in sections:
        _arrays_section(report, t, u, m, args.repeats)
        load.append(os.getloadavg()[0])
    if 4 in sections:
        _table_section(report, args.repeats)
        load.append(os.getloadavg()[0])
    if 5 in sections:
        _batch_section(report, args.repeats)
        load.append(os.getloadavg()[0])
    if 6 in sections:
        _sizes_section(report, u, m, args.largest, N, args.repeats)
        load.append(os.getloadavg()[0])
    report["load_average_1min"] = load
    print(f"\nload average (1 min) during the run: {min(load):.2f} to {max(load):.2f}")
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "solver_speed.json").write_text(json.dumps(report, indent=2) + "\n")
    return report


if __name__ == "__main__":
    main()
