"""The surroundings of a span, computed once and shared: the orbit, the Sun, the Moon and
the Earth's shadow, interpolated with a stated bound.

Every search of a run, every Monte Carlo sample on a worker and every failure time of
a study over one span asks the same question of the environment: where are the Sun,
the Moon and the Earth seen from the spacecraft, at many times of one span.  Their
answer does not depend on the attitude.  :class:`SharedSurroundings` computes it once
for a span and hands it to all of them.

**What is computed.**  The span (with a margin) is cut into pieces aligned on TT
multiples of 120 s from J2000 (600 s at the Earth's centre), the nodes of the Sun and
Moon ephemeris of :class:`attitude.environment.ephemeris.SunMoonFromEarth` falling on
piece ends, so that within a piece every input is analytic; the first and last pieces
are cut at the ends of what the orbit serves (an orbit file may cover the span
exactly: :func:`attitude.environment.orbit.coverage_seconds`).  On each piece, the
fields of :meth:`attitude.pointing.surroundings.SunMoonEarth.fields` (the apparent Sun
and Moon from the spacecraft, and on an orbit its position and velocity, from the
orbit's source, and the apparent Sun from the Earth's centre) are computed exactly at
the 9 Chebyshev points of the first kind and interpolated by the polynomial of degree
8 through them (Trefethen, *Approximation Theory and Approximation Practice*, SIAM
2013, ch. 2–4).  :meth:`SharedSurroundings.at` evaluates those polynomials and builds
:class:`attitude.pointing.surroundings.Surroundings` from them with the same code
(``assemble``) as the exact path: the shadow, the lit fraction, nadir and the limb.

**The bound.**  Each piece is checked against the exact fields halfway between its
nodes and at its two ends (where a Chebyshev interpolant errs most), and halved until
every checked point is within 1 mm in position and 1e-11 rad in every direction (at
most five times: a piece that still fails, an orbit file's jump between segments say,
is evaluated exactly).  The largest errors measured are kept:
:attr:`SharedSurroundings.position_error_m` and
:attr:`SharedSurroundings.direction_error_rad` (the Sun, the Moon, the shadow's axis,
and nadir: the position error over the least distance).  This is a measured bound,
not a proved one; ``tests/test_shared_surroundings_against_exact.py`` checks it at
random times.  Over a day of the examples' LEO orbit (a TLE) the measured errors are
7 µm (SGP4's own noise) and 1e-12 rad: a search on them finds times that differ from
those on the exact surroundings by the error over the rate at which the angle changes
(1e-11 s on a body turning at 1 rad/s; at most 5e-5 s on a body at rest, where only the
Sun moves, 2e-7 rad/s), below the interval precision (1 ms), and extrema within
1e-11 rad.

**Lifetime.**  An instance is built for one epoch (the scenario's TT Julian date),
one orbit (or the Earth's centre), one limb height and one span, and never changes
after it is built: it can be shared by searches, threads and samples.  It holds the
coefficients of its pieces, their derivatives and the targets' (2 MB a day on an
orbit, measured; 0.02 s of CPU to build).  It also
keeps, in :attr:`SharedSurroundings.memo`, what callers derive from it alone (the
eclipses of a span at a precision, :mod:`attitude.pointing.search`), so that they too
are computed once.  :func:`shared_surroundings` returns the instance for a
trajectory and a pointing spec from a process-wide cache of the last
:data:`CACHE_SIZE` built (keyed by the epoch, the orbit's content, the limb height;
reused when its span covers the one asked): a Monte Carlo worker builds it for its
first sample and reuses it for every later sample whose orbit, epoch and span are
the same; :func:`clear_cache` empties it.  A caller that runs many searches over one
span (a study of failure times) can also build one and pass it to
:func:`attitude.pointing.search.pointing_analysis` (``surroundings=``).
"""

from __future__ import annotations

import hashlib
import itertools
import math
import pickle
import threading
from collections import OrderedDict
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.polynomial import chebyshev
from numpy.typing import NDArray

from attitude.environment.earth import EARTH_EQUATORIAL_RADIUS_M
from attitude.environment.orbit import Orbit, coverage_seconds
from attitude.environment.timescales import SECONDS_PER_DAY
from attitude.pointing.eclipse import SUN_RADIUS_M
from attitude.pointing.spec import PointingSpec, for_scenario
from attitude.pointing.surroundings import (
    SunMoonEarth,
    Surroundings,
    assemble,
    norm,
    scenario_jd,
)
from attitude.trajectory.trajectory import Trajectory

