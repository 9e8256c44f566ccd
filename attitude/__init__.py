"""attitude: exact spacecraft attitude.

The layers are the subpackages, in the order data flows; each imports only its own
layer and the ones before it, with no loop between modules (``tests/test_layering.py``
checks it, and that the README's "Layout" table lists the same layers and modules):

1. ``attitude.base``: errors, units, quaternions, vectors, the compile policy
2. ``attitude.elliptic``: Jacobi elliptic functions and elliptic integrals, the phase table
3. ``attitude.solver``: the exact torque-free solver (``EulerSolver``), its free flow and
   its sensitivities
4. ``attitude.torques``: torques by splitting with the exact free flow (``TorquedSolver``)
5. ``attitude.environment``: time scales, the Sun and Moon, the Earth, frames, orbits
6. ``attitude.laws``: attitude laws (nadir, Sun, target, align-and-constrain, ...) and their rates
7. ``attitude.scenario``: the spacecraft, its initial state, events, a scenario's torques
8. ``attitude.trajectory``: the propagated motion, its validity horizon, its analysis
9. ``attitude.pointing``: the Sun, Moon and Earth on the body vectors; the exact search
10. ``attitude.outputs``: CSV, Parquet and AEM files, the output budget and folder
11. ``attitude.report``: a run's plan, summaries, figures, page and streamed writing
12. ``attitude.files``: scenario files read and written
13. ``attitude.jobs``: long jobs on Dask (a local cluster or a scheduler, its workers
    checked, the batches and their gathering), which the Monte Carlo and the envelope share
14. ``attitude.estimation``: spin state and inertia ratios fitted to telemetry
15. ``attitude.montecarlo``: Monte Carlo dispersions on Dask
16. ``attitude.envelope``: the loss-of-control envelope (a control loss at every instant
    of a nominal timeline), on Dask
17. ``attitude.cli``: the command line

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

from attitude.base.errors import AttitudeError, InertiaWarning, InputError
from attitude.base.version import __version__

if TYPE_CHECKING:  # what the lazy names below resolve to, for type checkers and IDEs
    from attitude.envelope.job import loss_of_control_envelope
    from attitude.envelope.settings import EnvelopeSettings
    from attitude.environment.keplerian import KeplerianOrbit
    from attitude.environment.oem import OemOrbit
    from attitude.environment.orbit import TleOrbit
    from attitude.estimation.fit import FitRefused, SpinStateFit, fit_spin_state
    from attitude.estimation.telemetry_files import TelemetryFile, read_telemetry
    from attitude.files.scenario_reader import load_scenario
    from attitude.laws.align_constrain import (
        AlignConstrainLaw,
        AttitudeLaw,
        BoundLaw,
        DegenerateLawError,
        LawState,
    )
    from attitude.laws.directions import CelestialTarget, FixedDirection, GroundSite
    from attitude.laws.named_laws import InertialLaw, NadirLaw, OrbitFrameLaw, SunLaw, TargetLaw
    from attitude.laws.slews import Slew, SlewLimits
    from attitude.laws.visibility import visible_intervals
    from attitude.montecarlo.job import run_montecarlo
    from attitude.outputs.aem_writer import write_aem
    from attitude.pointing.sampling import pointing_samples
    from attitude.pointing.search import pointing_analysis
    from attitude.pointing.spec import BodyVector, PointingSpec
    from attitude.report.run import write_report
    from attitude.scenario.events import AngularImpulse, AttitudeReset, InertiaChange
    from attitude.scenario.modes import ControlLoss, ControlResume, ModeChange, Wheels
    from attitude.scenario.scenario import InitialState, Scenario
    from attitude.scenario.spacecraft import Spacecraft
    from attitude.scenario.torques import Burn, ScenarioTorques
    from attitude.solver.batch import EulerSolverBatch
    from attitude.solver.euler_solver import EulerSolver
    from attitude.solver.free_flow import advance
    from attitude.solver.sensitivities import FlowSensitivities, flow_sensitivities
    from attitude.torques.models import ConstantTorque, GravityGradient, UserTorque
    from attitude.torques.solver import TorquedSolver, departure_time, propagate_batch
    from attitude.trajectory.handoff import hand_off, hand_off_at, hand_off_states
    from attitude.trajectory.horizon import validity_horizon
    from attitude.trajectory.motion import analyze
    from attitude.trajectory.trajectory import Trajectory, propagate

_LAZY = {
    "loss_of_control_envelope": "attitude.envelope.job",
    "EnvelopeSettings": "attitude.envelope.settings",
    "EulerSolver": "attitude.solver.euler_solver",
    "EulerSolverBatch": "attitude.solver.batch",
    "advance": "attitude.solver.free_flow",
    "FlowSensitivities": "attitude.solver.sensitivities",
    "flow_sensitivities": "attitude.solver.sensitivities",
    "fit_spin_state": "attitude.estimation.fit",
    "SpinStateFit": "attitude.estimation.fit",
    "FitRefused": "attitude.estimation.fit",
    "read_telemetry": "attitude.estimation.telemetry_files",
    "TelemetryFile": "attitude.estimation.telemetry_files",
    "TorquedSolver": "attitude.torques.solver",
    "propagate_batch": "attitude.torques.solver",
    "departure_time": "attitude.torques.solver",
    "GravityGradient": "attitude.torques.models",
    "ConstantTorque": "attitude.torques.models",
    "UserTorque": "attitude.torques.models",
    "Spacecraft": "attitude.scenario.spacecraft",
    "InitialState": "attitude.scenario.scenario",
    "Scenario": "attitude.scenario.scenario",
    "ScenarioTorques": "attitude.scenario.torques",
    "Burn": "attitude.scenario.torques",
    "validity_horizon": "attitude.trajectory.horizon",
    "AngularImpulse": "attitude.scenario.events",
    "InertiaChange": "attitude.scenario.events",
    "AttitudeReset": "attitude.scenario.events",
    "propagate": "attitude.trajectory.trajectory",
    "Trajectory": "attitude.trajectory.trajectory",
    "analyze": "attitude.trajectory.motion",
    "BodyVector": "attitude.pointing.spec",
    "PointingSpec": "attitude.pointing.spec",
    "pointing_samples": "attitude.pointing.sampling",
    "pointing_analysis": "attitude.pointing.search",
    "TleOrbit": "attitude.environment.orbit",
    "KeplerianOrbit": "attitude.environment.keplerian",
    "OemOrbit": "attitude.environment.oem",
    "AttitudeLaw": "attitude.laws.align_constrain",
    "AlignConstrainLaw": "attitude.laws.align_constrain",
    "BoundLaw": "attitude.laws.align_constrain",
    "DegenerateLawError": "attitude.laws.align_constrain",
    "LawState": "attitude.laws.align_constrain",
    "InertialLaw": "attitude.laws.named_laws",
    "OrbitFrameLaw": "attitude.laws.named_laws",
    "NadirLaw": "attitude.laws.named_laws",
    "SunLaw": "attitude.laws.named_laws",
    "TargetLaw": "attitude.laws.named_laws",
    "GroundSite": "attitude.laws.directions",
    "CelestialTarget": "attitude.laws.directions",
    "FixedDirection": "attitude.laws.directions",
    "visible_intervals": "attitude.laws.visibility",
    "Slew": "attitude.laws.slews",
    "SlewLimits": "attitude.laws.slews",
    "ModeChange": "attitude.scenario.modes",
    "ControlLoss": "attitude.scenario.modes",
    "ControlResume": "attitude.scenario.modes",
    "Wheels": "attitude.scenario.modes",
    "hand_off": "attitude.trajectory.handoff",
    "hand_off_at": "attitude.trajectory.handoff",
    "hand_off_states": "attitude.trajectory.handoff",
    "write_aem": "attitude.outputs.aem_writer",
    "load_scenario": "attitude.files.scenario_reader",
    "write_report": "attitude.report.run",
    "run_montecarlo": "attitude.montecarlo.job",
}

# Spelled out (not built from _LAZY) so that linters and IDEs read it statically;
# tests/test_layering.py checks that it, _LAZY and the TYPE_CHECKING imports agree.
__all__ = [
    "AlignConstrainLaw",
    "AngularImpulse",
    "AttitudeError",
    "AttitudeLaw",
    "AttitudeReset",
    "BodyVector",
    "BoundLaw",
    "Burn",
    "CelestialTarget",
    "ConstantTorque",
    "ControlLoss",
    "ControlResume",
    "DegenerateLawError",
    "EnvelopeSettings",
    "EulerSolver",
    "EulerSolverBatch",
    "FitRefused",
    "FixedDirection",
    "FlowSensitivities",
    "GravityGradient",
    "GroundSite",
    "InertiaChange",
    "InertiaWarning",
    "InertialLaw",
    "InitialState",
    "InputError",
    "KeplerianOrbit",
    "LawState",
    "ModeChange",
    "NadirLaw",
    "OemOrbit",
    "OrbitFrameLaw",
    "PointingSpec",
    "Scenario",
    "ScenarioTorques",
    "Slew",
    "SlewLimits",
    "Spacecraft",
    "SpinStateFit",
    "SunLaw",
    "TargetLaw",
    "TelemetryFile",
    "TleOrbit",
    "TorquedSolver",
    "Trajectory",
    "UserTorque",
    "Wheels",
    "__version__",
    "advance",
    "analyze",
    "departure_time",
    "fit_spin_state",
    "flow_sensitivities",
    "hand_off",
    "hand_off_at",
    "hand_off_states",
    "load_scenario",
    "loss_of_control_envelope",
    "pointing_analysis",
    "pointing_samples",
    "propagate",
    "propagate_batch",
    "read_telemetry",
    "run_montecarlo",
    "validity_horizon",
    "visible_intervals",
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
