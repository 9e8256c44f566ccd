"""The named attitude laws, each a case of align-and-constrain.

Every law here is an :class:`attitude.laws.align_constrain.AlignConstrainLaw` whose
constructor chooses the pair of body vectors and the pair of directions; the
subclasses keep the user's parameters (for summaries and files) and nothing else:
evaluation, rates and degenerate cases are the general law's.  In the table, "b on d"
is the primary pair, "b → d" the secondary (as close as possible):

====================================  ==========================  =================================
law                                   primary                     secondary
====================================  ==========================  =================================
``InertialLaw(R)``                    +x on R x̂ (fixed)           +y → R ŷ (fixed)
``OrbitFrameLaw("lvlh", R)``          R⁻¹ẑ on the Earth's centre  R⁻¹x̂ → velocity
``OrbitFrameLaw("rtn", R)``           R⁻¹x̂ on −Earth's centre     R⁻¹ŷ → velocity
``NadirLaw()``                        +z on geodetic nadir        +x → velocity
``NadirLaw(yaw_steering=              +z on geodetic nadir        +x → ground velocity of the
"zero_doppler")``                                                 sub-satellite point
``NadirLaw(yaw_steering="sun")``      +z on geodetic nadir        +x → the Sun
``SunLaw(axis, constraint_axis,       axis on the Sun             constraint_axis → constraint
constraint)``                                                     (default: ICRF +Z)
``TargetLaw(target, …)``              axis on the target          constraint_axis → constraint
                                                                  (default: velocity for a ground
                                                                  site, ICRF +Z otherwise)
====================================  ==========================  =================================

``OrbitFrameLaw`` with the identity is nadir pointing on the geocentric vertical (the
body axes are the LVLH axes: :mod:`attitude.environment.frames`), and so is
``NadirLaw(vertical="geocentric")``.  The Orekit providers of the same definitions:
``FrameAlignedProvider`` (inertial), ``LofOffset`` with ``LOFType.LVLH_CCSDS`` or
``QSW`` (orbit frames), ``NadirPointing``, ``YawCompensation``, ``YawSteering``,
``CelestialBodyPointed`` (Sun), ``TargetPointing`` (ground site); docs/laws.md shows the
measured agreement.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.environment.frames import ORBIT_FRAMES
from attitude.laws.align_constrain import AlignConstrainLaw, body_vector
from attitude.laws.directions import Direction, FixedDirection, GroundSite, direction

__all__ = [
    "CELESTIAL_NORTH",
    "YAW_STEERING",
    "InertialLaw",
    "NadirLaw",
    "OrbitFrameLaw",
    "SunLaw",
    "TargetLaw",
]

YAW_STEERING = ("none", "zero_doppler", "sun")
VERTICALS = ("geodetic", "geocentric")
# The default constraint of Sun and celestial pointing: the Sun (|δ| ≤ 23.44°) and the
# Moon (|δ| ≤ 28.7°) never come within 61° of it.
CELESTIAL_NORTH = FixedDirection([0.0, 0.0, 1.0], "the celestial north pole (ICRF +Z)")


def _single_rotation(value: Any, name: str) -> Rotation:
    if not (isinstance(value, Rotation) and value.single):
        raise InputError(f"{name} must be a single scipy Rotation, got {value!r}")
    return value


class InertialLaw(AlignConstrainLaw):
    """Hold ``attitude`` (body → ICRF, a scipy ``Rotation``): body +x on the fixed
    direction R x̂, body +y towards R ŷ.  Rate and acceleration are zero."""

    name = "inertial"

    def __init__(self, attitude: Rotation) -> None:
        self.rotation = _single_rotation(attitude, "inertial.attitude")
        axes = self.rotation.as_matrix()
        super().__init__(
            "+x",
            FixedDirection(axes[:, 0], "the held body x axis"),
            "+y",
            FixedDirection(axes[:, 1], "the held body y axis"),
        )

    def describe(self) -> str:
        q = np.array2string(self.rotation.as_quat(scalar_first=True), precision=9, separator=", ")
        return f"inertial, quaternion body → ICRF (scalar first) {q}"

    def parameters(self) -> dict[str, Any]:
        return {"quaternion_scalar_first": self.rotation.as_quat(scalar_first=True).tolist()}


class OrbitFrameLaw(AlignConstrainLaw):
    """Hold ``offset`` (body → orbit frame, a scipy ``Rotation``; identity by default)
    in the LVLH or RTN frame of :mod:`attitude.environment.frames`: the body's axes
    are the frame's axes turned by ``offset``."""

    name = "orbit_frame"

    def __init__(self, frame: str = "lvlh", offset: Rotation | None = None) -> None:
        frame = str(frame).lower()
        if frame not in ORBIT_FRAMES:
            raise InputError(
                f"orbit_frame.frame must be one of {', '.join(ORBIT_FRAMES)}, got {frame!r}"
            )
        self.frame = frame
        self.offset = (
            Rotation.identity()
            if offset is None
            else _single_rotation(offset, "orbit_frame.offset")
        )
        to_body = self.offset.inv()
        if frame == "lvlh":  # z = −r̂, x = the part of v across r̂
            primary_axis, primary = to_body.apply([0.0, 0.0, 1.0]), "earth_centre"
            secondary_axis = to_body.apply([1.0, 0.0, 0.0])
        else:  # R = r̂, T = the part of v across r̂
            primary_axis, primary = to_body.apply([1.0, 0.0, 0.0]), "-earth_centre"
            secondary_axis = to_body.apply([0.0, 1.0, 0.0])
        super().__init__(primary_axis, primary, secondary_axis, "velocity")

    def describe(self) -> str:
        if np.allclose(self.offset.as_matrix(), np.eye(3), rtol=0.0, atol=0.0):
            return f"body axes = {self.frame.upper()} axes"
        q = self.offset.as_quat(scalar_first=True)
        return (
            f"{self.frame.upper()} with offset quaternion body → {self.frame.upper()} "
            f"(scalar first) {np.array2string(q, precision=9, separator=', ')}"
        )

    def parameters(self) -> dict[str, Any]:
        return {
            "frame": self.frame,
            "offset_quaternion_scalar_first": self.offset.as_quat(scalar_first=True).tolist(),
        }


