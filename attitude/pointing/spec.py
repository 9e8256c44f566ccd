"""What a scenario asks of the pointing: body vectors, their constraints, the orbit.

A :class:`BodyVector` is a direction fixed in body axes (a panel normal, a boresight, a
star tracker's axis, a Sun sensor's axis) with its constraints: a Sun and a Moon
exclusion cone, a least angle above the Earth's limb, and a Sun inclusion cone (the
field of view of a Sun sensor, which must contain the Sun).  A :class:`PointingSpec`
gathers the vectors, where the spacecraft is (an
:class:`attitude.environment.orbit.Orbit`, or the Earth's centre when None), the
precision of interval ends, the height of the limb's atmosphere and an optional Euler
sequence for the attitude in LVLH.  Nothing here computes a direction: that is
:mod:`attitude.pointing.sampling` (at given times) and :mod:`attitude.pointing.search`
(intervals and extrema over a span).

Angles are radians (or angle Quantities) in the API; the ``*_deg`` fields keep the
degrees the user wrote, for the reports.
"""

from __future__ import annotations

import dataclasses
import math
import re
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from attitude.base.errors import InputError
from attitude.base.quantities import as_si_scalar, as_vector3
from attitude.environment.orbit import Orbit, TleOrbit
from attitude.scenario.scenario import Scenario, orbit_disagreement

__all__ = [
    "KINDS",
    "BodyVector",
    "PointingSpec",
    "describe_lines",
    "for_scenario",
    "interval_precision",
]

KINDS = ("panel", "instrument", "star_tracker", "sun_sensor", "other")


def _angle(value: Any, name: str, what: str, low: float, high: float) -> float | None:
    """``value`` (radians, or a Quantity) checked to lie in (low, high) degrees."""
    if value is None:
        return None
    value = as_si_scalar(value, "angle", f"body vector {name!r} {what}")
    if not math.radians(low) <= value < math.radians(high) or (low > 0 and value == 0.0):
        raise InputError(
            f"body vector {name!r}: {what} must be between {low:g} and {high:g} deg, "
            f"got {math.degrees(value):g} deg"
        )
    return value


@dataclass(frozen=True)
class BodyVector:
    """A named direction fixed in body axes (normalized on construction), and its
    constraints.

    ``kind``: 'panel' (its Sun incidence is reported), 'instrument', 'star_tracker',
    'sun_sensor' or 'other'.  Constraints (radians, or angle Quantities; None for none):

    - ``sun_exclusion_half_angle_rad``: the Sun must stay outside this cone about the
      vector (unless the spacecraft is in umbra: a hidden Sun blinds nothing);
    - ``moon_exclusion_half_angle_rad``: the same for the Moon (unless the Earth hides
      the Moon's centre);
    - ``earth_limb_exclusion_angle_rad``: the vector must stay at least this far above
      the Earth's limb (or the limb of its atmosphere, see :class:`PointingSpec`);
    - ``sun_inclusion_half_angle_rad``: the Sun must be *inside* this cone about the
      vector (a Sun sensor's field of view); it is seen there unless the spacecraft is
      in umbra.  With a Sun exclusion cone too, it must be the wider of the two, or
      the Sun could never be seen.

    The exclusions together say when the vector is blinded (by any of them); the
    inclusion when it sees the Sun (:class:`attitude.pointing.search.VectorAnalysis`).

    The ``*_deg`` fields carry the same angles in degrees as the user wrote them (30,
    not degrees(radians(30)) = 29.999999999999996), for the reports; computed from the
    radians when not given.
    """

    name: str
    vector: NDArray[np.float64]
    sun_exclusion_half_angle_rad: float | None = None
    kind: str = "other"
    sun_exclusion_half_angle_deg: float | None = None
    moon_exclusion_half_angle_rad: float | None = None
    moon_exclusion_half_angle_deg: float | None = None
    earth_limb_exclusion_angle_rad: float | None = None
    earth_limb_exclusion_angle_deg: float | None = None
    sun_inclusion_half_angle_rad: float | None = None
    sun_inclusion_half_angle_deg: float | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not re.fullmatch(r"[A-Za-z][A-Za-z0-9_]*", self.name):
            raise InputError(
                f"body vector name must be letters, digits and _ (it names CSV columns), "
                f"got {self.name!r}",
                key="name",
                value=self.name,
            )
        vector = as_vector3(self.vector, "dimensionless", f"body vector {self.name!r}")
        norm = np.linalg.norm(vector)
        if not norm > 0.0:
            raise InputError(
                f"body vector {self.name!r} must be non-zero, got {vector.tolist()}",
                key="vector",
                value=vector.tolist(),
            )
        object.__setattr__(self, "vector", vector / norm)
        if self.kind not in KINDS:
            raise InputError(
                f"body vector {self.name!r}: kind must be one of {KINDS}, got {self.kind!r}",
                key="kind",
                value=self.kind,
            )
        for prefix, what, low in (
            ("sun_exclusion_half_angle", "sun exclusion half angle", 0.0),
            ("moon_exclusion_half_angle", "moon exclusion half angle", 0.0),
            ("earth_limb_exclusion_angle", "earth limb exclusion angle", -90.0),
            ("sun_inclusion_half_angle", "sun inclusion half angle", 0.0),
        ):
            radians = _angle(getattr(self, f"{prefix}_rad"), self.name, what, low, 180.0)
            degrees = getattr(self, f"{prefix}_deg")
            if radians is None and degrees is not None:
                raise InputError(
                    f"body vector {self.name!r}: {prefix}_deg without the angle in radians"
                )
            object.__setattr__(self, f"{prefix}_rad", radians)
            if radians is not None and degrees is None:
                object.__setattr__(self, f"{prefix}_deg", math.degrees(radians))
        inclusion, exclusion = self.sun_inclusion_half_angle_rad, self.sun_exclusion_half_angle_rad
        if inclusion is not None and exclusion is not None and inclusion <= exclusion:
            raise InputError(
                f"body vector {self.name!r}: sun inclusion half angle "
                f"{self.sun_inclusion_half_angle_deg:g} deg is within its sun exclusion half "
                f"angle {self.sun_exclusion_half_angle_deg:g} deg: the Sun could never be seen"
            )

    @property
    def exclusions(self) -> list[str]:
        """The exclusions this vector has, by name (``sun_exclusion``, ``moon_exclusion``,
        ``earth_limb_exclusion``): what can blind it."""
        return [
            name
            for name, angle in (
                ("sun_exclusion", self.sun_exclusion_half_angle_rad),
                ("moon_exclusion", self.moon_exclusion_half_angle_rad),
                ("earth_limb_exclusion", self.earth_limb_exclusion_angle_rad),
            )
            if angle is not None
        ]