__all__ = [
    "CACHE_SIZE",
    "SharedSurroundings",
    "Targets",
    "clear_cache",
    "exact_surroundings",
    "shared_surroundings",
]

# Pieces: TT multiples of this many seconds from J2000 (the ephemeris' 600 s nodes
# fall on piece ends), polynomials of this degree.
_ORBIT_PIECE_S = 120.0
_CENTRE_PIECE_S = 600.0
_ORIGIN_JD = 2451545.0
_DEGREE = 8
# The check: a piece is halved until its checked errors are within these, at most
# this many times; then it is evaluated exactly.
_POSITION_TOLERANCE_M = 1e-3
_VELOCITY_TOLERANCE_M_S = 1e-6
_DIRECTION_TOLERANCE_RAD = 1e-11
_HALVINGS = 5
# The span is covered with this margin at each end (a search refines a few ulps
# outside its span; the ephemeris adds its own margin beyond).
_MARGIN_S = 1.0
# The fields interpolated, their widths, and what each error is measured as.
_ORBIT_FIELDS = ("r", "v", "sun", "moon", "sun_from_earth")
_CENTRE_FIELDS = ("sun", "moon")
_TARGET_FIELDS = ("sun", "moon", "r")

CACHE_SIZE = 4
# The Sun's least angular radius from near the Earth (at aphelion, 1.53e11 m).
_SUN_LEAST_RADIUS_RAD = SUN_RADIUS_M / 1.53e11


@dataclass(frozen=True)
class Targets:
    """The directions a search compares body vectors with, and their time derivatives,
    at some times: unit vectors (n, 3) to the Sun and the Moon (apparent, from the
    spacecraft) and, on an orbit, to nadir, with ``*_rate`` their derivatives (1/s)
    and, when asked, ``*_accel`` their second derivatives (1/s²); the limb's angular
    radius ``limb`` (rad) with its rate ``limb_rate``."""

    sun: NDArray[np.float64]
    sun_rate: NDArray[np.float64]
    moon: NDArray[np.float64]
    moon_rate: NDArray[np.float64]
    nadir: NDArray[np.float64] | None = None
    nadir_rate: NDArray[np.float64] | None = None
    limb: NDArray[np.float64] | None = None
    limb_rate: NDArray[np.float64] | None = None
    sun_accel: NDArray[np.float64] | None = None
    moon_accel: NDArray[np.float64] | None = None
    nadir_accel: NDArray[np.float64] | None = None


