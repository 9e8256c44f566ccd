"""Benchmark: ``fit_spin_state`` on a one-hour, 1 Hz gyro arc, against the fit an
analyst writes with scipy alone, in one run.

The telemetry: the exact motion of a tumbler (I = 100, 200, 260 kg m², ω0 = (0.05,
0.02, 0.03) rad/s, a body period of 267 s) sampled every second for an hour, with
1e-4 rad/s of white noise per axis, noise given.

- **ours**: ``fit_spin_state`` as a user calls it: the telemetry checks, the linear
  guess, least squares on the exact solver over the growing arc with the sensitivities
  of the exact flow as Jacobian, the outlier pass, the covariance and the goodness of
  fit.
- **the peer**: ``scipy.optimize.least_squares`` (trust region) on residuals from
  ``solve_ivp`` DOP853 (rtol 1e-10) of Euler's equations, with its default
  finite-difference Jacobian, started from our linear guess (a head start a
  research script would not have), over the whole arc at once.

CPU time (``time.process_time``), the two alternated, each warmed up first, best and
median of ``--repeats``; the machine's load average beside the figures.  Also how far
each lands from the truth, in our stated σ.

    python -m benchmarks.fit_speed               # 3 repeats of each
    python -m benchmarks.fit_speed --no-peer     # ours alone

Results go to stdout and to benchmarks/results/fit_speed.json.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import least_squares

from attitude import EulerSolver, fit_spin_state
from attitude.estimation.linear_guess import candidates
from attitude.estimation.telemetry import prepare_telemetry

RESULTS = Path(__file__).parent / "results"
MOMENTS = np.array([100.0, 200.0, 260.0])
ω0 = np.array([0.05, 0.02, 0.03])
SIGMA = 1e-4


def telemetry(seed: int = 0):
    t = np.arange(0.0, 3600.0, 1.0)
    solver = EulerSolver(MOMENTS, MOMENTS * ω0)
    rng = np.random.default_rng(seed)
    return t, solver.angular_velocity(t) + SIGMA * rng.standard_normal((t.size, 3))


def ours(t, ω):
    return fit_spin_state(t, angular_velocity=ω, gyro_sigma=SIGMA)


def peer(t, ω):
    """scipy alone: DOP853 residuals, finite differences, from our linear guess."""
    guesses, _ = candidates(prepare_telemetry(t, ω), False)
    guess = guesses[0]
    x0 = np.concatenate([guess.ω0, np.log(guess.moments[1:] / guess.moments[0])])

    def rates(x):
        J = np.array([1.0, np.exp(x[3]), np.exp(x[4])])

        def rhs(_, m):
            return np.cross(m, m / J)

        solution = solve_ivp(rhs, (t[0], t[-1]), J * x[:3], "DOP853", t, rtol=1e-10, atol=1e-14)
        return solution.y.T / J

    result = least_squares(lambda x: ((ω - rates(x)) / SIGMA).ravel(), x0, method="trf")
    return result.x


def _timed(function, *args):
    start = time.process_time()
    value = function(*args)
    return time.process_time() - start, value


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--no-peer", action="store_true")
    args = parser.parse_args(argv)
    t, ω = telemetry()
    truth = MOMENTS[1:] / MOMENTS[0]
    load_before = os.getloadavg()
    ours(t, ω)  # warm up: imports, numba's cache
    if not args.no_peer:
        peer(t[:600], ω[:600])
    our_times, peer_times = [], []
    fit = x_peer = None
    for _ in range(args.repeats):
        seconds, fit = _timed(ours, t, ω)
        our_times.append(seconds)
        if not args.no_peer:
            seconds, x_peer = _timed(peer, t, ω)
            peer_times.append(seconds)
    load_after = os.getloadavg()
    σ = fit.inertia_ratios_sigma[1:]
    report = {
        "machine": platform.processor() or platform.machine(),
        "python": platform.python_version(),
        "load_average_1min": [load_before[0], load_after[0]],
        "samples": int(t.size),
        "ours_cpu_s": {"best": min(our_times), "median": float(np.median(our_times))},
        "ours_ratio_error_in_sigma": ((fit.inertia_ratios[1:] - truth) / σ).tolist(),
        "ours_reduced_chi2": fit.reduced_chi2,
    }
    print(f"load average (1 min): {load_before[0]:.2f} before, {load_after[0]:.2f} after")
    print(
        f"fit_spin_state, 1 h at 1 Hz ({t.size} gyro samples): CPU best "
        f"{min(our_times):.3f} s, median {np.median(our_times):.3f} s; ratios off by "
        f"{np.round(report['ours_ratio_error_in_sigma'], 2).tolist()} σ, reduced chi2 "
        f"{fit.reduced_chi2:.3f}"
    )
    if peer_times:
        ratios = np.exp(x_peer[3:])
        report["peer_cpu_s"] = {"best": min(peer_times), "median": float(np.median(peer_times))}
        report["peer_ratio_error_in_our_sigma"] = ((ratios - truth) / σ).tolist()
        report["peer_over_ours_median"] = float(np.median(peer_times) / np.median(our_times))
        print(
            f"scipy DOP853 + finite differences from our guess: CPU best {min(peer_times):.3f} s, "
            f"median {np.median(peer_times):.3f} s; ratios off by "
            f"{np.round(report['peer_ratio_error_in_our_sigma'], 2).tolist()} of our σ"
        )
        print(
            f"peer / ours (medians): {report['peer_over_ours_median']:.1f}x "
            f"(peer {np.median(peer_times):.3f} s, ours {np.median(our_times):.3f} s)"
        )
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "fit_speed.json").write_text(json.dumps(report, indent=2) + "\n")


if __name__ == "__main__":
    main()
