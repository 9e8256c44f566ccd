"""The envelope's settings: the ``[envelope]`` table of a scenario file, or the same
values given in Python (:class:`EnvelopeSettings`).

::

    [envelope]
    every = 10.0                 # s: a control loss every Δτ over the nominal timeline
    # times = [600.0, 4200.0]    # or: these failure instants (s after the epoch)
    window = 3600.0              # s of motion after each loss
    wheels = { case = "spinning", momentum = [0.0, 2.0, 0.0] }   # N m s, body axes
    power_threshold = 0.5        # the panels' power fraction that counts as lost

``wheels`` defaults to the scenario's first ``control_loss`` event's, else locked
wheels holding nothing.  Every value is checked against the scenario (the failure
times within its span, the wheels' momentum against its inertia) and against the
job's budget (:data:`MAX_FAILURES` instants, :data:`MAX_FAILURE_SECONDS` seconds of
motion in all), by ``attitude check`` and ``attitude envelope`` alike, each refusal
one line naming the file, the key and the value.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from attitude.base.errors import InputError
from attitude.files.law_reader import read_wheels
from attitude.files.scenario_reader import ScenarioFile, ScenarioFileError
from attitude.files.scenario_reader import (
    _Table as Table,  # the reader's own errors: file, key, value
)
from attitude.scenario.modes import ControlLoss, Wheels
from attitude.scenario.scenario import Scenario

__all__ = [
    "MAX_FAILURES",
    "MAX_FAILURE_SECONDS",
    "MAX_WINDOW_S",
    "EnvelopeSettings",
    "failure_times",
    "read_envelope",
]

# The budget of one job: this many failure instants, this many seconds of motion after
# them in all (8640 instants of a day at 10 s with an hour each is 3.1e7 s), and a
# window of at most this long (a week: the safe-mode analyses ask for hours).
MAX_FAILURES = 200_000
MAX_FAILURE_SECONDS = 1e9
MAX_WINDOW_S = 7 * 86_400.0


@dataclass(frozen=True)
class EnvelopeSettings:
    """What an envelope computes.

    ``every`` (s): a control loss every Δτ from the epoch to the end of the nominal
    timeline (both included when the span is a whole number of Δτ); or ``times``: the
    failure instants, s after the epoch (TT).  ``window`` (s): how long the motion after
    each loss is followed.  ``wheels``: :class:`~attitude.scenario.modes.Wheels` at the
    loss (None: the scenario's first ``control_loss``'s, else locked holding nothing).
    ``power_threshold``: the fraction of the panels' full power (each panel square to
    the Sun, fully lit) below which the power counts as lost.
    """

    window: float
    every: float | None = None
    times: tuple[float, ...] | None = None
    wheels: Wheels | None = None
    power_threshold: float = 0.5
    keys: dict[str, str] = field(default_factory=dict, compare=False, repr=False)

    def __post_init__(self) -> None:
        if (self.every is None) == (self.times is None):
            raise InputError(
                "give the failure times as every (a step, s) or times (a list), one of them",
                key=self._key("every"),
            )
        window = _number(self.window, self._key("window"))
        if not 0.0 < window <= MAX_WINDOW_S:
            raise InputError(
                f"the window after each loss must be positive and at most {MAX_WINDOW_S:g} s "
                f"(a week), got {window!r} s",
                key=self._key("window"),
                value=window,
            )
        object.__setattr__(self, "window", window)
        if self.every is not None:
            every = _number(self.every, self._key("every"))
            if not every > 0.0:
                raise InputError(
                    f"the step between failure times must be positive, got {every!r} s",
                    key=self._key("every"),
                    value=every,
                )
            object.__setattr__(self, "every", every)
        if self.times is not None:
            times = np.asarray(self.times, dtype=np.float64).ravel()
            if times.size == 0 or times.size > MAX_FAILURES:
                raise InputError(
                    f"expected 1 to {MAX_FAILURES:,} failure times, got {times.size:,}",
                    key=self._key("times"),
                )
            if not np.all(np.isfinite(times)):
                raise InputError(
                    "expected finite numbers (s after the epoch)",
                    key=self._key("times"),
                    value=[float(t) for t in times[~np.isfinite(times)][:3]],
                )
            object.__setattr__(self, "times", tuple(float(t) for t in times))
        threshold = _number(self.power_threshold, self._key("power_threshold"))
        if not 0.0 < threshold <= 1.0:
            raise InputError(
                f"a fraction of the panels' full power, in (0, 1], got {threshold!r}",
                key=self._key("power_threshold"),
                value=threshold,
            )
        object.__setattr__(self, "power_threshold", threshold)
        if self.wheels is not None and not isinstance(self.wheels, Wheels):
            raise InputError(f"expected a Wheels, got {self.wheels!r}", key=self._key("wheels"))

    def _key(self, name: str) -> str:
        return self.keys.get(name, name)

    def wheels_for(self, scenario: Scenario) -> Wheels:
        """The wheels at each loss: these settings', else the scenario's first
        ``control_loss``'s, else locked holding nothing."""
        if self.wheels is not None:
            return self.wheels
        for _, event in scenario.events:
            if isinstance(event, ControlLoss):
                return event.wheels
        return Wheels()


