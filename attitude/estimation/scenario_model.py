"""The fitted motion under gravity gradient on a given orbit (with the scenario's burns
and known impulses), through the splitting of ``TorquedSolver``.  Burns without gravity
gradient are fitted on the exact motion instead (attitude.estimation.burns).

The same parameters and interface as ``ExactModel`` (attitude.estimation.model), but
the motion is a scenario (attitude.scenario) propagated by ``propagate``: each segment
under a torque by the splitting (docs/torques.md), the others by ``EulerSolver``.  The
splitting's step is chosen once, for the first motion the fit tries (from the
scenario's ``accuracy``, or its ``step``), and then kept: the model is then a smooth
function of the parameters, and its Jacobian is taken by forward differences (steps of
1e-7 in the parameters, which are all of order one or rad/s).  This costs one
propagation per parameter and iteration: a fit under torques takes seconds, where the
torque-free one takes a fraction of one.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from attitude.base.errors import InertiaWarning, InputError
from attitude.environment.timescales import time_from_tt_seconds
from attitude.estimation.model import ExactModel, Prediction
from attitude.scenario.events import AngularImpulse, Event
from attitude.scenario.scenario import InitialState, Scenario
from attitude.scenario.spacecraft import Spacecraft
from attitude.trajectory.torqued import TorquedMotion
from attitude.trajectory.trajectory import Trajectory, propagate

__all__ = ["ScenarioModel"]

# Forward-difference step: the parameters are all of order one (rotation vectors,
# logarithms, rates in units of their size).
_STEP = 1e-7


@dataclass
class ScenarioModel(ExactModel):
    """``ExactModel``'s parameters, propagated as a scenario under ``torques`` (a
    ``ScenarioTorques``) from ``epoch`` (an astropy ``Time``: the telemetry's t = 0)
    to ``end`` (s)."""

    torques: Any = None
    orbit: Any = None  # the scenario's orbit, for gravity_gradient=True
    epoch: Any = None
    end: float = 0.0
    steps: list[float | None] | None = None

    def __post_init__(self) -> None:
        if self.epoch is None:
            raise InputError(
                "a fit under torques needs the telemetry's times as epochs (astropy Time), "
                "to place the orbit and the burns"
            )

    def trajectory(self, x: NDArray[np.float64], end: float | None = None) -> Trajectory:
        """The propagated motion for parameters ``x`` over [0, end]."""
        J, A = self.moments(x), self.axes(x)
        R = A.as_matrix()
        tensor = R @ np.diag(J) @ R.T
        inertia = J if np.array_equal(R, np.eye(3)) else 0.5 * (tensor + tensor.T)
        state = InitialState(self.initial_attitude(x), angular_velocity=self.rate(x))
        events: list[Event] = [
            AngularImpulse(time_from_tt_seconds(self.epoch, i.t), i.vector, i.frame)
            for i in self.impulses
        ]
        with warnings.catch_warnings():  # moments the fit tries may break the triangle
            warnings.simplefilter("ignore", InertiaWarning)  # inequality on their way
            spacecraft = Spacecraft("fit", inertia)
        scenario = Scenario(
            "fit",
            spacecraft,
            self.epoch,
            state,
            events,
            duration=max(self.end, end or 0.0),
            torques=self.torques,
            orbit=self.orbit,
        )
        trajectory = propagate(scenario, self.steps)
        if self.steps is None:  # the step chosen now is kept for every later motion
            self.steps = [
                segment.solver.solver.step if isinstance(segment.solver, TorquedMotion) else None
                for segment in trajectory.segments
            ]
        return trajectory

    def predict(
        self,
        x: NDArray[np.float64],
        t_rates: NDArray[np.float64] | None,
        t_attitude: NDArray[np.float64] | None,
        jacobian: bool = True,
    ) -> tuple[Prediction, Prediction]:
        ends = [t.max() for t in (t_rates, t_attitude) if t is not None and t.size]
        end = max(ends) if ends else 0.0
        rates, attitude = self._values(x, t_rates, t_attitude, end)
        if not jacobian:
            return rates, attitude
        n = x.size
        dω = rates.dω = None if rates.ω is None else np.empty((*rates.ω.shape, n))
        dθ = attitude.dθ = (
            None if attitude.attitude is None else np.empty((len(attitude.attitude), 3, n))
        )
        for k in range(n):
            h = _STEP  # every parameter is of order one (model.py)
            shifted = x.copy()
            shifted[k] += h
            r, a = self._values(shifted, t_rates, t_attitude, end)
            if dω is not None and rates.ω is not None and r.ω is not None:
                dω[:, :, k] = (r.ω - rates.ω) / h
            if dθ is not None and attitude.attitude is not None and a.attitude is not None:
                dθ[:, :, k] = (attitude.attitude.inv() * a.attitude).as_rotvec() / h
        return rates, attitude

    def _values(self, x, t_rates, t_attitude, end: float) -> tuple[Prediction, Prediction]:
        trajectory = self.trajectory(x, end)
        rates, attitude = Prediction(), Prediction()
        if t_rates is not None:
            rates.ω = trajectory.angular_velocity(t_rates)
            if self.layout.bias:
                rates.ω = rates.ω + x[self.layout.block("b")] * self.rate_unit
        if t_attitude is not None:
            attitude.attitude = Rotation.from_quat(
                trajectory.attitude_quaternion(t_attitude, scalar_first=False)
            )
        return rates, attitude
