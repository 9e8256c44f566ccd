"""Scenarios under torques, against the torque-free scenario, momentum laws and the solver.

- **Zero torque.** A burn of zero torque through impulses, an inertia change (a full
  tensor) and an attitude reset propagates by splitting, and reproduces the exact
  torque-free scenario to rounding; a scenario without torques keeps EulerSolver.
- **Momentum.** An inertial burn across events changes the inertial angular momentum
  by exactly ∫τ dt (plus the events' own jumps), at any time within the burn; a
  body-fixed burn along the axis of a symmetric spinner spins it up by τ t / I3.
- **The orbit.** Gravity gradient on the scenario's orbit (a KeplerianOrbit, read at
  two-part TT dates) is the TorquedSolver's on the same circle written by hand.
- **The validity horizon** of a torque-free scenario against a direct comparison of
  TorquedSolver and EulerSolver from the same state (``departure_time``); that of a
  scenario with a burn alone against DOP853 on the burn with and without the gravity
  gradient (torqued_reference, none of the package's code).
- Through files and the command line: ``check`` and ``summary.json`` state the torques,
  the step and the estimated error, and the horizon of a scenario that neglects the
  gravity gradient (torque-free, or burns alone); one that models it states why none.
"""

import json
import math
from pathlib import Path

import numpy as np
import pytest
import torqued_reference as ref
from scipy.spatial.transform import Rotation

from attitude.cli.main import main
from attitude.environment.keplerian import KeplerianOrbit
from attitude.scenario.events import AngularImpulse, AttitudeReset, InertiaChange
from attitude.scenario.scenario import InitialState, Scenario
from attitude.scenario.spacecraft import Spacecraft
from attitude.scenario.torques import Burn, ScenarioTorques
from attitude.solver.euler_solver import EulerSolver
from attitude.torques.models import GravityGradient
from attitude.torques.solver import TorquedSolver, angles_between, departure_time
from attitude.trajectory.horizon import validity_horizon
from attitude.trajectory.torqued import TorquedMotion
from attitude.trajectory.trajectory import propagate

EPOCH = "2027-03-01T00:00:00"
MU = 3.986004418e14
A = 7.0e6
N = math.sqrt(MU / A**3)
I_TUMBLER = np.array([100.0, 200.0, 300.0])
W_TUMBLER = np.array([0.05, 0.02, 0.03])
R0 = Rotation.from_euler("ZYX", [10, 20, 30], degrees=True)


def circle(t):
    """A circular equatorial orbit of radius A, ICRF, position at t (s)."""
    t = np.asarray(t, dtype=float)
    return A * np.stack([np.cos(N * t), np.sin(N * t), np.zeros_like(t)], axis=-1)


def _events():
    tensor = Rotation.from_euler("xyz", [20, -35, 50], degrees=True).as_matrix()
    tensor = tensor @ np.diag([150.0, 200.0, 320.0]) @ tensor.T
    return [
        AngularImpulse(150.0, [1.0, -2.0, 0.5], "body"),
        InertiaChange(400.0, tensor),
        AngularImpulse(400.0, [0.0, 3.0, 0.0], "inertial"),
        AttitudeReset(700.0, Rotation.from_euler("z", 30, degrees=True)),
    ]


def _scenario(torques=None, events=(), duration=1000.0, inertia=I_TUMBLER, rate=W_TUMBLER):
    return Scenario(
        "torques",
        Spacecraft("sat", inertia),
        EPOCH,
        InitialState(R0, angular_velocity=rate),
        list(events),
        duration=duration,
        torques=torques,
    )


def test_a_scenario_without_torques_keeps_the_exact_solver():
    trajectory = propagate(_scenario(ScenarioTorques(), _events()))
    assert all(isinstance(s.solver, EulerSolver) for s in trajectory.segments)


