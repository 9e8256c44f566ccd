"""A scenario built in Python (no TOML file), propagated, and written as a report.

    python docs/examples/scenario_in_python.py results/t_handle

A T-handle spun about its intermediate axis, knocked by an angular impulse after a
minute: its flips before and after, its attitude as scalar-first quaternions
(w, x, y, z, body -> ICRF), and the report that ``attitude run`` would write.
"""

import sys
from pathlib import Path

import astropy.units as u
import numpy as np
from astropy.time import Time
from scipy.spatial.transform import Rotation

from attitude import (
    AngularImpulse,
    InitialState,
    Scenario,
    Spacecraft,
    Trajectory,
    propagate,
    write_report,
)


def build() -> Scenario:
    """The scenario: every value in SI units, or as an astropy Quantity."""
    spacecraft = Spacecraft("T-handle", inertia=[100.0, 200.0, 300.0])  # kg m², principal
    epoch = Time("2025-01-01T00:00:00", scale="utc")
    initial = InitialState(
        attitude=Rotation.identity(),  # body -> inertial (ICRF)
        angular_velocity=np.array([1e-3, 1.0, 1e-3]),  # rad/s, body axes
    )
    knock = AngularImpulse(epoch + 60.0 * u.s, np.array([0.0, 0.0, 20.0]))  # N m s, body
    return Scenario(
        "t-handle knocked", spacecraft, epoch, initial, [knock], duration=120.0 * u.s, step=1.0
    )


def describe(scenario: Scenario, trajectory: Trajectory) -> None:
    times = scenario.times([0.0, 30.0, 90.0])  # TT seconds since the epoch -> Time
    q = trajectory.attitude_quaternion(times)  # (3, 4): w, x, y, z; body -> ICRF
    for text, row in zip(times.isot, q, strict=True):
        print(f"{text}  q_body_to_icrf (w, x, y, z) = {np.round(row, 6)}")
    flips = trajectory.flip_times()  # TT seconds since the epoch, closed form
    print(f"{flips.size} flips; the first at {np.round(flips[:3], 2)} s")


def main(out_dir: Path) -> dict:
    scenario = build()
    describe(scenario, propagate(scenario))
    return write_report(scenario, out_dir)  # what `attitude run` writes; returns the summary


if __name__ == "__main__":
    main(Path(sys.argv[1] if len(sys.argv) > 1 else "results/t_handle"))
