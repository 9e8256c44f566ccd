"""A scenario: spacecraft, initial state at an epoch, events, and the output span.

Time rules (what a user can rely on):

- ``epoch`` is an ``astropy.time.Time`` in any scale; it is the time of the initial
  state, and the scale the outputs are written in.  Internally every epoch is
  reduced to TT seconds since ``epoch`` from two-part Julian dates (never one float).
- The propagation covers [epoch, stop].  Outputs are sampled on [start, stop] every
  ``step`` seconds (``start`` defaults to ``epoch``, and ``stop`` is always included).
- Events are applied in time order; the list may be given in any order (it is
  sorted, stably).  Events at the same epoch are applied in the order given.
- An event before ``epoch`` or after ``stop`` is an error (it would not change
  anything the scenario outputs, and is almost certainly a mistake).  An event at
  ``stop`` exactly is applied: the output at ``stop`` is the post-event state.
- At an event's epoch every output is the **post-event** state.
- An event's ``epoch`` is a ``Time`` (or ISO string in the epoch's scale), or a
  number of TT seconds after the scenario epoch (a float or a time ``Quantity``),
  taken exactly as given.
- Every epoch of the span lies in the years 0001–9999 of the epoch's scale (the
  years that ISO 8601 and the CCSDS files write with four digits).
- The output grid must be representable: a step that TT seconds resolve at the end
  of the span (see :meth:`Scenario.output_count`).

The orbit is given once, to the scenario (``orbit``): the gravity gradient of its
torques (``ScenarioTorques(gravity_gradient=True)``) and the pointing (a
``PointingSpec`` without an orbit) both use it.  An orbit given to the torques or to the
pointing as well is accepted when it is the same path (:func:`orbit_disagreement`), and
refused, with both named, when it is not.
"""

from __future__ import annotations

import copy
import dataclasses
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.base.quantities import as_si_scalar, as_vector3
from attitude.environment.orbit import Orbit, TleOrbit
from attitude.environment.timescales import (
    SAME_INSTANT_S,
    as_time,
    check_year_range,
    iso_texts,
    offline_time,
    time_from_tt_seconds,
    tt_seconds,
)
from attitude.scenario.events import Event
from attitude.scenario.spacecraft import Spacecraft
from attitude.scenario.torques import PlacedBurn, ScenarioTorques
from attitude.torques.solver import MAX_STEPS

if TYPE_CHECKING:  # astropy loads only when a Time is made
    from astropy.time import Time

__all__ = ["ORBIT_AGREEMENT_M", "InitialState", "Scenario", "orbit_disagreement"]

# Ten thousand Julian years: no span of years 0001–9999 is longer.
_LONGEST_SPAN_S = 1e4 * 365.25 * 86400.0
# Two orbits given for one scenario are the same path when their positions agree to
# this (m) at its start, middle and end: the same elements or file give the same bits.
ORBIT_AGREEMENT_M = 1.0


@dataclass(frozen=True)
class InitialState:
    """Attitude (body → inertial) and rate at the scenario epoch, or the law the body
    starts under.

    Give exactly one of ``angular_velocity`` (rad/s) and ``angular_momentum``
    (N m s), body axes.  See :meth:`from_quaternion` and :meth:`from_matrix` for
    the other ways of giving the attitude.  Or give ``law`` alone (an attitude law of
    :mod:`attitude.laws`, e.g. ``InitialState(law=NadirLaw("zero_doppler"))``): the
    attitude and the rate are then the law's (``attitude.scenario.modes``).
    """

    attitude: Rotation | None = None
    angular_velocity: NDArray[np.float64] | None = None
    angular_momentum: NDArray[np.float64] | None = None
    law: Any = None

    def __post_init__(self) -> None:
        if self.law is not None:
            from attitude.laws.align_constrain import AttitudeLaw

            if not isinstance(self.law, AttitudeLaw):
                raise InputError(
                    f"initial_state.law must be an attitude law (attitude.laws), got {self.law!r}"
                )
            given = [
                name
                for name in ("attitude", "angular_velocity", "angular_momentum")
                if getattr(self, name) is not None
            ]
            if given:
                raise InputError(
                    f"initial_state: give a law, or an attitude and a rate, not both (got law "
                    f"and {given[0]})"
                )
            return
        if not (isinstance(self.attitude, Rotation) and self.attitude.single):
            raise InputError(
                f"initial_state.attitude must be a single scipy Rotation, got {self.attitude!r}"
            )
        if (self.angular_velocity is None) == (self.angular_momentum is None):
            raise InputError(
                "initial_state: give exactly one of angular_velocity and angular_momentum"
            )
        for name in ("angular_velocity", "angular_momentum"):  # each is also its unit kind
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, as_vector3(value, name, f"initial_state.{name}"))

    @classmethod
    def from_quaternion(cls, quaternion_scalar_first: Any, **rate: Any) -> InitialState:
        """Attitude from a unit quaternion (w, x, y, z), body → inertial."""
        q = np.asarray(quaternion_scalar_first, dtype=float)
        if q.shape != (4,) or not np.all(np.isfinite(q)):
            raise InputError(f"initial_state.quaternion must be 4 finite numbers, got {q.tolist()}")
        norm = np.linalg.norm(q)
        if abs(norm - 1.0) > 1e-6:
            raise InputError(f"initial_state.quaternion must have unit norm, got |q| = {norm:.9g}")
        return cls(Rotation.from_quat(q, scalar_first=True), **rate)

    @classmethod
    def from_matrix(cls, matrix: Any, **rate: Any) -> InitialState:
        """Attitude from a direction cosine matrix taking body to inertial coordinates."""
        a = np.asarray(matrix, dtype=float)
        if a.shape != (3, 3) or not np.all(np.isfinite(a)):
            raise InputError(f"initial_state.matrix must be a finite 3x3 matrix, got {a.tolist()}")
        orthogonality = np.max(np.abs(a @ a.T - np.eye(3)))
        if orthogonality > 1e-6 or np.linalg.det(a) < 0:
            raise InputError(
                f"initial_state.matrix must be a rotation (orthonormal, det +1), got {a.tolist()}"
            )
        return cls(Rotation.from_matrix(a), **rate)


