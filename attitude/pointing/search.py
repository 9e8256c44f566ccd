"""The pointing's search: every interval and extremum over a span, on the exact motion.

:func:`pointing_analysis` finds, over [start_s, stop_s], the eclipses (any part of the
Sun hidden, all of it), the Moon behind the Earth, and for each body vector of the
:class:`attitude.pointing.spec.PointingSpec` its Sun visibility, constraint violations,
when any of them blinds it, and when its Sun inclusion cone holds the Sun (intervals),
the least and greatest of its Sun, Moon, nadir and limb angles and of its Sun
incidence (extrema), and the time averages of the incidence and of the lit fraction.
It finds them on the exact motion, whatever the output step, and in bounded memory.
The surroundings (orbit, Sun, Moon, shadow) come from
:class:`attitude.pointing.shared_surroundings.SharedSurroundings`, computed once for the
span and shared (within their stated bound of the exact ones, which
:mod:`attitude.pointing.surroundings` and :func:`attitude.pointing.sampling
.pointing_samples` compute); every extremum's value is then computed exactly at its
time, as a sample there gives it.

**Eclipses and the Moon behind the Earth** depend on the orbit alone: searched once
for the span on a 10 s grid with the geometry's rate bound, so that none is missed
however short (:func:`attitude.pointing.intervals.isolate`), and kept with the shared
surroundings for every later search of the same span.  Many searches of short spans
within one long one (the envelope's windows after each failure) share one search of
the long span (:func:`orbit_intervals`), each cut to its span; :func:`pointing_analyses`
runs such searches together, their torque-free searches as one set of arrays
(:func:`attitude.pointing.free_search.search_free_many`), each analysis the same, bit
for bit, as :func:`pointing_analysis` gives it alone.

**Torque-free segments** (:mod:`attitude.pointing.free_search`): the structure of the
closed-form motion bounds how fast each body vector's cosines with the Sun, the Moon
and nadir can bend; values and rates at nodes spaced by that bound, rigorous bounds
between nodes, and refinement only of the cells where something can happen: no
interval is missed however short, each crossing costs a few evaluations.

**Other segments** (torques, attitude laws): the search grid (:func:`search_grid`):
each quantity is sampled with a step that comes from the motion and the geometry, not
from the output step: 64 samples per 2π radians of the fastest rate any direction here
can turn at, the body's fastest rotation (√(2T/I_min), or the segment's own bound,
``angular_rate_bound``) plus the orbit's (the nadir's angular rate, the rate of the
Earth's angular radius, the Moon's parallax), and at most 30 s on an orbit (600 s at
the Earth's centre).  Wherever a condition could change sign twice between grid points
unseen (its rate bound allows it), the step is halved until it could not
(:func:`attitude.pointing.intervals.isolate`), so that none is missed there either;
each sign change is refined on the exact motion (regula falsi, then bisection where
needed) to ``interval_precision``.  Each grid minimum or maximum brackets an
extremum, narrowed by golden-section search (:func:`attitude.pointing.extrema
.least_of_each`) to 1 µs, with brackets that cannot hold the answer dropped on a rate
bound: each body vector's own (:func:`_vector_rates`) plus the sky's.

``tests/test_extrema_against_dense_sampling.py`` compares the extrema with a sampling
100× denser than a 10 s output grid, and ``tests/test_search_against_grid_search.py``
the torque-free search with the grid search on every example and hostile cases.

:func:`check_pointing` checks, before anything is sampled, what the search and the
samples need: the ephemeris and the orbit over the span, and the size of the search.
"""

from __future__ import annotations

import math
from collections.abc import Collection
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from attitude.base.errors import InputError
from attitude.environment.earth import EARTH_EQUATORIAL_RADIUS_M, angular_radius
from attitude.environment.ephemeris import skyfield_times
from attitude.environment.orbit import Orbit
from attitude.environment.timescales import SECONDS_PER_DAY
from attitude.pointing.eclipse import SUN_RADIUS_M
from attitude.pointing.extrema import Extremum, Problem, least_of_each
from attitude.pointing.free_search import (
    FreePiece,
    FreePlan,
    FreeResult,
    fits_one_window,
    free_plan,
    free_plans,
    search_free,
    search_free_many,
)
from attitude.pointing.intervals import (
    Interval,
    append_across,
    difference,
    find_all_intervals,
    join,
    union,
)
from attitude.pointing.shared_surroundings import SharedSurroundings, shared_surroundings
from attitude.pointing.spec import BodyVector, PointingSpec, for_scenario, interval_precision
from attitude.pointing.surroundings import moon_hidden, scenario_jd, vector_angles
from attitude.solver.euler_solver import EulerSolver
from attitude.trajectory.trajectory import Trajectory

__all__ = [
    "CHUNK_POINTS",
    "EXTREMA",
    "MAX_SEARCH_POINTS",
    "OrbitIntervals",
    "PointingAnalysis",
    "SearchGrid",
    "VectorAnalysis",
    "check_pointing",
    "orbit_intervals",
    "pointing_analyses",
    "pointing_analysis",
    "search_grid",
]

# The search grid: this many samples per turn (2π rad) of the fastest rate at which
# any direction here turns, and at most this step (on an orbit, at the Earth's centre).
_SAMPLES_PER_TURN = 64
_LONGEST_STEP_ON_ORBIT_S = 30.0
_LONGEST_STEP_S = 600.0
# The eclipses and the Moon behind the Earth: searched on a grid this fine.
_ORBIT_STEP_S = 10.0
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
# The search grid of segments searched on a grid is evaluated this many points at a
# time (bounded memory), and a run searches a span of at most this many points at 64 a
# turn of its fastest rotation (SearchGrid.turn_points: the torque-free search needs
# about a seventh of them).
CHUNK_POINTS = 65_536
MAX_SEARCH_POINTS = 100_000_000
# Extrema: refined to 1 µs, and a bracket that could improve the best by less than
# this (radians for angles, or a cosine) is not refined.
_EXTREMUM_PRECISION_S = 1e-6
_EXTREMUM_TOLERANCE = 5e-9
# A body vector's rate bound samples ω this many times over a body period of each
# segment, and at most this many times in all (at least the last figure a segment).
_RATE_SAMPLES = 16384
_RATE_SAMPLES_IN_ALL = 2_000_000
_RATE_SAMPLES_LEAST = 64
# The lit fraction's mean: Gauss–Legendre points on each stretch of penumbra.
_PENUMBRA_POINTS = 16


