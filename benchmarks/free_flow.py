"""Benchmark: the free-flow map ``attitude.solver.free_flow.advance``, against scipy's ellipj.

In one run, as ratios to peers timed side by side: CPU time (``time.process_time``),
the best of short windows of each in turn, both warm, with the peer's own cost printed
beside the ratio and the load average before and after:

- one state, one step: ``advance`` on a single state (its constants included), and
  ``advance_floats`` (tuples in and out: what the torqued solver calls for one
  spacecraft), against one scalar ``scipy.special.ellipj`` call and against building
  an ``EulerSolver`` and evaluating its attitude and momentum once (what a splitting
  step cost before);
- batches of N states, one step each, N = 1, 10, 100, 1000 and 1e5: nanoseconds per
  state-step, against ``scipy.special.ellipj`` on N points; and the same batch through
  a ``UnitBatch`` built once ("kept": the moments' constants kept from call to call, as
  the torqued solver's batch steps its spacecraft).

Each for several kinds of state: generic (both sides of the separatrix), within
|Δ2|/G² = 1e-10 of it (whose case test needs the exact integers), on it, next to it
with mc below the float range (the near-one kernels), a symmetric body, and a batch
that mixes every case.

    python -m benchmarks.free_flow
    python -m benchmarks.free_flow --quick      # fewer repeats, N up to 1e4

Results go to stdout and to benchmarks/results/free_flow.json.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
from pathlib import Path

import numpy as np
from scipy import special
from scipy.spatial.transform import Rotation

from attitude import EulerSolver
from attitude.solver.free_flow import UnitBatch, advance, advance_floats

RESULTS = Path(__file__).parent / "results"


def _cpu_per_call(function, repeats: int, window_s: float = 0.003) -> float:
    """The best, over ``repeats`` runs of about ``window_s`` of CPU each, of the mean CPU
    time of a call (seconds, ``time.process_time``).  Short runs, so that on a loaded
    machine some of them are not disturbed (cache, frequency): the best is close to the
    code's own cost, for ours and the peer's."""
    start = time.process_time()
    function()  # warm up, and size the runs
    calls = max(1, int(window_s / max(time.process_time() - start, 1e-7)))
    best = np.inf
    for _ in range(repeats):
        start = time.process_time()
        for _ in range(calls):
            function()
        best = min(best, (time.process_time() - start) / calls)
    return best


def _paired_per_call(ours, peer, repeats: int) -> tuple[float, float]:
    """``_cpu_per_call`` of ``ours`` and ``peer``, a window of each in turn (both warm),
    so that both see the same load."""
    best_ours = best_peer = np.inf
    _cpu_per_call(ours, 1)
    _cpu_per_call(peer, 1)
    for _ in range(repeats):
        best_ours = min(best_ours, _cpu_per_call(ours, 1))
        best_peer = min(best_peer, _cpu_per_call(peer, 1))
    return best_ours, best_peer


def _cpu_best(function, repeats: int = 3) -> float:
    """The best CPU time of one call of ``function`` over ``repeats`` calls."""
    best = np.inf
    for _ in range(repeats):
        start = time.process_time()
        function()
        best = min(best, time.process_time() - start)
    return best


def _machine_line() -> str:
    """The processor, its cores and the versions the figures depend on."""
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    import numba
    import scipy

    return (
        f"{cpu}, {os.cpu_count()} cores, Python {platform.python_version()}, numpy "
        f"{np.__version__}, scipy {scipy.__version__}, numba {numba.__version__}"
    )


def _state(kind: str, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Moments (in a random order) and a momentum of the given kind."""
    inertia = np.sort(rng.uniform(1.0, 10.0, 3))
    if kind == "generic":
        m = rng.normal(size=3)
    elif kind == "near separatrix (1e-10)":
        I1, I2, I3 = inertia
        a, b = (I1 - I2) / I1, (I3 - I2) / I3
        x1_2 = 0.3 * (1.0 - 1e-10 / b) / (1.0 - a / b)
        x3_2 = (1e-10 - a * x1_2) / b
        m = np.sqrt([x1_2, 1.0 - x1_2 - x3_2, x3_2])
    elif kind == "separatrix":
        inertia = np.array([2.0, 3.0, 6.0])
        m = np.array([1.0, rng.uniform(-2.0, 2.0), -1.0])
    elif kind == "mc below the float range":
        inertia = np.array([1.0, 2.0, 3.0])
        m = np.array([1e-200, 1.0, 2e-200])
    elif kind == "symmetric":
        inertia[1] = inertia[0]
        m = rng.normal(size=3)
    else:
        raise ValueError(kind)
    return inertia[rng.permutation(3)], m * rng.uniform(0.5, 2.0)


SCALAR_KINDS = [
    "generic",
    "near separatrix (1e-10)",
    "separatrix",
    "mc below the float range",
    "symmetric",
]
BATCH_KINDS = ["generic", "mixed (every case)"]


