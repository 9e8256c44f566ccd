"""Scenarios built in Python (no TOML file), propagated, and written as reports.

    python docs/examples/scenario_in_python.py results/t_handle

A T-handle spun about its intermediate axis, knocked by an angular impulse after a
minute: its flips before and after, its attitude as scalar-first quaternions
(w, x, y, z, body -> ICRF), and the report that ``attitude run`` would write.

Then a small satellite on an orbit (``results/t_handle_on_orbit``): the orbit is given
once, to the Scenario; its gravity gradient (``gravity_gradient=True``) and the
pointing (a ``PointingSpec`` without an orbit) both use it.
"""

import sys
from pathlib import Path

import astropy.units as u
import numpy as np
from astropy.time import Time
from scipy.spatial.transform import Rotation

from attitude import (
    AngularImpulse,
    BodyVector,
    InitialState,
    KeplerianOrbit,
    PointingSpec,
    Scenario,
    ScenarioTorques,
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


def build_on_orbit() -> tuple[Scenario, PointingSpec]:
    """A slowly tumbling small satellite in a 500 km sun-synchronous orbit, under the
    gravity gradient of that orbit, with a star tracker and a Sun sensor."""
    epoch = Time("2027-06-21T00:00:00", scale="utc")
    orbit = KeplerianOrbit(  # given once, here
        epoch,
        semi_major_axis_m=6878.137e3,
        eccentricity=0.0,
        inclination=97.4 * u.deg,
        raan=90.0 * u.deg,
        argument_of_perigee=0.0 * u.deg,
        mean_anomaly=0.0 * u.deg,
    )
    scenario = Scenario(
        "tumbler on orbit",
        Spacecraft("smallsat", inertia=[10.0, 12.0, 15.0]),  # kg m²
        epoch,
        InitialState(Rotation.identity(), angular_velocity=np.radians([0.5, 1.0, -0.3])),
        duration=600.0 * u.s,
        step=10.0,
        orbit=orbit,
        torques=ScenarioTorques(gravity_gradient=True),  # on the scenario's orbit
    )
    pointing = PointingSpec(  # no orbit: the scenario's
        [
            BodyVector(
                "tracker",
                [0.0, 0.0, -1.0],
                sun_exclusion_half_angle_rad=40.0 * u.deg,
                earth_limb_exclusion_angle_rad=20.0 * u.deg,
                kind="star_tracker",
            ),
            BodyVector("sun_sensor", [1.0, 0.0, 0.0], sun_inclusion_half_angle_rad=60.0 * u.deg),
        ]
    )
    return scenario, pointing


def on_orbit(out_dir: Path) -> dict:
    scenario, pointing = build_on_orbit()
    return write_report(scenario, out_dir, pointing)


if __name__ == "__main__":
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "results/t_handle")
    main(out)
    on_orbit(out.with_name(out.name + "_on_orbit"))
