"""The attitude-law cases compared with Orekit's attitude providers.

Shared by the generator of the frozen Orekit outputs (``tests/data/orekit/generate_laws.py``,
which needs orekit-jpype and a JDK) and by ``tests/test_laws_against_orekit.py`` (which
reads the frozen outputs only).  Each case names our law and the Orekit provider of
the same definition; Orekit is fed our own inputs (the orbit's position, velocity and
acceleration, the apparent Sun and Moon from the spacecraft, the same IERS EOP), so
that the comparison checks the laws, not the ephemerides.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial.transform import Rotation

from attitude.environment.keplerian import KeplerianOrbit
from attitude.laws.align_constrain import AlignConstrainLaw
from attitude.laws.directions import GroundSite
from attitude.laws.named_laws import InertialLaw, NadirLaw, OrbitFrameLaw, SunLaw, TargetLaw

EPOCH = "2024-06-15T00:00:00"  # UTC; final (Bulletin B) EOP there
# Epochs (TT seconds after EPOCH) over two LEO orbits, not on any grid of the inputs.
SECONDS = np.array(
    [0.0, 317.3, 1234.5, 2046.25, 2950.0, 3777.7, 4600.1, 5555.5, 6400.0, 7310.9, 8888.8, 10000.0]
)

ORBITS = {
    # Sun-synchronous LEO (J2 secular drift: its rates come from our analytic derivatives).
    "sso": dict(
        semi_major_axis_m=7_078_137.0,
        eccentricity=0.0012,
        inclination=math.radians(98.19),
        raan=math.radians(63.0),
        argument_of_perigee=math.radians(90.0),
        mean_anomaly=math.radians(10.0),
        j2=True,
    ),
    # A Molniya-like orbit: perigee at 1000 km, apogee at 39 600 km.
    "heo": dict(
        semi_major_axis_m=26_678_137.0,
        eccentricity=0.7234,
        inclination=math.radians(63.4),
        raan=math.radians(200.0),
        argument_of_perigee=math.radians(270.0),
        mean_anomaly=math.radians(-20.0),
    ),
}

# Toulouse, at the height of its ground station.
SITE = dict(latitude=math.radians(43.5605), longitude=math.radians(1.4688), height=150.0)
# An offset (body → LVLH) for LofOffset: Orekit's XYZ angles 0.1, −0.2, 0.3 rad, turned
# into our rotation by the generator from Orekit's own offset (see _offset).
LOF_ANGLES = (0.1, -0.2, 0.3)
INERTIAL_ROTVEC = (0.3, -1.1, 0.7)


def orbit(name: str) -> KeplerianOrbit:
    return KeplerianOrbit(EPOCH, **ORBITS[name])


def site() -> GroundSite:
    return GroundSite(SITE["latitude"], SITE["longitude"], SITE["height"], name="Toulouse")


def lof_offset() -> Rotation:
    """Orekit's LofOffset(XYZ, 0.1, −0.2, 0.3) as our body → LVLH rotation: Orekit's
    offset rotation is R(order, VECTOR_OPERATOR, α1, α2, α3) reverted, a frame
    transform LVLH → body, i.e. our body → LVLH matrix transposed twice over: the
    vector operator of the angles is our body → LVLH rotation."""
    a1, a2, a3 = LOF_ANGLES
    return Rotation.from_euler("XYZ", [a1, a2, a3])


KEPLERIAN_JERK = (
    "Orekit takes the jerk of a Keplerian orbit from (r, v, a); this orbit's J2 drift changes it"
)
# case → (orbit, our law, whether Orekit's angular acceleration is the exact derivative
# of its rate: where it is not, the reason, and only attitude and rate are compared).
CASES = {
    "inertial": ("sso", lambda: InertialLaw(Rotation.from_rotvec(INERTIAL_ROTVEC)), None),
    "lvlh": ("sso", lambda: OrbitFrameLaw("lvlh"), KEPLERIAN_JERK),
    "lvlh_offset": ("heo", lambda: OrbitFrameLaw("lvlh", lof_offset()), None),
    "rtn": ("heo", lambda: OrbitFrameLaw("rtn"), None),
    "nadir": ("sso", lambda: NadirLaw(), KEPLERIAN_JERK),
    "nadir_heo": ("heo", lambda: NadirLaw(), None),
    "body_centre": ("sso", lambda: NadirLaw(vertical="geocentric"), KEPLERIAN_JERK),
    "zero_doppler": (
        "sso",
        lambda: NadirLaw("zero_doppler"),
        "YawCompensation sets the ground velocity's second derivative to zero",
    ),
    "yaw_steering": ("sso", lambda: NadirLaw("sun"), None),
    "sun": ("sso", lambda: SunLaw(), "CelestialBodyPointed returns no angular acceleration"),
    "moon": (
        "heo",
        lambda: TargetLaw("moon"),
        "CelestialBodyPointed returns no angular acceleration",
    ),
    "ground_site": ("sso", lambda: TargetLaw(site()), KEPLERIAN_JERK),
    "aligned_sun_momentum": (
        "sso",
        lambda: AlignConstrainLaw("+x", "sun", "+z", "orbit_normal"),
        "PredefinedTarget.MOMENTUM takes the jerk as zero",
    ),
    "aligned_velocity_earth": (
        "heo",
        lambda: AlignConstrainLaw("+y", "velocity", "-z", "earth_centre"),
        "PredefinedTarget.VELOCITY takes the jerk as zero",
    ),
    "aligned_nadir_sun": ("sso", lambda: AlignConstrainLaw("-z", "nadir", "+x", "sun"), None),
    "aligned_site_moon": ("sso", lambda: AlignConstrainLaw("+z", site(), "+y", "moon"), None),
}
