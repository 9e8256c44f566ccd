"""An OEM whose one segment covers the span exactly, written from a Keplerian orbit,
against that Keplerian orbit.

Everything that samples the orbit around the span keeps within what the file serves:
the shared surroundings' pieces (aligned on TT multiples of 120 s from J2000, they
reached up to 121 s before the span: the file was refused naming an epoch 68.3 s before
the scenario's, a regression of a7ba2bc), the validity horizon's interpolated orbit (two
nodes of margin), and the splitting's last step, which reached past the span's end when
the step does not divide it.  Each run below is accepted, and gives what the Keplerian
orbit gives, within the file's interpolation (Lagrange of degree 5 on 60 s nodes).
"""

import astropy.units as u
import numpy as np
import pytest
from astropy.time import Time

from attitude.environment.keplerian import KeplerianOrbit
from attitude.environment.timescales import offline_time, time_from_tt_seconds
from attitude.files.scenario_reader import load_scenario
from attitude.pointing.shared_surroundings import SharedSurroundings, clear_cache
from attitude.pointing.surroundings import scenario_jd
from attitude.report.plan import plan_run

EPOCH = "2027-06-21T00:00:00"
SPAN_S = 600.0
KEPLERIAN = """
[pointing.keplerian]
semi_major_axis = { value = 6878.137, unit = "km" }
eccentricity = 0.001
inclination = { value = 97.4, unit = "deg" }
raan = { value = 0.0, unit = "deg" }
argument_of_perigee = { value = 0.0, unit = "deg" }
mean_anomaly = { value = 0.0, unit = "deg" }
"""
BASE = f"""
[scenario]
name = "an orbit file that covers the span exactly"
epoch = "{EPOCH}"

[spacecraft]
name = "sat"
principal_moments = [10.0, 20.0, 25.0]

[output]
duration = {SPAN_S}
step = 1.0
"""
FREE = "[initial_state]\nquaternion = [1.0, 0.0, 0.0, 0.0]\nangular_velocity = [0.01, 0.2, 0.01]\n"
# A torque step that does not divide the span: the last step ends 2 s past it.
GRAVITY_GRADIENT = "[torques]\ngravity_gradient = true\nstep = 7.0\n"
# Nadir, then free: the validity horizon runs the free part under the gravity gradient.
GUIDED = (
    '[initial_state.law]\nname = "nadir"\n\n[[events]]\ntype = "control_loss"\noffset = 300.0\n'
)
VECTOR = '[[pointing.body_vectors]]\nname = "tracker"\nvector = [0.0, 0.0, 1.0]\n'


def _write_oem(path):
    """The Keplerian orbit every 60 s from the epoch to the span's end, UTC epochs."""
    start = Time(EPOCH, scale="utc")
    orbit = KeplerianOrbit(start, 6878137.0, 0.001, 97.4 * u.deg, 0 * u.deg, 0 * u.deg,
                           mean_anomaly=0 * u.deg)  # fmt: skip
    nodes = time_from_tt_seconds(start, np.arange(0.0, SPAN_S + 1.0, 60.0))
    r, v = orbit.position_velocity(nodes)
    with offline_time():
        epochs = list(nodes.utc.isot)
    lines = ["CCSDS_OEM_VERS = 2.0", "CREATION_DATE = 2027-06-20T00:00:00", "ORIGINATOR = ME", ""]
    lines += ["META_START", "OBJECT_NAME = SAT", "OBJECT_ID = 2027-001A", "CENTER_NAME = EARTH"]
    lines += ["REF_FRAME = ICRF", "TIME_SYSTEM = UTC", f"START_TIME = {epochs[0]}"]
    lines += [f"STOP_TIME = {epochs[-1]}", "INTERPOLATION = LAGRANGE"]
    lines += ["INTERPOLATION_DEGREE = 5", "META_STOP", ""]
    for epoch, a, b in zip(epochs, r / 1e3, v / 1e3, strict=True):
        lines.append(epoch + " " + " ".join(f"{x:.15e}" for x in [*a, *b]))
    path.write_text("\n".join(lines) + "\n")


def _plans(tmp_path, body: str):
    """The plans (check's and run's path) of the scenario on the OEM and on the orbit."""
    _write_oem(tmp_path / "exact.oem")
    plans = []
    for orbit in ('[pointing]\noem = "exact.oem"\n', "[pointing]\n" + KEPLERIAN):
        path = tmp_path / "s.toml"
        path.write_text(BASE + body + orbit + VECTOR)
        loaded = load_scenario(path)
        clear_cache()
        plans.append(plan_run(loaded.scenario, loaded.pointing, loaded.outputs, check=True))
    return plans


@pytest.mark.parametrize("body", [FREE + GRAVITY_GRADIENT, GUIDED], ids=["torqued", "guided"])
def test_accepted_and_the_same_motion_as_on_the_keplerian_orbit(tmp_path, body):
    on_file, on_orbit = _plans(tmp_path, body)
    t = np.linspace(0.0, SPAN_S, 61)
    apart = on_file.trajectory.attitude(t).inv() * on_orbit.trajectory.attitude(t)
    assert np.max(apart.magnitude()) < 1e-9  # rad: the file's interpolation, mm in 6878 km


def test_the_shared_surroundings_stay_within_the_file(tmp_path):
    on_file, _ = _plans(tmp_path, FREE)
    orbit = on_file.pointing.orbit
    shared = SharedSurroundings(scenario_jd(on_file.trajectory), orbit, 0.0, 0.0, SPAN_S)
    assert shared.start_s >= -1e-6 and shared.stop_s <= SPAN_S + 1e-6
    assert shared.covers(0.0, SPAN_S)
    # At the span's ends, the interpolated position is the file's.
    fields, _ = shared.fields(np.array([0.0, SPAN_S]))
    exact = shared._exact_fields(np.array([0.0, SPAN_S]))[:, :3]
    assert np.max(np.linalg.norm(fields["r"] - exact, axis=-1)) < 1e-3  # m