class NadirLaw(AlignConstrainLaw):
    """Body +z on nadir, the yaw set by ``yaw_steering``:

    - ``"none"``: +x towards the velocity (the z–x plane holds the velocity);
    - ``"zero_doppler"``: +x along the ground-relative velocity of the sub-satellite
      point (yaw compensation of the Earth's rotation);
    - ``"sun"``: ``phasing_axis`` (+x or −x) towards the Sun, which then lies in the
      body x–z plane, where a solar array turning about y can face it.

    ``vertical``: ``"geodetic"`` (the WGS 84 normal, towards the sub-satellite point;
    default) or ``"geocentric"`` (the Earth's centre: with no yaw steering this is
    LVLH).
    """

    name = "nadir"

    def __init__(
        self, yaw_steering: str = "none", vertical: str = "geodetic", phasing_axis: Any = "+x"
    ) -> None:
        if yaw_steering not in YAW_STEERING:
            raise InputError(
                f"nadir.yaw_steering must be one of {', '.join(YAW_STEERING)}, got {yaw_steering!r}"
            )
        if vertical not in VERTICALS:
            raise InputError(
                f"nadir.vertical must be one of {', '.join(VERTICALS)}, got {vertical!r}"
            )
        self.yaw_steering = yaw_steering
        self.vertical = vertical
        self.phasing_axis = body_vector(phasing_axis, "nadir.phasing_axis")
        if yaw_steering == "sun" and abs(self.phasing_axis[2]) > 1e-12:
            raise InputError(
                "nadir.phasing_axis must be across z (in the body x-y plane), got "
                f"{self.phasing_axis.tolist()}"
            )
        secondary = {"none": "velocity", "zero_doppler": "ground_velocity", "sun": "sun"}[
            yaw_steering
        ]
        axis = self.phasing_axis if yaw_steering == "sun" else "+x"
        super().__init__(
            "+z", "nadir" if vertical == "geodetic" else "earth_centre", axis, secondary
        )

    def describe(self) -> str:
        steering = {
            "none": "+x towards the velocity",
            "zero_doppler": "zero-Doppler yaw steering",
            "sun": "Sun yaw steering",
        }[self.yaw_steering]
        return f"+z on {self.vertical} nadir, {steering}"

    def parameters(self) -> dict[str, Any]:
        return {
            "yaw_steering": self.yaw_steering,
            "vertical": self.vertical,
            "phasing_axis": self.phasing_axis.tolist(),
        }


class SunLaw(AlignConstrainLaw):
    """Body ``axis`` on the apparent Sun; body ``constraint_axis`` as close as possible
    to ``constraint`` (any direction; default the celestial north pole, ICRF +Z, which
    the Sun never comes within 66° of)."""

    name = "sun"

    def __init__(
        self, axis: Any = "+z", constraint_axis: Any = "+x", constraint: Any = None
    ) -> None:
        super().__init__(
            axis, "sun", constraint_axis, CELESTIAL_NORTH if constraint is None else constraint
        )

    def describe(self) -> str:
        return "Sun pointing: " + super().describe()


class TargetLaw(AlignConstrainLaw):
    """Body ``axis`` on ``target``: a :class:`GroundSite`, a :class:`CelestialTarget`,
    or ``"moon"``; body ``constraint_axis`` as close as possible to ``constraint``
    (default: the velocity for a ground site, as Orekit's ``TargetPointing``; the
    celestial north pole otherwise).

    A ground site below the horizon is still tracked (through the Earth): the law is
    defined, and :func:`attitude.laws.visibility.visible_intervals` says when it is not.
    """

    name = "target"

    def __init__(
        self, target: Any, axis: Any = "+z", constraint_axis: Any = "+x", constraint: Any = None
    ) -> None:
        target_direction = direction(target)
        if constraint is None:
            constraint = "velocity" if isinstance(target_direction, GroundSite) else CELESTIAL_NORTH
        super().__init__(axis, target_direction, constraint_axis, constraint)
        self.target: Direction = target_direction

    @property
    def site(self) -> GroundSite | None:
        """The ground site tracked, if the target is one."""
        return self.target if isinstance(self.target, GroundSite) else None

    def describe(self) -> str:
        return "target pointing: " + super().describe()
