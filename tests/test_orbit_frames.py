"""Orbit frames (LVLH, RTN) by hand, their round trip, and a nadir-pointing spacecraft.

- The axes against their definitions (CCSDS/SANA "LVLH": z towards the Earth's centre,
  y against the orbit normal, x = y × z; "RTN": R radial, N along r × v, T = N × R) on
  constructed states, where they can be written down.
- LVLH ↔ ICRF round trips, through the scenario file: an attitude given in LVLH at the
  epoch comes back from the body → LVLH quaternion of the outputs.
- A spacecraft placed in LVLH at the epoch (identity quaternion, one line of TOML) and
  turning once per orbit about its −y axis, on a circular two-body orbit: its +z stays
  on nadir (nadir angle 0 to 1e-9 rad) and its attitude in LVLH stays the identity, over
  a whole orbit.  Torque-free, this is a steady spin about a principal axis: the closed
  form and the orbit must agree on the rate for this to hold.
"""

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.environment.frames import (
    euler_angles_deg,
    lvlh_to_icrf,
    orbit_frame_to_icrf,
    rtn_to_icrf,
)
from attitude.files.scenario_reader import ScenarioFileError, load_scenario
from attitude.pointing.sampling import pointing_samples
from attitude.trajectory.trajectory import propagate


def test_lvlh_and_rtn_axes_by_hand():
    r = np.array([7.0e6, 0.0, 0.0])
    v = np.array([0.0, 5.0e3, 5.0e3])  # an orbit inclined 45°, at the node
    lvlh = lvlh_to_icrf(r, v).as_matrix()
    s = math.sqrt(0.5)
    np.testing.assert_allclose(lvlh[:, 2], [-1.0, 0.0, 0.0], atol=1e-15)  # z: nadir
    np.testing.assert_allclose(lvlh[:, 1], [0.0, s, -s], atol=1e-15)  # y: −(r × v)/|r × v|
    np.testing.assert_allclose(lvlh[:, 0], [0.0, s, s], atol=1e-15)  # x: along v here
    rtn = rtn_to_icrf(r, v).as_matrix()
    np.testing.assert_allclose(rtn, np.column_stack([lvlh[:, 2] * -1, lvlh[:, 0], -lvlh[:, 1]]))
    # On an eccentric orbit x is v's horizontal part, not v.
    v_climbing = np.array([1.0e3, 7.0e3, 0.0])
    x = lvlh_to_icrf(r, v_climbing).as_matrix()[:, 0]
    np.testing.assert_allclose(x, [0.0, 1.0, 0.0], atol=1e-15)


def test_round_trip_and_euler_angles():
    rng = np.random.default_rng(7)
    r = rng.normal(size=(50, 3)) * 7e6
    v = rng.normal(size=(50, 3)) * 7e3
    body_to_icrf = Rotation.random(50, random_state=3)
    for frame in ("lvlh", "rtn"):
        to_icrf = orbit_frame_to_icrf(frame, r, v)
        body_to_frame = to_icrf.inv() * body_to_icrf
        back = to_icrf * body_to_frame
        assert np.max((back.inv() * body_to_icrf).magnitude()) < 1e-15
    # A yaw of 30° then a pitch of 10° in LVLH, as ZYX Euler angles.
    attitude = Rotation.from_euler("ZYX", [30.0, 10.0, 0.0], degrees=True)
    np.testing.assert_allclose(euler_angles_deg(attitude, "ZYX"), [30.0, 10.0, 0.0], atol=1e-12)
    with pytest.raises(InputError, match="frame must be one of lvlh, rtn"):
        orbit_frame_to_icrf("vvlh", r, v)
    with pytest.raises(InputError, match="the orbit normal r × v is zero"):
        lvlh_to_icrf([7e6, 0.0, 0.0], [7e3, 0.0, 0.0])


NADIR = """
[scenario]
name = "nadir"
epoch = "2027-06-21T00:00:00"

[spacecraft]
name = "3U"
principal_moments = [0.0067, 0.0431, 0.0419]   # y is the axis of greatest inertia

[initial_state]
frame = "lvlh"                 # body axes = LVLH axes at the epoch: +z on nadir
quaternion = {quaternion}
angular_velocity = [0.0, {rate}, 0.0]

[output]
duration = {duration}
step = 30.0

[pointing]
lvlh_euler_sequence = "ZYX"

[pointing.keplerian]
semi_major_axis = {{ value = 6878.137, unit = "km" }}
eccentricity = 0.0
inclination = {{ value = 97.4, unit = "deg" }}
raan = {{ value = 40.0, unit = "deg" }}
argument_of_perigee = {{ value = 0.0, unit = "deg" }}
mean_anomaly = {{ value = 10.0, unit = "deg" }}

[[pointing.body_vectors]]
name = "camera"
vector = [0.0, 0.0, 1.0]
"""
MU = 3.986004418e14
A = 6_878_137.0
ORBIT_RATE = math.sqrt(MU / A**3)


def _load(tmp_path, quaternion="[1.0, 0.0, 0.0, 0.0]", rate=-ORBIT_RATE, duration=None):
    duration = 2 * math.pi / ORBIT_RATE if duration is None else duration
    path = tmp_path / "nadir.toml"
    path.write_text(NADIR.format(quaternion=quaternion, rate=repr(rate), duration=duration))
    return load_scenario(path)


def test_a_nadir_pointing_spacecraft_stays_on_nadir(tmp_path):
    loaded = _load(tmp_path)
    trajectory = propagate(loaded.scenario)
    samples = pointing_samples(trajectory, loaded.pointing, loaded.scenario.output_seconds())
    camera = samples.vectors[0]
    assert camera.nadir_angle_rad.max() < 1e-9
    np.testing.assert_allclose(samples.q_body_to_lvlh[:, 0], 1.0, atol=1e-15)
    assert np.abs(samples.lvlh_euler_deg).max() < 1e-7
    # Its limb angle is minus the Earth's angular radius: it looks at the Earth's centre.
    np.testing.assert_allclose(
        camera.earth_limb_angle_rad, -samples.earth_angular_radius_rad, atol=1e-9
    )


def test_an_attitude_given_in_lvlh_comes_back_in_lvlh(tmp_path):
    q = Rotation.from_euler("ZYX", [25.0, -40.0, 70.0], degrees=True).as_quat(scalar_first=True)
    loaded = _load(tmp_path, quaternion=str(q.tolist()), rate=0.0, duration=60.0)
    samples = pointing_samples(propagate(loaded.scenario), loaded.pointing, np.array([0.0]))
    sign = np.sign(samples.q_body_to_lvlh[0, 0] * q[0])
    np.testing.assert_allclose(samples.q_body_to_lvlh[0], sign * q, atol=1e-15)
    np.testing.assert_allclose(samples.lvlh_euler_deg[0], [25.0, -40.0, 70.0], atol=1e-12)


def test_lvlh_without_an_orbit_is_refused(tmp_path):
    path = tmp_path / "bad.toml"
    text = NADIR.format(quaternion="[1.0, 0.0, 0.0, 0.0]", rate="0.0", duration=60.0)
    path.write_text(text.split("[pointing]")[0])
    with pytest.raises(
        ScenarioFileError,
        match=r"bad\.toml: initial_state\.frame: frame = "
        r"'lvlh' needs an orbit",
    ):
        load_scenario(path)
