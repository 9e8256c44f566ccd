"""attitude: exact spacecraft attitude.

The layers, each importing only the ones above it in this list (README "Layout"):

- ``attitude.elliptic``: Jacobi functions and elliptic integrals in mc = 1 − m
- ``attitude.euler_solver``: ``EulerSolver``, the closed-form torque-free rigid body
- ``attitude.torques``, ``splitting``, ``torqued_solver``: ``TorquedSolver``, torques
  (gravity gradient, constant torques, user torques) by splitting with the exact free flow
- ``attitude.spacecraft``, ``events``, ``scenario_torques``, ``scenario``, ``timescales``:
  the scenario layer
- ``attitude.torqued_segment``, ``trajectory``, ``horizon``, ``motion_analysis``:
  the propagated motion
- ``attitude.ephemeris``, ``earth``, ``frames``, ``orbit``, ``keplerian``, ``oem``,
  ``aem_input``, ``intervals``, ``extrema``, ``eclipse``, ``pointing_spec``,
  ``surroundings``, ``pointing_sampling``, ``pointing_search``, ``pointing``: pointing
- ``attitude.csv_files``, ``aem``, ``summaries``, ``plots``, ``report_page``, ``report``: reports
  and exports
- ``attitude.scenario_file``, ``cli``: scenario files and the command line; beside them,
  ``dispersions``, ``scenario_writer`` and ``montecarlo`` (``run_montecarlo``): Monte
  Carlo jobs on Dask, which drive the scenario layer from above

The names below are importable from ``attitude`` directly; all but the errors are
loaded on first use, so that ``import attitude`` stays light (numpy, scipy, astropy,
skyfield, matplotlib, dask and pandas load only when needed), and the command line can install its
signal handlers before anything heavy loads.

Conventions: SI units (s, kg m², N m s, rad/s; astropy Quantities accepted at the
public edge); an attitude is the ``scipy.spatial.transform.Rotation`` taking body
coordinates to inertial (ICRF/GCRS) coordinates; quaternions shown to a user are
scalar first and say so.
"""

from importlib import import_module
from typing import TYPE_CHECKING, Any

from attitude.errors import AttitudeError, InertiaWarning, InputError
from attitude.version import __version__

if TYPE_CHECKING:  # what the lazy names below resolve to, for type checkers and IDEs
    from attitude.aem import write_aem
    from attitude.euler_solver import EulerSolver
    from attitude.events import AngularImpulse, AttitudeReset, InertiaChange
    from attitude.horizon import validity_horizon
    from attitude.keplerian import KeplerianOrbit
    from attitude.montecarlo import run_montecarlo
    from attitude.motion_analysis import analyze
    from attitude.oem import OemOrbit
    from attitude.orbit import TleOrbit
    from attitude.pointing import BodyVector, PointingSpec, pointing_analysis, pointing_samples
    from attitude.report import write_report
    from attitude.scenario import InitialState, Scenario
    from attitude.scenario_file import load_scenario
    from attitude.scenario_torques import Burn, ScenarioTorques
    from attitude.spacecraft import Spacecraft
    from attitude.torqued_solver import TorquedSolver, departure_time, propagate_batch
    from attitude.torques import ConstantTorque, GravityGradient, UserTorque
    from attitude.trajectory import Trajectory, propagate

_LAZY = {
    "EulerSolver": "attitude.euler_solver",
    "TorquedSolver": "attitude.torqued_solver",
    "propagate_batch": "attitude.torqued_solver",
    "departure_time": "attitude.torqued_solver",
    "GravityGradient": "attitude.torques",
    "ConstantTorque": "attitude.torques",
    "UserTorque": "attitude.torques",
    "Spacecraft": "attitude.spacecraft",
    "InitialState": "attitude.scenario",
    "Scenario": "attitude.scenario",
    "ScenarioTorques": "attitude.scenario_torques",
    "Burn": "attitude.scenario_torques",
    "validity_horizon": "attitude.horizon",
    "AngularImpulse": "attitude.events",
    "InertiaChange": "attitude.events",
    "AttitudeReset": "attitude.events",
    "propagate": "attitude.trajectory",
    "Trajectory": "attitude.trajectory",
    "analyze": "attitude.motion_analysis",
    "BodyVector": "attitude.pointing",
    "PointingSpec": "attitude.pointing",
    "pointing_samples": "attitude.pointing",
    "pointing_analysis": "attitude.pointing",
    "TleOrbit": "attitude.orbit",
    "KeplerianOrbit": "attitude.keplerian",
    "OemOrbit": "attitude.oem",
    "write_aem": "attitude.aem",
    "load_scenario": "attitude.scenario_file",
    "write_report": "attitude.report",
    "run_montecarlo": "attitude.montecarlo",
}

# Spelled out (not built from _LAZY) so that linters and IDEs read it statically;
# tests/test_layering.py checks that it, _LAZY and the TYPE_CHECKING imports agree.
__all__ = [
    "AngularImpulse",
    "AttitudeError",
    "AttitudeReset",
    "BodyVector",
    "Burn",
    "ConstantTorque",
    "EulerSolver",
    "GravityGradient",
    "InertiaChange",
    "InertiaWarning",
    "InitialState",
    "InputError",
    "KeplerianOrbit",
    "OemOrbit",
    "PointingSpec",
    "Scenario",
    "ScenarioTorques",
    "Spacecraft",
    "TleOrbit",
    "TorquedSolver",
    "Trajectory",
    "UserTorque",
    "__version__",
    "analyze",
    "departure_time",
    "load_scenario",
    "pointing_analysis",
    "pointing_samples",
    "propagate",
    "propagate_batch",
    "run_montecarlo",
    "validity_horizon",
    "write_aem",
    "write_report",
]


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        return getattr(import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'attitude' has no attribute {name!r}")


def __dir__() -> list[str]:
    """The module's own names and the lazy ones, so that ``dir(attitude)`` shows the API."""
    return sorted({*globals(), *_LAZY})
