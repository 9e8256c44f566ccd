"""Pointing: where the Sun, the Moon and the Earth fall on the spacecraft's body vectors.

Body vectors are directions fixed in the body (panel normals, instrument boresights,
star tracker axes), declared in a :class:`PointingSpec` with their constraints: a Sun
and a Moon exclusion cone, and a least angle above the Earth's limb.  Two entry points:

- :func:`pointing_samples` at any times (the output grid, a chunk of it): the Sun and
  Moon directions, each vector's Sun, Moon, nadir and limb angles, the Sun's incidence,
  the constraint flags, its right ascension and declination, and the attitude in the
  orbit's LVLH frame.  No intervals, no state kept between calls: a long run asks for
  its output grid chunk by chunk.
- :func:`pointing_analysis` over the whole span: every interval (eclipse, umbra, each
  exclusion, Sun visibility) and every extremum (least and greatest Sun, Moon, nadir
  and limb angles, incidence), found on the exact motion, independent of the output
  step, in bounded memory (the span is searched in chunks).

**Where the spacecraft is**: on an orbit (:class:`attitude.orbit.Orbit`: a TLE, an OEM
file, Keplerian elements), or at the Earth's centre when none is given (then only the
Sun and Moon directions are computed: no eclipse, nadir or limb).  The Sun and the
Moon are their apparent places seen from the spacecraft (light time, aberration of its
barycentric velocity; :func:`attitude.ephemeris.apparent_from_observer`), from DE421
sampled every 600 s and interpolated (:class:`attitude.ephemeris.SunMoonFromEarth`,
2e-10 rad for the Moon); the orbit is evaluated at every epoch by its source, never
interpolated again here.

**How intervals and extrema are found.**  Each quantity is sampled on a search grid
whose step comes from the motion and the geometry, not from the output step: 64
samples per 2π radians of the fastest rate any direction here can turn at, the body's
fastest rotation (bounded by √(2T/I_min) over the segments) plus the orbit's (the
nadir's angular rate, the rate of the Earth's angular radius, the Moon's parallax),
and at most 30 s on an orbit (600 s at the Earth's centre).  A condition's sign
changes are bisected on the exact motion (:func:`attitude.intervals.find_all_intervals`)
to ``interval_precision``; each grid minimum or maximum brackets an extremum, narrowed
by golden-section search on the exact motion (:func:`attitude.extrema.least_of_each`)
to 1 µs, with brackets that cannot hold the answer dropped on the rate bound.
``tests/test_extrema_against_dense_sampling.py`` compares them with a sampling 100×
denser than a 10 s output grid.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np
from numpy.typing import NDArray

from attitude.earth import EARTH_EQUATORIAL_RADIUS_M, angular_radius
from attitude.eclipse import SUN_RADIUS_M, fraction_from_angles, shadow_angles
from attitude.ephemeris import SunMoonFromEarth, apparent_from_observer, skyfield_times
from attitude.errors import InputError
from attitude.extrema import Extremum, Problem, least_of_each
from attitude.frames import euler_angles_deg, lvlh_to_icrf
from attitude.intervals import Interval, difference, find_all_intervals, join
from attitude.orbit import Orbit, TleOrbit
from attitude.quantities import as_si_scalar, as_vector3
from attitude.timescales import SECONDS_PER_DAY, offline_time
from attitude.trajectory import Trajectory

__all__ = [
    "CHUNK_POINTS",
    "KINDS",
    "MAX_SEARCH_POINTS",
    "BodyVector",
    "PointingAnalysis",
    "PointingSamples",
    "PointingSpec",
    "SearchGrid",
    "SunMoonEarth",
    "VectorAnalysis",
    "VectorSamples",
    "check_pointing",
    "describe_lines",
    "interval_precision",
    "pointing_analysis",
    "pointing_samples",
    "search_grid",
    "undersampling_note",
]

KINDS = ("panel", "instrument", "star_tracker", "other")


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

    ``kind``: 'panel' (its Sun incidence is reported), 'instrument', 'star_tracker'
    or 'other'.  Constraints (radians, or angle Quantities; None for none):

    - ``sun_exclusion_half_angle_rad``: the Sun must stay outside this cone about the
      vector (unless the spacecraft is in umbra: a hidden Sun blinds nothing);
    - ``moon_exclusion_half_angle_rad``: the same for the Moon (unless the Earth hides
      the Moon's centre);
    - ``earth_limb_exclusion_angle_rad``: the vector must stay at least this far above
      the Earth's limb (or the limb of its atmosphere, see :class:`PointingSpec`).

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
        for prefix, what, low in (
            ("sun_exclusion_half_angle", "sun exclusion half angle", 0.0),
            ("moon_exclusion_half_angle", "moon exclusion half angle", 0.0),
            ("earth_limb_exclusion_angle", "earth limb exclusion angle", -90.0),
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


_EULER_SEQUENCE = re.compile(r"[XYZ]{3}|[xyz]{3}")


@dataclass(frozen=True)
class PointingSpec:
    """What pointing outputs a scenario asks for.

    ``body_vectors``: the :class:`BodyVector` list.  ``orbit``: an
    :class:`attitude.orbit.Orbit`, or the two lines of a TLE; None places the
    spacecraft at the Earth's centre (Sun and Moon directions only).
    ``interval_precision_s``: the precision to which interval ends are refined.
    ``earth_limb_atmosphere_height_m``: the height above the Earth's equatorial radius
    of the limb that the limb angles are measured from (0: the solid Earth; 50–100 km
    is a common margin for the bright atmosphere).  ``lvlh_euler_sequence``: with an
    orbit, also give the attitude in LVLH as Euler angles in this sequence (scipy's
    notation: "ZYX" intrinsic, "zyx" extrinsic).
    """

    body_vectors: list[BodyVector] = field(default_factory=list)
    orbit: Orbit | tuple[str, str] | None = None
    interval_precision_s: float = 1e-3
    earth_limb_atmosphere_height_m: float = 0.0
    lvlh_euler_sequence: str | None = None

    def __post_init__(self) -> None:
        if isinstance(self.orbit, tuple | list):
            object.__setattr__(self, "orbit", TleOrbit(*self.orbit))
        if self.orbit is not None and not isinstance(self.orbit, Orbit):
            raise InputError(
                f"orbit must be an Orbit or the two lines of a TLE, got {self.orbit!r}"
            )
        if not self.interval_precision_s > 0.0:
            raise InputError(
                f"interval_precision must be positive, got {self.interval_precision_s!r} s"
            )
        height = as_si_scalar(self.earth_limb_atmosphere_height_m, "length", "atmosphere height")
        if not 0.0 <= height <= 1e6:
            raise InputError(
                f"earth_limb_atmosphere_height must be between 0 and 1000 km, got {height:g} m"
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
                "lvlh_euler_sequence must be three axes, all upper case (intrinsic) or all "
                f"lower case (extrinsic), no axis twice in a row (ZYX, zxz...), got {sequence!r}"
            )
        if self.orbit is None:
            needs = [v.name for v in self.body_vectors if v.earth_limb_exclusion_angle_rad]
            if needs:
                raise InputError(
                    f"body vector {needs[0]!r}: an earth limb exclusion needs an orbit "
                    "(a TLE, an OEM file or Keplerian elements)"
                )
            if sequence is not None:
                raise InputError("lvlh_euler_sequence needs an orbit (LVLH is the orbit's frame)")

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


def describe_lines(spec: PointingSpec) -> list[str]:
    """What ``attitude check`` says of the pointing: the orbit, and each body vector with
    its constraints in degrees (as the user wrote them)."""
    if spec.is_empty:
        return []
    where = "Earth centre" if spec.orbit is None else spec.orbit.describe()
    lines = [
        f"pointing    {len(spec.body_vectors)} body vectors, orbit: {where}, interval ends "
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


# The search grid: this many samples per turn (2π rad) of the fastest rate at which
# any direction here turns, and at most this step (on an orbit, at the Earth's centre).
_SAMPLES_PER_TURN = 64
_LONGEST_STEP_ON_ORBIT_S = 30.0
_LONGEST_STEP_S = 600.0
# The orbit is sampled this often to bound its angular rates (and checked above ground).
_ORBIT_CHECK_STEP_S = 60.0
# Bounds on how fast the Sun and the Moon move across the sky of a spacecraft near
# the Earth: their own motion plus the parallax of the spacecraft's velocity at their
# least distance (1.47e11 m, 3.56e8 m).
_SUN_SKY_RATE = 3.1e4 / 1.47e11
_MOON_SKY_RATE = 1.1e3 / 3.56e8
# The Sun's least angular radius from near the Earth (at aphelion): the fastest the
# lit fraction can change is (2/π a) per radian of the discs' relative motion.
_SUN_LEAST_RADIUS_RAD = SUN_RADIUS_M / 1.53e11
# The search grid is evaluated this many points at a time (bounded memory), and a run
# searches at most this many points: about 20 µs a point with the refinements (the
# spinner scenario, 2-core machine), so half an hour.
CHUNK_POINTS = 32_768
MAX_SEARCH_POINTS = 100_000_000
# Extrema: refined to 1 µs, and a bracket that could improve the best by less than
# this (radians for angles, or a cosine) is not refined.
_EXTREMUM_PRECISION_S = 1e-6
_EXTREMUM_TOLERANCE = 5e-9


@dataclass(frozen=True)
class SearchGrid:
    """The search grid of :func:`pointing_analysis` and the rate bounds behind it.

    ``step_s``: the grid step; ``count``: its points over the span;
    ``body_rate_rad_s``: a bound on the body's rotation rate (√(2T/I_min));
    ``orbit_rate_rad_s``: the
    fastest turn of the nadir (|r × v|/r²) plus the rate of the Earth's angular radius;
    ``orbit_speed_m_s``: the greatest orbital speed.
    """

    start_s: float
    stop_s: float
    step_s: float
    count: int
    body_rate_rad_s: float
    orbit_rate_rad_s: float
    orbit_speed_m_s: float

    @property
    def angle_rate_bound(self) -> float:
        """A bound on how fast any angle between two of our directions changes, rad/s."""
        return (
            self.body_rate_rad_s
            + self.orbit_rate_rad_s
            + _SUN_SKY_RATE
            + _MOON_SKY_RATE
            + 2.0 * self.orbit_speed_m_s / 3.56e8
        )

    @property
    def fraction_rate_bound(self) -> float:
        """A bound on how fast the lit fraction of the Sun's disc changes, 1/s."""
        return 2.0 * self.orbit_rate_rad_s / (math.pi * _SUN_LEAST_RADIUS_RAD)