@dataclass(frozen=True)
class SearchGrid:
    """How :func:`pointing_analysis` searches [start_s, stop_s], and the rate bounds.

    ``step_s``: the finest step between the points the search evaluates first (the
    nodes of a torque-free segment, :mod:`attitude.pointing.free_search`, or the grid
    of the others); ``count``: how many such points over the span (the search adds
    its refinements); ``grid_step_s``: the grid's step on segments searched on a grid
    (64 points a turn); ``plans``: for each segment of the trajectory, its
    :class:`~attitude.pointing.free_search.FreePlan` when it is searched as torque-free
    (None otherwise, or outside the span).
    ``body_rate_rad_s``: a bound on the body's rotation rate (√(2T/I_min));
    ``orbit_rate_rad_s``: the fastest turn of the nadir (|r × v|/r²) plus the rate of
    the Earth's angular radius; ``orbit_speed_m_s``: the greatest orbital speed;
    ``vector_rates_rad_s``: for each body vector by name, a bound on how fast it turns
    (:func:`_vector_rates`; never above ``body_rate_rad_s``, which stands for a vector
    not listed).
    """

    start_s: float
    stop_s: float
    step_s: float
    count: int
    body_rate_rad_s: float
    orbit_rate_rad_s: float
    orbit_speed_m_s: float
    vector_rates_rad_s: dict[str, float] = field(default_factory=dict, compare=False)
    grid_step_s: float = 0.0
    plans: tuple[FreePlan | None, ...] = field(default=(), compare=False)

    @property
    def turn_points(self) -> int:
        """Points at 64 a turn of the fastest rotation over the span (every
        ``grid_step_s``): the measure of what a span holds (about two intervals a turn of
        each vector) that the limit of a run (:data:`MAX_SEARCH_POINTS`) and the output
        budget (``attitude.outputs.budget``) count, whichever way it is searched."""
        step = self.grid_step_s if self.grid_step_s > 0.0 else self.step_s
        return max(math.ceil((self.stop_s - self.start_s) / step) + 1, 2)

    @property
    def _geometry_rate(self) -> float:
        """How fast the Sun, the Moon and the Earth can move across the sky, rad/s."""
        return _geometry_rate(self.orbit_rate_rad_s, self.orbit_speed_m_s)

    def vector_angle_rate_bound(self, name: str) -> float:
        """A bound on how fast an angle between body vector ``name`` and the Sun, the
        Moon, the nadir or the limb changes, rad/s: the vector's own rate plus theirs."""
        return self.vector_rates_rad_s.get(name, self.body_rate_rad_s) + self._geometry_rate

    @property
    def fraction_rate_bound(self) -> float:
        """A bound on how fast the lit fraction of the Sun's disc changes, 1/s."""
        return 2.0 * self.orbit_rate_rad_s / (math.pi * _SUN_LEAST_RADIUS_RAD)


def _geometry_rate(orbit_rate: float, orbit_speed: float) -> float:
    """How fast the Sun, the Moon and the Earth can move across the sky, rad/s, from the
    orbit's fastest nadir turn (with the limb's) and its greatest speed."""
    return orbit_rate + _SUN_SKY_RATE + _MOON_SKY_RATE + 2.0 * orbit_speed / 3.56e8


def _segment_rate(solver) -> float:
    """A bound on a segment's body rate, rad/s: its own where it states one (a segment
    under a law or a slew: ``angular_rate_bound``, attitude.trajectory.guided), else
    √(2T/I_min), since |ω|² = Σ m_i²/I_i² ≤ (Σ m_i²/I_i)/I_min = 2T/I_min (tighter than
    G/I_min, which it never exceeds)."""
    stated = getattr(solver, "angular_rate_bound", None)
    if stated is not None:
        return float(stated)
    return math.sqrt(
        max(2.0 * solver.kinetic_energy, 0.0) / float(np.min(solver.moments_of_inertia))
    )


def _in_span(trajectory: Trajectory, start_s: float, stop_s: float):
    """(index, segment) of the segments that meet [start_s, stop_s]."""
    return [
        (k, segment)
        for k, segment in enumerate(trajectory.segments)
        if segment.end_s >= start_s and segment.start_s <= stop_s
    ]


def _body_rate(trajectory: Trajectory, start_s: float, stop_s: float) -> float:
    """A bound on the body's rotation rate over [start_s, stop_s], rad/s: the largest
    over the segments of :func:`_segment_rate`."""
    rates = [_segment_rate(segment.solver) for _, segment in _in_span(trajectory, start_s, stop_s)]
    return max(rates, default=0.0)


