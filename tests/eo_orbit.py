"""The sun-synchronous orbit of the Earth-observation tests (the examples' orbit in
``scenarios/eo_modes_control_loss.toml``): 700 km, 98.2°, J2, from 2025-05-01 10:00 UTC."""

from __future__ import annotations

import astropy.units as u
from astropy.time import Time

from attitude import KeplerianOrbit

EPOCH = Time("2025-05-01T10:00:00", scale="utc")
ORBIT = KeplerianOrbit(
    EPOCH,
    7078.137 * u.km,
    0.001,
    98.2 * u.deg,
    170 * u.deg,
    0 * u.deg,
    mean_anomaly=0 * u.deg,
    j2=True,
)