def test_zero_torque_reproduces_the_torque_free_scenario_through_events():
    zero = ScenarioTorques(burns=[Burn(0.0, 1000.0, [0.0, 0.0, 0.0])], step=7.0)
    torqued = propagate(_scenario(zero, _events()))
    free = propagate(_scenario(None, _events()))
    assert all(isinstance(s.solver, TorquedMotion) for s in torqued.segments)
    t = np.sort(np.random.default_rng(1).uniform(0.0, 1000.0, 300))
    t = np.concatenate([t, [150.0, 400.0, 700.0, 1000.0]])  # events: post-event states
    angle = angles_between(torqued.attitude_quaternion(t), free.attitude_quaternion(t))
    assert np.max(angle) < 1e-11
    np.testing.assert_allclose(
        torqued.angular_momentum(t), free.angular_momentum(t), rtol=0, atol=1e-11
    )
    np.testing.assert_allclose(
        torqued.kinetic_energy(t), free.kinetic_energy(t), rtol=1e-12, atol=0
    )


def test_an_inertial_burn_changes_the_momentum_by_its_integral_across_events():
    τ = np.array([0.03, -0.02, 0.05])
    burn = Burn(100.0, 500.0, τ, "inertial")  # on across the impulse and the inertia change
    events = [
        AngularImpulse(250.0, [0.5, 0.0, -1.0], "inertial"),
        InertiaChange(400.0, [110, 230, 320]),
    ]
    trajectory = propagate(_scenario(ScenarioTorques(burns=[burn], step=9.0), events))
    H0 = trajectory.inertial_angular_momentum(0.0)
    # Inside the burn (between grid points), after each event, and after the burn.
    for t, expected in [
        (100.0, 0.0),
        (213.7, 113.7),
        (250.0, 150.0),
        (333.3, 233.3),
        (400.0, 300.0),
        (555.5, 455.5),
        (600.0, 500.0),
        (1000.0, 500.0),
    ]:
        jump = np.array([0.5, 0.0, -1.0]) if t >= 250.0 else 0.0
        H = trajectory.inertial_angular_momentum(t)
        np.testing.assert_allclose(H - H0, τ * expected + jump, rtol=0, atol=1e-12 * 20)


def test_a_body_burn_along_the_axis_of_a_symmetric_spinner_spins_it_up():
    inertia = np.array([500.0, 500.0, 800.0])
    rate = np.array([0.0, 0.0, 0.5])
    burn = Burn(10.0, 60.0, [0.0, 0.0, 2.0], "body")
    trajectory = propagate(
        _scenario(ScenarioTorques(burns=[burn], step=2.5), inertia=inertia, rate=rate, duration=100)
    )
    for t in (5.0, 10.0, 31.3, 70.0, 100.0):
        spun = 2.0 * min(max(t - 10.0, 0.0), 60.0) / 800.0
        np.testing.assert_allclose(
            trajectory.angular_velocity(t), [0.0, 0.0, 0.5 + spun], rtol=0, atol=1e-14
        )


def test_gravity_gradient_on_the_scenario_orbit_is_the_solver_on_the_same_circle():
    from astropy.time import Time

    orbit = KeplerianOrbit(Time(EPOCH, scale="utc"), A, 0.0, 0.0, 0.0, 0.0, mean_anomaly=0.0)
    settings = ScenarioTorques(gravity_gradient=orbit, step=20.0)
    trajectory = propagate(_scenario(settings, duration=3000.0))
    direct = TorquedSolver(
        I_TUMBLER, I_TUMBLER * W_TUMBLER, R0, 0.0, [GravityGradient(circle)], step=20.0
    )
    t = np.linspace(0.0, 3000.0, 77)
    angle = angles_between(trajectory.attitude_quaternion(t), direct.attitude_quaternion(t))
    assert np.max(angle) < 1e-9
    # ... and the torque matters: the torque-free motion is degrees away by the end.
    free = propagate(_scenario(None, duration=3000.0))
    assert (
        angles_between(free.attitude_quaternion(3000.0), direct.attitude_quaternion(3000.0)) > 0.02
    )


