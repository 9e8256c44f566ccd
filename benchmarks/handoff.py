"""Benchmark: what the exact hand-off at a control loss costs, per failure instant.

For the loss-of-control envelope: a day of nadir pointing with zero-Doppler steering
(sun-synchronous, J2), a failure every 10 s (8640 instants), a one-hour window after
each, sampled every 10 s (361 times).  CPU time (``time.process_time``), best of a few
runs after a warm-up, with the load average beside it:

1. the initial states of all 8640 hand-offs, from one evaluation of the law at every
   instant (``hand_off_states``);
2. locked wheels, one instant at a time: ``hand_off`` (the exact solver) and its window;
3. spinning wheels, one instant at a time: ``hand_off`` (the gyrostat's splitting) at
   a fixed step of 10 s, and with the step chosen for 1e-6 rad over the window;
4. spinning wheels, every instant at once: ``propagate_batch(..., wheel_momentum=h)``
   at 10 s.

    python -m benchmarks.handoff
"""

from __future__ import annotations

import math
import os
import time

import numpy as np
from scipy.spatial.transform import Rotation

from attitude import KeplerianOrbit, NadirLaw, Wheels, hand_off, hand_off_states, propagate_batch

EPOCH = "2025-05-01T10:00:00"
INERTIA = np.array([820.0, 1040.0, 610.0])
H = np.array([0.0, 2.0, 0.0])
WINDOW = np.arange(0.0, 3600.0 + 1.0, 10.0)


def _best(function, repeats: int) -> float:
    function()
    best = math.inf
    for _ in range(repeats):
        start = time.process_time()
        function()
        best = min(best, time.process_time() - start)
    return best


def main() -> None:
    orbit = KeplerianOrbit(
        EPOCH,
        7_078_137.0,
        0.001,
        math.radians(98.2),
        math.radians(170.0),
        0.0,
        mean_anomaly=0.0,
        j2=True,
    )
    bound = NadirLaw("zero_doppler").bind(EPOCH, 0.0, 86400.0, orbit)
    taus = np.arange(0.0, 86400.0, 10.0)
    print(f"load average before: {os.getloadavg()[0]:.2f} (2 cores)")

    law = _best(lambda: bound.state(taus), 2)
    states = bound.state(taus)
    spinning, locked = Wheels("spinning", H), Wheels("locked", H)
    initial = _best(lambda: hand_off_states(states, INERTIA, spinning), 3)
    print(f"law at {taus.size} instants:             {law / taus.size * 1e6:8.2f} µs an instant")
    print(f"hand_off_states for all of them:   {initial / taus.size * 1e6:8.3f} µs an instant")

    picked = taus[:: taus.size // 40]  # 40 instants spread over the day

    def one_at_a_time(wheels, **options):
        for tau in picked:
            k = int(tau // 10.0)
            motion = hand_off(
                states.attitude[k], states.angular_velocity[k], INERTIA, tau, wheels, **options
            )
            motion.attitude_quaternion(tau + WINDOW)

    for label, wheels, options in (
        ("locked, exact solver", locked, {}),
        ("spinning, step 10 s", spinning, {"step": 10.0}),
        ("spinning, 1e-6 rad", spinning, {"accuracy": 1e-6, "span": 3600.0}),
    ):
        cost = _best(lambda wheels=wheels, options=options: one_at_a_time(wheels, **options), 2)
        print(f"hand_off + window, {label:22s} {cost / picked.size * 1e3:8.2f} ms an instant")

    attitudes, momenta = hand_off_states(states, INERTIA, spinning)
    chunk = 1024

    def batch():
        for first in range(0, taus.size, chunk):
            part = slice(first, first + chunk)
            propagate_batch(
                INERTIA,
                momenta[part],
                Rotation.from_quat(attitudes[part].as_quat()),
                0.0,
                WINDOW,
                step=10.0,
                wheel_momentum=H,
            )

    cost = _best(batch, 1)
    print(
        f"propagate_batch, spinning, 10 s:   {cost / taus.size * 1e3:8.3f} ms an instant "
        f"({cost:.1f} s for the day)"
    )
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