def _batch(kind: str, count: int, rng: np.random.Generator):
    if kind == "generic":
        states = [_state("generic", rng) for _ in range(count)]
    else:
        kinds = [*SCALAR_KINDS, "sphere", "rest"]
        states = []
        for k in range(count):
            which = kinds[k % len(kinds)]
            if which == "sphere":
                states.append((np.full(3, 2.0), rng.normal(size=3)))
            elif which == "rest":
                states.append((rng.uniform(1.0, 10.0, 3), np.zeros(3)))
            else:
                states.append(_state(which, rng))
    moments = np.array([s[0] for s in states])
    momentum = np.array([s[1] for s in states])
    q = Rotation.random(count, random_state=1).as_quat(scalar_first=True)
    dt = rng.uniform(0.1, 10.0, count)
    return moments, momentum, q, dt


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args(argv)
    repeats = 9 if args.quick else 41
    sizes = [1, 10, 100, 1000, 10_000] if args.quick else [1, 10, 100, 1000, 100_000]
    rng = np.random.default_rng(2026)
    load_before = os.getloadavg()

    report: dict = {
        "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
        "machine": _machine_line(),
        "clock": "CPU (time.process_time), best of alternated windows",
        "scalar": {},
        "batch": {},
    }
    print(f"{report['machine']}; {report['clock']}; load average {load_before[0]:.2f}")

    # ------------------------------------------------------------ one state, one step
    scalar_ellipj = lambda: special.ellipj(0.7, 0.3)  # noqa: E731
    print(
        f"{'one state, one step':34s} {'advance':>10s} {'/ellipj':>8s} "
        f"{'advance_floats':>15s} {'/ellipj':>8s} {'EulerSolver':>12s} [ellipj]"
    )
    for kind in SCALAR_KINDS:
        inertia, m = _state(kind, rng)
        q = Rotation.random(random_state=3).as_quat(scalar_first=True)
        dt = 3.7
        step, ellipj = _paired_per_call(
            lambda: advance(inertia, m, q, dt),  # noqa: B023
            scalar_ellipj,
            repeats,
        )
        floats = (tuple(inertia.tolist()), tuple(m.tolist()), tuple(q.tolist()), dt)
        step_floats, _ = _paired_per_call(
            lambda: advance_floats(*floats),  # noqa: B023
            scalar_ellipj,
            repeats,
        )
        attitude0 = Rotation.from_quat(q, scalar_first=True)

        def solver_step():
            solver = EulerSolver(inertia, m, attitude0)  # noqa: B023
            return solver.angular_momentum(dt), solver.attitude_quaternion(dt)  # noqa: B023

        solver, _ = _paired_per_call(solver_step, scalar_ellipj, repeats)
        report["scalar"][kind] = {
            "advance_us": step * 1e6,
            "ratio_to_ellipj": step / ellipj,
            "advance_floats_us": step_floats * 1e6,
            "advance_floats_ratio_to_ellipj": step_floats / ellipj,
            "euler_solver_us": solver * 1e6,
            "ratio_euler_solver_to_advance": solver / step,
            "scalar_ellipj_us": ellipj * 1e6,
        }
        print(
            f"  {kind:32s} {step * 1e6:8.1f} µs {step / ellipj:7.1f}x "
            f"{step_floats * 1e6:13.1f} µs {step_floats / ellipj:7.1f}x "
            f"{solver * 1e6:9.0f} µs ({solver / step:.0f}x advance) [{ellipj * 1e6:.2f} µs]"
        )

    # ------------------------------------------------------------ N states, one step each
    header = ("N states, one step each", "N", "ns/state", "kept ns/state", "ellipj ns/pt", "ratio")
    print("\n{:24s} {:>7s} {:>10s} {:>14s} {:>13s} {:>7s}".format(*header))
    for kind in BATCH_KINDS:
        report["batch"][kind] = {}
        for count in sizes:
            moments, momentum, q, dt = _batch(kind, count, rng)
            u, mpar = rng.uniform(-3.0, 3.0, count), rng.uniform(0.0, 1.0, count)
            ours, peer = _paired_per_call(
                lambda: advance(moments, momentum, q, dt),  # noqa: B023
                lambda: special.ellipj(u, mpar),  # noqa: B023
                repeats,
            )
            # The torqued batch's flow: moments kept from call to call (UnitBatch).
            unit_batch = UnitBatch(np.ascontiguousarray(moments, dtype=np.float64))
            q_unit = q / np.linalg.norm(q, axis=1, keepdims=True)
            kept, _ = _paired_per_call(
                lambda: unit_batch.advance(momentum, q_unit, dt),  # noqa: B023
                lambda: special.ellipj(u, mpar),  # noqa: B023
                repeats,
            )
            report["batch"][kind][count] = {
                "advance_ns_per_state": ours / count * 1e9,
                "unit_batch_ns_per_state": kept / count * 1e9,
                "ellipj_ns_per_point": peer / count * 1e9,
                "ratio_to_ellipj": ours / peer,
            }
            print(
                f"  {kind:22s} {count:7d} {ours / count * 1e9:10.0f} {kept / count * 1e9:14.0f} "
                f"{peer / count * 1e9:13.0f} {ours / peer:7.1f}"
            )
    load_after = os.getloadavg()
    report["load_average_1min_before_after"] = [load_before[0], load_after[0]]
    print(f"\nload average (1 min) before/after: {load_before[0]:.2f} / {load_after[0]:.2f}")
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "free_flow.json").write_text(json.dumps(report, indent=2) + "\n")
    return report


if __name__ == "__main__":
    main()
