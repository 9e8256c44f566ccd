"""A scenario with laws built in Python (``from attitude import ...``, no TOML) against
the same scenario read from its file (scenarios/eo_modes_control_loss.toml): the same
segments, the same attitude, rates and momentum at every instant, bit for bit or to
the last digits.
"""

from pathlib import Path

import astropy.units as u
import numpy as np
from astropy.time import Time

from attitude import (
    ControlLoss,
    GroundSite,
    InitialState,
    KeplerianOrbit,
    ModeChange,
    NadirLaw,
    Scenario,
    SlewLimits,
    Spacecraft,
    SunLaw,
    TargetLaw,
    Wheels,
    load_scenario,
    propagate,
)

EXAMPLE = Path(__file__).parents[1] / "scenarios" / "eo_modes_control_loss.toml"


def _in_python() -> Scenario:
    epoch = Time("2025-05-01T10:00:00", scale="utc")
    orbit = KeplerianOrbit(
        epoch,
        7078.137 * u.km,
        0.001,
        98.2 * u.deg,
        170.0 * u.deg,
        0.0 * u.deg,
        mean_anomaly=0.0 * u.deg,
        j2=True,
    )
    kiruna = GroundSite(67.857 * u.deg, 20.964 * u.deg, 400.0, name="kiruna")
    slew = SlewLimits(1.0 * u.deg / u.s, 0.05 * u.deg / u.s**2)
    imaging = NadirLaw(yaw_steering="zero_doppler")
    return Scenario(
        "Sun-synchronous EO satellite: nadir, station pass, Sun charging, control loss",
        Spacecraft("EO-1200", [820.0, 1040.0, 610.0]),
        epoch,
        InitialState(law=imaging),
        [
            ModeChange(1200.0, TargetLaw(kiruna, "+z", "+x"), slew, label="station pass"),
            ModeChange(2100.0, imaging, slew, label="imaging"),
            ModeChange(3000.0, SunLaw("-z", "+x", "orbit_normal"), slew, label="charging"),
            ModeChange(4800.0, imaging, slew, label="imaging"),
            ControlLoss(6600.0, Wheels("spinning", [0.0, 2.0, 0.0]), label="safe-mode trigger"),
        ],
        duration=10200.0,
        step=10.0,
        orbit=orbit,
    )


def test_the_same_motion_from_python_and_from_the_file():
    from_file = propagate(load_scenario(EXAMPLE).scenario)
    from_python = propagate(_in_python())
    assert [(s.start_s, s.end_s, s.solver.formula) for s in from_python.segments] == [
        (s.start_s, s.end_s, s.solver.formula) for s in from_file.segments
    ]
    t = np.linspace(0.0, 10200.0, 2041)
    assert np.array_equal(from_python.attitude_quaternion(t), from_file.attitude_quaternion(t))
    assert np.array_equal(from_python.angular_velocity(t), from_file.angular_velocity(t))
    assert np.array_equal(from_python.angular_momentum(t), from_file.angular_momentum(t))