def test_the_validity_horizon_against_torqued_and_exact_solvers_side_by_side():
    scenario = _scenario(None, duration=6000.0)
    horizon = validity_horizon(propagate(scenario), circle)
    direct = departure_time(
        I_TUMBLER, I_TUMBLER * W_TUMBLER, R0, 0.0, [GravityGradient(circle)], 6000.0, step=5.0
    )
    assert 100.0 < direct < 6000.0
    assert horizon.within_span and abs(horizon.horizon_s - direct) < 0.01
    # A user threshold of 5°: later, and beyond a span shorter than that.
    five = ScenarioTorques(horizon_threshold=math.radians(5.0))
    later = validity_horizon(propagate(_scenario(five, duration=6000.0)), circle)
    direct5 = departure_time(
        I_TUMBLER,
        I_TUMBLER * W_TUMBLER,
        R0,
        0.0,
        [GravityGradient(circle)],
        6000.0,
        threshold=math.radians(5.0),
        step=5.0,
    )
    assert abs(later.horizon_s - direct5) < 0.01 and later.horizon_s > horizon.horizon_s
    short = validity_horizon(propagate(_scenario(None, duration=0.5 * direct)), circle)
    assert not short.within_span and "beyond the span" in short.describe(scenario.format_epoch)


def test_the_validity_horizon_of_a_burn_alone_against_dop853_with_and_without_gravity_gradient():
    """A scenario with a burn and no gravity gradient neglects the latter: its horizon is
    where DOP853 on the burn alone and on the burn with the gravity gradient part by 1°."""
    τ = np.array([0.002, -0.001, 0.003])
    burn = Burn(100.0, 400.0, τ, "inertial")
    scenario = _scenario(ScenarioTorques(burns=[burn], step=2.0), duration=1500.0)
    horizon = validity_horizon(propagate(scenario), circle)
    orbit = ref.circular_orbit(A, mu=MU)
    gradient = ref.gravity_gradient(orbit, np.diag(I_TUMBLER))

    def burning(t, q, m, t_mid):
        on = 100.0 <= t_mid <= 500.0
        return ref.matrix_body_to_inertial(q).T @ τ if on else np.zeros(3)

    def both(t, q, m, t_mid):
        return burning(t, q, m, t_mid) + gradient(t, q, m)

    t = np.arange(0.25, 1500.0, 0.25)
    q0 = R0.as_quat(scalar_first=True)
    runs = [
        ref.integrate_dop853(
            I_TUMBLER, I_TUMBLER * W_TUMBLER, q0, torque, t, (100.0, 500.0), 1e-11
        )[1]
        for torque in (burning, both)
    ]
    angle = ref.angle(*runs)
    k = int(np.flatnonzero(angle >= math.radians(1.0))[0])
    # Linear between the two samples around the crossing (0.25 s apart).
    crossing = t[k - 1] + (math.radians(1.0) - angle[k - 1]) / (angle[k] - angle[k - 1]) * 0.25
    assert 100.0 < crossing < 1500.0 and horizon.within_span
    assert abs(horizon.horizon_s - crossing) < 0.02, (horizon.horizon_s, crossing)


SCENARIO = """
[scenario]
name = "tumbler"
epoch = "2027-03-01T00:00:00"

[spacecraft]
name = "sat"
principal_moments = [100.0, 200.0, 300.0]

[initial_state]
quaternion = [0.9515485246437885, 0.2392983377447303, 0.18930785741199993, 0.03813457647485015]
angular_velocity = [0.05, 0.02, 0.03]

[output]
duration = 1200.0
step = 10.0
formats = ["csv", "report"]

[pointing]
[pointing.keplerian]
semi_major_axis = { value = 7000.0, unit = "km" }
eccentricity = 0.0
inclination = { value = 0.0, unit = "deg" }
raan = { value = 0.0, unit = "deg" }
argument_of_perigee = { value = 0.0, unit = "deg" }
mean_anomaly = { value = 0.0, unit = "deg" }
"""


def _horizon_through_the_cli(tmp_path, capsys, text, torques_line):
    """``check`` and ``run`` of the scenario ``text``: both state the horizon (and
    ``check`` the torques as ``torques_line``); returns summary.json's horizon entry."""
    path = tmp_path / "scenario.toml"
    path.write_text(text, encoding="utf-8")
    assert main(["check", str(path)]) == 0
    out = capsys.readouterr().out
    assert torques_line in out
    assert "horizon     the neglected gravity gradient moves the attitude by 1 deg after" in out
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert "valid until then" in (tmp_path / "out" / "report.html").read_text()
    return summary["torques"]["validity_horizon"]