def _to_power() -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The Chebyshev points of the first kind on [−1, 1], the matrix from values there
    to Chebyshev coefficients, and the matrix from those to power coefficients."""
    nodes = np.asarray(chebyshev.chebpts1(_DEGREE + 1), dtype=np.float64)
    to_chebyshev = np.asarray(np.linalg.inv(chebyshev.chebvander(nodes, _DEGREE)), np.float64)
    to_power = np.zeros((_DEGREE + 1, _DEGREE + 1))
    for k in range(_DEGREE + 1):
        to_power[: k + 1, k] = chebyshev.cheb2poly(np.eye(_DEGREE + 1)[k])
    return nodes, to_chebyshev, to_power


_NODES, _TO_CHEBYSHEV, _TO_POWER = _to_power()
# Halfway between consecutive nodes, and the two ends: where the check looks.
_CHECKS = np.concatenate([[-1.0], 0.5 * (_NODES[1:] + _NODES[:-1]), [1.0]])


class SharedSurroundings:
    """The surroundings of the span [start_s, stop_s] (TT seconds since the epoch
    ``jd``, a two-part TT Julian date), from ``orbit`` (None: the Earth's centre), with
    the limb ``limb_height_m`` above the Earth: see the module notes.

    ``position_error_m`` and ``direction_error_rad``: the largest errors measured by
    the check (0 where nothing is interpolated).  ``memo``: results derived from these
    surroundings alone, kept with them by their callers.
    """

    def __init__(
        self,
        jd: tuple[float, float],
        orbit: Orbit | None,
        limb_height_m: float,
        start_s: float,
        stop_s: float,
    ) -> None:
        self.jd = (float(jd[0]), float(jd[1]))
        self.orbit = orbit
        self.limb_height_m = float(limb_height_m)
        self.spec = PointingSpec([], orbit, earth_limb_atmosphere_height_m=limb_height_m)
        self.memo: dict[Any, Any] = {}
        piece_s = _CENTRE_PIECE_S if orbit is None else _ORBIT_PIECE_S
        self._fields = _CENTRE_FIELDS if orbit is None else _ORBIT_FIELDS
        first, last = self._aligned(start_s - _MARGIN_S, stop_s + _MARGIN_S, piece_s)
        ends = self._within_orbit(np.concatenate([first, last[-1:]]), start_s, stop_s)
        self.start_s, self.stop_s = float(ends[0]), float(ends[-1])
        self._exact = SunMoonEarth(None, self.spec, self.start_s, self.stop_s, jd=self.jd)
        self.position_error_m = 0.0
        self.direction_error_rad = 0.0
        edges, coefficients, exact = self._fit(ends)
        self._edges = edges
        self._coefficients = coefficients  # (pieces, degree + 1, components), powers of t
        self._exact_pieces = exact
        widths = np.diff(edges)
        degree = coefficients.shape[1] - 1
        # The derivative's power coefficients (per second) of every piece.
        k = np.arange(1, degree + 1, dtype=np.float64)
        self._derivative = coefficients[:, 1:, :] * (
            k[None, :, None] * (2.0 / widths)[:, None, None]
        )
        self._slices = self._field_slices()
        self._rates = self._rate_bounds(widths)
        # What targets() needs (the Sun, the Moon, the position), degree first: each
        # step of Horner's rule gathers one contiguous row per point.
        columns = np.concatenate(
            [np.arange(3 * k, 3 * k + 3) for k, n in enumerate(self._fields) if n in _TARGET_FIELDS]
        )
        self._target_names = [n for n in self._fields if n in _TARGET_FIELDS]
        self._target_values = np.ascontiguousarray(np.moveaxis(coefficients[:, :, columns], 1, 0))
        self._target_rates = np.ascontiguousarray(
            np.moveaxis(self._derivative[:, :, columns], 1, 0)
        )
        k2 = np.arange(1, max(degree, 1), dtype=np.float64)
        second = self._derivative[:, 1:, :] * (k2[None, :, None] * (2.0 / widths)[:, None, None])
        if second.shape[1] == 0:
            second = np.zeros((second.shape[0], 1, second.shape[2]))
        self._target_accels = np.ascontiguousarray(np.moveaxis(second[:, :, columns], 1, 0))

    # ------------------------------------------------------------------ building

    def _aligned(self, start_s: float, stop_s: float, piece_s: float):
        """The ends of the aligned pieces covering [start_s, stop_s]: TT multiples of
        ``piece_s`` from J2000, as seconds since the epoch (first ends, and the last)."""
        jd1, jd2 = self.jd
        per_day = SECONDS_PER_DAY / piece_s
        base = (jd1 - _ORIGIN_JD) * per_day
        base_frac = base - math.floor(base)
        offset_s = jd2 * SECONDS_PER_DAY

        def position(τ: float) -> float:
            return (offset_s + τ) / piece_s + base_frac

        first = math.floor(position(start_s))
        last = math.ceil(position(stop_s))
        k = np.arange(first, max(last, first + 1) + 1, dtype=np.float64)
        ends = (k - base_frac) * piece_s - offset_s
        return ends[:-1], ends[-1:]

    def _within_orbit(
        self, ends: NDArray[np.float64], start_s: float, stop_s: float
    ) -> NDArray[np.float64]:
        """The aligned piece ends, the outer two moved in to the orbit's coverage
        (:func:`attitude.environment.orbit.coverage_seconds`: an orbit file that
        covers the span exactly ends inside the first and last aligned pieces), never
        inside [start_s, stop_s] itself, which the orbit's own check refuses when it is
        not covered.  A piece cut so keeps its ephemeris nodes at its ends (it lies
        within an aligned piece)."""
        first_s, last_s = coverage_seconds(self.orbit, self.jd)
        lower = min(max(float(ends[0]), first_s), start_s)
        upper = max(min(float(ends[-1]), last_s), stop_s)
        inner = ends[(ends > lower) & (ends < upper)]
        return np.concatenate([[lower], inner, [upper]])

    def _exact_fields(self, seconds: NDArray[np.float64]) -> NDArray[np.float64]:
        """The fields at ``seconds``, side by side: (n, 3 × fields)."""
        fields = self._exact.fields(seconds)
        return np.concatenate([fields[name] for name in self._fields], axis=1)

    def _fit(self, edges: NDArray[np.float64]):
        """Fit every piece, halving the ones that fail the check (module notes)."""
        pieces = [(float(a), float(b), 0) for a, b in itertools.pairwise(edges)]
        done: list[tuple[float, float, NDArray[np.float64] | None]] = []
        while pieces:
            lower = np.array([p[0] for p in pieces])
            upper = np.array([p[1] for p in pieces])
            half, mid = 0.5 * (upper - lower), 0.5 * (upper + lower)
            at_nodes = (mid[:, None] + half[:, None] * _NODES[None, :]).ravel()
            at_checks = (mid[:, None] + half[:, None] * _CHECKS[None, :]).ravel()
            values = self._exact_fields(np.concatenate([at_nodes, at_checks]))
            count = len(pieces)
            nodes_values = values[: at_nodes.size].reshape(count, _DEGREE + 1, -1)
            check_values = values[at_nodes.size :].reshape(count, _CHECKS.size, -1)
            # Chebyshev coefficients of each piece, then powers of its local t.
            cheb = np.einsum("kj,pjc->pkc", _TO_CHEBYSHEV, nodes_values)
            power = np.einsum("ik,pkc->pic", _TO_POWER, cheb)
            model = _horner(power, np.broadcast_to(_CHECKS, (count, _CHECKS.size)))
            errors = self._errors(model - check_values, check_values)
            again = []
            for k, (a, b, depth) in enumerate(pieces):
                position_error, direction_error = errors[0][k], errors[1][k]
                good = position_error <= _POSITION_TOLERANCE_M and direction_error <= (
                    _DIRECTION_TOLERANCE_RAD
                )
                good = good and errors[2][k] <= _VELOCITY_TOLERANCE_M_S
                if good or depth >= _HALVINGS:
                    done.append((a, b, cheb[k] if good else None))
                    if good:
                        self.position_error_m = max(self.position_error_m, position_error)
                        self.direction_error_rad = max(self.direction_error_rad, direction_error)
                else:
                    m = 0.5 * (a + b)
                    again += [(a, m, depth + 1), (m, b, depth + 1)]
            pieces = again
        done.sort(key=lambda item: item[0])
        edges_out = np.array([a for a, _, _ in done] + [done[-1][1]])
        width = 3 * len(self._fields)
        cheb_all = np.zeros((len(done), _DEGREE + 1, width))
        exact = np.zeros(len(done), dtype=bool)
        for k, (_, _, cheb_k) in enumerate(done):
            if cheb_k is None:
                exact[k] = True
            else:
                cheb_all[k] = cheb_k
        # The degree from the fitted pieces alone: a piece left exact has no series (its
        # zeros would read as a position at the Earth's centre).
        degree = self._least_degree(cheb_all[~exact])
        # Powers of t of the truncated series: |T_k| ≤ 1 on [−1, 1], so the dropped
        # coefficients bound what the truncation adds (``_least_degree``).
        to_power = _TO_POWER[: degree + 1, : degree + 1]
        coefficients = np.einsum("ik,pkc->pic", to_power, cheb_all[:, : degree + 1, :])
        return edges_out, coefficients, exact

    def _least_degree(self, cheb: NDArray[np.float64]) -> int:
        """The least degree whose dropped Chebyshev coefficients stay within a tenth of
        the check's tolerances in every piece (a slowly moving sky needs few); what
        they can add is added to the stated errors."""
        columns = {name: slice(3 * k, 3 * k + 3) for k, name in enumerate(self._fields)}
        scale = {"r": _POSITION_TOLERANCE_M, "v": _VELOCITY_TOLERANCE_M_S}
        if "r" in columns:
            r = cheb[:, 0, columns["r"]]
            sun = cheb[:, 0, columns["sun_from_earth"]]
            least_r = float(np.min(np.linalg.norm(r, axis=-1), initial=np.inf))
            least_sun = float(np.min(np.linalg.norm(sun, axis=-1), initial=np.inf))
        for degree in range(1, _DEGREE + 1):
            tail = np.abs(cheb[:, degree + 1 :, :]).sum(axis=1)  # (pieces, components)
            position = direction = velocity = 0.0
            for name, cols in columns.items():
                size = float(np.max(np.linalg.norm(tail[:, cols], axis=-1), initial=0.0))
                if name == "r":
                    position = size
                    direction = max(direction, size / least_r)
                elif name == "v":
                    velocity = size
                elif name == "sun_from_earth":
                    direction = max(direction, size / least_sun)
                else:
                    direction = max(direction, size)
            if (
                position <= 0.1 * scale["r"]
                and velocity <= 0.1 * scale["v"]
                and direction <= 0.1 * _DIRECTION_TOLERANCE_RAD
            ):
                self.position_error_m += position
                self.direction_error_rad += direction
                return degree
        return _DEGREE

    def _errors(self, difference: NDArray[np.float64], exact: NDArray[np.float64]):
        """Per piece: the largest position error (m), direction error (rad; nadir's is
        the position error over the distance) and velocity error (m/s) at the checks."""
        columns = {name: slice(3 * k, 3 * k + 3) for k, name in enumerate(self._fields)}

        def size(name: str) -> NDArray[np.float64]:
            return np.linalg.norm(difference[..., columns[name]], axis=-1)

        directions = np.maximum(size("sun"), size("moon"))
        zero = np.zeros(difference.shape[0])
        if "r" not in columns:
            return zero, np.max(directions, axis=1), zero
        distance = np.linalg.norm(exact[..., columns["r"]], axis=-1)
        sun_distance = np.linalg.norm(exact[..., columns["sun_from_earth"]], axis=-1)
        directions = np.maximum(directions, size("r") / distance)
        directions = np.maximum(directions, size("sun_from_earth") / sun_distance)
        return np.max(size("r"), axis=1), np.max(directions, axis=1), np.max(size("v"), axis=1)

    def _field_slices(self) -> dict[str, slice]:
        return {name: slice(3 * k, 3 * k + 3) for k, name in enumerate(self._fields)}

    def _rate_bounds(self, widths: NDArray[np.float64]) -> dict[str, float]:
        """Bounds over the span on the rates of the targets (module notes of
        :mod:`attitude.pointing.free_search`): ``<field>_1`` ≥ |p'| and ``<field>_2`` ≥
        |p''| of each interpolated field p (a polynomial of t ∈ [−1, 1] on each piece is
        at most the sum of its coefficients' magnitudes there), and the least distance
        ``r_least`` (m) on an orbit, over the fitted pieces (a piece left exact has no
        series; where there is one, every rate bound is infinite)."""
        k = np.arange(self._coefficients.shape[1], dtype=np.float64)
        scale = (2.0 / widths)[:, None]
        first = np.einsum("k,pkc->pc", k, np.abs(self._coefficients)) * scale
        second = np.einsum("k,pkc->pc", k * (k - 1.0), np.abs(self._coefficients)) * scale**2
        bounds: dict[str, float] = {}
        for name, columns in self._slices.items():
            bounds[f"{name}_1"] = float(np.max(norm(first[:, columns]), initial=0.0))
            bounds[f"{name}_2"] = float(np.max(norm(second[:, columns]), initial=0.0))
        if "r" in self._slices:
            # The least |r|: every coefficient but the constant bounds the variation.
            fitted = self._coefficients[~self._exact_pieces]
            constant = fitted[:, 0, self._slices["r"]]
            rest = np.sum(np.abs(fitted[:, 1:, self._slices["r"]]), axis=1)
            bounds["r_least"] = float(np.min(norm(constant) - norm(rest), initial=math.inf))
        if np.any(self._exact_pieces):
            bounds = {name: math.inf for name in bounds} | (
                {"r_least": bounds["r_least"]} if "r_least" in bounds else {}
            )
        return bounds

    # ---------------------------------------------------------------- evaluating

    def covers(self, start_s: float, stop_s: float) -> bool:
        """Whether [start_s, stop_s] lies within the interpolated span."""
        return self.start_s <= start_s and stop_s <= self.stop_s

    def _locate(self, seconds: NDArray[np.float64]):
        index = np.searchsorted(self._edges, seconds, side="right") - 1
        np.clip(index, 0, self._edges.size - 2, out=index)
        lower, upper = self._edges[index], self._edges[index + 1]
        t = (2.0 * seconds - (lower + upper)) / (upper - lower)
        return index, t

    def fields(
        self, seconds: NDArray[np.float64], derivative: bool = False
    ) -> tuple[dict[str, NDArray[np.float64]], dict[str, NDArray[np.float64]] | None]:
        """The interpolated fields at TT ``seconds`` (the names of
        :meth:`~attitude.pointing.surroundings.SunMoonEarth.fields`), and their time
        derivatives with ``derivative`` (else None)."""
        seconds = np.asarray(seconds, dtype=np.float64).ravel()
        index, t = self._locate(seconds)
        values = _horner_at(self._coefficients, index, t)
        rates = _horner_at(self._derivative, index, t) if derivative else None
        exact = self._exact_pieces[index]
        if np.any(exact):
            values[exact] = self._exact_fields(seconds[exact])
            if rates is not None:
                rates[exact] = self._difference_rates(seconds[exact])
        out = {name: values[:, columns] for name, columns in self._slices.items()}
        out_rates = None
        if rates is not None:
            out_rates = {name: rates[:, columns] for name, columns in self._slices.items()}
        return out, out_rates

    def _difference_rates(self, seconds: NDArray[np.float64]) -> NDArray[np.float64]:
        """Rates by central differences (1 ms), where a piece is evaluated exactly; one
        sided at the span's ends (an orbit file may end there)."""
        step = 1e-3
        ahead_s = np.minimum(seconds + step, self.stop_s)
        behind_s = np.maximum(seconds - step, self.start_s)
        ahead = self._exact_fields(ahead_s)
        behind = self._exact_fields(behind_s)
        return (ahead - behind) / (ahead_s - behind_s)[:, None]

    def at(self, seconds: NDArray[np.float64]) -> Surroundings:
        """The surroundings at TT ``seconds``, as :meth:`SunMoonEarth.at` gives them,
        from the interpolated fields (within the bounds of the module notes)."""
        fields, _ = self.fields(seconds)
        fields["sun"] = _unit(fields["sun"])
        fields["moon"] = _unit(fields["moon"])
        return assemble(self.spec, fields)

    def _target_fields(self, seconds: NDArray[np.float64], accelerations: bool = False):
        """The Sun, the Moon and the position (on an orbit), their rates and, with
        ``accelerations``, their second derivatives (else None) at ``seconds``."""
        seconds = np.asarray(seconds, dtype=np.float64).ravel()
        index, t = self._locate(seconds)
        values = _horner_rows(self._target_values, index, t)
        rates = _horner_rows(self._target_rates, index, t)
        accels = _horner_rows(self._target_accels, index, t) if accelerations else None
        exact = self._exact_pieces[index]
        if np.any(exact):
            fields, field_rates = self.fields(seconds[exact], derivative=True)
            assert field_rates is not None
            values[exact] = np.concatenate([fields[n] for n in self._target_names], axis=1)
            rates[exact] = np.concatenate([field_rates[n] for n in self._target_names], axis=1)
            if accels is not None:
                accels[exact] = 0.0  # exact pieces: not used for bounds (rate_bounds is inf)

        def split(x):
            return {n: x[:, 3 * k : 3 * k + 3] for k, n in enumerate(self._target_names)}

        return split(values), split(rates), None if accels is None else split(accels)

    def exact(self, seconds: NDArray[np.float64]) -> Surroundings:
        """The exact surroundings at TT ``seconds`` (no interpolation: what
        :func:`attitude.pointing.sampling.pointing_samples` computes there, on the same
        ephemeris nodes), for values that must be a sample's."""
        return self._exact.at(np.asarray(seconds, dtype=np.float64))

    def targets(self, seconds: NDArray[np.float64], accelerations: bool = False) -> Targets:
        """The search's :class:`Targets` at TT ``seconds``: unit directions and their
        rates, nadir from the position, the limb's angular radius and its rate; with
        ``accelerations``, the directions' second derivatives too."""
        fields, rates, accels = self._target_fields(seconds, accelerations)
        # The Sun's and the Moon's interpolated directions are unit vectors within
        # the stated bound: used as they are.
        sun, sun_rate = fields["sun"], rates["sun"]
        moon, moon_rate = fields["moon"], rates["moon"]
        extra = {}
        if accels is not None:
            extra = {"sun_accel": accels["sun"], "moon_accel": accels["moon"]}
        if "r" not in fields:
            return Targets(sun, sun_rate, moon, moon_rate, **extra)
        r, r_rate = fields["r"], rates["r"]
        up, up_rate = _unit_and_rate(r, r_rate)
        if accels is not None:
            # ü = (r̈ − 2 ρ̇ u̇ − ρ̈ u)/ρ for u = r/ρ, ρ = |r|: ρ̇ = u·ṙ, ρ̈ = (|ṙ|² +
            # r·r̈)/ρ − ρ̇²/ρ.
            distance = norm(r)
            r_accel = accels["r"]
            ρ_rate = np.einsum("ij,ij->i", up, r_rate)
            ρ_accel = (
                np.einsum("ij,ij->i", r_rate, r_rate) + np.einsum("ij,ij->i", r, r_accel)
            ) / distance
            ρ_accel -= ρ_rate * ρ_rate / distance
            up_accel = (
                r_accel - 2.0 * ρ_rate[:, None] * up_rate - ρ_accel[:, None] * up
            ) / distance[:, None]
            extra["nadir_accel"] = -up_accel
        distance = norm(r)
        radius = EARTH_EQUATORIAL_RADIUS_M + self.limb_height_m
        ratio = np.minimum(1.0, radius / distance)
        limb = np.arcsin(ratio)
        # dρ/dt = −tan ρ · (r̂·ṙ)/|r|; 0 inside the sphere (ρ held at π/2).
        radial = np.einsum("ij,ij->i", up, r_rate)
        with np.errstate(divide="ignore", invalid="ignore"):
            limb_rate = np.where(ratio < 1.0, -np.tan(limb) * radial / distance, 0.0)
        return Targets(sun, sun_rate, moon, moon_rate, -up, -up_rate, limb, limb_rate, **extra)

    def rate_bounds(self) -> dict[str, float]:
        """Bounds over the span on |ṡ| (``<target>_1``) and |s̈| (``<target>_2``) of each
        target direction (``sun``, ``moon`` and on an orbit ``nadir``), and on the
        limb's |ρ̇| and |ρ̈| (``limb_1``, ``limb_2``), per second: from the bounds of the
        polynomials (:meth:`_rate_bounds`), through the normalization.  Infinite where
        a piece is evaluated exactly."""
        b = self._rates
        out: dict[str, float] = {}
        for name in ("sun", "moon"):
            # s = p/|p| with |p| within 1e-9 of 1: |ṡ| ≤ |ṗ|/|p|, |s̈| ≤ (|p̈| + 3|ṗ|²)/|p|.
            p1, p2 = b[f"{name}_1"], b[f"{name}_2"]
            out[f"{name}_1"] = p1 * (1.0 + 1e-8)
            out[f"{name}_2"] = (p2 + 3.0 * p1 * p1) * (1.0 + 1e-8)
        if "r_1" in b:
            # n = −r/|r|: |ṅ| ≤ |ṙ|/|r|, |n̈| ≤ 2|r̈|/|r| + 5|ṙ|²/|r|² (the notes of
            # attitude.pointing.free_search derive both).
            least = b["r_least"]
            r1, r2 = b["r_1"], b["r_2"]
            if not (0.0 < least < math.inf and math.isfinite(r1)):
                # A piece left exact (or none fitted): nothing of the orbit is bounded.
                out.update(
                    dict.fromkeys(
                        ("nadir_1", "nadir_2", "fraction_1", "limb_1", "limb_2"), math.inf
                    )
                )
                return out
            out["nadir_1"] = r1 / least
            out["nadir_2"] = 2.0 * r2 / least + 5.0 * (r1 / least) ** 2
            # The lit fraction changes at most at (2/π a) per radian of the discs'
            # relative motion (a: the Sun's least angular radius near the Earth), the
            # discs moving at most at nadir's rate plus the Sun's.
            out["fraction_1"] = (
                2.0 * (out["nadir_1"] + out["sun_1"]) / (math.pi * _SUN_LEAST_RADIUS_RAD)
            )
            radius = EARTH_EQUATORIAL_RADIUS_M + self.limb_height_m
            if least > radius:
                tan = radius / math.sqrt(least * least - radius * radius)
                out["limb_1"] = tan * r1 / least
                out["limb_2"] = tan * ((tan * tan + 3.0) * (r1 / least) ** 2 + r2 / least)
            else:
                out["limb_1"] = out["limb_2"] = math.inf
        return out


def _horner(power: NDArray[np.float64], t: NDArray[np.float64]) -> NDArray[np.float64]:
    """Each piece's polynomial (pieces, degree + 1, components) at its own points t
    (pieces, m): (pieces, m, components)."""
    value = np.broadcast_to(power[:, -1:, :], (power.shape[0], t.shape[1], power.shape[2])).copy()
    for k in range(power.shape[1] - 2, -1, -1):
        value *= t[:, :, None]
        value += power[:, k : k + 1, :]
    return value


def _horner_at(
    power: NDArray[np.float64], index: NDArray[np.intp], t: NDArray[np.float64]
) -> NDArray[np.float64]:
    """The polynomials of pieces ``index`` at their local ``t`` (n,): (n, components),
    gathering one coefficient of every point's piece at a time."""
    degree = power.shape[1] - 1
    value = power[index, degree, :]
    tt = t[:, None]
    for k in range(degree - 1, -1, -1):
        value *= tt
        value += power[index, k, :]
    return value


def _horner_rows(rows: NDArray[np.float64], index: NDArray[np.intp], t: NDArray[np.float64]):
    """Polynomials stored degree first, (degree + 1, pieces, components), of pieces
    ``index`` at their local ``t``: (n, components)."""
    degree = rows.shape[0] - 1
    value = rows[degree].take(index, axis=0)
    tt = t[:, None]
    for k in range(degree - 1, -1, -1):
        value *= tt
        value += rows[k].take(index, axis=0)
    return value


def _unit(p: NDArray[np.float64]) -> NDArray[np.float64]:
    return p / norm(p)[:, None]


def _unit_and_rate(p: NDArray[np.float64], rate: NDArray[np.float64]):
    """p/|p| and its time derivative (ṗ − (u·ṗ)u)/|p|."""
    size = norm(p)
    u = p / size[:, None]
    along = np.einsum("ij,ij->i", u, rate)
    return u, (rate - along[:, None] * u) / size[:, None]


# ------------------------------------------------------------------------ the cache

_CACHE: OrderedDict[tuple, SharedSurroundings] = OrderedDict()
_CACHE_LOCK = threading.Lock()


def _as_orbit(orbit: Orbit | tuple[str, str] | None) -> Orbit | None:
    """A spec's orbit (a PointingSpec makes an Orbit of two TLE lines when it is built)."""
    assert orbit is None or isinstance(orbit, Orbit)
    return orbit


def _orbit_key(orbit: Orbit | None) -> str:
    """The orbit's content, as a digest: two orbits read from the same lines or file
    share it (a Monte Carlo sample's, read again from its document)."""
    if orbit is None:
        return "earth centre"
    try:
        return hashlib.sha256(pickle.dumps(orbit, protocol=4)).hexdigest()
    except Exception:  # an orbit that cannot be pickled is its own key
        return f"object {id(orbit)}"


def shared_surroundings(
    trajectory: Trajectory,
    spec: PointingSpec,
    start_s: float | None = None,
    stop_s: float | None = None,
) -> SharedSurroundings:
    """The :class:`SharedSurroundings` of ``spec``'s orbit (or the scenario's) over
    [start_s, stop_s] (the output span by default), from the process-wide cache when one
    built before covers that span for the same epoch, orbit and limb height (module
    notes); built, and cached, otherwise."""
    scenario = trajectory.scenario
    spec = for_scenario(spec, scenario)
    start_s = scenario.start_s if start_s is None else float(start_s)
    stop_s = scenario.stop_s if stop_s is None else float(stop_s)
    jd = scenario_jd(trajectory)
    orbit = _as_orbit(spec.orbit)
    key = (jd, _orbit_key(orbit), float(spec.earth_limb_atmosphere_height_m))
    with _CACHE_LOCK:
        found = _CACHE.get(key)
        if found is not None and found.covers(start_s, stop_s):
            _CACHE.move_to_end(key)
            return found
    built = SharedSurroundings(jd, orbit, spec.earth_limb_atmosphere_height_m, start_s, stop_s)
    with _CACHE_LOCK:
        _CACHE[key] = built
        _CACHE.move_to_end(key)
        while len(_CACHE) > CACHE_SIZE:
            _CACHE.popitem(last=False)
    return built


def exact_surroundings(
    trajectory: Trajectory, spec: PointingSpec, start_s: float, stop_s: float
) -> SunMoonEarth:
    """The exact surroundings of ``spec`` (resolved for the scenario) over [start_s,
    stop_s]: those a cached :class:`SharedSurroundings` covering the span holds (its
    ephemeris sampled once: the same values, the nodes being aligned on J2000), else
    new ones (nothing is built for the cache)."""
    jd = scenario_jd(trajectory)
    key = (jd, _orbit_key(_as_orbit(spec.orbit)), float(spec.earth_limb_atmosphere_height_m))
    with _CACHE_LOCK:
        found = _CACHE.get(key)
    if found is not None and found.covers(start_s, stop_s):
        return found._exact
    return SunMoonEarth(trajectory, spec, start_s, stop_s)


def clear_cache() -> None:
    """Forget every :class:`SharedSurroundings` the cache holds."""
    with _CACHE_LOCK:
        _CACHE.clear()