def _vector_rates(
    trajectory: Trajectory,
    spec: PointingSpec,
    start_s: float,
    stop_s: float,
    segments: list | None = None,
) -> dict[str, float]:
    """For each body vector b, a bound on its inertial rate |ω × b| over [start_s,
    stop_s] on ``segments`` (those meeting the span by default), rad/s: the pointing's
    extrema are pruned with it (a vector near the spin axis turns far slower than the
    body, and :func:`_body_rate` would keep every bracket of its Sun angle).

    Per segment, ω(t) (body axes) is sampled :data:`_RATE_SAMPLES` times (fewer when
    many segments share :data:`_RATE_SAMPLES_IN_ALL`) over one body period of its
    solver, in which it takes all its values (the torque-free ω repeats in the body),
    or over the part of the segment in the span if that is shorter.
    Within s ≤ Δ/2 of a sample t_k, |ω(t) − ω(t_k)| ≤ |ω̇(t_k)| s + ½ max|ω̈| s², with
    ω̇ = I⁻¹(m × ω) (Euler's equations, m = Iω, ṁ = m × ω) at the sample, and
    |ω̈| = |I⁻¹((m × ω) × ω + m × ω̇)| ≤ (G ω_max² + G² ω_max / I_min) / I_min
    ≤ 2 G² ω_max / I_min² (as G ≥ I_min ω_max); ω_max = √(2T/I_min), the body's
    bound, also caps the result.
    """
    vectors = [(v.name, v.vector) for v in spec.body_vectors]
    rates = dict.fromkeys((name for name, _ in vectors), 0.0)
    if segments is None:
        segments = [segment for _, segment in _in_span(trajectory, start_s, stop_s)]
    if not vectors or not segments:
        return rates
    # Thousands of events share the samples (the bound stays rigorous, only looser).
    samples = min(_RATE_SAMPLES, max(_RATE_SAMPLES_LEAST, _RATE_SAMPLES_IN_ALL // len(segments)))
    for segment in segments:
        a, b = max(segment.start_s, start_s), min(segment.end_s, stop_s)
        solver = segment.solver
        least = float(np.min(solver.moments_of_inertia))
        highest = _segment_rate(solver)
        window = min(b - a, solver.period) if isinstance(solver, EulerSolver) else math.nan
        if not math.isfinite(window):  # under torques ω need not repeat; no period
            for name, _ in vectors:
                rates[name] = max(rates[name], highest)
            continue
        s = window / samples / 2.0
        ω = solver.angular_velocity(a + 2.0 * s * np.arange(samples + 1.0))
        tensor = solver.inertia_tensor
        ω_dot = np.linalg.solve(tensor, np.cross(ω @ tensor.T, ω)[..., None])[..., 0]
        G = solver.angular_momentum_norm
        curvature = 0.5 * (2.0 * G * G * highest / (least * least)) * s * s
        step = np.linalg.norm(ω_dot, axis=-1) * s + curvature
        for name, vector in vectors:
            found = float(np.max(np.linalg.norm(np.cross(ω, vector), axis=-1) + step))
            rates[name] = max(rates[name], min(found, highest))
    return rates


def _orbit_samples(
    trajectory: Trajectory, orbit: Orbit, start_s: float, stop_s: float
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The orbit every 60 s over [start_s, stop_s] (both ends included): τ, r, v."""
    count = max(math.ceil((stop_s - start_s) / _ORBIT_CHECK_STEP_S), 1) + 1
    τ = np.linspace(start_s, stop_s, count)
    jd1, jd2 = scenario_jd(trajectory)
    r, v = orbit.state_tt(np.full(τ.size, jd1), jd2 + τ / SECONDS_PER_DAY)
    return τ, r, v


def _orbit_rates(
    trajectory: Trajectory, spec: PointingSpec, start_s: float, stop_s: float
) -> tuple[float, float]:
    """Bounds on the orbit's angular rate as the search grid states it (the nadir's turn
    plus the rate of the Earth's angular radius, rad/s) and on its speed (m/s) over
    [start_s, stop_s]; zeros at the Earth's centre."""
    if spec.orbit is None:
        return 0.0, 0.0
    _, r, v = _orbit_samples(trajectory, spec.orbit, start_s, stop_s)
    distance = np.linalg.norm(r, axis=-1)
    nadir_rate = np.linalg.norm(np.cross(r, v), axis=-1) / distance**2
    rho = angular_radius(r, spec.earth_limb_atmosphere_height_m)
    radial = np.abs(np.sum(r * v, axis=-1)) / distance
    rho_rate = np.tan(np.minimum(rho, 1.5)) * radial / distance
    # Between samples 60 s apart the rates change little: 25 % covers the peaks
    # of a perigee pass that the samples straddle.
    orbit_rate = 1.25 * float(np.max(nadir_rate + rho_rate))
    return orbit_rate, float(np.max(np.linalg.norm(v, axis=-1)))


def search_grid(
    trajectory: Trajectory,
    spec: PointingSpec,
    start_s: float | None = None,
    stop_s: float | None = None,
    surroundings: SharedSurroundings | None = None,
    orbit: OrbitIntervals | None = None,
    planned: dict[int, FreePlan | None] | None = None,
) -> SearchGrid:
    """The search grid of :func:`pointing_analysis` over [start_s, stop_s] (the output
    span by default), from the rates of the motion and the orbit (see the module notes).
    ``surroundings``: the shared surroundings to plan on, if they cover the span (by
    default the process's cached ones); ``orbit``: the orbit's intervals over a span
    holding this one, whose rate bounds serve here too (else the orbit is sampled over
    this span); ``planned``: the free plans of some segments (by index) found already,
    on these surroundings over this span (:func:`pointing_analyses`).
    """
    scenario = trajectory.scenario
    spec = for_scenario(spec, scenario)  # the scenario's orbit, when the spec has none
    start_s = scenario.start_s if start_s is None else float(start_s)
    stop_s = scenario.stop_s if stop_s is None else float(stop_s)
    body = _body_rate(trajectory, start_s, stop_s)
    if orbit is not None and spec.orbit is not None and orbit.covers(start_s, stop_s):
        orbit_rate, speed = orbit.orbit_rate_rad_s, orbit.orbit_speed_m_s
    else:
        orbit_rate, speed = _orbit_rates(trajectory, spec, start_s, stop_s)
    longest = _LONGEST_STEP_ON_ORBIT_S if spec.orbit is not None else _LONGEST_STEP_S
    rate = body + orbit_rate + _SUN_SKY_RATE + _MOON_SKY_RATE
    grid_step = min(longest, 2.0 * math.pi / (_SAMPLES_PER_TURN * rate))
    segments = _in_span(trajectory, start_s, stop_s)
    plans: list[FreePlan | None] = [None] * len(trajectory.segments)
    shared = None
    if spec.body_vectors:
        shared = surroundings
        if shared is None or not shared.covers(start_s, stop_s):
            shared = shared_surroundings(trajectory, spec, start_s, stop_s)
    count, steps = 0, []
    for k, segment in segments:
        a, b = max(segment.start_s, start_s), min(segment.end_s, stop_s)
        plan = None
        if shared is not None and isinstance(segment.solver, EulerSolver):
            if planned is not None and k in planned:
                plan = planned[k]
            else:
                plan = free_plan(segment.solver, spec, shared, a, b)
        if plan is not None:
            plans[k] = plan
            count += plan.count
            steps.append(plan.step_s)
        elif spec.body_vectors:
            count += math.ceil((b - a) / grid_step) + 1
            steps.append(grid_step)
    if spec.orbit is not None:
        count += math.ceil((stop_s - start_s) / _ORBIT_STEP_S) + 1
        steps.append(_ORBIT_STEP_S)
    # Each vector's rate bound: the free plans' own, the sampled one elsewhere.
    others = [segment for k, segment in segments if plans[k] is None]
    rates = _vector_rates(trajectory, spec, start_s, stop_s, others)
    for plan in plans:
        if plan is not None:
            for name, motion in plan.motion.items():
                rates[name] = max(rates[name], motion.rate)
    return SearchGrid(
        start_s,
        stop_s,
        min(steps, default=grid_step),
        max(count, 2),
        body,
        orbit_rate,
        speed,
        rates,
        grid_step,
        tuple(plans),
    )


def check_pointing(
    trajectory: Trajectory, spec: PointingSpec
) -> tuple[list[str], SearchGrid | None]:
    """Everything the pointing of ``spec`` needs, checked before anything is sampled.

    The orbit over the span (the source covers it, and stays above the ground: see
    each source's ``check_span``; a TLE far from its epoch is noted with its age),
    and the Sun and Moon ephemeris over the span with the margins the interpolation
    adds.  Raises :class:`InputError` whose ``key`` names the scenario key
    (``pointing.tle``, ``output.duration``); returns notes for the user and the
    search grid of :func:`pointing_analysis` (None without pointing).
    """
    scenario = trajectory.scenario
    spec = for_scenario(spec, scenario)  # the scenario's orbit, when the spec has none
    if spec.is_empty:
        return [], None
    notes = []
    _, note = interval_precision(spec, scenario.stop_s)
    if note:
        notes.append(f"pointing.interval_precision: {note}")
    margin = 600.0  # one node of the Sun and Moon ephemeris
    ends = np.array([scenario.start_s - margin, scenario.stop_s + margin])
    # The start of the span is placed by the scenario's epoch, its end by its length.
    for end, key in zip(ends, ("scenario.epoch", scenario.end_key), strict=True):
        try:
            skyfield_times(scenario.times(end), name="span")
        except InputError as exc:
            raise InputError(
                f"the span with its {margin:g} s margins needs the Sun and the Moon over "
                f"{scenario.format_epoch(ends[0])} to {scenario.format_epoch(ends[1])}: "
                f"{exc.reason}",
                key=key,
            ) from None
    orbit = spec.orbit
    if orbit is not None:
        notes += orbit.check_span(scenario.times(scenario.start_s), scenario.times(scenario.stop_s))
        try:
            τ, r, _ = _orbit_samples(trajectory, orbit, scenario.start_s, scenario.stop_s)
        except InputError as exc:  # the source's own key when it names one
            raise (exc if exc.key else exc.located(key=orbit.key)) from None
        distance = np.linalg.norm(r, axis=-1)
        low = distance <= EARTH_EQUATORIAL_RADIUS_M
        if np.any(low):
            when = scenario.format_epoch(float(τ[np.argmax(low)]))
            raise InputError(
                f"the orbit is inside the Earth at {when} "
                f"({float(distance[np.argmax(low)]) / 1e3:.1f} km from its centre, less than "
                f"its {EARTH_EQUATORIAL_RADIUS_M / 1e3:g} km radius)",
                key=orbit.key,
            )
    grid = search_grid(trajectory, spec)
    if grid.turn_points > MAX_SEARCH_POINTS:
        raise InputError(
            f"the pointing's search needs {grid.turn_points:.3g} points over the span "
            f"(every {grid.grid_step_s:.3g} s: 64 a turn of the fastest rotation), more than "
            f"the {MAX_SEARCH_POINTS:.0e} one run searches: use a shorter span",
            key=scenario.end_key,
        )
    return notes, grid


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
    ``earth_limb_exclusion`` (each constraint violated, as in :class:`VectorSamples`),
    ``blinded`` (their union: any of the vector's exclusions violated; empty for a
    vector with none), ``sun_in_view`` (the Sun inside its inclusion cone and the
    spacecraft not in umbra; empty without an inclusion cone).
    ``extrema``: for each quantity of :data:`EXTREMA` it has, (least, greatest)
    :class:`attitude.pointing.extrema.Extremum`, radians for angles.  ``mean_cos_incidence``:
    the time average of the incidence over the span.
    """

    vector: BodyVector
    extrema: dict[str, tuple[Extremum, Extremum]]
    sun_visible: list[Interval] = field(default_factory=list)
    sun_exclusion: list[Interval] = field(default_factory=list)
    moon_exclusion: list[Interval] = field(default_factory=list)
    earth_limb_exclusion: list[Interval] = field(default_factory=list)
    mean_cos_incidence: float = 0.0
    blinded: list[Interval] = field(default_factory=list)
    sun_in_view: list[Interval] = field(default_factory=list)


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
    """Every body vector's quantity the grid search looks at, at any times of a span:
    the exact attitude and the shared surroundings."""

    def __init__(self, trajectory: Trajectory, spec: PointingSpec, shared: SharedSurroundings):
        self.trajectory = trajectory
        self.spec = spec
        self.shared = shared

    def __call__(self, seconds: NDArray[np.float64]) -> dict[str, NDArray[np.float64]]:
        env = self.shared.at(seconds)
        attitude = self.trajectory.attitude(seconds)
        values = {"sunlit_fraction": env.sunlit_fraction}
        for v in self.spec.body_vectors:
            for quantity, value in vector_angles(attitude.apply(v.vector), env).items():
                values[f"{v.name}.{quantity}"] = value
        return values


def _orbit_conditions(env) -> dict[str, NDArray[np.float64]]:
    """The eclipses' and the hidden Moon's functions (> 0 where each holds)."""
    a, b, c = env.shadow_angles
    return {"shadow": (a + b) - c, "umbra": (b - a) - c, "moon_hidden": moon_hidden(env)}


def _conditions(spec: PointingSpec) -> dict[str, tuple[str, float, float]]:
    """Each body vector's interval condition: (quantity, scale, offset), true where
    scale·q − offset > 0."""
    conditions: dict[str, tuple[str, float, float]] = {}
    for v in spec.body_vectors:
        name = v.name
        conditions[f"{name}.sun_visible"] = (f"{name}.sun_cosine", 1.0, 0.0)
        for kind, quantity, angle in (
            ("sun_exclusion", "sun_angle", v.sun_exclusion_half_angle_rad),
            ("moon_exclusion", "moon_angle", v.moon_exclusion_half_angle_rad),
            ("earth_limb_exclusion", "earth_limb_angle", v.earth_limb_exclusion_angle_rad),
            ("sun_in_view", "sun_angle", v.sun_inclusion_half_angle_rad),
        ):
            if angle is not None and (kind != "earth_limb_exclusion" or spec.orbit is not None):
                conditions[f"{name}.{kind}"] = (f"{name}.{quantity}", -1.0, -angle)
    return conditions


def _grid_points(start_s: float, stop_s: float, step_s: float) -> NDArray[np.float64]:
    """The grid over [start_s, stop_s], at most ``step_s`` apart, both ends included."""
    count = max(math.ceil((stop_s - start_s) / step_s), 1) + 1
    τ = start_s + (stop_s - start_s) * np.arange(count, dtype=np.float64) / (count - 1)
    τ[-1] = stop_s
    return τ


class _Search:
    """The intervals, extrema and averages of the analysis, accumulated segment by
    segment (and window by window)."""

    def __init__(
        self,
        trajectory: Trajectory,
        spec: PointingSpec,
        grid: SearchGrid,
        shared: SharedSurroundings,
        extrema: Collection[tuple[str, str]] | None = None,
    ) -> None:
        self.trajectory, self.spec, self.grid, self.shared = trajectory, spec, grid, shared
        self.precision = interval_precision(spec, trajectory.scenario.stop_s)[0]
        self.extremum_precision = max(_EXTREMUM_PRECISION_S, 4.0 * float(np.spacing(grid.stop_s)))
        self.conditions = _conditions(spec)
        self.found: dict[str, list[Interval]] = {name: [] for name in self.conditions}
        self.orbit: dict[str, list[Interval]] = {}
        # (vector, quantity) pairs, and the least and greatest of each found so far.
        self.wanted = [
            (v.name, quantity)
            for v in spec.body_vectors
            for quantity, needs_orbit in EXTREMA.items()
            if (spec.on_orbit or not needs_orbit)
            and (extrema is None or (v.name, quantity) in extrema)
        ]
        self.lows: dict[tuple[str, str], Extremum | None] = dict.fromkeys(self.wanted)
        self.highs: dict[tuple[str, str], Extremum | None] = dict.fromkeys(self.wanted)
        self.sums = {f"{v.name}.cos_incidence": 0.0 for v in spec.body_vectors}
        self.sunlit_integral = grid.stop_s - grid.start_s
        self.searched_to: float | None = None  # the end of what was searched so far
        self.evaluations = 0

    def _rate(self, name: str, quantity: str) -> float:
        """A bound on the rate of change of a vector's quantity (the incidence adds the
        lit fraction's)."""
        rate = self.grid.vector_angle_rate_bound(name)
        if quantity == "cos_incidence":
            return rate + self.grid.fraction_rate_bound
        return rate

    # ------------------------------------------------------------ the orbit alone

    def orbit_only(self, given: OrbitIntervals | None = None) -> None:
        """The eclipses and the Moon behind the Earth over the span, and the lit
        fraction's integral: cut from ``given`` (found once over a longer span), else
        computed once per span and precision, and kept with the shared surroundings
        (``memo``)."""
        if self.spec.orbit is None:
            return
        grid = self.grid
        if given is not None:
            self.orbit, self.sunlit_integral = given.within(
                self.shared, grid.start_s, grid.stop_s, self.precision
            )
            return
        key = ("orbit_only", grid.start_s, grid.stop_s, self.precision, grid._geometry_rate)
        found = self.shared.memo.get(key)
        if found is None:
            found = _orbit_only(self.shared, grid, self.precision)
            self.shared.memo[key] = found
        self.orbit, self.sunlit_integral = found

    # --------------------------------------------------------- torque-free segments

    def free(self, pieces: list[FreePiece]) -> None:
        """Search consecutive torque-free segments together (free_search)."""
        problems, incumbents = self.free_problems()
        result = search_free(
            pieces,
            self.spec,
            self.shared,
            self.precision,
            self.extremum_precision,
            _EXTREMUM_TOLERANCE,
            problems,
            incumbents,
            self.orbit.get("shadow", []),
            self.orbit.get("umbra", []),
        )
        self.take_free(pieces, result)

    def free_problems(self) -> tuple[dict[str, Problem], dict[str, Extremum | None]]:
        """The extremum problems of a free search, and the best known of each."""
        problems, incumbents = {}, {}
        for name, quantity in self.wanted:
            rate = self._rate(name, quantity)
            low, high = self.lows[(name, quantity)], self.highs[(name, quantity)]
            problems[f"{name}.{quantity}.low"] = Problem(np.empty(0), rate, low)
            problems[f"{name}.{quantity}.high"] = Problem(np.empty(0), rate, None)
            incumbents[f"{name}.{quantity}.low"] = low
            incumbents[f"{name}.{quantity}.high"] = (
                None if high is None else Extremum(high.time_s, -high.value)
            )
        return problems, incumbents

    def take_free(self, pieces: list[FreePiece], result: FreeResult) -> None:
        """Fold a free search's result in."""
        self.evaluations += result.evaluations
        start_s = pieces[0].start_s
        self._add(result.intervals, start_s)
        for name, quantity in self.wanted:
            low = result.extrema[f"{name}.{quantity}.low"]
            high = result.extrema[f"{name}.{quantity}.high"]
            if quantity == "cos_incidence" and result.dark[name]:
                # No light: 0 is the least incidence, placed from the intervals (result).
                low = Extremum(float(start_s), 0.0)
            self.lows[(name, quantity)] = low
            self.highs[(name, quantity)] = Extremum(high.time_s, -high.value)
        for name, value in result.incidence_integral.items():
            self.sums[f"{name}.cos_incidence"] += value

    def _add(self, intervals: dict[str, list[Interval]], start_s: float) -> None:
        """Fold a segment's (or a window's) intervals in: joined to the previous ones
        across ``start_s``, where an event may make a value jump."""
        for name in self.conditions:
            if self.searched_to is None:
                join(self.found[name], intervals[name], start_s)
            else:
                append_across(self.found[name], intervals[name], start_s)
        self.searched_to = start_s

    # ------------------------------------------------------------- the grid search

    def gridded(self, start_s: float, end_s: float) -> None:
        """Search [start_s, end_s] (consecutive segments under torques or laws) on the
        grid, with the events' epochs within it as points (the trajectory gives each
        point its segment: the later one at an event)."""
        step = self.grid.grid_step_s if self.grid.grid_step_s > 0.0 else self.grid.step_s
        τ_all = _grid_points(start_s, end_s, step)
        events = np.array([t for t, _ in self.trajectory.scenario.events], dtype=np.float64)
        inside = events[(events > start_s) & (events < end_s)]
        if inside.size:
            τ_all = np.unique(np.concatenate([τ_all, inside]))
        first = 0
        while first < τ_all.size - 1:
            last = min(first + CHUNK_POINTS, τ_all.size - 1)
            self.chunk(τ_all[first : last + 1], first == 0)
            first = last

    def chunk(self, τ: NDArray[np.float64], segment_start: bool = True) -> None:
        """Search the grid points τ (one chunk) and fold what they hold into the totals."""
        quantities = _Quantities(self.trajectory, self.spec, self.shared)
        values = quantities(τ)
        self.evaluations += τ.size
        pieces = find_all_intervals(
            lambda t: self._condition_values(quantities(t)),
            τ,
            self.precision,
            self._condition_values(values),
            {name: self._rate(name.split(".")[0], "sun_angle") for name in self.conditions},
        )
        if segment_start:
            self._add(pieces, float(τ[0]))
        else:
            for name in self.conditions:
                join(self.found[name], pieces[name], float(τ[0]))
        self._extrema(quantities, τ, values)
        widths = np.diff(τ)
        for key in self.sums:  # the trapezoid rule on the search grid
            self.sums[key] += float(np.sum(0.5 * (values[key][1:] + values[key][:-1]) * widths))

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
                problems[f"{key}.low"] = Problem(
                    on_grid[f"{key}.low"], self._rate(name, quantity), low
                )
            problems[f"{key}.high"] = Problem(
                on_grid[f"{key}.high"],
                self._rate(name, quantity),
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

    # ------------------------------------------------------------------ the result

    def _exact_values(self) -> None:
        """Each extremum's value computed at its time as a sample there gives it (the
        exact surroundings), so that the values reported are the samples' values."""
        found = [
            (which, key, extremum)
            for which in (self.lows, self.highs)
            for key, extremum in which.items()
            if extremum is not None
        ]
        if not found:
            return
        times = np.array([extremum.time_s for _, _, extremum in found])
        # As pointing_samples computes them: the exact surroundings (the shared ones'
        # exact path: the same ephemeris nodes), the trajectory's attitude.
        env = self.shared.exact(times)
        attitude = self.trajectory.attitude(times)
        wanted = {name for _, (name, _), _ in found}  # the vectors with an extremum
        angles = {
            v.name: vector_angles(attitude.apply(v.vector), env)
            for v in self.spec.body_vectors
            if v.name in wanted
        }
        for k, (which, (name, quantity), extremum) in enumerate(found):
            if quantity == "cos_incidence" and extremum.value == 0.0:
                continue  # the dark's 0, placed from the intervals
            value = angles[name][quantity][k]
            which[(name, quantity)] = Extremum(extremum.time_s, float(value))

    def _orbit_description(self) -> str:
        """The orbit in words, kept with the shared surroundings (which are those of
        this orbit): a search of a short window pays for it once."""
        if self.spec.orbit is None:
            return "Earth centre"
        text = self.shared.memo.get("orbit_description")
        if text is None:
            text = self.shared.memo["orbit_description"] = self.spec.orbit.describe()
        return str(text)

    def result(self) -> PointingAnalysis:
        """The analysis: the accumulated intervals (each condition less what hides it),
        extrema and averages."""
        self._exact_values()
        grid, spec, found = self.grid, self.spec, self.found
        span = max(grid.stop_s - grid.start_s, 1e-300)
        umbra = self.orbit.get("umbra", [])
        analysis = PointingAnalysis(
            start_s=grid.start_s,
            stop_s=grid.stop_s,
            precision_s=self.precision,
            on_orbit=spec.on_orbit,
            orbit=self._orbit_description(),
            grid=grid,
            vectors=[],
            shadow=self.orbit.get("shadow", []),
            umbra=umbra,
            moon_hidden=self.orbit.get("moon_hidden", []),
            sunlit_fraction_mean=self.sunlit_integral / span,
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
                extrema=extrema,  # type: ignore[arg-type]
                sun_visible=difference(found[f"{name}.sun_visible"], umbra),
                sun_exclusion=difference(found.get(f"{name}.sun_exclusion", []), umbra),
                moon_exclusion=difference(
                    found.get(f"{name}.moon_exclusion", []), analysis.moon_hidden
                ),
                earth_limb_exclusion=found.get(f"{name}.earth_limb_exclusion", []),
                mean_cos_incidence=self.sums[f"{name}.cos_incidence"] / span,
                sun_in_view=difference(found.get(f"{name}.sun_in_view", []), umbra),
            )
            item.blinded = union(*(getattr(item, kind) for kind in v.exclusions))
            if "cos_incidence" in extrema:
                low, high = extrema["cos_incidence"]
                item.extrema["cos_incidence"] = (_first_dark(item, grid) or low, high)  # type: ignore[assignment]
            analysis.vectors.append(item)
        return analysis


def _orbit_only(
    shared: SharedSurroundings, grid: SearchGrid, precision: float
) -> tuple[dict[str, list[Interval]], float]:
    """The eclipses and the Moon behind the Earth over the span of ``grid`` (each
    interval found however short: the geometry's rate bounds each function, 1 + the
    Sun's and Moon's rates for the angles' sums), and the integral of the lit fraction
    (the span less, in the shadow, the umbra's length and the penumbra's unlit part by
    Gauss–Legendre on each stretch)."""
    return _orbit_search(shared, grid.start_s, grid.stop_s, grid._geometry_rate, precision)


def _orbit_search(
    shared: SharedSurroundings, start_s: float, stop_s: float, geometry: float, precision: float
) -> tuple[dict[str, list[Interval]], float]:
    """:func:`_orbit_only` over [start_s, stop_s] with the geometry's rate bound
    ``geometry`` (rad/s)."""
    τ = _grid_points(start_s, stop_s, _ORBIT_STEP_S)

    def evaluate(t: NDArray[np.float64]) -> dict[str, NDArray[np.float64]]:
        return _orbit_conditions(shared.at(t))

    rate = 2.0 * geometry
    found = find_all_intervals(
        evaluate, τ, precision, evaluate(τ), dict.fromkeys(("shadow", "umbra", "moon_hidden"), rate)
    )
    penumbra = difference(found["shadow"], found["umbra"])
    unlit = sum(_unlit(shared, p.start_s, p.end_s) for p in penumbra)
    unlit += sum(i.end_s - i.start_s for i in found["umbra"])
    return found, (stop_s - start_s) - unlit


@dataclass(frozen=True)
class OrbitIntervals:
    """The eclipses (``shadow``: any part of the Sun hidden; ``umbra``: all of it) and
    the Moon behind the Earth (``moon_hidden``) over [start_s, stop_s], found once
    (:func:`orbit_intervals`) and cut to any span within it (:meth:`within`) by
    :func:`pointing_analysis`: they depend on the orbit alone, so that many searches of
    short spans (the envelope's windows after each failure) share one search.
    ``penumbra_unlit``: for each stretch of shadow outside the umbra, ∫(1 − λ) dt over
    it (λ the lit fraction), for the lit fraction's mean.  ``orbit_rate_rad_s``,
    ``orbit_speed_m_s``: the orbit's rate bounds over the whole span (as
    :class:`SearchGrid` states them), which bound them over any part of it."""

    start_s: float
    stop_s: float
    precision_s: float
    intervals: dict[str, list[Interval]]
    penumbra_unlit: tuple[tuple[Interval, float], ...]
    orbit_rate_rad_s: float
    orbit_speed_m_s: float

    def covers(self, start_s: float, stop_s: float) -> bool:
        return self.start_s <= start_s and stop_s <= self.stop_s

    def within(
        self, shared: SharedSurroundings, start_s: float, stop_s: float, precision_s: float
    ) -> tuple[dict[str, list[Interval]], float]:
        """The intervals over [start_s, stop_s] (cut at its ends, flagged as starting
        before or ending after it, as a search of that span states them) and the
        integral of the lit fraction over it (the penumbra cut by an end integrated
        again, by Gauss–Legendre, over its part within the span)."""
        if not self.covers(start_s, stop_s) or precision_s != self.precision_s:
            raise ValueError(
                f"the orbit's intervals over [{self.start_s:g}, {self.stop_s:g}] s at "
                f"{self.precision_s:g} s do not serve [{start_s:g}, {stop_s:g}] s at "
                f"{precision_s:g} s"
            )
        cut = {name: _cut(found, start_s, stop_s) for name, found in self.intervals.items()}
        unlit = sum(i.end_s - i.start_s for i in cut["umbra"])
        for piece, whole in self.penumbra_unlit:
            a, b = max(piece.start_s, start_s), min(piece.end_s, stop_s)
            if b <= a:
                continue
            unlit += whole if (a, b) == (piece.start_s, piece.end_s) else _unlit(shared, a, b)
        return cut, (stop_s - start_s) - unlit


def _cut(intervals: list[Interval], start_s: float, stop_s: float) -> list[Interval]:
    """``intervals`` (sorted, disjoint) within [start_s, stop_s]: one that holds at an
    end starts before (ends after) the span, as :func:`find_all_intervals` states it."""
    ends = np.array([i.end_s for i in intervals], dtype=np.float64)
    out = []
    for interval in intervals[int(np.searchsorted(ends, start_s)) :]:
        if interval.start_s > stop_s or (interval.start_s == stop_s and start_s < stop_s):
            break
        if interval.end_s == start_s and start_s < stop_s:
            continue  # touches the span's start only
        before = interval.start_s < start_s or (
            interval.start_s == start_s and interval.starts_before
        )
        after = interval.end_s > stop_s or (interval.end_s == stop_s and interval.ends_after)
        start, end = max(interval.start_s, start_s), min(interval.end_s, stop_s)
        out.append(Interval(start, end, before, after))
    return out


def _unlit(shared: SharedSurroundings, a: float, b: float) -> float:
    """∫(1 − λ) dt over [a, b] (a stretch of penumbra) by Gauss–Legendre."""
    x, w = np.polynomial.legendre.leggauss(_PENUMBRA_POINTS)
    half = 0.5 * (b - a)
    t = a + half * (1.0 + x)
    return half * float(np.sum(w * (1.0 - shared.at(t).sunlit_fraction)))


def orbit_intervals(
    trajectory: Trajectory,
    spec: PointingSpec,
    start_s: float,
    stop_s: float,
    surroundings: SharedSurroundings | None = None,
) -> OrbitIntervals | None:
    """The :class:`OrbitIntervals` of ``spec``'s orbit (or the scenario's) over
    [start_s, stop_s] (None at the Earth's centre), searched as
    :func:`pointing_analysis` searches them (the geometry's rate bound over this span,
    which bounds it over any part), to the interval precision of ``trajectory``'s
    scenario: pass it to :func:`pointing_analysis` (``orbit``) for spans within it."""
    spec = for_scenario(spec, trajectory.scenario)
    if spec.orbit is None:
        return None
    shared = surroundings
    if shared is None or not shared.covers(start_s, stop_s):
        shared = shared_surroundings(trajectory, spec, start_s, stop_s)
    precision = interval_precision(spec, trajectory.scenario.stop_s)[0]
    orbit_rate, speed = _orbit_rates(trajectory, spec, start_s, stop_s)
    found, _ = _orbit_search(shared, start_s, stop_s, _geometry_rate(orbit_rate, speed), precision)
    penumbra = tuple(
        (piece, _unlit(shared, piece.start_s, piece.end_s))
        for piece in difference(found["shadow"], found["umbra"])
    )
    return OrbitIntervals(start_s, stop_s, precision, found, penumbra, orbit_rate, speed)


def pointing_analysis(
    trajectory: Trajectory,
    spec: PointingSpec,
    start_s: float | None = None,
    stop_s: float | None = None,
    grid: SearchGrid | None = None,
    surroundings: SharedSurroundings | None = None,
    orbit: OrbitIntervals | None = None,
    extrema: Collection[tuple[str, str]] | None = None,
) -> PointingAnalysis:
    """Every interval and extremum of ``spec``'s pointing over [start_s, stop_s] (TT s
    since the epoch; the output span by default), on the exact motion.

    Torque-free segments are searched on their structure
    (:mod:`attitude.pointing.free_search`), the others on a grid, both in windows of
    bounded size (see the module notes): memory does not grow with the span, only the
    list of intervals found.  Interval ends are refined to
    ``spec.interval_precision_s``, extrema to 1 µs.  ``surroundings``: the
    :class:`~attitude.pointing.shared_surroundings.SharedSurroundings` to use (one
    covering the span, for the same epoch, orbit and limb height); by default the
    process's cached one (:func:`~attitude.pointing.shared_surroundings
    .shared_surroundings`).  ``orbit``: the eclipses and the Moon behind the Earth
    found once over a span holding this one (:func:`orbit_intervals`), cut to it.
    ``extrema``: the (vector name, quantity) pairs of :data:`EXTREMA` to find (all by
    default); the others are left out of each vector's ``extrema``.
    """
    search = _prepared(trajectory, spec, start_s, stop_s, grid, surroundings, orbit, extrema)
    _searched(search)
    return search.result()


def _prepared(
    trajectory, spec, start_s, stop_s, grid, surroundings, orbit, extrema, planned=None
) -> _Search:
    """The search of :func:`pointing_analysis`, planned, with the orbit's intervals."""
    spec = for_scenario(spec, trajectory.scenario)  # the scenario's orbit, if the spec has none
    if grid is None:
        grid = search_grid(trajectory, spec, start_s, stop_s, surroundings, orbit, planned)
    shared = surroundings
    if shared is None or not shared.covers(grid.start_s, grid.stop_s):
        shared = shared_surroundings(trajectory, spec, grid.start_s, grid.stop_s)
    search = _Search(trajectory, spec, grid, shared, extrema)
    search.orbit_only(orbit)
    return search


def _one_free_run(search: _Search) -> list[FreePiece] | None:
    """The pieces of a search whose span is one run of torque-free segments in one
    window of nodes (what :func:`pointing_analyses` searches together), else None."""
    if not search.spec.body_vectors:
        return None
    grid, run = search.grid, []
    for k, segment in _in_span(search.trajectory, grid.start_s, grid.stop_s):
        a, b = max(segment.start_s, grid.start_s), min(segment.end_s, grid.stop_s)
        if b <= a and not (a == b == grid.start_s == grid.stop_s):
            continue
        plan = grid.plans[k] if k < len(grid.plans) else None
        if plan is None or not isinstance(segment.solver, EulerSolver):
            return None
        run.append(FreePiece(segment.solver, plan, a, b, b < grid.stop_s))
    return run if run and fits_one_window(run) else None


def pointing_analyses(
    trajectories: list[Trajectory],
    spec: PointingSpec,
    spans: list[tuple[float, float]],
    surroundings: SharedSurroundings | None = None,
    orbit: OrbitIntervals | None = None,
    extrema: Collection[tuple[str, str]] | None = None,
) -> list[PointingAnalysis]:
    """:func:`pointing_analysis` of each trajectory over its span (``spans[i]``: start
    and stop, TT s), the same analyses, found together: the searches whose spans are
    one run of torque-free segments (the envelope's windows after each failure) are
    searched as one set of arrays (:func:`attitude.pointing.free_search
    .search_free_many`), each with its own decisions and element by element, so that
    each analysis is the one :func:`pointing_analysis` gives alone, bit for bit; the
    others are searched alone."""
    planned = _free_plans(trajectories, spec, spans, surroundings)
    searches = [
        _prepared(trajectory, spec, a, b, None, surroundings, orbit, extrema, plans)
        for trajectory, (a, b), plans in zip(trajectories, spans, planned, strict=True)
    ]
    together: list[tuple[_Search, list[FreePiece]]] = []
    for search in searches:
        run = _one_free_run(search)
        if run is None or (together and _batch_key(search) != _batch_key(together[0][0])):
            _searched(search)
        else:
            together.append((search, run))
    if together:
        first = together[0][0]
        problems = [search.free_problems() for search, _ in together]
        results = search_free_many(
            [run for _, run in together],
            first.spec,
            first.shared,
            first.precision,
            first.extremum_precision,
            _EXTREMUM_TOLERANCE,
            [p for p, _ in problems],
            [i for _, i in problems],
            [search.orbit.get("shadow", []) for search, _ in together],
            [search.orbit.get("umbra", []) for search, _ in together],
        )
        for (search, run), result in zip(together, results, strict=True):
            search.take_free(run, result)
    return [search.result() for search in searches]


def _free_plans(
    trajectories: list[Trajectory],
    spec: PointingSpec,
    spans: list[tuple[float, float]],
    surroundings: SharedSurroundings | None,
) -> list[dict[int, FreePlan | None] | None]:
    """The free plans of every torque-free segment of the trajectories of one scenario
    over their spans, found together (:func:`attitude.pointing.free_search.free_plans`)
    as :func:`search_grid` finds each (by segment index); None for a trajectory whose
    plans :func:`search_grid` finds itself (other scenarios, surroundings that do not
    cover its span)."""
    out: list[dict[int, FreePlan | None] | None] = [None] * len(trajectories)
    if not trajectories or surroundings is None or not spec.body_vectors:
        return out
    scenario = trajectories[0].scenario
    spec = for_scenario(spec, scenario)
    where, solvers, parts = [], [], []
    for i, (trajectory, (start_s, stop_s)) in enumerate(zip(trajectories, spans, strict=True)):
        if trajectory.scenario is not scenario or not surroundings.covers(start_s, stop_s):
            continue
        out[i] = {}
        for k, segment in _in_span(trajectory, start_s, stop_s):
            if isinstance(segment.solver, EulerSolver):
                where.append((i, k))
                solvers.append(segment.solver)
                parts.append((max(segment.start_s, start_s), min(segment.end_s, stop_s)))
    for (i, k), plan in zip(where, free_plans(solvers, spec, surroundings, parts), strict=True):
        out[i][k] = plan  # type: ignore[index]
    return out


def _batch_key(search: _Search) -> tuple:
    return (search.shared, search.spec, search.precision, search.extremum_precision)


def _searched(search: _Search) -> None:
    """Run the search of :func:`pointing_analysis` over its span."""
    trajectory, spec, grid = search.trajectory, search.spec, search.grid
    if spec.body_vectors:
        # Consecutive torque-free segments are searched together, and so are
        # consecutive other ones, on the grid.
        run: list[FreePiece] = []
        gridded: list[float] = []  # the start and end of the segments to grid
        for k, segment in _in_span(trajectory, grid.start_s, grid.stop_s):
            a, b = max(segment.start_s, grid.start_s), min(segment.end_s, grid.stop_s)
            if b <= a and not (a == b == grid.start_s == grid.stop_s):
                continue  # an event at the span's end, or two at one epoch
            plan = grid.plans[k] if k < len(grid.plans) else None
            if plan is not None and isinstance(segment.solver, EulerSolver):
                if gridded:
                    search.gridded(gridded[0], gridded[-1])
                    gridded = []
                run.append(FreePiece(segment.solver, plan, a, b, b < grid.stop_s))
                continue
            if run:
                search.free(run)
                run = []
            gridded = [gridded[0] if gridded else a, b]
        if run:
            search.free(run)
        if gridded:
            search.gridded(gridded[0], gridded[-1])


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
