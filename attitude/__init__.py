"""attitude: exact spacecraft attitude.

The layers, each importing only the ones above it in this list (README "Layout"):

- ``attitude.elliptic``: Jacobi functions and elliptic integrals in mc = 1 − m
- ``attitude.euler_solver``: ``EulerSolver``, the closed-form torque-free rigid body
- ``attitude.torques``, ``splitting``, ``torqued_solver``: ``TorquedSolver``, torques
  (gravity gradient, constant torques, user torques) by splitting with the exact free flow
- ``attitude.spacecraft``, ``events``, ``scenario``, ``timescales``: the scenario layer
- ``attitude.trajectory``, ``motion_analysis``: the propagated motion
- ``attitude.ephemeris``, ``orbit``, ``eclipse``, ``pointing``, ``intervals``: pointing
- ``attitude.exports``, ``aem``, ``plots``, ``report``: reports and exports
- ``attitude.scenario_file``, ``cli``: scenario files and the command line

The names below are importable from ``attitude`` directly; all but the solver and the
errors are loaded on first use, so that ``import attitude`` stays light (astropy,
skyfield and matplotlib load only when needed).

Conventions: SI units (s, kg m², N m s, rad/s; astropy Quantities accepted at the
public edge); an attitude is the ``scipy.spatial.transform.Rotation`` taking body
coordinates to inertial (ICRF/GCRS) coordinates; quaternions shown to a user are
scalar first and say so.
"""

from importlib import import_module
from typing import Any

from attitude.errors import AttitudeError, InertiaWarning, InputError
from attitude.euler_solver import EulerSolver
from attitude.version import __version__

_LAZY = {
    "TorquedSolver": "attitude.torqued_solver",
    "propagate_batch": "attitude.torqued_solver",
    "departure_time": "attitude.torqued_solver",
    "GravityGradient": "attitude.torques",
    "ConstantTorque": "attitude.torques",
    "UserTorque": "attitude.torques",
    "Spacecraft": "attitude.spacecraft",
    "InitialState": "attitude.scenario",
    "Scenario": "attitude.scenario",
    "AngularImpulse": "attitude.events",
    "InertiaChange": "attitude.events",
    "AttitudeReset": "attitude.events",
    "propagate": "attitude.trajectory",
    "Trajectory": "attitude.trajectory",
    "analyze": "attitude.motion_analysis",
    "BodyVector": "attitude.pointing",
    "PointingSpec": "attitude.pointing",
    "compute_pointing": "attitude.pointing",
    "TleOrbit": "attitude.orbit",
    "write_aem": "attitude.aem",
    "load_scenario": "attitude.scenario_file",
    "produce": "attitude.report",
}

__all__ = ["AttitudeError", "EulerSolver", "InertiaWarning", "InputError", "__version__", *_LAZY]


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        return getattr(import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'attitude' has no attribute {name!r}")
