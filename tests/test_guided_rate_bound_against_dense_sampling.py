"""The body-rate bound of a guided segment (what the exact pointing search and the AEM
sampling rely on) against the rate sampled every 10 ms, where it is hardest: a ground
station passed straight overhead (the tracking rate peaks at v/h in a few tens of
seconds), an align-and-constrain law whose directions come within 0.3° of each other
(its rate about the primary peaks there), and a slew.
"""

import astropy.units as u
import numpy as np
import pytest
from eo_orbit import EPOCH, ORBIT

from attitude import (
    AlignConstrainLaw,
    GroundSite,
    NadirLaw,
    SlewLimits,
    SunLaw,
    TargetLaw,
)
from attitude.laws.slews import Slew
from attitude.solver.inertia import principal_axes
from attitude.trajectory.guided import GuidedMotion

INERTIA = principal_axes([820.0, 1040.0, 610.0])


def _overhead_site() -> GroundSite:
    """The sub-satellite point at t = 900 s: the pass goes straight over it."""
    bound = NadirLaw().bind(EPOCH, 0.0, 1800.0, ORBIT)
    at = bound.at([900.0])
    r = at.position_itrs.value[0]
    lat = np.arctan2(r[2], np.hypot(r[0], r[1]))  # geocentric: within 0.2° of the foot
    lon = np.arctan2(r[1], r[0])
    return GroundSite(lat, lon, 0.0, name="overhead")


def _near_parallel_law() -> AlignConstrainLaw:
    """+x on the velocity, +y towards a fixed direction 0.3° from the velocity at 900 s."""
    bound = NadirLaw().bind(EPOCH, 0.0, 1800.0, ORBIT)
    v = bound.at([900.0]).velocity.value[0]
    v = v / np.linalg.norm(v)
    across = np.cross(v, [0.0, 0.0, 1.0])
    across /= np.linalg.norm(across)
    fixed = np.cos(np.radians(0.3)) * v + np.sin(np.radians(0.3)) * across
    return AlignConstrainLaw("+x", "velocity", "+y", fixed)


CASES = {
    "a pass overhead": lambda: TargetLaw(_overhead_site()),
    "directions 0.3 deg apart": _near_parallel_law,
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_rate_bound_holds_where_the_rate_peaks(case):
    law = CASES[case]()
    bound = law.bind(EPOCH, 0.0, 1800.0, ORBIT)
    motion = GuidedMotion(bound, INERTIA, 0.0, 1800.0, "law")
    t = np.arange(0.0, 1800.0, 0.01)
    rate = np.linalg.norm(bound.state(t).angular_velocity, axis=1)
    assert np.max(rate) > 5e-3  # the peak is there to be bounded
    assert motion.angular_rate_bound >= np.max(rate)
    assert motion.angular_rate_bound < 2.0 * np.max(rate)  # and not far above it
    # The layers above read the bounds of |Iω| and ½ω·Iω from it.
    momentum = np.linalg.norm(motion.angular_momentum(t[::100]), axis=1)
    assert motion.angular_momentum_norm >= np.max(momentum)


def test_rate_bound_of_a_slew():
    limits = SlewLimits(1.0 * u.deg / u.s, 0.05 * u.deg / u.s**2)
    start = NadirLaw("zero_doppler").bind(EPOCH, 0.0, 1800.0, ORBIT).state([600.0])
    target = SunLaw("-z", "+x", "orbit_normal").bind(EPOCH, 600.0, 1800.0, ORBIT)
    slew = Slew(600.0, start.attitude[0], start.angular_velocity[0], target, limits, 1800.0)
    motion = GuidedMotion(slew, INERTIA, 600.0, slew.end_s, "slew")
    t = np.arange(600.0, slew.end_s, 0.01)
    rate = np.max(np.linalg.norm(slew.state(t).angular_velocity, axis=1))
    assert rate <= motion.angular_rate_bound <= limits.max_rate