_EULER_SEQUENCE = re.compile(r"[XYZ]{3}|[xyz]{3}")


@dataclass(frozen=True)
class PointingSpec:
    """What pointing outputs a scenario asks for.

    ``body_vectors``: the :class:`BodyVector` list.  ``orbit``: an
    :class:`attitude.environment.orbit.Orbit`, or the two lines of a TLE; None takes the
    scenario's orbit (``Scenario(..., orbit=...)``, :func:`for_scenario`), and with none
    there either places the spacecraft at the Earth's centre (Sun and Moon directions
    only).
    ``interval_precision_s``: the precision to which interval ends are refined.
    ``earth_limb_atmosphere_height_m``: the height above the Earth's equatorial radius
    of the limb that the limb angles are measured from (0: the solid Earth; 50–100 km
    is a common margin for the bright atmosphere).  ``lvlh_euler_sequence``: with an
    orbit, also give the attitude in LVLH as Euler angles in this sequence (scipy's
    notation: "ZYX" intrinsic, "zyx" extrinsic).
    """

    body_vectors: list[BodyVector] = field(default_factory=list)
    # The two lines of a TLE are taken too (made a TleOrbit on construction): after it,
    # the orbit is an Orbit or None.
    orbit: Orbit | None = None
    interval_precision_s: float = 1e-3
    earth_limb_atmosphere_height_m: float = 0.0
    lvlh_euler_sequence: str | None = None

    def __post_init__(self) -> None:
        given: Any = self.orbit
        if isinstance(given, tuple | list):
            object.__setattr__(self, "orbit", TleOrbit(*given))
        if self.orbit is not None and not isinstance(self.orbit, Orbit):
            raise InputError(
                f"orbit must be an Orbit or the two lines of a TLE, got {self.orbit!r}"
            )
        if not self.interval_precision_s > 0.0:
            raise InputError(
                f"must be positive, got {self.interval_precision_s!r} s",
                key="interval_precision",
                value=self.interval_precision_s,
            )
        height = as_si_scalar(self.earth_limb_atmosphere_height_m, "length", "atmosphere height")
        if not 0.0 <= height <= 1e6:
            raise InputError(
                f"must be between 0 and 1000 km, got {height:g} m",
                key="earth_limb_atmosphere_height",
                value=height,
            )
        object.__setattr__(self, "earth_limb_atmosphere_height_m", height)
        sequence = self.lvlh_euler_sequence
        if sequence is not None and (
            not isinstance(sequence, str)
            or not _EULER_SEQUENCE.fullmatch(sequence)
            or sequence[0] == sequence[1]
            or sequence[1] == sequence[2]
        ):
            raise InputError(
                "must be three axes, all upper case (intrinsic) or all "
                f"lower case (extrinsic), no axis twice in a row (ZYX, zxz...), got {sequence!r}",
                key="lvlh_euler_sequence",
                value=sequence,
            )

    def check_orbit(self) -> None:
        """Refuse (InputError) what needs an orbit without one: an Earth limb exclusion,
        the attitude in LVLH.  Checked where the spec meets its scenario
        (:func:`for_scenario`), whose orbit it takes when it has none of its own."""
        if self.orbit is not None:
            return
        needs = [
            (index, v)
            for index, v in enumerate(self.body_vectors)
            if v.earth_limb_exclusion_angle_rad
        ]
        if needs:
            index, vector = needs[0]
            raise InputError(
                f"body vector {vector.name!r}: an earth limb exclusion needs an orbit "
                "(a TLE, an OEM file or Keplerian elements)",
                key=f"body_vectors[{index}].earth_limb_exclusion_angle",
                value=vector.earth_limb_exclusion_angle_deg,
            )
        if self.lvlh_euler_sequence is not None:
            raise InputError(
                "needs an orbit (LVLH is the orbit's frame)",
                key="lvlh_euler_sequence",
                value=self.lvlh_euler_sequence,
            )

    @property
    def is_empty(self) -> bool:
        return not self.body_vectors and self.orbit is None

    @property
    def on_orbit(self) -> bool:
        return self.orbit is not None

    @property
    def tle(self) -> tuple[str, str] | None:
        """The TLE lines, when the orbit is a TLE."""
        return self.orbit.lines if isinstance(self.orbit, TleOrbit) else None


