"""The validity horizon and its averaged-kick screen against DOP853, on hostile cases.

Each case: the first time the attitude under gravity gradient and the torque-free one
part by the threshold, both integrated by scipy's DOP853 (rtol 1e-12: Euler's
equations and quaternion kinematics, ``torqued_reference``, none of the package's
code), against ``validity_horizon`` (its screen finds half the threshold crossed, so
the crossing comes from the splitting) and against the averaged kicks themselves
(``averaged_horizon`` at the threshold, ``attitude.trajectory.averaged_kicks``): both
within the horizon's stated accuracy, 1 % (``HORIZON_RELATIVE_ACCURACY``).

- a body near the separatrix (spinning about its intermediate axis: the Dzhanibekov
  flip), where the linearized flow grows and the kick's effect with it;
- a slow body turning at about the orbit rate (one sub-interval an eighth of an orbit);
- a fast spinner, 3 rad/s (hundreds of turns in a step), one about its minor axis at
  4 rad/s, and the oblate 5 rpm spinner of ``benchmarks.horizon_share`` (its
  sub-intervals the longest, its fastest turn nearest the bound that sets them);
- a huge torque relative to the momentum: the crossing after two and a half minutes;
- an off-axis angular impulse on a body given by a full inertia tensor (the events
  and the principal axes of the run alongside);
- and the horizon's own process does not import numba.

The orbit is a circle inclined 51.6°, written here.  A case with a burn keeps the
splitting (``tests/test_scenario_torques_against_torque_free_and_momentum_laws.py``
compares its horizon with DOP853).
"""

import math
import subprocess
import sys
import textwrap

import numpy as np
import pytest
import torqued_reference as ref
from astropy.time import Time, TimeDelta
from scipy.spatial.transform import Rotation

from attitude.scenario.events import AngularImpulse
from attitude.scenario.scenario import InitialState, Scenario
from attitude.scenario.spacecraft import Spacecraft
from attitude.scenario.torques import ScenarioTorques
from attitude.trajectory.horizon import (
    HORIZON_RELATIVE_ACCURACY,
    averaged_horizon,
    validity_horizon,
)
from attitude.trajectory.trajectory import propagate

EPOCH = "2027-03-01T00:00:00"
R0 = Rotation.from_euler("ZYX", [10, 20, 30], degrees=True)
ORBIT = ref.circular_orbit(6.9e6, tilt=Rotation.from_euler("x", 51.6, degrees=True).as_matrix())
MOMENTS = [100.0, 200.0, 300.0]

# name: (inertia, body rate (rad/s), threshold (deg), DOP853 end (s), its sampling (s))
CASES = {
    "separatrix": (MOMENTS, [0.001, 0.1, 0.001], 1.0, 400.0, 0.2),
    "slow, about the orbit rate": (MOMENTS, [0.0002, 0.0011, 0.0003], 1.0, 400.0, 1.0),
    "fast spinner, 3 rad/s": (MOMENTS, [0.05, 0.05, 3.0], 0.002, 160.0, 0.02),
    "oblate spinner, 5 rpm": ([850.0, 900.0, 1200.0], [0.02, 0.01, 0.52], 0.01, 300.0, 0.1),
    "minor axis, 4 rad/s": (MOMENTS, [4.0, 0.05, 0.05], 0.002, 100.0, 0.01),
    "huge torque, minutes": (MOMENTS, [0.003, 0.004, 0.005], 1.0, 400.0, 0.1),
}


def _dop853_crossing(tensor, m0, threshold, end, sample, impulse=None) -> float:
    """The first time the two DOP853 runs part by ``threshold``, linear between
    samples; ``impulse``: (time, body impulse) applied to both at that time."""
    t = np.arange(sample, end, sample)
    q0 = R0.as_quat(scalar_first=True)
    runs = []
    for torque in (ref.gravity_gradient(ORBIT, tensor), lambda *_: np.zeros(3)):
        if impulse is None:
            _, q = ref.integrate_dop853(tensor, m0, q0, torque, t, rtol=1e-12)
        else:
            at, kick = impulse
            before, after = t[t <= at], t[t > at]
            m, q = ref.integrate_dop853(tensor, m0, q0, torque, np.append(before, at), rtol=1e-12)
            # Restarted from the state after the impulse, its clock shifted by `at`.
            shifted = (
                ref.gravity_gradient(_Shifted(at), tensor)
                if torque.__name__ == "torque"
                else torque
            )
            _, q_after = ref.integrate_dop853(
                tensor, m[-1] + kick, q[-1], shifted, after - at, rtol=1e-12
            )
            q = np.concatenate([q[:-1], q_after])
        runs.append(q)
    angle = ref.angle(runs[0], runs[1])
    k = int(np.flatnonzero(angle >= threshold)[0])
    return t[k - 1] + (threshold - angle[k - 1]) / (angle[k] - angle[k - 1]) * sample