def _number(value: Any, key: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float | np.floating | np.integer):
        raise InputError(f"expected a number, got {value!r}", key=key, value=value)
    number = float(value)
    if not math.isfinite(number):
        raise InputError(f"expected a finite number, got {value!r}", key=key, value=value)
    return number


def failure_times(settings: EnvelopeSettings, scenario: Scenario) -> NDArray[np.float64]:
    """The failure instants τ (TT s after the epoch), checked: within the nominal
    timeline [0, stop], within the job's budget."""
    stop = scenario.stop_s
    if settings.every is not None:
        count = math.floor(stop / settings.every * (1.0 + 1e-12)) + 1
        if count > MAX_FAILURES:
            raise InputError(
                f"{settings.every:g} s over the {stop:g} s timeline is {count:,} failure "
                f"times, more than the {MAX_FAILURES:,} one job computes: use a longer step",
                key=settings._key("every"),
                value=settings.every,
            )
        times = settings.every * np.arange(count, dtype=np.float64)
        times = times[times <= stop]
    else:
        assert settings.times is not None
        times = np.asarray(settings.times, dtype=np.float64)
        outside = times[(times < 0.0) | (times > stop)]
        if outside.size:
            raise InputError(
                f"{outside[0]:g} s is outside the nominal timeline [0, {stop:g}] s "
                f"({scenario.format_epoch(0.0)} to {scenario.format_epoch(stop)})",
                key=settings._key("times"),
                value=float(outside[0]),
            )
        times = np.unique(times)
    total = times.size * settings.window
    if total > MAX_FAILURE_SECONDS:
        raise InputError(
            f"{times.size:,} failures of {settings.window:g} s each are {total:.3g} s of "
            f"motion to search, more than the {MAX_FAILURE_SECONDS:.0e} s one job computes: "
            "use fewer failure times or a shorter window",
            key=settings._key("window"),
            value=settings.window,
        )
    return times


def read_envelope(loaded: ScenarioFile) -> EnvelopeSettings:
    """The ``[envelope]`` table of ``loaded`` (a :class:`ScenarioFileError` naming the
    file, the key and the value for anything wrong)."""
    root = Table(loaded.path, "", loaded.document)
    table = root.table("envelope", required=False)
    if table is None:
        raise ScenarioFileError(
            "missing table: add one with the failure times (every or times) and the "
            "window (docs/envelope.md)",
            key="envelope",
            file=loaded.path.name,
        )
    table.allow("every", "times", "window", "wheels", "power_threshold")
    every = table.positive("every", "time", required=False)
    times = None
    if table.has("times"):
        raw = table.raw("times")
        if not isinstance(raw, list):
            table.fail(
                f"expected a list of failure times (s after the epoch), got {raw!r}", "times", raw
            )
        if len(raw) > MAX_FAILURES:
            table.fail(
                f"expected at most {MAX_FAILURES:,} failure times, got {len(raw):,}",
                "times",
                len(raw),
            )
        times = table.quantity("times", "time", (len(raw),))
    window = table.quantity("window", "time", ())
    wheels = None
    sub = table.table("wheels", required=False)
    if sub is not None:
        wheels = read_wheels(sub)
    threshold = table.raw("power_threshold", required=False, default=0.5)
    keys = {
        name: f"envelope.{name}"
        for name in ("every", "times", "window", "wheels", "power_threshold")
    }
    try:
        return EnvelopeSettings(
            window=window,
            every=every,
            times=None if times is None else tuple(np.atleast_1d(times).tolist()),
            wheels=wheels,
            power_threshold=threshold,
            keys=keys,
        )
    except InputError as exc:  # its keys are the file's, from the root: said as written
        root.refuse(exc)