def _epoch_key(epoch: Any) -> str:
    """The key an event's or a burn's time was given as: ``epoch`` (a date) or ``offset``
    (seconds after the scenario epoch)."""
    return "epoch" if isinstance(epoch, str) or hasattr(epoch, "jd1") else "offset"


class Scenario:
    """Everything needed to propagate: spacecraft, epoch, initial state, events, span.

    Parameters
    ----------
    name
        Title of the scenario.
    spacecraft
        The :class:`Spacecraft` (its inertia at the epoch).
    epoch
        ``astropy.time.Time`` (or ISO 8601 string in UTC) of the initial state.
    initial_state
        :class:`InitialState`.
    events
        Events (``attitude.scenario.events``), in any order.
    stop, duration
        End of the propagation: a ``Time`` (or ISO string in the epoch's scale), or
        a duration in seconds from the epoch.  Exactly one.
    start
        First output epoch (default: the epoch).
    step
        Output step, seconds (default: the output span / 1000).
    torques
        :class:`~attitude.scenario.torques.ScenarioTorques`: gravity gradient, burns,
        and the splitting's step and order (default: none, the exact torque-free
        motion).  ``gravity_gradient=True`` acts on ``orbit``.
    orbit
        Where the spacecraft is: an :class:`attitude.environment.orbit.Orbit`
        (``TleOrbit``, ``KeplerianOrbit``, ``OemOrbit``) or the two lines of a TLE; the
        gravity gradient and the pointing use it (module notes).  None: no orbit.
    """

    def __init__(
        self,
        name: str,
        spacecraft: Spacecraft,
        epoch: Any,
        initial_state: InitialState,
        events: list[Event] | tuple[Event, ...] = (),
        *,
        stop: Any = None,
        duration: Any = None,
        start: Any = None,
        step: Any = None,
        torques: ScenarioTorques | None = None,
        orbit: Orbit | tuple[str, str] | list[str] | None = None,
    ) -> None:
        self.name = str(name)
        if not isinstance(spacecraft, Spacecraft):
            raise InputError(f"spacecraft must be a Spacecraft, got {spacecraft!r}")
        if not isinstance(initial_state, InitialState):
            raise InputError(f"initial_state must be an InitialState, got {initial_state!r}")
        self.spacecraft = spacecraft
        self.initial_state = initial_state
        self._set_epoch(epoch)
        self._set_span(stop, duration)
        self._set_output_grid(start, step)
        self._place_events(events)
        self._set_orbit(orbit)
        self._place_torques(torques)

    def _set_orbit(self, orbit: Any) -> None:
        """``orbit``: an Orbit, the two lines of a TLE, or None."""
        if isinstance(orbit, tuple | list):
            if len(orbit) != 2 or not all(isinstance(line, str) for line in orbit):
                raise InputError(f"orbit: expected the two lines of a TLE, got {orbit!r}")
            orbit = TleOrbit(*orbit)
        if orbit is not None and not isinstance(orbit, Orbit):
            raise InputError(
                "orbit: must be an Orbit (TleOrbit, KeplerianOrbit, OemOrbit) or the two "
                f"lines of a TLE, got {orbit!r}"
            )
        self.orbit: Orbit | None = orbit

    def _set_epoch(self, epoch: Any) -> None:
        self.epoch = as_time(epoch, name="epoch")
        if not self.epoch.isscalar:
            raise InputError(
                f"must be a single epoch, got {len(self.epoch)} of them", key="epoch", value=epoch
            )
        check_year_range(self.epoch, "epoch")

    def _set_span(self, stop: Any, duration: Any) -> None:
        """The end of the propagation, ``stop_s``: within 10,000 years and years 1–9999."""
        if (stop is None) == (duration is None):
            raise InputError("give exactly one of stop and duration")
        # The scenario file's key for the end of the span, which errors about the span's
        # length name (the ephemeris, the pointing's search, a step too fine for it).
        self.end_key = "output.duration" if duration is not None else "output.stop"
        if duration is not None:
            self.stop_s = as_si_scalar(duration, "time", "duration")
        else:
            self.stop_s = float(tt_seconds(as_time(stop, self.time_scale, name="stop"), self.epoch))
        # The span's errors name its end, ``stop`` (given as a stop or as a duration).
        if not self.stop_s > 0.0:
            raise InputError(
                f"the span must end after the epoch, got {self.stop_s:g} s",
                key="stop",
                value=self.stop_s,
            )
        if self.stop_s > _LONGEST_SPAN_S:
            raise InputError(
                f"the span must be shorter than 10,000 years, got {self.stop_s:g} s",
                key="stop",
                value=self.stop_s,
            )
        with offline_time():
            end = time_from_tt_seconds(self.epoch, self.stop_s)
            check_year_range(getattr(end, self.time_scale), "stop")

    def _set_output_grid(self, start: Any, step: Any) -> None:
        """The output grid's ``start_s`` and ``step_s``: a grid that TT seconds resolve."""
        if start is None:
            self.start_s = 0.0
        else:
            self.start_s = float(tt_seconds(as_time(start, self.time_scale, "start"), self.epoch))
        if not 0.0 <= self.start_s < self.stop_s:
            raise InputError(
                f"must lie in [epoch, stop), got {self.start_s:g} s after the epoch "
                f"(stop at {self.stop_s:g} s)",
                key="start",
                value=start,
            )
        span = self.stop_s - self.start_s
        self.step_s = span / 1000.0 if step is None else as_si_scalar(step, "time", "step")
        if not self.step_s > 0.0:
            raise InputError(
                f"must be positive, got {self.step_s:g} s", key="step", value=self.step_s
            )
        resolution = float(np.spacing(self.stop_s))
        if self.step_s < 4.0 * resolution:
            raise InputError(
                f"{self.step_s:g} s is below what TT seconds resolve at the end of the "
                f"span ({self.stop_s:g} s, resolution {resolution:.3g} s): the output grid "
                "would repeat epochs",
                key="step",
                value=self.step_s,
            )

    def _place_events(self, events: list[Event] | tuple[Event, ...]) -> None:
        """``events`` as (offset, event) in time order, stably; each within [0, stop]."""
        timed = []
        for index, event in enumerate(events):
            key = f"events[{index}].{_epoch_key(event.epoch)}"
            offset = self._offset_in_span(event.epoch, key)
            # Formatted only for an error: a Monte Carlo sample places its events
            # thousands of times.
            if offset < 0.0:
                what = f"the {event.kind} at {self.format_epoch(offset)}"
                raise InputError(
                    f"{what} is before the scenario epoch {self.format_epoch(0.0)}",
                    key=key,
                    value=event.epoch,
                )
            if offset > self.stop_s:
                what = f"the {event.kind} at {self.format_epoch(offset)}"
                end = self.format_epoch(self.stop_s)
                raise InputError(
                    f"{what} is after the end of the propagation span {end}",
                    key=key,
                    value=event.epoch,
                )
            timed.append((offset, index, event))
        timed.sort(key=lambda item: (item[0], item[1]))
        self.events: list[tuple[float, Event]] = [(offset, event) for offset, _, event in timed]
        # The place of each event (in time order) in the list given: events[i].
        self.event_indices: list[int] = [index for _, index, _ in timed]

    def _place_torques(self, torques: ScenarioTorques | None) -> None:
        """``torques`` (none: torque-free) and its burns on the time line, ``burns``.

        A burn starts within [epoch, stop) and may run past the end of the span; a
        step that would take more than ``MAX_STEPS`` over the span is refused.
        """
        if torques is None:
            torques = ScenarioTorques()
        if not isinstance(torques, ScenarioTorques):
            raise InputError(f"torques must be a ScenarioTorques, got {torques!r}")
        torques = self._gravity_gradient_on_the_orbit(torques)
        self.torques = torques
        self.burns: list[PlacedBurn] = []
        for index, burn in enumerate(torques.burns):
            where = f"torques.burns[{index}]"
            key = f"{where}.{_epoch_key(burn.epoch)}"
            start_s = self._offset_in_span(burn.epoch, key)
            if not 0.0 <= start_s < self.stop_s:
                raise InputError(
                    f"the burn starts at {self.format_epoch(start_s)}, outside "
                    f"the span [{self.format_epoch(0.0)}, {self.format_epoch(self.stop_s)})",
                    key=key,
                    value=burn.epoch,
                )
            # The momentum it adds, and the kinetic energy (~ H²/2I), must be floats.
            impulse = math.hypot(*burn.torque) * min(burn.duration, self.stop_s - start_s)
            if not math.isfinite(impulse * impulse):
                raise InputError(
                    f"{burn.torque.tolist()} N m over the span is an angular "
                    f"impulse of {impulse:.3g} N m s, beyond what floats hold (its square)",
                    key=f"{where}.torque",
                    value=burn.torque.tolist(),
                )
            self.burns.append(PlacedBurn(start_s, start_s + burn.duration, burn, index))
        if torques.step is not None and torques.step > self.stop_s:
            raise InputError(
                f"{torques.step:g} s is longer than the span ({self.stop_s:g} s)",
                key="torques.step",
                value=torques.step,
            )
        if torques.step is not None and self.stop_s / torques.step > MAX_STEPS:
            raise InputError(
                f"{torques.step:g} s is {self.stop_s / torques.step:.3g} steps "
                f"over the span of {self.stop_s:g} s, more than {MAX_STEPS:g}: give a larger "
                "step, an accuracy, or a shorter span",
                key="torques.step",
                value=torques.step,
            )

    def _gravity_gradient_on_the_orbit(self, torques: ScenarioTorques) -> ScenarioTorques:
        """``torques`` with ``gravity_gradient=True`` placed on the scenario's orbit; an
        orbit of their own accepted if it agrees with the scenario's."""
        source = torques.gravity_gradient
        if source is True:
            if self.orbit is None:
                raise InputError(
                    "True acts on the scenario's orbit, and it has none: give "
                    "Scenario(..., orbit=...)",
                    key="torques.gravity_gradient",
                    value=True,
                )
            return dataclasses.replace(torques, gravity_gradient=self.orbit)
        if source is not None and self.orbit is not None:
            disagreement = orbit_disagreement(self.orbit, source, self)
            if disagreement:
                raise InputError(
                    f"its orbit is not the scenario's: "
                    f"{disagreement}; give the orbit once, Scenario(..., orbit=...), and "
                    "gravity_gradient=True",
                    key="torques.gravity_gradient",
                )
        return torques

    def with_torques(self, torques: ScenarioTorques | None) -> Scenario:
        """The same scenario propagated under ``torques`` (e.g. to measure what a
        torque-free run neglects)."""
        other = copy.copy(self)
        other._place_torques(torques)
        return other

    def _offset_in_span(self, epoch: Any, name: str) -> float:
        """An epoch's TT seconds after the scenario epoch, snapped to 0 or to stop when
        within a nanosecond of either (the rounding of a UTC → TT conversion)."""
        offset = self._event_offset(epoch, name)
        if abs(offset) <= SAME_INSTANT_S:
            return 0.0
        if abs(offset - self.stop_s) <= SAME_INSTANT_S:
            return self.stop_s
        return offset

    def _event_offset(self, epoch: Any, name: str) -> float:
        """TT seconds after the epoch of an event's epoch (Time, ISO text or seconds)."""
        from astropy.time import Time

        if isinstance(epoch, Time | str):
            return float(tt_seconds(as_time(epoch, self.epoch.scale, name), self.epoch))
        if isinstance(epoch, bool):
            raise InputError(f"{name} must be a Time or seconds after the epoch, got {epoch!r}")
        return as_si_scalar(epoch, "time", name)

    @property
    def time_scale(self) -> str:
        """The astropy scale of the epoch, used for every epoch written out."""
        return self.epoch.scale

    def times(self, seconds: Any) -> Time:
        """``Time`` (in the scenario's scale) of TT ``seconds`` after the epoch."""
        t = time_from_tt_seconds(self.epoch, seconds)
        with offline_time():
            t = getattr(t, self.time_scale)
        t.precision = 9  # ISO texts to the nanosecond, like the epochs read in
        return t

    def format_epoch(self, seconds: float) -> str:
        """ISO 8601 text of the epoch ``seconds`` after the scenario epoch, with its scale;
        for an instant no calendar date names (an offset of 1e30 s, which a refusal
        says), the offset itself."""
        try:
            return f"{self.iso(seconds)} {self.time_scale.upper()}"
        except (ValueError, OverflowError):  # ERFA's "unacceptable date" is a ValueError
            return f"{float(seconds):.6g} s after the epoch (beyond any calendar date)"

    def iso(self, seconds: Any) -> Any:
        """ISO 8601 texts (in the scenario's scale) of TT ``seconds`` after the epoch."""
        return iso_texts(self.times(seconds))

    def _regular_count(self) -> int:
        """The epochs start + step × k of the output grid that do not pass stop (a step
        that reaches stop within 1e-12 of the span counts as reaching it)."""
        steps = (self.stop_s - self.start_s) / self.step_s * (1 + 1e-12)
        return int(steps) + 1  # steps is finite and ≥ 0: step is checked above

    def output_count(self) -> int:
        """The number of output epochs (start, start + step, ..., and stop), without
        building the grid: a span of 1e9 s every 1e-3 s is 1e12 epochs."""
        count = self._regular_count()
        last = self.start_s + self.step_s * (count - 1)
        # stop itself ends the grid when the last regular epoch falls short of it.
        return count + (1 if self.stop_s - last > 1e-9 * self.step_s else 0)

    def output_seconds(self, first: int = 0, stop: int | None = None) -> NDArray[np.float64]:
        """The output grid, TT s since the epoch: start, start + step, ..., and stop
        itself last when the step does not reach it.  ``first``, ``stop``: only the
        epochs ``first`` … ``stop`` − 1, without building the rest (a run streams its
        outputs a chunk at a time)."""
        regular = self._regular_count()
        count = self.output_count()
        stop = count if stop is None else min(stop, count)
        k = np.arange(first, min(stop, regular), dtype=np.float64)
        seconds = self.start_s + self.step_s * k
        if stop > regular:
            seconds = np.append(seconds, self.stop_s)
        return seconds

    def __repr__(self) -> str:
        return (
            f"Scenario({self.name!r}, {self.spacecraft.name!r}, epoch {self.format_epoch(0.0)}, "
            f"{len(self.events)} events, {self.stop_s:g} s)"
        )


