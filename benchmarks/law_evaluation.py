"""Benchmark: what evaluating an attitude law costs (attitude, rate and acceleration).

For each law, on a Keplerian orbit (analytic orbit derivatives) and on SGP4 (finite
differences of the orbit): the CPU time (``time.process_time``) of a day at 1 s
(86 400 epochs in one call) per epoch, and of one epoch alone (what a root search
pays per call), best of a few runs.  The load average is printed beside the figures.

    python -m benchmarks.law_evaluation
"""

from __future__ import annotations

import math
import os
import time

import numpy as np

from attitude import (
    AlignConstrainLaw,
    GroundSite,
    KeplerianOrbit,
    NadirLaw,
    OrbitFrameLaw,
    SunLaw,
    TargetLaw,
    TleOrbit,
)

EPOCH = "2024-06-15T00:00:00"
TLE = (
    "1 25544U 98067A   24166.50000000  .00016717  00000-0  10270-3 0  9001",
    "2 25544  51.6416 247.4627 0006703 130.5360 325.0288 15.72125391563537",
)
LAWS = {
    "orbit_frame lvlh": lambda: OrbitFrameLaw("lvlh"),
    "nadir": lambda: NadirLaw(),
    "nadir zero_doppler": lambda: NadirLaw("zero_doppler"),
    "nadir sun": lambda: NadirLaw("sun"),
    "sun": lambda: SunLaw(),
    "target site": lambda: TargetLaw(GroundSite(math.radians(43.56), math.radians(1.47), 150.0)),
    "align sun/orbit normal": lambda: AlignConstrainLaw("+x", "sun", "+z", "orbit_normal"),
}


def _best(function, repeats: int) -> float:
    function()  # warm: caches of the EOP, the Earth's rotation nodes, the ephemeris
    best = math.inf
    for _ in range(repeats):
        start = time.process_time()
        function()
        best = min(best, time.process_time() - start)
    return best


def main() -> None:
    orbits = {
        "keplerian": KeplerianOrbit(
            EPOCH, 7_078_137.0, 0.0012, 1.7138, 1.0996, 1.5708, mean_anomaly=0.17, j2=True
        ),
        "sgp4": TleOrbit(*TLE),
    }
    day = np.arange(0.0, 86400.0, 1.0)
    print(f"load average before: {os.getloadavg()[0]:.2f}")
    print(f"{'law':24s} {'orbit':10s} {'day at 1 s, per epoch':>22s} {'one epoch':>12s}")
    for name, make in LAWS.items():
        for orbit_name, orbit in orbits.items():
            bound = make().bind(EPOCH, 0.0, 86400.0, orbit)
            batch = _best(lambda bound=bound: bound.state(day), 2) / day.size
            single = _best(lambda bound=bound: bound.state([4321.5]), 20)
            print(f"{name:24s} {orbit_name:10s} {batch * 1e6:19.2f} µs {single * 1e3:9.2f} ms")
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
