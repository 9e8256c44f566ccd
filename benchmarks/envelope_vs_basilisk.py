"""Benchmark: the loss-of-control envelope against Basilisk, per failure case.

The case of issue 21: one simulated day of a nominal law (a sun-synchronous
Earth-observation satellite, 700 km, J2, in nadir with zero-Doppler yaw steering), a
control loss every Δτ = 10 s (8640 failures), a one-hour window after each, three body
vectors (a camera with a 25° Sun exclusion, a star tracker with a 30° Sun exclusion and
20° above the Earth's limb, a solar array), locked wheels holding 2 N m s (the
torque-free rigid body of momentum I ω_law + h).

- **attitude**: failures as the envelope computes them on a worker, a task of
  ``BATCH`` consecutive failures (``attitude.envelope.failure.evaluate_batch``: for
  each the hand-off, the exact pointing search on the shared surroundings, the rate,
  the flips; the pointing searches of the task as one set of arrays, its power
  searches together), the task's CPU divided by ``BATCH``; and a task of one
  failure, for the cost of a failure alone.
- **Basilisk** (bsk, ``/work/venv-bench``), as its users would do it: one simulation per
  failure, a rigid hub from the same initial state (σ_BN, ω_BN_B from our hand-off), RK4
  at 0.1 s over the hour, every step recorded; its cost is the simulation alone (the
  metrics read off its samples are not counted, which favours it).

CPU time (``time.process_time``), the two alternated on a sample of failures spread
over the day (at each, our task of ``BATCH`` failures from there, our failure alone,
then Basilisk's run of that failure), both warmed first.  Accuracy: Basilisk's attitude
against the exact one over each window, and the first violation of each exclusion read
on its 0.1 s samples against ours (refined to 1 ms).  ``--day`` also runs the whole
day's envelope (8640 failures) on a local cluster of 2 workers and states its wall
time.

    PYTHONPATH=. /work/venv-bench/bin/python -m benchmarks.envelope_vs_basilisk [--day]
"""

from __future__ import annotations

import argparse
import math
import os
import time

import numpy as np
from scipy.spatial.transform import Rotation

from attitude import (
    BodyVector,
    EnvelopeSettings,
    InitialState,
    KeplerianOrbit,
    NadirLaw,
    PointingSpec,
    Scenario,
    Spacecraft,
    Wheels,
    loss_of_control_envelope,
)
from attitude.envelope.failure import evaluate_batch, motion_after
from attitude.envelope.plan import make_job, plan_envelope
from attitude.pointing.shared_surroundings import shared_surroundings
from benchmarks.peer_basilisk import _simulate, mrp_to_quaternion, quaternion_to_mrp

EPOCH = "2025-05-01T10:00:00"
INERTIA = [820.0, 1040.0, 610.0]
STEP_S = 0.1
SAMPLE = 16  # failures timed on each side
BATCH = 32  # failures a task (the engine makes a task last 100 times its scheduling cost)


def case(every: float = 10.0) -> tuple[Scenario, PointingSpec, EnvelopeSettings]:
    orbit = KeplerianOrbit(
        EPOCH, 7_078_137.0, 0.001, math.radians(98.2), math.radians(170.0), 0.0,
        mean_anomaly=0.0, j2=True,
    )  # fmt: skip
    scenario = Scenario(
        "EO satellite, a day of nadir with zero-Doppler steering",
        Spacecraft("EO-1200", INERTIA),
        EPOCH,
        InitialState(law=NadirLaw("zero_doppler")),
        duration=86_400.0,
        orbit=orbit,
    )
    deg = math.radians
    pointing = PointingSpec(
        body_vectors=[
            BodyVector("camera", [0, 0, 1], deg(25.0), kind="instrument"),
            BodyVector(
                "star_tracker",
                [0.0, -0.6427876096865393, -0.766044443118978],
                deg(30.0),
                kind="star_tracker",
                earth_limb_exclusion_angle_rad=deg(20.0),
            ),
            BodyVector("solar_array", [0, 0, -1], kind="panel"),
        ],
        orbit=orbit,
    )
    settings = EnvelopeSettings(
        window=3600.0, every=every, wheels=Wheels("locked", [0.0, 2.0, 0.0]), power_threshold=0.3
    )
    return scenario, pointing, settings