def _positions(source: Any, scenario: Scenario, seconds: NDArray[np.float64]) -> NDArray:
    """The GCRS positions (m) of an orbit source at TT ``seconds`` since the scenario
    epoch: an Orbit (two-part TT dates), a callable of those seconds, or an object with
    ``position_velocity``/``position`` taking ``Time``."""
    if isinstance(source, Orbit):
        with offline_time():
            tt = scenario.epoch.tt
        jd1 = np.full(seconds.shape, float(tt.jd1))
        return source.state_tt(jd1, float(tt.jd2) + seconds / 86400.0)[0]
    if callable(source):
        return np.asarray(source(seconds), dtype=np.float64).reshape(seconds.size, 3)
    times = scenario.times(seconds)
    if hasattr(source, "position_velocity"):
        return np.asarray(source.position_velocity(times)[0], dtype=np.float64)
    return np.asarray(source.position(times), dtype=np.float64)


def orbit_disagreement(orbit: Any, other: Any, scenario: Scenario) -> str | None:
    """None if ``other`` (an orbit given to the torques or the pointing beside the
    scenario's) is the scenario's ``orbit``: the same object, or positions within
    :data:`ORBIT_AGREEMENT_M` at the start, middle and end of the span; else what
    differs, in words."""
    if other is orbit:
        return None
    seconds = np.array([0.0, 0.5 * scenario.stop_s, scenario.stop_s])
    mine, theirs = _positions(orbit, scenario, seconds), _positions(other, scenario, seconds)
    gaps = np.linalg.norm(np.asarray(theirs) - np.asarray(mine), axis=-1)
    worst = int(np.argmax(gaps))
    if gaps[worst] <= ORBIT_AGREEMENT_M:
        return None
    return (
        f"{getattr(other, 'describe', lambda: repr(other))()} is {gaps[worst] / 1e3:.6g} km "
        f"from the scenario's {orbit.describe()} at {scenario.format_epoch(seconds[worst])}"
    )
