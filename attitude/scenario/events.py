"""Events that change the spacecraft's motion at an epoch.

Between events the motion is torque-free and the exact solver propagates it; each
event starts a new solver segment.  An event maps the state just before its epoch
to the state just after (``apply``):

- :class:`AngularImpulse`: a thruster pulse or a docking bump, ΔH in N m s, in body
  or inertial axes.  The inertial angular momentum jumps by exactly ΔH.
- :class:`InertiaChange`: a deployment, propellant use, the separation of a part.
  The attitude and the inertial angular momentum are continuous (no external
  torque acts), so the body angular momentum is unchanged; the angular velocity
  and the kinetic energy change with the inertia (T = ½ m·I⁻¹m).
- :class:`AttitudeReset`: a kinematic reset, the spacecraft placed in a commanded
  attitude and/or rate, as after a slew performed by a controller outside this tool.

Epochs are ``astropy.time.Time``.  Ordering rules are the scenario's (see
``attitude.scenario.scenario``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.base.quantities import as_vector3
from attitude.scenario.spacecraft import check_inertia
from attitude.solver.inertia import PrincipalAxes

__all__ = ["AngularImpulse", "AttitudeReset", "Event", "InertiaChange", "State"]


@dataclass(frozen=True)
class State:
    """The state of the spacecraft at an instant.

    ``attitude``: body → inertial.  ``angular_momentum``: body axes, N m s.
    ``inertia``: the principal axes and tensor in force.
    """

    attitude: Rotation
    angular_momentum: NDArray[np.float64]
    inertia: PrincipalAxes

    @property
    def angular_velocity(self) -> NDArray[np.float64]:
        """Body angular velocity, rad/s: I⁻¹ m."""
        return np.asarray(np.linalg.solve(self.inertia.tensor, self.angular_momentum), np.float64)

    @property
    def kinetic_energy(self) -> float:
        """½ m·ω, J."""
        return 0.5 * float(self.angular_momentum @ self.angular_velocity)


def _check_frame(frame: str) -> str:
    if frame not in ("body", "inertial"):
        raise InputError(f"frame must be 'body' or 'inertial', got {frame!r}")
    return frame


@dataclass(frozen=True)
class AngularImpulse:
    """An angular impulse ΔH (N m s) applied at ``epoch``, in body or inertial axes."""

    epoch: Any
    impulse: NDArray[np.float64]
    frame: str = "body"
    label: str = ""
    kind: str = field(default="angular_impulse", init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "impulse", as_vector3(self.impulse, "angular_momentum", "impulse"))
        _check_frame(self.frame)

    def apply(self, state: State) -> State:
        ΔH_body = self.impulse if self.frame == "body" else state.attitude.inv().apply(self.impulse)
        return State(state.attitude, state.angular_momentum + ΔH_body, state.inertia)


@dataclass(frozen=True)
class InertiaChange:
    """The inertia becomes ``inertia`` (3 moments or a 3×3 tensor, body axes, kg m²)."""

    epoch: Any
    inertia: Any
    label: str = ""
    kind: str = field(default="inertia_change", init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "inertia", check_inertia(self.inertia, "inertia_change.inertia"))

    def apply(self, state: State) -> State:
        return State(state.attitude, state.angular_momentum, self.inertia)


@dataclass(frozen=True)
class AttitudeReset:
    """The spacecraft is placed in ``attitude`` and/or given a new rate at ``epoch``.

    Give ``angular_velocity`` (rad/s) or ``angular_momentum`` (N m s), body axes,
    or neither to keep the rate; ``attitude`` None keeps the attitude.
    """

    epoch: Any
    attitude: Rotation | None = None
    angular_velocity: NDArray[np.float64] | None = None
    angular_momentum: NDArray[np.float64] | None = None
    label: str = ""
    kind: str = field(default="attitude_reset", init=False)

    def __post_init__(self) -> None:
        if self.angular_velocity is not None and self.angular_momentum is not None:
            raise InputError("attitude_reset: give angular_velocity or angular_momentum, not both")
        if (
            self.attitude is None
            and self.angular_velocity is None
            and self.angular_momentum is None
        ):
            raise InputError("attitude_reset: give an attitude, a rate, or both")
        if self.attitude is not None and not (
            isinstance(self.attitude, Rotation) and self.attitude.single
        ):
            raise InputError(
                f"attitude_reset.attitude must be a single Rotation, got {self.attitude!r}"
            )
        if self.angular_velocity is not None:
            value = as_vector3(self.angular_velocity, "angular_velocity", "angular_velocity")
            object.__setattr__(self, "angular_velocity", value)
        if self.angular_momentum is not None:
            value = as_vector3(self.angular_momentum, "angular_momentum", "angular_momentum")
            object.__setattr__(self, "angular_momentum", value)

    def apply(self, state: State) -> State:
        attitude = state.attitude if self.attitude is None else self.attitude
        if self.angular_velocity is not None:
            m = state.inertia.tensor @ self.angular_velocity
        elif self.angular_momentum is not None:
            m = self.angular_momentum
        else:
            m = state.angular_momentum
        return State(attitude, m, state.inertia)


Event = AngularImpulse | InertiaChange | AttitudeReset