class _Shifted:
    """The orbit with its clock starting at ``at``."""

    mu = ORBIT.mu

    def __init__(self, at: float) -> None:
        self.at = at

    def __call__(self, t):
        return ORBIT(np.asarray(t) + self.at)


def _horizon(inertia, rate, threshold, duration, events=()):
    state = InitialState(R0, angular_velocity=np.asarray(rate, dtype=float))
    torques = ScenarioTorques(horizon_threshold=threshold)
    scenario = Scenario(
        "h",
        Spacecraft("sat", inertia),
        EPOCH,
        state,
        list(events),
        duration=duration,
        torques=torques,
    )
    trajectory = propagate(scenario)
    found = validity_horizon(trajectory, ORBIT)
    return found, averaged_horizon(trajectory, ORBIT, threshold), scenario


def _check(name, inertia, rate, threshold_deg, end, sample):
    threshold = math.radians(threshold_deg)
    found, averaged, _ = _horizon(np.array(inertia), rate, threshold, 2.0 * end)
    tensor = np.diag(inertia)
    crossing = _dop853_crossing(tensor, tensor @ np.asarray(rate), threshold, end, sample)
    assert found.within_span and found.method == "splitting", name
    assert averaged.within_span and averaged.method == "averaged kicks", name
    for horizon in (found, averaged):
        assert abs(horizon.horizon_s - crossing) < HORIZON_RELATIVE_ACCURACY * crossing, (
            name,
            horizon.method,
            horizon.horizon_s,
            crossing,
        )


@pytest.mark.parametrize("name", list(CASES))
def test_the_horizon_of_a_hostile_case_against_dop853(name):
    _check(name, *CASES[name])


def test_the_horizon_across_an_impulse_on_a_full_tensor_against_dop853():
    axes = Rotation.from_euler("xyz", [20, -35, 50], degrees=True).as_matrix()
    tensor = axes @ np.diag([150.0, 200.0, 320.0]) @ axes.T
    rate = np.array([0.005, 0.004, 0.006])
    kick = np.array([0.3, -0.2, 0.1])  # N m s, body axes
    at = Time(EPOCH, scale="utc") + TimeDelta(120.0, format="sec")
    found, averaged, scenario = _horizon(
        tensor, rate, math.radians(1.0), 1200.0, [AngularImpulse(at, kick, "body")]
    )
    offset = scenario.events[0][0]
    crossing = _dop853_crossing(
        tensor, tensor @ rate, math.radians(1.0), 600.0, 0.1, (offset, kick)
    )
    assert offset < crossing < 400.0 and found.within_span and averaged.within_span
    for horizon in (found, averaged):
        assert abs(horizon.horizon_s - crossing) < HORIZON_RELATIVE_ACCURACY * crossing, (
            horizon.method,
            horizon.horizon_s,
            crossing,
        )


def test_the_horizons_process_imports_no_numba():
    """A run's horizon beyond its span (the screen's answer), in the process forked
    beside it, neither finds numba imported nor imports it (numba's start alone was a
    tenth of a second)."""
    code = textwrap.dedent(
        """
        import sys
        import numpy as np
        from scipy.spatial.transform import Rotation
        sys.path.insert(0, "tests")
        import torqued_reference as ref
        from attitude.report.beside import Beside
        from attitude.scenario.scenario import InitialState, Scenario
        from attitude.scenario.spacecraft import Spacecraft
        from attitude.trajectory.horizon import validity_horizon
        from attitude.trajectory.trajectory import propagate

        state = InitialState(Rotation.identity(), angular_velocity=np.array([0.01, 0.02, 0.5]))
        scenario = Scenario(
            "h", Spacecraft("s", [850.0, 900.0, 1200.0]), "2027-03-01T00:00:00", state, [],
            duration=86400.0,
        )
        trajectory = propagate(scenario)
        orbit = ref.circular_orbit(7.0e6)

        def horizon():
            found = validity_horizon(trajectory, orbit)
            assert found.method == "averaged kicks" and not found.within_span
            return found.searched_s, "numba" in sys.modules

        before = "numba" in sys.modules
        with Beside(horizon) as beside:
            searched, child = beside.result()
        print(before, child, searched, "numba" in sys.modules)
        """
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=300
    )
    before, child, searched, after = done.stdout.split()
    assert (before, child, after) == ("False", "False", "False")
    assert float(searched) > 0.0
