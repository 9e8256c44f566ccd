"""Mode events: a controlled spacecraft changes law, loses control, regains it.

A scenario may start under an attitude law (``InitialState(law=...)``,
:mod:`attitude.laws`) and then:

- :class:`ModeChange`: change law at an epoch, through a slew within ``slew``'s limits
  (:class:`attitude.laws.slews.SlewLimits`: eigen-axis, bang–coast–bang, from the old
  law's rate to the new one's) or, without limits, by an instantaneous switch;
- :class:`ControlLoss`: the law ends; from that epoch the body moves freely (or under
  the scenario's torques) from the law's attitude, with the momentum I·ω_law plus the
  momentum the reaction wheels hold (:class:`Wheels`): ``locked`` wheels pass it to the
  body (the torque-free rigid body), ``spinning`` wheels keep their speed relative to
  the body (a gyrostat: :mod:`attitude.torques.gyrostat`);
- :class:`ControlResume`: a law takes the body again, through a slew from the tumbling
  state (refused, naming why, when the tumble is faster than the limits can capture),
  or instantly without limits.

The timeline these make is built by :mod:`attitude.trajectory.modes`; the hand-off at
a control loss is :func:`attitude.trajectory.handoff.hand_off`.  Events that act on a
free body (an angular impulse, an attitude reset) are refused while a law holds the
attitude: the controller would absorb them; an inertia change is allowed (the law
holds on, with the new I·ω).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from attitude.base.errors import InputError
from attitude.base.quantities import as_vector3
from attitude.laws.align_constrain import AttitudeLaw
from attitude.laws.slews import SlewLimits

__all__ = [
    "MAX_WHEEL_RATE_RAD_S",
    "MODE_EVENTS",
    "WHEEL_CASES",
    "ControlLoss",
    "ControlResume",
    "ModeChange",
    "Wheels",
]

WHEEL_CASES = ("locked", "spinning")
# Wheels that would turn the body faster than this (|I⁻¹h|, rad/s: about 1000 rpm) hold a
# momentum no reaction wheel or control moment gyro holds: refused as a mistake.
MAX_WHEEL_RATE_RAD_S = 100.0
MODE_EVENTS = ("mode_change", "control_loss", "control_resume")


def _law(value: Any, name: str) -> AttitudeLaw:
    if not isinstance(value, AttitudeLaw):
        raise InputError(f"{name} must be an attitude law (attitude.laws), got {value!r}")
    return value


def _limits(value: Any, name: str) -> SlewLimits | None:
    if value is None or isinstance(value, SlewLimits):
        return value
    raise InputError(
        f"{name} must be a SlewLimits or None (an instantaneous switch), got {value!r}"
    )


@dataclass(frozen=True)
class Wheels:
    """The reaction wheels at a control loss: ``case`` ``"locked"`` (their momentum
    passes to the body) or ``"spinning"`` (they keep their speed relative to the body);
    ``momentum``: the momentum they hold, body axes, N m s (3 numbers or a Quantity)."""

    case: str = "locked"
    momentum: Any = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        if self.case not in WHEEL_CASES:
            raise InputError(
                f"must be one of {', '.join(WHEEL_CASES)}, got {self.case!r}",
                key="wheels.case",
                value=self.case,
            )
        momentum = as_vector3(self.momentum, "angular_momentum", "wheels.momentum")
        object.__setattr__(self, "momentum", momentum)

    @property
    def momentum_vector(self) -> NDArray[np.float64]:
        return np.asarray(self.momentum, dtype=np.float64)

    def check_against(self, inertia_tensor: NDArray[np.float64], key: str = "") -> None:
        """Refuse a momentum that would turn the body beyond :data:`MAX_WHEEL_RATE_RAD_S`
        (|I⁻¹h|): no wheel holds it; ``key`` names the event (none: the wheels alone,
        ``wheels.momentum``)."""
        rate = float(np.linalg.norm(np.linalg.solve(inertia_tensor, self.momentum_vector)))
        if not rate <= MAX_WHEEL_RATE_RAD_S:
            raise InputError(
                f"{np.asarray(self.momentum).tolist()} N m s would turn "
                f"the body at {rate:.3g} rad/s ({rate * 30.0 / math.pi:.3g} rpm, |I⁻¹h|): no "
                f"reaction wheel holds that much (at most {MAX_WHEEL_RATE_RAD_S:g} rad/s is "
                "accepted); give the wheels' momentum in N m s",
                key=f"{key}.wheels.momentum" if key else "wheels.momentum",
                value=self.momentum_vector,
            )

    def describe(self) -> str:
        h = np.array2string(self.momentum_vector, precision=6, separator=", ")
        what = (
            "locked: their momentum passes to the body"
            if self.case == "locked"
            else "spinning at constant speed relative to the body: a gyrostat"
        )
        return f"wheels {what}, h = {h} N m s (body axes)"


@dataclass(frozen=True)
class ModeChange:
    """At ``epoch`` the law ``law`` takes over, through a slew within ``slew`` (a
    :class:`SlewLimits`) or, with ``slew`` None, instantly."""

    epoch: Any
    law: AttitudeLaw
    slew: SlewLimits | None = None
    label: str = ""
    kind: str = field(default="mode_change", init=False)

    def __post_init__(self) -> None:
        _law(self.law, "mode_change.law")
        _limits(self.slew, "mode_change.slew")


@dataclass(frozen=True)
class ControlLoss:
    """At ``epoch`` the law ends: the body moves freely from the law's state, with the
    wheels' momentum (:class:`Wheels`, default: locked, holding none)."""

    epoch: Any
    wheels: Wheels = field(default_factory=Wheels)
    label: str = ""
    kind: str = field(default="control_loss", init=False)

    def __post_init__(self) -> None:
        if not isinstance(self.wheels, Wheels):
            raise InputError(f"control_loss.wheels must be a Wheels, got {self.wheels!r}")


@dataclass(frozen=True)
class ControlResume:
    """At ``epoch`` the law ``law`` takes the free body again, through a slew within
    ``slew`` from its tumbling state, or instantly with ``slew`` None."""

    epoch: Any
    law: AttitudeLaw
    slew: SlewLimits | None = None
    label: str = ""
    kind: str = field(default="control_resume", init=False)

    def __post_init__(self) -> None:
        _law(self.law, "control_resume.law")
        _limits(self.slew, "control_resume.slew")


ModeEvent = ModeChange | ControlLoss | ControlResume