def _first(t, violated) -> float:
    hits = np.flatnonzero(violated)
    return math.inf if hits.size == 0 else float(t[hits[0]])


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--day", action="store_true", help="also run the whole day on 2 workers")
    args = parser.parse_args()
    print(f"load average before: {os.getloadavg()} (2 cores)")
    scenario, pointing, settings = case()
    begin = time.process_time()
    plan = plan_envelope(scenario, pointing, settings)
    job, _, _ = make_job(plan)
    setup = time.process_time() - begin
    print(f"{job.count} failures; the plan and the hand-off states of all: {setup:.2f} s CPU")
    picks = np.linspace(0, job.count - BATCH, SAMPLE).round().astype(int)
    axes = scenario.spacecraft.principal_axes
    # Warm both sides.
    evaluate_batch(job, int(picks[0]), int(picks[0]) + 1)
    _simulate(INERTIA, [0, 0, 0.001], [0, 0, 0], 60.0, STEP_S, "rk4", STEP_S)
    ours, alone, theirs, attitude_errors, time_errors = [], [], [], [], []
    for k in picks:
        k = int(k)
        begin = time.process_time()
        evaluate_batch(job, k, k + BATCH)
        ours.append((time.process_time() - begin) / BATCH)
        begin = time.process_time()
        evaluate_batch(job, k, k + 1)
        alone.append(time.process_time() - begin)
        q = job.quaternions[k]  # scipy order (scalar last)
        q_first = np.array([q[3], q[0], q[1], q[2]])
        omega = np.linalg.solve(axes.tensor, job.momenta[k])  # the body's rate after the loss
        begin = time.process_time()
        t, sigma, _ = _simulate(
            INERTIA, omega, quaternion_to_mrp(q_first), 3600.0, STEP_S, "rk4", STEP_S
        )
        theirs.append(time.process_time() - begin)
        # Accuracy: their attitude against the exact one, and the star tracker's first
        # Sun exclusion read on their samples against ours.
        τ = float(job.seconds[k])
        trajectory = motion_after(job, k)
        exact = trajectory.attitude(τ + t)
        q_b = mrp_to_quaternion(sigma)
        basilisk = Rotation.from_quat(q_b, scalar_first=True)
        attitude_errors.append(float(np.max((exact.inv() * basilisk).magnitude())))
        shared = shared_surroundings(trajectory, job.spec, 0.0, job.scenario.stop_s)
        around = shared.at(τ + t)
        tracker = pointing.body_vectors[1]
        cosine = np.einsum("ij,ij->i", basilisk.apply(tracker.vector), around.sun_direction)
        violated = (cosine > math.cos(tracker.sun_exclusion_half_angle_rad)) & (
            around.sunlit_fraction > 0.0
        )
        row = evaluate_batch(job, k, k + 1).rows[0]
        mine = row["star_tracker_sun_exclusion_s"]
        sampled = _first(t, violated)
        if math.isfinite(mine) or math.isfinite(sampled):
            time_errors.append(abs(sampled - mine))
    ours_a, alone_a, theirs_a = np.array(ours), np.array(alone), np.array(theirs)
    print(f"load average after: {os.getloadavg()}")
    print(
        f"per failure (CPU, {SAMPLE} places alternated): attitude in tasks of {BATCH} median "
        f"{1e3 * np.median(ours_a):.1f} ms (range {1e3 * ours_a.min():.1f}-"
        f"{1e3 * ours_a.max():.1f}); Basilisk RK4 {STEP_S} s median "
        f"{1e3 * np.median(theirs_a):.0f} ms (range {1e3 * theirs_a.min():.0f}-"
        f"{1e3 * theirs_a.max():.0f}); ratio of medians "
        f"{np.median(theirs_a) / np.median(ours_a):.0f}x, "
        f"of sums {theirs_a.sum() / ours_a.sum():.0f}x"
    )
    print(
        f"a failure alone (a task of one): median {1e3 * np.median(alone_a):.1f} ms (range "
        f"{1e3 * alone_a.min():.1f}-{1e3 * alone_a.max():.1f}); Basilisk's median "
        f"{1e3 * np.median(theirs_a):.0f} ms is {np.median(theirs_a) / np.median(alone_a):.0f}x"
    )
    print(
        f"Basilisk's attitude error over the hour (against the exact motion): max "
        f"{max(attitude_errors):.2g} rad; its first star tracker Sun exclusion, read on its "
        f"0.1 s samples, differs from ours (1 ms) by at most "
        f"{max(time_errors, default=0.0):.3f} s over {len(time_errors)} failures"
    )
    print(
        f"the day on one core, extrapolated from the sample: "
        f"{job.count * np.mean(ours_a):.0f} s CPU (attitude), "
        f"{job.count * np.mean(theirs_a) / 3600:.1f} h CPU (Basilisk)"
    )
    if args.day:
        begin = time.perf_counter()
        cpu = time.process_time()
        table = loss_of_control_envelope(scenario, pointing, settings, workers=2)
        wall = time.perf_counter() - begin
        print(
            f"the whole day, {len(table)} failures ({(table['status'] == 'ok').sum()} ok) on "
            f"a local cluster of 2 workers: {wall:.0f} s wall ({time.process_time() - cpu:.0f} s "
            f"CPU on the client); load average after: {os.getloadavg()}"
        )


if __name__ == "__main__":
    main()
