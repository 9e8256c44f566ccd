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
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from attitude.errors import InputError
from attitude.events import Event
from attitude.quantities import as_si_scalar, as_vector3
from attitude.spacecraft import Spacecraft
from attitude.timescales import SAME_INSTANT_S, as_time, time_from_tt_seconds, tt_seconds

__all__ = ["InitialState", "Scenario"]


@dataclass(frozen=True)
class InitialState:
    """Attitude (body → inertial) and rate at the scenario epoch.

    Give exactly one of ``angular_velocity`` (rad/s) and ``angular_momentum``
    (N m s), body axes.  See :meth:`from_quaternion` and :meth:`from_matrix` for
    the other ways of giving the attitude.
    """

    attitude: Rotation
    angular_velocity: NDArray[np.float64] | None = None
    angular_momentum: NDArray[np.float64] | None = None

    def __post_init__(self) -> None:
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
        Events (``attitude.events``), in any order.
    stop, duration
        End of the propagation: a ``Time`` (or ISO string in the epoch's scale), or
        a duration in seconds from the epoch.  Exactly one.
    start
        First output epoch (default: the epoch).
    step
        Output step, seconds (default: the output span / 1000).
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
    ) -> None:
        self.name = str(name)
        if not isinstance(spacecraft, Spacecraft):
            raise InputError(f"spacecraft must be a Spacecraft, got {spacecraft!r}")
        if not isinstance(initial_state, InitialState):
            raise InputError(f"initial_state must be an InitialState, got {initial_state!r}")
        self.spacecraft = spacecraft
        self.initial_state = initial_state
        self.epoch = as_time(epoch, name="epoch")
        if not self.epoch.isscalar:
            raise InputError(f"epoch must be a single epoch, got {len(self.epoch)} of them")
        scale = self.epoch.scale

        if (stop is None) == (duration is None):
            raise InputError("give exactly one of stop and duration")
        if duration is not None:
            self.stop_s = as_si_scalar(duration, "time", "duration")
        else:
            self.stop_s = float(tt_seconds(as_time(stop, scale, name="stop"), self.epoch))
        if not self.stop_s > 0.0:
            raise InputError(f"the span must end after the epoch, got {self.stop_s:g} s")
        self.start_s = (
            0.0 if start is None else float(tt_seconds(as_time(start, scale, "start"), self.epoch))
        )
        if not 0.0 <= self.start_s < self.stop_s:
            raise InputError(
                f"start must lie in [epoch, stop), got {self.start_s:g} s after the epoch "
                f"(stop at {self.stop_s:g} s)"
            )
        span = self.stop_s - self.start_s
        self.step_s = span / 1000.0 if step is None else as_si_scalar(step, "time", "step")
        if not self.step_s > 0.0:
            raise InputError(f"step must be positive, got {self.step_s:g} s")

        timed = []
        for index, event in enumerate(events):
            offset = float(
                tt_seconds(as_time(event.epoch, scale, f"events[{index}].epoch"), self.epoch)
            )
            if abs(offset) <= SAME_INSTANT_S:
                offset = 0.0
            elif abs(offset - self.stop_s) <= SAME_INSTANT_S:
                offset = self.stop_s
            where = f"events[{index}] ({event.kind} at {self.format_epoch(offset)})"
            if offset < 0.0:
                raise InputError(f"{where} is before the scenario epoch {self.format_epoch(0.0)}")
            if offset > self.stop_s:
                end = self.format_epoch(self.stop_s)
                raise InputError(f"{where} is after the end of the propagation span {end}")
            timed.append((offset, index, event))
        timed.sort(key=lambda item: (item[0], item[1]))
        self.events: list[tuple[float, Event]] = [(offset, event) for offset, _, event in timed]

    @property
    def time_scale(self) -> str:
        """The astropy scale of the epoch, used for every epoch written out."""
        return self.epoch.scale

    def times(self, seconds: Any):
        """``Time`` (in the scenario's scale) of TT ``seconds`` after the epoch."""
        from attitude.timescales import offline_time

        t = time_from_tt_seconds(self.epoch, seconds)
        with offline_time():
            t = getattr(t, self.time_scale)
        t.precision = 9  # ISO texts to the nanosecond, like the epochs read in
        return t

    def format_epoch(self, seconds: float) -> str:
        """ISO 8601 text of the epoch ``seconds`` after the scenario epoch, with its scale."""
        return f"{self.iso(seconds)} {self.time_scale.upper()}"

    def iso(self, seconds: Any) -> Any:
        """ISO 8601 texts (in the scenario's scale) of TT ``seconds`` after the epoch."""
        from attitude.timescales import offline_time

        with offline_time():  # formatting a UTC epoch runs ERFA's leap-second code
            return self.times(seconds).isot

    def output_seconds(self) -> NDArray[np.float64]:
        """The output grid: start, start + step, ..., and stop (TT s since the epoch)."""
        count = int(np.floor((self.stop_s - self.start_s) / self.step_s * (1 + 1e-12))) + 1
        grid = self.start_s + self.step_s * np.arange(count)
        if self.stop_s - grid[-1] > 1e-9 * self.step_s:
            grid = np.append(grid, self.stop_s)
        return grid

    def __repr__(self) -> str:
        return (
            f"Scenario({self.name!r}, {self.spacecraft.name!r}, epoch {self.format_epoch(0.0)}, "
            f"{len(self.events)} events, {self.stop_s:g} s)"
        )
