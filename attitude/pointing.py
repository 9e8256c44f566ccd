"""Pointing: where the Sun (and the Earth) fall on the spacecraft's body vectors.

Body vectors are directions fixed in the body (panel normals, instrument
boresights, star tracker axes), declared in the scenario.  For each, on the output
grid: the Sun angle, the cosine of Sun incidence (zero when the Sun is behind the
vector or the spacecraft in umbra, scaled by the visible fraction of the Sun's disc
in penumbra), whether the Sun is inside its exclusion cone, its right ascension and
declination and, on an orbit, its angle from nadir.  And the intervals: eclipses
(from ``attitude.eclipse``), each constraint violation and each Sun-visibility
window, with ends refined on the exact motion to a stated precision.

Where the spacecraft is: at the Earth's centre by default (the Sun direction from
the Earth, apparent), or on a TLE orbit (``attitude.orbit``), which adds eclipses,
nadir and the Sun seen from the spacecraft (apparent: light time, aberration).

The Sun and the spacecraft move slowly against the attitude, so their positions are
sampled once on a coarse grid (60 s on an orbit, 600 s at the Earth's centre) and
interpolated in TT seconds (cubic Hermite with the velocities for the orbit, cubic
spline for the Sun).  ``tests/test_pointing_against_hand_calculation.py`` measures
what this costs against direct evaluation: below 1e-3 arcsec for the Sun direction.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import CubicHermiteSpline, CubicSpline

from attitude.eclipse import eclipse_intervals, sunlit_fraction
from attitude.ephemeris import (
    skyfield_times,
    sun_position_from_earth,
    sun_position_from_observer,
)
from attitude.errors import InputError
from attitude.intervals import Interval, difference, find_intervals
from attitude.orbit import EARTH_EQUATORIAL_RADIUS_M, TleOrbit
from attitude.quantities import as_si_scalar, as_vector3
from attitude.timescales import tt_seconds
from attitude.trajectory import Trajectory
from attitude.vectors import angle_between

__all__ = [
    "TLE_NOTED_AFTER_DAYS",
    "TLE_REFUSED_AFTER_DAYS",
    "BodyVector",
    "Geometry",
    "PointingResult",
    "PointingSpec",
    "check_pointing",
    "compute_pointing",
    "interval_precision",
    "node_seconds",
    "search_grid_count",
]

KINDS = ("panel", "instrument", "star_tracker", "other")


@dataclass(frozen=True)
class BodyVector:
    """A named direction fixed in body axes (normalized on construction).

    ``sun_exclusion_half_angle_rad``: the Sun must stay outside this cone about the
    vector (a star tracker or a sensitive instrument); None for no constraint.
    ``kind``: 'panel' (its Sun incidence is reported), 'instrument', 'star_tracker'
    or 'other'.  ``sun_exclusion_half_angle_deg``: the same angle in degrees, as the
    user wrote it (30, not degrees(radians(30)) = 29.999999999999996), for the
    reports; computed from the radians when not given.
    """

    name: str
    vector: NDArray[np.float64]
    sun_exclusion_half_angle_rad: float | None = None
    kind: str = "other"
    sun_exclusion_half_angle_deg: float | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not re.fullmatch(r"[A-Za-z][A-Za-z0-9_]*", self.name):
            raise InputError(
                f"body vector name must be letters, digits and _ (it names CSV columns), "
                f"got {self.name!r}"
            )
        vector = as_vector3(self.vector, "dimensionless", f"body vector {self.name!r}")
        norm = np.linalg.norm(vector)
        if not norm > 0.0:
            raise InputError(f"body vector {self.name!r} must be non-zero, got {vector.tolist()}")
        object.__setattr__(self, "vector", vector / norm)
        if self.kind not in KINDS:
            raise InputError(
                f"body vector {self.name!r}: kind must be one of {KINDS}, got {self.kind!r}"
            )
        half = self.sun_exclusion_half_angle_rad
        if half is not None:
            half = as_si_scalar(half, "angle", f"body vector {self.name!r} exclusion half angle")
            if not 0.0 < half < math.pi:
                raise InputError(
                    f"body vector {self.name!r}: sun exclusion half angle must be between "
                    f"0 and 180 deg, got {math.degrees(half):g} deg"
                )
            object.__setattr__(self, "sun_exclusion_half_angle_rad", half)
            if self.sun_exclusion_half_angle_deg is None:
                object.__setattr__(self, "sun_exclusion_half_angle_deg", math.degrees(half))
        elif self.sun_exclusion_half_angle_deg is not None:
            raise InputError(
                f"body vector {self.name!r}: sun_exclusion_half_angle_deg without the angle "
                "in radians"
            )


@dataclass(frozen=True)
class PointingSpec:
    """What pointing outputs a scenario asks for.

    ``tle``: the two lines of a TLE placing the spacecraft on an orbit (None: the
    spacecraft is taken at the Earth's centre, and only Sun directions are computed).
    ``interval_precision_s``: the precision to which interval ends are refined.
    """

    body_vectors: list[BodyVector] = field(default_factory=list)
    tle: tuple[str, str] | None = None
    interval_precision_s: float = 1e-3

    def __post_init__(self) -> None:
        if not self.interval_precision_s > 0.0:
            raise InputError(
                f"interval_precision must be positive, got {self.interval_precision_s!r} s"
            )

    @property
    def is_empty(self) -> bool:
        return not self.body_vectors and self.tle is None

    def describe(self) -> dict[str, Any]:
        return {
            "body_vectors": [
                {
                    "name": v.name,
                    "vector_body": v.vector.tolist(),
                    "kind": v.kind,
                    "sun_exclusion_half_angle_deg": v.sun_exclusion_half_angle_deg,
                }
                for v in self.body_vectors
            ],
            "orbit": "TLE" if self.tle else "Earth centre",
            "interval_precision_s": self.interval_precision_s,
        }


# Sampling of the Sun and orbit positions (TT seconds).
_ORBIT_NODE_STEP_S = 60.0
_SUN_NODE_STEP_S = 600.0
# Search grid for the body-vector intervals: this many samples per turn of the fastest
# rotation, so that the Sun cannot cross a body vector's cone and back between two.
_SAMPLES_PER_TURN = 64
# Search step of the eclipse edges (attitude.eclipse.eclipse_intervals).
_ECLIPSE_STEP_S = 30.0
# SGP4 elements are for days to weeks around their epoch: beyond the first limit a
# run says that eclipse times are approximate, beyond the second it is refused.
TLE_NOTED_AFTER_DAYS = 30.0
TLE_REFUSED_AFTER_DAYS = 365.0


def node_seconds(stop_s: float, on_orbit: bool) -> NDArray[np.float64]:
    """The TT seconds at which the Sun (and the orbit) are sampled for a span [0, stop_s]:
    a step beyond each end, so that the interpolation covers the span with margin."""
    step = _ORBIT_NODE_STEP_S if on_orbit else _SUN_NODE_STEP_S
    count = max(4, math.ceil(stop_s / step) + 3)
    return -step + step * np.arange(count)


def search_grid_count(trajectory: Trajectory, start_s: float, stop_s: float) -> int:
    """The number of samples of the interval search grid on [start_s, stop_s]: enough
    per turn of the fastest rotation of any segment (see :func:`_search_grid`)."""
    return int(_search_step(trajectory, trajectory.scenario.step_s, (stop_s - start_s)))


def _search_step(trajectory: Trajectory, step_s: float, span_s: float | None = None):
    """The search step on the output step ``step_s`` (or, with ``span_s``, the count)."""
    turn_s = min(
        2.0
        * math.pi
        * float(np.min(segment.solver.moments_of_inertia))
        / max(segment.solver.angular_momentum_norm, 1e-300)
        for segment in trajectory.segments
    )
    step = min(step_s, turn_s / _SAMPLES_PER_TURN)
    if span_s is None:
        return step
    return max(math.ceil(span_s / step) + 1, 2)


def interval_precision(spec: PointingSpec, stop_s: float) -> tuple[float, str | None]:
    """The precision to which interval ends are refined, and why it differs if it does.

    Bisection cannot narrow a bracket below the spacing of floats at its time: a
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


def check_pointing(trajectory: Trajectory, spec: PointingSpec) -> list[str]:
    """Everything the pointing of ``spec`` needs, checked before anything is sampled.

    The TLE (its lines, its elements, SGP4 at every orbit node of the span, its epoch
    within :data:`TLE_REFUSED_AFTER_DAYS` of the span), and the Sun ephemeris over the
    span with the margins the interpolation adds.  Raises :class:`InputError` whose
    message starts with the key (``pointing.tle: ...``, ``output: ...``); returns notes
    for the user (a TLE far from its epoch, a clamped interval precision).
    """
    scenario = trajectory.scenario
    if spec.is_empty:
        return []
    notes = []
    _, note = interval_precision(spec, scenario.stop_s)
    if note:
        notes.append(f"pointing.interval_precision: {note}")
    nodes = node_seconds(scenario.stop_s, spec.tle is not None)
    try:
        skyfield_times(scenario.times(nodes[[0, -1]]), name="span")
    except InputError as exc:
        raise InputError(
            f"output: the span with its {abs(nodes[0]):g} s margins needs the Sun over "
            f"{scenario.format_epoch(nodes[0])} to {scenario.format_epoch(nodes[-1])}: "
            f"{str(exc).removeprefix('span: ')}"
        ) from None
    if spec.tle is not None:
        try:
            orbit = TleOrbit(*spec.tle, name=scenario.spacecraft.name)
        except InputError as exc:
            raise InputError(f"pointing.tle: {exc}") from None
        days = (
            float(np.max(np.abs(tt_seconds(scenario.times(nodes[[0, -1]]), orbit.epoch)))) / 86400.0
        )
        if days > TLE_REFUSED_AFTER_DAYS:
            raise InputError(
                f"pointing.tle: the span reaches {days:.0f} days from the TLE's epoch "
                f"{orbit.epoch.isot} UTC: SGP4 elements describe an orbit for days to weeks "
                f"around their epoch (this tool refuses beyond {TLE_REFUSED_AFTER_DAYS:g} "
                "days): use elements from near the span"
            )
        if days > TLE_NOTED_AFTER_DAYS:
            notes.append(
                f"pointing.tle: the span reaches {days:.0f} days from the TLE's epoch: SGP4 "
                "drifts by kilometres a day, so eclipse times are approximate"
            )
        failure = orbit.sgp4_failure(scenario.times(nodes))
        if failure:
            raise InputError(f"pointing.tle: {failure}")
    return notes


class Geometry:
    """The Sun and the spacecraft over a scenario's span, at any TT seconds.

    Samples the ephemeris (and the orbit) once on a coarse grid covering the span and
    interpolates.  Vectors are ICRF axes (GCRS), metres.
    """

    def __init__(self, trajectory: Trajectory, tle: tuple[str, str] | None) -> None:
        scenario = trajectory.scenario
        self.scenario = scenario
        self.orbit = None if tle is None else TleOrbit(*tle, name=scenario.spacecraft.name)
        nodes = node_seconds(scenario.stop_s, self.orbit is not None)
        times = scenario.times(nodes)
        sun_earth = sun_position_from_earth(times)
        self._sun_from_earth = CubicSpline(nodes, sun_earth, axis=0)
        if self.orbit is None:
            self._sun = self._sun_from_earth
            self._position = None
        else:
            r_m, v_m_s = self.orbit.position_velocity(times)
            self._position = CubicHermiteSpline(nodes, r_m, v_m_s, axis=0)
            self._sun = CubicSpline(nodes, sun_position_from_observer(times, r_m, v_m_s), axis=0)

    @property
    def on_orbit(self) -> bool:
        return self.orbit is not None

    def sun_from_spacecraft(self, seconds: NDArray[np.float64]) -> NDArray[np.float64]:
        """Apparent Sun position seen from the spacecraft (or the Earth's centre), m."""
        return self._sun(seconds)

    def sun_direction(self, seconds: NDArray[np.float64]) -> NDArray[np.float64]:
        s = self.sun_from_spacecraft(seconds)
        return s / np.linalg.norm(s, axis=-1, keepdims=True)

    def position(self, seconds: NDArray[np.float64]) -> NDArray[np.float64] | None:
        """Spacecraft position from the Earth's centre, m; None at the Earth's centre."""
        return None if self._position is None else self._position(seconds)

    def sunlit_fraction(self, seconds: NDArray[np.float64]) -> NDArray[np.float64]:
        """Visible fraction of the Sun's disc (1 at the Earth's centre: no eclipses)."""
        if self._position is None:
            return np.ones(np.shape(seconds))
        return sunlit_fraction(self._position(seconds), self._sun_from_earth(seconds))

    def eclipse_intervals(
        self, start_s: float, stop_s: float
    ) -> tuple[list[Interval], list[Interval]]:
        """(shadow, umbra) intervals in [start_s, stop_s]; empty at the Earth's centre."""
        if self.orbit is None:
            return [], []
        found = eclipse_intervals(
            self.orbit,
            self.scenario.times(start_s),
            self.scenario.times(stop_s),
            step_s=_ECLIPSE_STEP_S,
        )

        def as_intervals(edges) -> list[Interval]:
            if edges.size == 0:
                return []
            seconds = tt_seconds(edges, self.scenario.epoch).reshape(-1, 2)
            return [
                Interval(float(a), float(b), bool(a <= start_s + 1e-9), bool(b >= stop_s - 1e-9))
                for a, b in seconds
            ]

        return as_intervals(found.shadow), as_intervals(found.umbra)


@dataclass
class VectorPointing:
    """One body vector's pointing on the output grid and its intervals."""

    vector: BodyVector
    sun_angle_rad: NDArray[np.float64]
    cos_incidence: NDArray[np.float64]
    right_ascension_rad: NDArray[np.float64]
    declination_rad: NDArray[np.float64]
    nadir_angle_rad: NDArray[np.float64] | None
    violated: NDArray[np.bool_] | None
    violations: list[Interval] = field(default_factory=list)
    sun_visible: list[Interval] = field(default_factory=list)


@dataclass
class PointingResult:
    """Pointing on the output grid (``seconds``, TT s since the epoch) and its intervals."""

    seconds: NDArray[np.float64]
    sun_direction_icrf: NDArray[np.float64]
    sunlit_fraction: NDArray[np.float64]
    earth_angular_radius_rad: NDArray[np.float64] | None
    vectors: list[VectorPointing]
    shadow: list[Interval]
    umbra: list[Interval]
    precision_s: float
    on_orbit: bool


def _right_ascension(icrf: NDArray[np.float64]) -> NDArray[np.float64]:
    """Right ascension in [0, 2π): mod 2π of a tiny negative angle rounds to 2π itself."""
    ra = np.mod(np.arctan2(icrf[:, 1], icrf[:, 0]), 2.0 * math.pi)
    return np.where(ra >= 2.0 * math.pi, 0.0, ra)


def _search_grid(trajectory: Trajectory, start_s: float, stop_s: float, step_s: float):
    """A grid on [start_s, stop_s] fine enough for the fastest rotation of any segment."""
    step = _search_step(trajectory, step_s)
    count = math.ceil((stop_s - start_s) / step) + 1
    return np.linspace(start_s, stop_s, max(count, 2))


def compute_pointing(
    trajectory: Trajectory, spec: PointingSpec, seconds: NDArray[np.float64]
) -> PointingResult:
    """The pointing of ``spec``'s body vectors at ``seconds``, and the intervals over them."""
    geometry = Geometry(trajectory, spec.tle)
    attitude = trajectory.attitude(seconds)
    sun = geometry.sun_direction(seconds)
    sun_body = attitude.apply(sun, inverse=True)
    fraction = geometry.sunlit_fraction(seconds)
    position = geometry.position(seconds)
    start_s, stop_s = float(seconds[0]), float(seconds[-1])
    shadow, umbra = geometry.eclipse_intervals(start_s, stop_s)
    grid = _search_grid(trajectory, start_s, stop_s, trajectory.scenario.step_s)

    # The Sun in body axes on the search grid, once for every vector and condition.
    sun_body_grid = trajectory.attitude(grid).apply(geometry.sun_direction(grid), inverse=True)

    def sun_cosine(v: NDArray[np.float64], offset: float = 0.0):
        """τ ↦ cos(Sun angle of v) − offset, on the exact attitude."""

        def f(τ: NDArray[np.float64]) -> NDArray[np.float64]:
            return (
                trajectory.attitude(τ).apply(geometry.sun_direction(τ), inverse=True) @ v - offset
            )

        return f

    vectors = []
    for body_vector in spec.body_vectors:
        v = body_vector.vector
        cosine = sun_body @ v
        angle = angle_between(sun_body, v)
        icrf = attitude.apply(v)
        nadir = None
        if position is not None:
            nadir = angle_between(icrf, -position)
        half = body_vector.sun_exclusion_half_angle_rad
        result = VectorPointing(
            vector=body_vector,
            sun_angle_rad=angle,
            cos_incidence=np.maximum(cosine, 0.0) * fraction,
            right_ascension_rad=_right_ascension(icrf),
            declination_rad=np.arcsin(np.clip(icrf[:, 2], -1.0, 1.0)),
            nadir_angle_rad=nadir,
            violated=None if half is None else (angle < half) & (fraction > 0.0),
        )
        # In umbra the Sun is hidden: it neither blinds a sensor nor lights a panel.
        precision = interval_precision(spec, trajectory.scenario.stop_s)[0]
        on_grid = sun_body_grid @ v
        visible = find_intervals(sun_cosine(v), grid, precision, on_grid)
        result.sun_visible = difference(visible, umbra)
        if half is not None:
            cos_half = math.cos(half)
            inside = find_intervals(sun_cosine(v, cos_half), grid, precision, on_grid - cos_half)
            result.violations = difference(inside, umbra)
        vectors.append(result)

    return PointingResult(
        seconds=seconds,
        sun_direction_icrf=sun,
        sunlit_fraction=fraction,
        earth_angular_radius_rad=None
        if position is None
        else np.arcsin(
            np.minimum(1.0, EARTH_EQUATORIAL_RADIUS_M / np.linalg.norm(position, axis=-1))
        ),
        vectors=vectors,
        shadow=shadow,
        umbra=umbra,
        precision_s=interval_precision(spec, trajectory.scenario.stop_s)[0],
        on_orbit=geometry.on_orbit,
    )