def test_a_torque_free_file_with_an_orbit_states_its_validity_horizon(tmp_path, capsys):
    horizon = _horizon_through_the_cli(
        tmp_path,
        capsys,
        SCENARIO,
        "torques     none: exact torque-free motion (closed form, no integration)",
    )
    direct = departure_time(
        I_TUMBLER, I_TUMBLER * W_TUMBLER, R0, 0.0, [GravityGradient(circle)], 1200.0, step=5.0
    )
    assert abs(horizon["horizon_s"] - direct) < 0.01 and horizon["threshold_deg"] == 1.0


def test_a_file_with_torques_states_them_with_the_step_and_the_error(tmp_path, capsys):
    text = (
        SCENARIO
        + """
[torques]
gravity_gradient = true
accuracy = { value = 1e-7, unit = "rad" }

[[torques.burns]]
offset = 300.0
duration = 120.0
torque = [0.0, 0.0, 0.02]
frame = "inertial"
label = "burn"
"""
    )
    path = tmp_path / "gg.toml"
    path.write_text(text, encoding="utf-8")
    assert main(["check", str(path)]) == 0
    out = capsys.readouterr().out
    assert (
        "torques     gravity gradient (point-mass Earth), 1 burn; order 4, "
        "step chosen for 1e-07 rad" in out
    )
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    torques = summary["torques"]
    assert torques["modelled"] == ["gravity gradient (point-mass Earth)", "1 burn"]
    assert torques["burns"][0]["duration_s"] == 120.0 and torques["order"] == 4
    (segment,) = torques["segments"]
    assert 0.0 < segment["estimated_error_rad"] <= 1e-7 and segment["step_s"] > 0.0
    # The gravity gradient is modelled: no horizon, and the summary says why.
    assert torques["validity_horizon"] is None
    assert "gravity gradient is modelled" in torques["validity_horizon_note"]
    assert summary["motion"]["segments"][0]["motion"] == "torqued"
    # The run is the scenario's torqued motion: against the solver on the same circle.
    csv = tmp_path / "out" / "timeseries.csv"
    preamble = sum(1 for line in csv.read_text().splitlines() if line.startswith("#"))
    data = np.genfromtxt(
        csv, delimiter=",", skip_header=preamble, names=True, dtype=None, encoding="utf-8"
    )
    q = np.column_stack([data[f"q_body_to_icrf_{c}"] for c in "wxyz"])
    from attitude.torques.models import ConstantTorque

    direct = TorquedSolver(
        I_TUMBLER,
        I_TUMBLER * W_TUMBLER,
        R0,
        0.0,
        [GravityGradient(circle), ConstantTorque([0.0, 0.0, 0.02], 300.0, 420.0, "inertial")],
        step=5.0,
    )
    assert np.max(angles_between(q, direct.attitude_quaternion(data["t_s"]))) < 1e-6
    page = (tmp_path / "out" / "report.html").read_text()
    assert "<h2>Torques</h2>" in page and "splitting with the exact free flow" in page


def test_a_file_with_burns_alone_on_an_orbit_states_its_validity_horizon(tmp_path, capsys):
    text = (
        SCENARIO
        + """
[torques]
step = 2.0

[[torques.burns]]
offset = 100.0
duration = 400.0
torque = [0.002, -0.001, 0.003]
frame = "inertial"
"""
    )
    horizon = _horizon_through_the_cli(
        tmp_path, capsys, text, "torques     1 burn; order 4, step 2 s"
    )
    # The horizon of the same burn without a file (the DOP853 test above): 307.62 s.
    scenario = _scenario(
        ScenarioTorques(burns=[Burn(100.0, 400.0, [0.002, -0.001, 0.003], "inertial")], step=2.0),
        duration=1200.0,
    )
    direct = validity_horizon(propagate(scenario), circle).horizon_s
    assert abs(horizon["horizon_s"] - direct) < 0.01 and horizon["threshold_deg"] == 1.0


@pytest.mark.parametrize(
    "path", sorted((Path(__file__).parents[1] / "scenarios").glob("*gravity*.toml"))
)
def test_the_example_with_gravity_gradient_and_a_burn_checks(path, capsys):
    assert main(["check", str(path)]) == 0
    assert "torques     gravity gradient (point-mass Earth), 1 burn" in capsys.readouterr().out