def for_scenario(spec: PointingSpec, scenario: Scenario) -> PointingSpec:
    """``spec`` as it applies to ``scenario``: with the scenario's orbit when the spec
    gives none (the orbit is given once, to the Scenario), checked for what needs an
    orbit.  A spec whose own orbit disagrees with the scenario's is refused
    (:func:`attitude.scenario.scenario.orbit_disagreement`)."""
    if scenario.orbit is not None:
        if spec.orbit is None:
            spec = dataclasses.replace(spec, orbit=scenario.orbit)
        else:
            disagreement = orbit_disagreement(scenario.orbit, spec.orbit, scenario)
            if disagreement:
                raise InputError(
                    f"the PointingSpec's orbit is not the scenario's: "
                    f"{disagreement}; give the orbit once, Scenario(..., orbit=...), and "
                    "leave it out of the PointingSpec",
                    key="pointing.orbit",
                )
    try:
        spec.check_orbit()
    except InputError as exc:  # its keys are the [pointing] table's
        raise exc.under("pointing") from None
    return spec


def describe_lines(spec: PointingSpec) -> list[str]:
    """What ``attitude check`` says of the pointing: the orbit, and each body vector with
    its constraints in degrees (as the user wrote them)."""
    if spec.is_empty:
        return []
    where = "Earth centre" if spec.orbit is None else spec.orbit.describe()
    lines = [
        f"pointing    {len(spec.body_vectors)} body "
        f"{'vector' if len(spec.body_vectors) == 1 else 'vectors'}, orbit: {where}, interval ends "
        f"to {spec.interval_precision_s:g} s"
    ]
    if spec.earth_limb_atmosphere_height_m:
        lines.append(
            f"  limb angles from {spec.earth_limb_atmosphere_height_m / 1e3:g} km of atmosphere"
        )
    for vector in spec.body_vectors:
        limits = [
            f"{what} {angle:.12g} deg"
            for what, angle in (
                ("Sun exclusion half angle", vector.sun_exclusion_half_angle_deg),
                ("Moon exclusion half angle", vector.moon_exclusion_half_angle_deg),
                ("Earth limb exclusion angle", vector.earth_limb_exclusion_angle_deg),
                ("Sun inclusion half angle", vector.sun_inclusion_half_angle_deg),
            )
            if angle is not None
        ]
        lines.append(
            f"  {vector.name}: {vector.kind}, {vector.vector.tolist()} (body)"
            + "".join(f", {limit}" for limit in limits)
        )
    return lines


def interval_precision(spec: PointingSpec, stop_s: float) -> tuple[float, str | None]:
    """The precision to which interval ends are refined, and why it differs if it does.

    A search cannot narrow a bracket below the spacing of floats at its time: a
    precision finer than twice that spacing at the end of the span (1e-13 s asked
    over a day, where TT seconds resolve 1.5e-11 s) would never be reached, so it is
    raised to it, and the note says so.
    """
    resolution = 2.0 * float(np.spacing(max(stop_s, 1.0)))
    asked = spec.interval_precision_s
    if asked >= resolution:
        return asked, None
    return resolution, (
        f"interval_precision {asked:g} s is finer than TT seconds resolve over the span "
        f"(2 ulp at {stop_s:g} s): interval ends are refined to {resolution:.3g} s"
    )
