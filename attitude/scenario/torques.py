"""The torques of a scenario: gravity gradient, finite burns, and how they are propagated.

A scenario without torques is propagated by the exact torque-free solver between its
events.  With :class:`ScenarioTorques` its segments are propagated by
:class:`~attitude.torques.solver.TorquedSolver` (splitting with the exact free flow,
``docs/torques.md``) under:

- **gravity gradient** from a point-mass Earth, at the position of the scenario's
  orbit (``gravity_gradient=True``: the orbit given to the ``Scenario``, once for the
  torques and the pointing; or, given here, an orbit object with ``position(times)``
  or ``position_velocity(times)`` taking ``astropy.time.Time``, such as a
  ``TleOrbit``, ``OemOrbit`` or ``KeplerianOrbit``, or a callable of TT seconds since
  the scenario epoch returning inertial positions in metres; the scenario refuses one
  that disagrees with its own orbit);
- **burns** (:class:`Burn`): a constant torque, N m, fixed in the body axes or in
  inertial axes, from a start epoch over a duration.  A burn is continuous across the
  scenario's events: an impulse, an inertia change or an attitude reset during a burn
  leaves it on (its torque is fixed in the body axes, or in inertial axes, whatever
  the inertia or attitude).

The method: ``order`` 2, 4 (default) or 6, with either a ``step`` (s) or an
``accuracy`` (rad): with an accuracy, the one step of every torqued segment is chosen
so that the estimated attitude error of the whole run, errors carried across events
included, is within it (``attitude.trajectory.steps``; ``docs/torques.md``, "The
scenario route").  Neither: an accuracy of 1e-6 rad (the AEM's default tolerance).

``horizon_threshold`` (rad, default 1°) is the angle that defines the validity
horizon of a torque-free scenario that has an orbit: how long until the neglected
gravity gradient would move the attitude that far
(``attitude.trajectory.horizon.validity_horizon``).

Errors are :class:`~attitude.base.errors.InputError` whose message starts with the key
(``torques.step: ...``, ``torques.burns[1].duration: ...``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from attitude.base.errors import InputError
from attitude.base.quantities import as_si_scalar, as_vector3
from attitude.torques.solver import ACCURACY_RANGE_RAD

__all__ = [
    "DEFAULT_ACCURACY_RAD",
    "DEFAULT_HORIZON_THRESHOLD_RAD",
    "Burn",
    "PlacedBurn",
    "ScenarioTorques",
]

DEFAULT_ACCURACY_RAD = 1e-6
DEFAULT_HORIZON_THRESHOLD_RAD = math.radians(1.0)


@dataclass(frozen=True)
class Burn:
    """A constant torque from ``epoch`` for ``duration`` seconds: a finite thruster burn.

    ``epoch``: an ``astropy.time.Time`` (or ISO text in the scenario's scale), or TT
    seconds after the scenario epoch, as for events; ``duration``: s (> 0);
    ``torque``: N m (3 numbers, or an astropy Quantity); ``frame``: ``"body"`` (fixed
    in the body axes) or ``"inertial"`` (ICRF axes).
    """

    epoch: Any
    duration: Any
    torque: Any
    frame: str = "body"
    label: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "torque", as_vector3(self.torque, "torque", "torque"))
        duration = as_si_scalar(self.duration, "time", "duration")
        if not duration > 0.0:
            raise InputError(f"duration must be positive (s), got {duration!r}")
        object.__setattr__(self, "duration", duration)
        if self.frame not in ("body", "inertial"):
            raise InputError(f"frame must be 'body' or 'inertial', got {self.frame!r}")


@dataclass(frozen=True)
class ScenarioTorques:
    """The torques a scenario is propagated under, and the splitting's step and order.

    See the module docstring.  ``gravity_gradient``: True for the scenario's orbit,
    the orbit (or position callable) whose gravity gradient acts, or None (False);
    ``burns``: :class:`Burn` s; ``step`` (s) or ``accuracy`` (rad), not both;
    ``order``: 2, 4 or 6; ``horizon_threshold``: rad.
    """

    gravity_gradient: Any = None
    burns: tuple[Burn, ...] = field(default=())
    step: Any = None
    accuracy: Any = None
    order: int = 4
    horizon_threshold: Any = DEFAULT_HORIZON_THRESHOLD_RAD

    def __post_init__(self) -> None:
        burns = tuple(self.burns)
        for index, burn in enumerate(burns):
            if not isinstance(burn, Burn):
                raise InputError(
                    f"must be a Burn, got {burn!r}", key=f"torques.burns[{index}]", value=burn
                )
        object.__setattr__(self, "burns", burns)
        if self.step is not None and self.accuracy is not None:
            raise InputError("give step or accuracy, not both", key="torques")
        if self.step is not None:
            step = as_si_scalar(self.step, "time", "torques.step")
            if not step > 0.0:
                raise InputError(
                    f"must be positive (s), got {step!r}", key="torques.step", value=step
                )
            object.__setattr__(self, "step", step)
        if self.accuracy is not None:
            accuracy = as_si_scalar(self.accuracy, "angle", "torques.accuracy")
            low, high = ACCURACY_RANGE_RAD
            if not low <= accuracy <= high:
                raise InputError(
                    f"must be between {low:g} and {high:g} rad, got {accuracy!r} rad",
                    key="torques.accuracy",
                    value=accuracy,
                )
            object.__setattr__(self, "accuracy", accuracy)
        if isinstance(self.order, bool) or self.order not in (2, 4, 6):
            raise InputError(
                f"must be 2, 4 or 6, got {self.order!r}", key="torques.order", value=self.order
            )
        threshold = as_si_scalar(self.horizon_threshold, "angle", "torques.horizon_threshold")
        if not 0.0 < threshold < math.pi:
            raise InputError(
                f"must be between 0 and 180 deg, got {math.degrees(threshold)!r} deg",
                key="torques.horizon_threshold",
                value=math.degrees(threshold),
            )
        object.__setattr__(self, "horizon_threshold", threshold)
        if self.gravity_gradient is False:
            object.__setattr__(self, "gravity_gradient", None)
        if (
            self.gravity_gradient is not None
            and self.gravity_gradient is not True
            and not (
                callable(self.gravity_gradient)
                or hasattr(self.gravity_gradient, "position")
                or hasattr(self.gravity_gradient, "position_velocity")
            )
        ):
            raise InputError(
                "must be True (the scenario's orbit), an orbit "
                "(position(times) or position_velocity(times)) or a callable t -> inertial "
                f"position (m), got {self.gravity_gradient!r}",
                key="torques.gravity_gradient",
                value=self.gravity_gradient,
            )

    @property
    def any(self) -> bool:
        """True if any torque acts (gravity gradient or a burn)."""
        return self.gravity_gradient is not None or bool(self.burns)

    @property
    def accuracy_rad(self) -> float | None:
        """The accuracy the step is chosen for (the default when neither is given)."""
        if self.step is not None:
            return None
        return DEFAULT_ACCURACY_RAD if self.accuracy is None else float(self.accuracy)

    def modelled(self) -> list[str]:
        """What acts, in words, for the summary and ``check``."""
        names = []
        if self.gravity_gradient is not None:
            names.append("gravity gradient (point-mass Earth)")
        if self.burns:
            names.append(f"{len(self.burns)} burn" + ("s" if len(self.burns) > 1 else ""))
        return names


@dataclass(frozen=True)
class PlacedBurn:
    """A burn placed on the scenario's time line: [start_s, stop_s) in TT seconds."""

    start_s: float
    stop_s: float
    burn: Burn
    index: int  # its place in the list given: burns[index]

    @property
    def torque(self) -> NDArray[np.float64]:
        return self.burn.torque
