"""The orbit given once, to the Scenario, against the route that gives it twice.

``Scenario(..., orbit=orbit, torques=ScenarioTorques(gravity_gradient=True))`` with a
``PointingSpec`` that names no orbit must compute what the older route computes, with
the orbit given to the torques and to the pointing spec separately (still accepted):
the same trajectory to the last bit, and the same summary.  An orbit given twice that
is the same path (the same object, or the same elements rebuilt) is accepted; two that
disagree are refused with one line naming the key and both orbits.  The example of
``docs/examples/scenario_in_python.py`` runs on the new route.
"""

import importlib.util
from pathlib import Path

import astropy.units as u
import numpy as np
import pytest
from astropy.time import Time
from scipy.spatial.transform import Rotation

from attitude import (
    BodyVector,
    InitialState,
    InputError,
    KeplerianOrbit,
    PointingSpec,
    Scenario,
    ScenarioTorques,
    Spacecraft,
    pointing_analysis,
    propagate,
)
from attitude.report.plan import plan_run
from attitude.report.run import write_report

EPOCH = Time("2027-06-21T00:00:00", scale="utc")


def _orbit(raan_deg: float = 90.0) -> KeplerianOrbit:
    return KeplerianOrbit(
        EPOCH,
        semi_major_axis_m=6878.137e3,
        eccentricity=0.001,
        inclination=97.4 * u.deg,
        raan=raan_deg * u.deg,
        argument_of_perigee=0.0 * u.deg,
        mean_anomaly=0.0 * u.deg,
    )


def _scenario(**route) -> Scenario:
    return Scenario(
        "tumbler",
        Spacecraft("smallsat", inertia=[10.0, 12.0, 15.0]),
        EPOCH,
        InitialState(Rotation.identity(), angular_velocity=np.radians([0.5, 1.0, -0.3])),
        duration=300.0,
        step=10.0,
        **route,
    )


VECTORS = [
    BodyVector(
        "tracker",
        [0.0, 0.0, -1.0],
        sun_exclusion_half_angle_rad=40.0 * u.deg,
        earth_limb_exclusion_angle_rad=20.0 * u.deg,
    )
]


@pytest.fixture(scope="module")
def twice(tmp_path_factory):
    """The route that gives the orbit twice (no orbit on the Scenario)."""
    orbit = _orbit()
    scenario = _scenario(torques=ScenarioTorques(gravity_gradient=orbit))
    out = tmp_path_factory.mktemp("twice") / "out"
    summary = write_report(scenario, out, PointingSpec(VECTORS, orbit))
    return scenario, summary


def test_once_computes_what_twice_computes(twice, tmp_path):
    old, old_summary = twice
    scenario = _scenario(orbit=_orbit(), torques=ScenarioTorques(gravity_gradient=True))
    seconds = np.linspace(0.0, 300.0, 61)
    np.testing.assert_array_equal(
        propagate(scenario).attitude_quaternion(seconds),
        propagate(old).attitude_quaternion(seconds),
    )
    summary = write_report(scenario, tmp_path / "out", PointingSpec(VECTORS))
    assert summary["pointing"] == old_summary["pointing"]
    assert summary["torques"] == old_summary["torques"]
    assert summary["torques"]["modelled"] == ["gravity gradient (point-mass Earth)"]
    assert summary["pointing"]["position"].startswith("Keplerian elements")
    assert "earth_limb_exclusion" in summary["pointing"]["body_vectors"]["tracker"]


def test_the_scenario_orbit_reaches_a_pointing_analysis_from_python():
    scenario = _scenario(orbit=_orbit())
    analysis = pointing_analysis(propagate(scenario), PointingSpec(VECTORS))
    assert analysis.on_orbit and analysis.vectors[0].earth_limb_exclusion is not None
    assert analysis.shadow is not None


def test_an_orbit_given_twice_that_agrees_is_accepted():
    orbit = _orbit()
    same = _scenario(orbit=orbit, torques=ScenarioTorques(gravity_gradient=orbit))
    rebuilt = _scenario(orbit=orbit, torques=ScenarioTorques(gravity_gradient=_orbit()))
    assert same.torques.gravity_gradient is orbit
    assert rebuilt.torques.gravity_gradient is not orbit
    plan = plan_run(rebuilt, PointingSpec(VECTORS, _orbit()), horizon=False)
    assert plan.pointing.on_orbit


def test_an_orbit_given_twice_that_disagrees_is_refused():
    with pytest.raises(InputError) as caught:
        _scenario(orbit=_orbit(), torques=ScenarioTorques(gravity_gradient=_orbit(91.0)))
    message = str(caught.value)
    assert message.startswith("torques.gravity_gradient: its orbit is not the scenario's: ")
    assert "km from the scenario's Keplerian elements" in message and "\n" not in message
    scenario = _scenario(orbit=_orbit())
    with pytest.raises(InputError, match=r"^pointing\.orbit: the PointingSpec's orbit is not"):
        plan_run(scenario, PointingSpec(VECTORS, _orbit(91.0)), horizon=False)
    # A position callable of the torques' route is compared the same way.
    with pytest.raises(InputError, match=r"^torques\.gravity_gradient: its orbit is not"):
        _scenario(
            orbit=_orbit(),
            torques=ScenarioTorques(gravity_gradient=lambda t: np.tile([7.0e6, 0.0, 0.0], (3, 1))),
        )


def test_what_needs_an_orbit_without_one_is_refused():
    with pytest.raises(InputError, match=r"^torques\.gravity_gradient: True acts on"):
        _scenario(torques=ScenarioTorques(gravity_gradient=True))
    with pytest.raises(InputError, match="an earth limb exclusion needs an orbit"):
        plan_run(_scenario(), PointingSpec(VECTORS), horizon=False)
    with pytest.raises(InputError, match=r"^orbit: must be an Orbit"):
        _scenario(orbit="ISS")


def test_the_docs_example_runs_on_the_orbit_given_once(tmp_path):
    path = Path(__file__).parents[1] / "docs" / "examples" / "scenario_in_python.py"
    spec = importlib.util.spec_from_file_location("scenario_in_python", path)
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    scenario, pointing = example.build_on_orbit()
    assert pointing.orbit is None and scenario.orbit is not None
    assert scenario.torques.gravity_gradient is scenario.orbit
    summary = example.on_orbit(tmp_path / "out")
    assert summary["torques"]["modelled"] == ["gravity gradient (point-mass Earth)"]
    assert summary["pointing"]["position"] == scenario.orbit.describe()
    assert "eclipses" in summary["pointing"] and (tmp_path / "out" / "eclipse.png").exists()
