"""``attitude.cli`` with ``TleOrbit.position_velocity`` evaluated in blocks of epochs.

For ``report_one_day --blocked-orbit`` only: it measures what the peak memory of a long
run with a TLE becomes once the orbit's nodes are sampled in blocks (a change that
belongs in attitude.orbit / attitude.pointing, whose owner makes it).  At once,
skyfield's TEME -> GCRS transformation holds about 21 kB per epoch: 0.9 GB for the
43 203 orbit nodes of 30 days.  The positions are the same, block or not.

    python -m benchmarks.blocked_orbit_run run SCENARIO --out DIR
"""

from __future__ import annotations

import sys

import numpy as np

BLOCK = 1000


def main() -> int:
    from attitude.orbit import TleOrbit

    whole = TleOrbit.position_velocity

    def in_blocks(self, times):
        if np.size(times) <= BLOCK:
            return whole(self, times)
        flat = times.ravel()
        parts = [whole(self, flat[a : a + BLOCK]) for a in range(0, flat.size, BLOCK)]
        return np.concatenate([p for p, _ in parts]), np.concatenate([v for _, v in parts])

    TleOrbit.position_velocity = in_blocks
    from attitude.cli import main as cli

    return cli(sys.argv[1:])


if __name__ == "__main__":
    sys.exit(main())
