"""Benchmark: ``fit_spin_state`` across a known burn, against the torque-free fit of
an arc of the same length (the time class the fit across burns is meant to be in), and
optionally against the method the fit used before (the burn's scenario propagated by
the splitting, the Jacobian by forward differences).

The case of issue 27: a tumbler (I = 100, 200, 260 kg m², ω0 = (0.05, 0.02, 0.03)
rad/s) with a body-frame burn of (0.3, −0.2, 0.25) N m at 200–260 s of a 700 s arc of
gyro rates every 2 s, 1e-4 rad/s of noise; the truth from ``TorquedSolver`` at a 0.5 s
step.  The peer's arc is the same body's torque-free motion over the same 700 s.

CPU time (``time.process_time``), ours and the peer alternated, each warmed up first,
best and median of ``--repeats``; the load average beside the figures; how far the
moments land from the truth, in the fit's stated σ.

    python -m benchmarks.fit_across_burns                   # 3 repeats of each
    python -m benchmarks.fit_across_burns --propagated      # also the old method (~1 min)

Results go to stdout and to benchmarks/results/fit_across_burns.json.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
from pathlib import Path

import numpy as np

from attitude import (
    Burn,
    ConstantTorque,
    EulerSolver,
    ScenarioTorques,
    TorquedSolver,
    fit_spin_state,
)
from attitude.environment.timescales import as_time, time_from_tt_seconds

RESULTS = Path(__file__).parent / "results"
MOMENTS = np.array([100.0, 200.0, 260.0])
ω0 = np.array([0.05, 0.02, 0.03])
TORQUE = np.array([0.3, -0.2, 0.25])
SIGMA = 1e-4
EPOCH = as_time("2027-03-01T00:00:00")


def telemetry(burn: bool, seed: int = 0):
    t = np.arange(0.0, 700.0, 2.0)
    if burn:
        solver = TorquedSolver(
            MOMENTS, MOMENTS * ω0, torques=[ConstantTorque(TORQUE, 200.0, 260.0)], step=0.5
        )
    else:
        solver = EulerSolver(MOMENTS, MOMENTS * ω0)
    rng = np.random.default_rng(seed)
    ω = solver.angular_velocity(t) + SIGMA * rng.standard_normal((t.size, 3))
    return time_from_tt_seconds(EPOCH, t), ω


TORQUES = ScenarioTorques(burns=(Burn(time_from_tt_seconds(EPOCH, 200.0), 60.0, TORQUE),))


def ours(times, ω):
    return fit_spin_state(times, angular_velocity=ω, gyro_sigma=SIGMA, torques=TORQUES)


def torque_free(times, ω):
    return fit_spin_state(times, angular_velocity=ω, gyro_sigma=SIGMA)


def propagated(times, ω):
    """The method before: the scenario propagated by the splitting, forward differences."""
    import attitude.estimation.fit as fit_module
    from attitude.estimation.scenario_model import ScenarioModel

    original = fit_module._model

    def scenario_model(layout, impulses, torques, telemetry, orbit=None, burns=()):
        end = telemetry.span[1]
        return ScenarioModel(layout, impulses, torques=torques, epoch=telemetry.epoch, end=end)

    fit_module._model = scenario_model
    try:
        return ours(times, ω)
    finally:
        fit_module._model = original


def _timed(function, *args):
    start = time.process_time()
    value = function(*args)
    return time.process_time() - start, value


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--propagated", action="store_true")
    args = parser.parse_args(argv)
    burned, free = telemetry(True), telemetry(False)
    load_before = os.getloadavg()
    ours(*burned)  # warm up: imports, numba's cache
    torque_free(*free)
    our_times, peer_times = [], []
    fit = None
    for _ in range(args.repeats):
        seconds, fit = _timed(ours, *burned)
        our_times.append(seconds)
        seconds, _ = _timed(torque_free, *free)
        peer_times.append(seconds)
    old = None
    if args.propagated:
        old, _ = _timed(propagated, *burned)
    load_after = os.getloadavg()
    errors = ((fit.principal_moments - MOMENTS) / fit.principal_moments_sigma).tolist()
    report = {
        "machine": platform.processor() or platform.machine(),
        "python": platform.python_version(),
        "load_average_1min": [load_before[0], load_after[0]],
        "ours_cpu_s": {"best": min(our_times), "median": float(np.median(our_times))},
        "torque_free_cpu_s": {"best": min(peer_times), "median": float(np.median(peer_times))},
        "propagated_cpu_s": old,
        "moments_error_in_sigma": errors,
        "reduced_chi2": fit.reduced_chi2,
    }
    print(f"load average (1 min): {load_before[0]:.2f} before, {load_after[0]:.2f} after")
    print(
        f"across the burn: CPU best {min(our_times):.3f} s, median {np.median(our_times):.3f} "
        f"s; moments off by {np.round(errors, 2).tolist()} σ, reduced chi2 "
        f"{fit.reduced_chi2:.3f}"
    )
    print(
        f"torque-free, the same 700 s: CPU best {min(peer_times):.3f} s, median "
        f"{np.median(peer_times):.3f} s; ratio (median) "
        f"{np.median(our_times) / np.median(peer_times):.2f}"
    )
    if old is not None:
        print(f"the propagated scenario with forward differences: CPU {old:.1f} s")
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "fit_across_burns.json").write_text(json.dumps(report, indent=2) + "\n")


if __name__ == "__main__":
    main()