def _body_rate(trajectory: Trajectory, start_s: float, stop_s: float) -> float:
    """A bound on the body's rotation rate over [start_s, stop_s], rad/s: the largest
    over the segments of √(2T/I_min), since |ω|² = Σ m_i²/I_i² ≤ (Σ m_i²/I_i)/I_min =
    2T/I_min (tighter than G/I_min, which it never exceeds)."""
    rates = [
        math.sqrt(
            max(2.0 * segment.solver.kinetic_energy, 0.0)
            / float(np.min(segment.solver.moments_of_inertia))
        )
        for segment in trajectory.segments
        if segment.end_s >= start_s and segment.start_s <= stop_s
    ]
    return max(rates, default=0.0)


def _jd(trajectory: Trajectory) -> tuple[float, float]:
    """The scenario epoch's two-part TT Julian date."""
    with offline_time():
        tt = trajectory.scenario.epoch.tt
        return float(tt.jd1), float(tt.jd2)


def _orbit_samples(
    trajectory: Trajectory, orbit: Orbit, start_s: float, stop_s: float
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The orbit every 60 s over [start_s, stop_s] (both ends included): τ, r, v."""
    count = max(math.ceil((stop_s - start_s) / _ORBIT_CHECK_STEP_S), 1) + 1
    τ = np.linspace(start_s, stop_s, count)
    jd1, jd2 = _jd(trajectory)
    r, v = orbit.state_tt(np.full(τ.size, jd1), jd2 + τ / SECONDS_PER_DAY)
    return τ, r, v


def search_grid(
    trajectory: Trajectory,
    spec: PointingSpec,
    start_s: float | None = None,
    stop_s: float | None = None,
) -> SearchGrid:
    """The search grid of :func:`pointing_analysis` over [start_s, stop_s] (the output
    span by default), from the rates of the motion and the orbit (see the module notes).
    """
    scenario = trajectory.scenario
    start_s = scenario.start_s if start_s is None else float(start_s)
    stop_s = scenario.stop_s if stop_s is None else float(stop_s)
    body = _body_rate(trajectory, start_s, stop_s)
    orbit_rate = speed = 0.0
    if spec.orbit is not None:
        _, r, v = _orbit_samples(trajectory, spec.orbit, start_s, stop_s)
        distance = np.linalg.norm(r, axis=-1)
        nadir_rate = np.linalg.norm(np.cross(r, v), axis=-1) / distance**2
        rho = angular_radius(r, spec.earth_limb_atmosphere_height_m)
        radial = np.abs(np.sum(r * v, axis=-1)) / distance
        rho_rate = np.tan(np.minimum(rho, 1.5)) * radial / distance
        # Between samples 60 s apart the rates change little: 25 % covers the peaks
        # of a perigee pass that the samples straddle.
        orbit_rate = 1.25 * float(np.max(nadir_rate + rho_rate))
        speed = float(np.max(np.linalg.norm(v, axis=-1)))
    longest = _LONGEST_STEP_ON_ORBIT_S if spec.orbit is not None else _LONGEST_STEP_S
    rate = body + orbit_rate + _SUN_SKY_RATE + _MOON_SKY_RATE
    step = min(longest, 2.0 * math.pi / (_SAMPLES_PER_TURN * rate))
    count = max(math.ceil((stop_s - start_s) / step) + 1, 2)
    return SearchGrid(
        start_s, stop_s, (stop_s - start_s) / (count - 1), count, body, orbit_rate, speed
    )


def check_pointing(
    trajectory: Trajectory, spec: PointingSpec
) -> tuple[list[str], SearchGrid | None]:
    """Everything the pointing of ``spec`` needs, checked before anything is sampled.

    The orbit over the span (the source covers it, and stays above the ground: see
    each source's ``check_span``; a TLE far from its epoch is noted with its age),
    and the Sun and Moon ephemeris over the span with the margins the interpolation
    adds.  Raises :class:`InputError` whose message starts with the key
    (``pointing.tle: ...``, ``output: ...``); returns notes for the user and the
    search grid of :func:`pointing_analysis` (None without pointing).
    """
    scenario = trajectory.scenario
    if spec.is_empty:
        return [], None
    notes = []
    _, note = interval_precision(spec, scenario.stop_s)
    if note:
        notes.append(f"pointing.interval_precision: {note}")
    margin = 600.0  # one node of the Sun and Moon ephemeris
    ends = np.array([scenario.start_s - margin, scenario.stop_s + margin])
    try:
        skyfield_times(scenario.times(ends), name="span")
    except InputError as exc:
        raise InputError(
            f"output: the span with its {margin:g} s margins needs the Sun and the Moon over "
            f"{scenario.format_epoch(ends[0])} to {scenario.format_epoch(ends[1])}: "
            f"{str(exc).removeprefix('span: ')}"
        ) from None
    orbit = spec.orbit
    if orbit is not None:
        notes += orbit.check_span(scenario.times(scenario.start_s), scenario.times(scenario.stop_s))
        try:
            τ, r, _ = _orbit_samples(trajectory, orbit, scenario.start_s, scenario.stop_s)
        except InputError as exc:
            raise InputError(f"{orbit.key}: {exc}") from None
        distance = np.linalg.norm(r, axis=-1)
        low = distance <= EARTH_EQUATORIAL_RADIUS_M
        if np.any(low):
            when = scenario.format_epoch(float(τ[np.argmax(low)]))
            raise InputError(
                f"{orbit.key}: the orbit is inside the Earth at {when} "
                f"({float(distance[np.argmax(low)]) / 1e3:.1f} km from its centre, less than "
                f"its {EARTH_EQUATORIAL_RADIUS_M / 1e3:g} km radius)"
            )
    grid = search_grid(trajectory, spec)
    if grid.count > MAX_SEARCH_POINTS:
        raise InputError(
            f"output: the pointing's search needs {grid.count:.3g} points over the span "
            f"(every {grid.step_s:.3g} s: 64 a turn of the fastest rotation), more than the "
            f"{MAX_SEARCH_POINTS:.0e} one run searches (about 20 µs a point): use a shorter span"
        )
    return notes, grid


def undersampling_note(trajectory: Trajectory, motion) -> str | None:
    """One line when the output step is more than a tenth of the shortest period of
    the motion in any segment (``motion``: :func:`attitude.motion_analysis.analyze`),
    naming the step and the period; None otherwise."""
    scenario = trajectory.scenario
    worst = None
    for index, item in enumerate(motion):
        if item.end_s < scenario.start_s or item.start_s > scenario.stop_s:
            continue
        periods = {
            "body period": item.period_s,
            "spin period": item.spin_period_s,
            "nutation period": item.nutation_period_s,
            "precession period": item.precession_period_s,
            "flip period": item.flip_period_s,
        }
        for name, period in periods.items():
            if period is not None and math.isfinite(period) and period > 0.0:
                if worst is None or period < worst[0]:
                    worst = (period, name, index)
    if worst is None or scenario.step_s <= 0.1 * worst[0]:
        return None
    period, name, index = worst
    return (
        f"output.step: {scenario.step_s:.6g} s is more than a tenth of the {period:.6g} s "
        f"{name} of segment {index}: the time series undersamples the motion (extrema and "
        "intervals are found on the exact motion regardless)"
    )


@dataclass
class Surroundings:
    """The Sun, the Moon and the Earth seen from the spacecraft at some times (GCRS).

    Directions are unit vectors from the spacecraft (apparent places).  On an orbit,
    ``position_m``/``velocity_m_s`` (from the Earth's centre) and the Earth: its
    angular radius (solid Earth) and the shadow's angles (:func:`attitude.eclipse
    .shadow_angles`); at the Earth's centre these are None and the Sun is always lit.
    """

    sun_direction: NDArray[np.float64]
    moon_direction: NDArray[np.float64]
    sunlit_fraction: NDArray[np.float64]
    position_m: NDArray[np.float64] | None = None
    velocity_m_s: NDArray[np.float64] | None = None
    earth_angular_radius_rad: NDArray[np.float64] | None = None
    limb_angular_radius_rad: NDArray[np.float64] | None = None
    shadow_angles: tuple[NDArray[np.float64], ...] | None = None
    nadir: NDArray[np.float64] | None = None  # unit vector to the Earth's centre


class SunMoonEarth:
    """What the spacecraft sees around it over [start_s, stop_s]: the Sun, the Moon
    and, on an orbit, the Earth, at any TT seconds in that span (:meth:`at`).

    The Sun and the Moon are sampled once for the span (:class:`attitude.ephemeris
    .SunMoonFromEarth`, nodes aligned on J2000, so that any split of a span into
    chunks gives the same values); the orbit is its source's, at every epoch.
    """

    def __init__(
        self, trajectory: Trajectory, spec: PointingSpec, start_s: float, stop_s: float
    ) -> None:
        self.spec = spec
        self._jd1, self._jd2 = _jd(trajectory)
        self._bodies = SunMoonFromEarth(
            self._jd1,
            self._jd2 + start_s / SECONDS_PER_DAY,
            self._jd2 + stop_s / SECONDS_PER_DAY,
        )

    def at(self, seconds: NDArray[np.float64]) -> Surroundings:
        seconds = np.asarray(seconds, dtype=np.float64)
        jd2 = self._jd2 + seconds / SECONDS_PER_DAY
        bodies = self._bodies.at(jd2)
        orbit = self.spec.orbit
        if orbit is None:
            r = v = np.zeros((seconds.size, 3))
        else:
            r, v = orbit.state_tt(np.full(seconds.size, self._jd1), jd2)
        earth_m_s = bodies["earth_velocity_m_s"]
        sun_distance = np.linalg.norm(bodies["sun_m"] - r, axis=-1)
        sun = apparent_from_observer(
            bodies["sun_m"], bodies["sun_velocity_m_s"], earth_m_s, r, v, sun_distance
        )
        moon = apparent_from_observer(
            bodies["moon_m"], bodies["moon_velocity_m_s"], earth_m_s, r, v, sun_distance
        )
        sun /= np.linalg.norm(sun, axis=-1, keepdims=True)
        moon /= np.linalg.norm(moon, axis=-1, keepdims=True)
        if orbit is None:
            return Surroundings(sun, moon, np.ones(seconds.size))
        # The shadow's axis is the apparent Sun from the Earth's centre (attitude.eclipse).
        zeros = np.zeros_like(r)
        sun_from_earth = apparent_from_observer(
            bodies["sun_m"],
            bodies["sun_velocity_m_s"],
            earth_m_s,
            zeros,
            zeros,
            np.linalg.norm(bodies["sun_m"], axis=-1),
        )
        a, b, c = shadow_angles(r, sun_from_earth)
        height = self.spec.earth_limb_atmosphere_height_m
        return Surroundings(
            sun,
            moon,
            fraction_from_angles(a, b, c),
            r,
            v,
            b,
            b if height == 0.0 else angular_radius(r, height),
            (a, b, c),
            -r / _norm(r)[:, None],
        )


# ---------------------------------------------------------------------------------
# Samples: everything the time series needs, at any times.


@dataclass
class VectorSamples:
    """One body vector's pointing at the sample times (radians; flags as booleans).

    ``sun_violated``: the Sun inside the exclusion cone and the spacecraft not in
    umbra; ``moon_violated``: the Moon inside its cone and not hidden by the Earth;
    ``earth_limb_violated``: the vector less than the exclusion angle above the limb.
    None where the constraint (or the orbit) is absent.
    """

    vector: BodyVector
    sun_angle_rad: NDArray[np.float64]
    cos_incidence: NDArray[np.float64]
    moon_angle_rad: NDArray[np.float64]
    right_ascension_rad: NDArray[np.float64]
    declination_rad: NDArray[np.float64]
    nadir_angle_rad: NDArray[np.float64] | None = None
    earth_limb_angle_rad: NDArray[np.float64] | None = None
    sun_violated: NDArray[np.bool_] | None = None
    moon_violated: NDArray[np.bool_] | None = None
    earth_limb_violated: NDArray[np.bool_] | None = None


@dataclass
class PointingSamples:
    """The pointing at ``seconds`` (TT s since the epoch): see :func:`pointing_samples`.

    ``q_body_to_lvlh``: (w, x, y, z), scalar first, w ≥ 0, the rotation taking body
    coordinates to LVLH coordinates; ``lvlh_euler_deg``: the same rotation as Euler
    angles in ``lvlh_euler_sequence`` (degrees).
    """

    seconds: NDArray[np.float64]
    on_orbit: bool
    sun_direction_icrf: NDArray[np.float64]
    moon_direction_icrf: NDArray[np.float64]
    sunlit_fraction: NDArray[np.float64]
    vectors: list[VectorSamples]
    earth_angular_radius_rad: NDArray[np.float64] | None = None
    q_body_to_lvlh: NDArray[np.float64] | None = None
    lvlh_euler_deg: NDArray[np.float64] | None = None
    lvlh_euler_sequence: str | None = None


def _right_ascension(icrf: NDArray[np.float64]) -> NDArray[np.float64]:
    """Right ascension in [0, 2π): mod 2π of a tiny negative angle rounds to 2π itself."""
    ra = np.mod(np.arctan2(icrf[:, 1], icrf[:, 0]), 2.0 * math.pi)
    return np.where(ra >= 2.0 * math.pi, 0.0, ra)


def _moon_hidden(env: Surroundings) -> NDArray[np.float64] | None:
    """> 0 where the Moon's centre is behind the Earth's disc (None at the Earth's
    centre): the Earth's angular radius minus the Moon's angle from nadir."""
    if env.position_m is None:
        return None
    return env.earth_angular_radius_rad - _unit_angle(env.moon_direction, env.nadir)


def _norm(v: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.sqrt(np.einsum("ij,ij->i", v, v))


def _unit_angle(u: NDArray[np.float64], v: NDArray[np.float64]) -> NDArray[np.float64]:
    """The angle between unit vectors (n, 3): 2 atan2(|u − v|, |u + v|), accurate at
    every angle like atan2(|u × v|, u·v), and cheaper (W. Kahan, "How Futile are
    Mindless Assessments of Roundoff in Floating-Point Computation?", 2006)."""
    return 2.0 * np.arctan2(_norm(u - v), _norm(u + v))


def _vector_angles(icrf: NDArray[np.float64], env: Surroundings) -> dict[str, NDArray]:
    """A body vector's angles (radians) and Sun incidence from its ICRF direction."""
    cos_sun = np.sum(icrf * env.sun_direction, axis=-1)
    angles = {
        "sun_angle": _unit_angle(icrf, env.sun_direction),
        "sun_cosine": cos_sun,
        "cos_incidence": np.maximum(cos_sun, 0.0) * env.sunlit_fraction,
        "moon_angle": _unit_angle(icrf, env.moon_direction),
    }
    if env.position_m is not None:
        angles["nadir_angle"] = _unit_angle(icrf, env.nadir)
        angles["earth_limb_angle"] = angles["nadir_angle"] - env.limb_angular_radius_rad
    return angles


def _vector_samples(vector: BodyVector, icrf: NDArray[np.float64], env: Surroundings):
    """A body vector's quantities from its ICRF direction and the surroundings."""
    angles = _vector_angles(icrf, env)
    item = VectorSamples(
        vector=vector,
        sun_angle_rad=angles["sun_angle"],
        cos_incidence=angles["cos_incidence"],
        moon_angle_rad=angles["moon_angle"],
        right_ascension_rad=_right_ascension(icrf),
        declination_rad=np.arcsin(np.clip(icrf[:, 2], -1.0, 1.0)),
        nadir_angle_rad=angles.get("nadir_angle"),
        earth_limb_angle_rad=angles.get("earth_limb_angle"),
    )
    if vector.sun_exclusion_half_angle_rad is not None:
        # In umbra the Sun is hidden: it blinds nothing.
        item.sun_violated = (item.sun_angle_rad < vector.sun_exclusion_half_angle_rad) & (
            env.sunlit_fraction > 0.0
        )
    if vector.moon_exclusion_half_angle_rad is not None:
        hidden = _moon_hidden(env)
        item.moon_violated = item.moon_angle_rad < vector.moon_exclusion_half_angle_rad
        if hidden is not None:
            item.moon_violated &= hidden <= 0.0
    if vector.earth_limb_exclusion_angle_rad is not None:
        item.earth_limb_violated = item.earth_limb_angle_rad < vector.earth_limb_exclusion_angle_rad
    return item


def pointing_samples(
    trajectory: Trajectory, spec: PointingSpec, seconds: NDArray[np.float64]
) -> PointingSamples:
    """The pointing of ``spec`` at ``seconds`` (TT s since the epoch, within the span).

    Everything the time-series columns need (see :class:`PointingSamples`,
    :class:`VectorSamples`); no intervals and no extrema (:func:`pointing_analysis`),
    and nothing kept between calls, so a long output grid can be asked chunk by chunk,
    each chunk giving the values it would have given in one call.
    """
    seconds = np.asarray(seconds, dtype=np.float64).ravel()
    if seconds.size == 0:
        raise InputError("seconds: no times to sample")
    if seconds.size == 1:
        # One epoch is evaluated as a pair and the first kept: numpy's one-row products
        # take another path (gemv), which can differ in the last bit, and a stream's
        # chunk of one epoch must give what the whole grid gives.
        return _first_row(pointing_samples(trajectory, spec, np.repeat(seconds, 2)))
    env = SunMoonEarth(trajectory, spec, float(seconds.min()), float(seconds.max())).at(seconds)
    attitude = trajectory.attitude(seconds)
    result = PointingSamples(
        seconds=seconds,
        on_orbit=spec.on_orbit,
        sun_direction_icrf=env.sun_direction,
        moon_direction_icrf=env.moon_direction,
        sunlit_fraction=env.sunlit_fraction,
        vectors=[_vector_samples(v, attitude.apply(v.vector), env) for v in spec.body_vectors],
        earth_angular_radius_rad=env.earth_angular_radius_rad,
    )
    if env.position_m is not None:
        body_to_lvlh = lvlh_to_icrf(env.position_m, env.velocity_m_s).inv() * attitude
        q = body_to_lvlh.as_quat(canonical=True, scalar_first=True)
        result.q_body_to_lvlh = np.atleast_2d(q)
        if spec.lvlh_euler_sequence is not None:
            result.lvlh_euler_sequence = spec.lvlh_euler_sequence
            result.lvlh_euler_deg = np.atleast_2d(
                euler_angles_deg(body_to_lvlh, spec.lvlh_euler_sequence)
            )
    return result


def _first_row(samples: PointingSamples) -> PointingSamples:
    """``samples`` at its first time only."""

    def first(value):
        return value[:1] if isinstance(value, np.ndarray) else value

    vectors = [
        VectorSamples(**{f.name: first(getattr(v, f.name)) for f in fields(VectorSamples)})
        for v in samples.vectors
    ]
    values = {f.name: first(getattr(samples, f.name)) for f in fields(PointingSamples)}
    return PointingSamples(**(values | {"vectors": vectors}))


# ---------------------------------------------------------------------------------
# Analysis: intervals and extrema over the whole span, on the exact motion.

# The extrema reported per body vector, and whether each needs an orbit.
EXTREMA = {
    "sun_angle": False,
    "moon_angle": False,
    "nadir_angle": True,
    "earth_limb_angle": True,
    "cos_incidence": False,
}


@dataclass
class VectorAnalysis:
    """One body vector's intervals and extrema over the analysed span.

    Intervals (TT s since the epoch): ``sun_visible`` (the Sun in front of the
    vector and the spacecraft not in umbra), ``sun_exclusion``, ``moon_exclusion`` and
    ``earth_limb_exclusion`` (each constraint violated, as in :class:`VectorSamples`).
    ``extrema``: for each quantity of :data:`EXTREMA` it has, (least, greatest)
    :class:`attitude.extrema.Extremum`, radians for angles.  ``mean_cos_incidence``:
    the time average of the incidence over the span.
    """

    vector: BodyVector
    extrema: dict[str, tuple[Extremum, Extremum]]
    sun_visible: list[Interval] = field(default_factory=list)
    sun_exclusion: list[Interval] = field(default_factory=list)
    moon_exclusion: list[Interval] = field(default_factory=list)
    earth_limb_exclusion: list[Interval] = field(default_factory=list)
    mean_cos_incidence: float = 0.0


@dataclass
class PointingAnalysis:
    """Intervals and extrema over [start_s, stop_s]: see :func:`pointing_analysis`.

    ``shadow``/``umbra``: the eclipses (any part, all of the Sun hidden);
    ``moon_hidden``: the Moon's centre behind the Earth; ``sunlit_fraction_mean``: the
    time average of the lit fraction; ``grid``: the search grid used.
    """

    start_s: float
    stop_s: float
    precision_s: float
    on_orbit: bool
    orbit: str
    grid: SearchGrid
    vectors: list[VectorAnalysis]
    shadow: list[Interval] = field(default_factory=list)
    umbra: list[Interval] = field(default_factory=list)
    moon_hidden: list[Interval] = field(default_factory=list)
    sunlit_fraction_mean: float = 1.0


class _Quantities:
    """Every quantity the analysis searches, at any times of one chunk."""

    def __init__(self, trajectory: Trajectory, spec: PointingSpec, start_s: float, stop_s: float):
        self.trajectory = trajectory
        self.spec = spec
        self.env = SunMoonEarth(trajectory, spec, start_s, stop_s)

    def __call__(self, seconds: NDArray[np.float64]) -> dict[str, NDArray[np.float64]]:
        env = self.env.at(seconds)
        attitude = self.trajectory.attitude(seconds)
        values = {"sunlit_fraction": env.sunlit_fraction}
        if env.shadow_angles is not None:
            a, b, c = env.shadow_angles
            values["shadow"] = (a + b) - c
            values["umbra"] = (b - a) - c
            values["moon_hidden"] = _moon_hidden(env)
        for v in self.spec.body_vectors:
            for quantity, value in _vector_angles(attitude.apply(v.vector), env).items():
                values[f"{v.name}.{quantity}"] = value
        return values


def _conditions(spec: PointingSpec) -> dict[str, tuple[str, float, float]]:
    """Each interval condition: (quantity, scale, offset), true where scale·q − offset > 0."""
    conditions: dict[str, tuple[str, float, float]] = {}
    if spec.orbit is not None:
        conditions["shadow"] = ("shadow", 1.0, 0.0)
        conditions["umbra"] = ("umbra", 1.0, 0.0)
        conditions["moon_hidden"] = ("moon_hidden", 1.0, 0.0)
    for v in spec.body_vectors:
        name = v.name
        conditions[f"{name}.sun_visible"] = (f"{name}.sun_cosine", 1.0, 0.0)
        if v.sun_exclusion_half_angle_rad is not None:
            conditions[f"{name}.sun_exclusion"] = (
                f"{name}.sun_angle",
                -1.0,
                -v.sun_exclusion_half_angle_rad,
            )
        if v.moon_exclusion_half_angle_rad is not None:
            conditions[f"{name}.moon_exclusion"] = (
                f"{name}.moon_angle",
                -1.0,
                -v.moon_exclusion_half_angle_rad,
            )
        if v.earth_limb_exclusion_angle_rad is not None:
            conditions[f"{name}.earth_limb_exclusion"] = (
                f"{name}.earth_limb_angle",
                -1.0,
                -v.earth_limb_exclusion_angle_rad,
            )
    return conditions


def _grid_points(
    grid: SearchGrid, first: int, last: int, events_s: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Points first..last of the search grid, with the event epochs between them."""
    span = grid.stop_s - grid.start_s
    index = np.arange(first, last + 1, dtype=np.float64)
    τ = grid.start_s + span * index / (grid.count - 1)
    τ[-1] = grid.stop_s if last == grid.count - 1 else τ[-1]
    inside = events_s[(events_s > τ[0]) & (events_s < τ[-1])]
    return np.unique(np.concatenate([τ, inside])) if inside.size else τ


class _Search:
    """The intervals, extrema and averages of the analysis, accumulated chunk by chunk."""

    def __init__(self, trajectory: Trajectory, spec: PointingSpec, grid: SearchGrid) -> None:
        self.trajectory, self.spec, self.grid = trajectory, spec, grid
        self.precision = interval_precision(spec, trajectory.scenario.stop_s)[0]
        self.extremum_precision = max(_EXTREMUM_PRECISION_S, 4.0 * float(np.spacing(grid.stop_s)))
        self.conditions = _conditions(spec)
        self.found: dict[str, list[Interval]] = {name: [] for name in self.conditions}
        # (vector, quantity) pairs, and the least and greatest of each found so far.
        self.wanted = [
            (v.name, quantity)
            for v in spec.body_vectors
            for quantity, needs_orbit in EXTREMA.items()
            if spec.on_orbit or not needs_orbit
        ]
        self.lows: dict[tuple[str, str], Extremum | None] = dict.fromkeys(self.wanted)
        self.highs: dict[tuple[str, str], Extremum | None] = dict.fromkeys(self.wanted)
        self.sums = {"sunlit_fraction": 0.0} | {
            f"{v.name}.cos_incidence": 0.0 for v in spec.body_vectors
        }

    def _rate(self, quantity: str) -> float:
        """A bound on the quantity's rate of change (the incidence adds the lit fraction's)."""
        if quantity == "cos_incidence":
            return self.grid.angle_rate_bound + self.grid.fraction_rate_bound
        return self.grid.angle_rate_bound

    def _condition_values(self, values: dict[str, NDArray]) -> dict[str, NDArray]:
        return {
            name: scale * values[key] - offset
            for name, (key, scale, offset) in self.conditions.items()
        }

    def _extremum_values(self, values: dict[str, NDArray]) -> dict[str, NDArray]:
        """Each quantity to minimize ('.low') and its negative to minimize ('.high')."""
        out = {}
        for name, quantity in self.wanted:
            key = f"{name}.{quantity}"
            out[f"{key}.low"] = values[key]
            out[f"{key}.high"] = -values[key]
        return out

    def chunk(self, τ: NDArray[np.float64]) -> None:
        """Search the grid points τ (one chunk) and fold what they hold into the totals."""
        quantities = _Quantities(self.trajectory, self.spec, float(τ[0]), float(τ[-1]))
        values = quantities(τ)
        self._intervals(quantities, τ, values)
        self._extrema(quantities, τ, values)
        widths = np.diff(τ)
        for key in self.sums:  # the trapezoid rule on the search grid
            self.sums[key] += float(np.sum(0.5 * (values[key][1:] + values[key][:-1]) * widths))

    def _intervals(self, quantities: _Quantities, τ, values) -> None:
        pieces = find_all_intervals(
            lambda t: self._condition_values(quantities(t)),
            τ,
            self.precision,
            self._condition_values(values),
        )
        for name in self.conditions:
            join(self.found[name], pieces[name], float(τ[0]))

    def _extrema(self, quantities: _Quantities, τ, values) -> None:
        on_grid = self._extremum_values(values)
        problems = {}
        for name, quantity in self.wanted:
            key = f"{name}.{quantity}"
            low, high = self.lows[(name, quantity)], self.highs[(name, quantity)]
            if quantity == "cos_incidence" and np.min(on_grid[f"{key}.low"]) <= 0.0:
                # No light: 0 is the least incidence, placed from the intervals (result).
                self.lows[(name, quantity)] = Extremum(float(τ[0]), 0.0)
            else:
                problems[f"{key}.low"] = Problem(on_grid[f"{key}.low"], self._rate(quantity), low)
            problems[f"{key}.high"] = Problem(
                on_grid[f"{key}.high"],
                self._rate(quantity),
                None if high is None else Extremum(high.time_s, -high.value),
            )
        if not problems:
            return
        best = least_of_each(
            lambda t: self._extremum_values(quantities(t)),
            τ,
            problems,
            _EXTREMUM_TOLERANCE,
            self.extremum_precision,
        )
        for name, quantity in self.wanted:
            key = f"{name}.{quantity}"
            if f"{key}.low" in best:
                self.lows[(name, quantity)] = best[f"{key}.low"]
            high = best[f"{key}.high"]
            self.highs[(name, quantity)] = Extremum(high.time_s, -high.value)

    def result(self) -> PointingAnalysis:
        """The analysis: the accumulated intervals (each condition less what hides it),
        extrema and averages."""
        grid, spec, found = self.grid, self.spec, self.found
        span = max(grid.stop_s - grid.start_s, 1e-300)
        umbra = found.get("umbra", [])
        analysis = PointingAnalysis(
            start_s=grid.start_s,
            stop_s=grid.stop_s,
            precision_s=self.precision,
            on_orbit=spec.on_orbit,
            orbit="Earth centre" if spec.orbit is None else spec.orbit.describe(),
            grid=grid,
            vectors=[],
            shadow=found.get("shadow", []),
            umbra=umbra,
            moon_hidden=found.get("moon_hidden", []),
            sunlit_fraction_mean=self.sums["sunlit_fraction"] / span,
        )
        for v in spec.body_vectors:
            name = v.name
            extrema = {
                q: (self.lows[(name, q)], self.highs[(name, q)])
                for n, q in self.wanted
                if n == name
            }
            item = VectorAnalysis(
                vector=v,
                extrema=extrema,
                sun_visible=difference(found[f"{name}.sun_visible"], umbra),
                sun_exclusion=difference(found.get(f"{name}.sun_exclusion", []), umbra),
                moon_exclusion=difference(
                    found.get(f"{name}.moon_exclusion", []), analysis.moon_hidden
                ),
                earth_limb_exclusion=found.get(f"{name}.earth_limb_exclusion", []),
                mean_cos_incidence=self.sums[f"{name}.cos_incidence"] / span,
            )
            low, high = extrema["cos_incidence"]
            item.extrema["cos_incidence"] = (_first_dark(item, grid) or low, high)
            analysis.vectors.append(item)
        return analysis


def pointing_analysis(
    trajectory: Trajectory,
    spec: PointingSpec,
    start_s: float | None = None,
    stop_s: float | None = None,
    grid: SearchGrid | None = None,
) -> PointingAnalysis:
    """Every interval and extremum of ``spec``'s pointing over [start_s, stop_s] (TT s
    since the epoch; the output span by default), on the exact motion.

    The span is searched in chunks of :data:`CHUNK_POINTS` grid points (see the
    module notes for the grid): memory does not grow with the span, only the list of
    intervals found.  Interval ends are refined to ``spec.interval_precision_s``,
    extrema to 1 µs.
    """
    if grid is None:
        grid = search_grid(trajectory, spec, start_s, stop_s)
    search = _Search(trajectory, spec, grid)
    events_s = np.array([t for t, _ in trajectory.scenario.events], dtype=np.float64)
    first = 0
    while first < grid.count - 1:
        last = min(first + CHUNK_POINTS, grid.count - 1)
        search.chunk(_grid_points(grid, first, last, events_s))
        first = last
    return search.result()


def _first_dark(item: VectorAnalysis, grid: SearchGrid) -> Extremum | None:
    """The least incidence, 0, at the first time the vector gets no sunlight (the end of
    its first Sun-visible interval, or the start of the span): exact from the
    intervals, where the search would stop at whichever grid point first reads 0."""
    visible = item.sun_visible
    if visible and visible[0].starts_before:
        if visible[0].ends_after:
            return None  # lit throughout
        return Extremum(visible[0].end_s, 0.0)
    return Extremum(grid.start_s, 0.0)
