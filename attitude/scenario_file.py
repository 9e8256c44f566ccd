"""Scenario files: the TOML format (``docs/scenarios.md``) read into a Scenario.

Every error names the file, the key path and the value, e.g.
``dzhanibekov.toml: events[1].impulse: expected 3 numbers, got [0.0, 1.0]``; unknown
keys are refused (a misspelt key would otherwise be silently ignored).

Numbers are in SI units (s, kg m², N m s, rad/s) unless given as a table with a
unit, ``{ value = [0, 30, 0], unit = "deg/s" }``, read by ``astropy.units`` and
converted strictly (``Hz`` is refused as ambiguous, see ``attitude.quantities``).
An angle (``sun_exclusion_half_angle``) must carry its unit: a bare 3 would be
171.9° in radians, or 3° to a reader of a data sheet.  Numbers are TOML numbers:
booleans and strings are refused, not read as 1 or parsed.  Warnings (a body that
breaks the triangle inequality) are :class:`ScenarioFileWarning`, one line naming the
file and the key.
"""

from __future__ import annotations

import math
import tomllib
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from attitude.errors import InertiaWarning, InputError
from attitude.events import AngularImpulse, AttitudeReset, InertiaChange
from attitude.pointing import BodyVector, PointingSpec
from attitude.quantities import convert_unit
from attitude.scenario import InitialState, Scenario
from attitude.spacecraft import Spacecraft
from attitude.timescales import SCALES, as_time

__all__ = [
    "ScenarioFile",
    "ScenarioFileError",
    "ScenarioFileWarning",
    "load_scenario",
    "read_document",
    "scenario_from_document",
]

# A scenario is a few kilobytes; anything this large is not one (and reading a huge
# or endless file, e.g. /dev/zero, must not exhaust the memory).
MAX_FILE_BYTES = 1 << 20


class ScenarioFileError(InputError):
    """A scenario file has a bad or missing key; the message says where and what."""


class ScenarioFileWarning(UserWarning):
    """Something in a scenario file is computed but suspicious; the message says where."""


@dataclass
class ScenarioFile:
    """A loaded scenario file: the scenario and what to compute and write from it."""

    path: Path
    scenario: Scenario
    pointing: PointingSpec = field(default_factory=PointingSpec)
    # The TOML document as read: attitude.dispersions reads its [dispersions] table
    # and writes each Monte Carlo sample as a copy of it.
    document: dict[str, Any] = field(default_factory=dict)


class _Table:
    """A TOML table with its key path, for reading typed values with clear errors."""

    def __init__(self, file: Path, path: str, data: Any) -> None:
        self.file, self.path = file, path
        if not isinstance(data, dict):
            self.fail(f"expected a table, got {data!r}")
        self.data = data

    def where(self, key: str | None = None) -> str:
        return self.path if key is None else (f"{self.path}.{key}" if self.path else key)

    def fail(self, message: str, key: str | None = None):
        where = self.where(key)
        raise ScenarioFileError(
            f"{self.file.name}: {where}: {message}" if where else f"{self.file.name}: {message}"
        )

    def allow(self, *keys: str) -> None:
        unknown = sorted(set(self.data) - set(keys))
        if unknown:
            self.fail(f"unknown key {unknown[0]!r}; expected one of: {', '.join(keys)}")

    def has(self, key: str) -> bool:
        return key in self.data

    def table(self, key: str, required: bool = True) -> _Table | None:
        if key not in self.data:
            if required:
                self.fail(f"missing table [{self.where(key)}]")
            return None
        return _Table(self.file, self.where(key), self.data[key])

    def tables(self, key: str) -> list[_Table]:
        value = self.data.get(key, [])
        if not isinstance(value, list):
            self.fail(f"expected an array of tables [[{key}]], got {value!r}", key)
        return [_Table(self.file, f"{self.where(key)}[{i}]", item) for i, item in enumerate(value)]

    def raw(self, key: str, required: bool = True, default: Any = None) -> Any:
        if key not in self.data:
            if required:
                self.fail("missing key", key)
            return default
        return self.data[key]

    def string(self, key: str, required: bool = True, default: str | None = None) -> str | None:
        value = self.raw(key, required, default)
        if value is not None and not isinstance(value, str):
            self.fail(f"expected a string, got {_short(value)}", key)
        if value is not None and not value.isprintable():
            self.fail(f"expected one line of printable text, got {_short(value)}", key)
        return value

    def choice(self, key: str, choices: tuple[str, ...], default: str | None = None) -> str:
        value = self.string(key, default is None, default)
        if value not in choices:
            self.fail(f"expected one of {', '.join(choices)}, got {value!r}", key)
        return value

    def quantity(
        self,
        key: str,
        kind: str,
        shape: tuple[int, ...],
        required: bool = True,
        to: str | None = None,
    ):
        """A number or array in SI units, or ``{ value = ..., unit = "..." }``; finite.

        ``kind``: a key of ``SI_UNITS``; ``to``: another unit of that kind to convert
        to (e.g. "deg").  An angle must be given with its unit; a dimensionless value
        (quaternion, matrix, direction) takes none.
        """
        value = self.raw(key, required)
        if value is None:
            return None
        unit = None
        if isinstance(value, dict):
            sub = _Table(self.file, self.where(key), value)
            sub.allow("value", "unit")
            unit = sub.string("unit")
            value = sub.raw("value")
            if kind == "dimensionless":
                self.fail(f"takes no unit (it is a pure number), got unit {unit!r}", key)
        elif kind == "angle":
            self.fail(
                f'an angle needs its unit, e.g. {{ value = {value!r}, unit = "deg" }} '
                "(a bare number would be read as radians)",
                key,
            )
        if not _is_numbers(value):
            self.fail(f"expected {_describe(shape)}, got {_short(value)}", key)
        try:
            array = np.array(value, dtype=float)
        except OverflowError:
            self.fail(f"a number is beyond the float range (1.8e308): {_short(value)}", key)
        except (TypeError, ValueError):
            self.fail(f"expected {_describe(shape)}, got {_short(value)}", key)
        if array.shape != shape:
            self.fail(f"expected {_describe(shape)}, got {_short(value)}", key)
        if not np.all(np.isfinite(array)):
            self.fail(f"expected finite numbers, got {_short(value)}", key)
        if unit is not None:
            try:
                array = np.asarray(convert_unit(array, unit, kind, "", to), dtype=float)
            except InputError as exc:
                self.fail(str(exc).removeprefix(": "), key)
            if not np.all(np.isfinite(array)):
                self.fail(f"{value!r} {unit} is beyond the float range in SI units", key)
        return array if shape else float(array)

    def epoch(self, key: str, scale: str, required: bool = True):
        value = self.string(key, required)
        if value is None:
            return None
        try:
            return as_time(value, scale, name=self.where(key))
        except InputError as exc:
            self.fail(str(exc).removeprefix(f"{self.where(key)}: "), key)

    def positive(self, key: str, kind: str, required: bool = True):
        value = self.quantity(key, kind, (), required)
        if value is not None and not value > 0.0:
            self.fail(f"must be positive, got {value!r}", key)
        return value


def _is_numbers(value: Any) -> bool:
    """True for a TOML number or nested arrays of them (not booleans, not strings)."""
    if isinstance(value, list):
        return all(_is_numbers(item) for item in value)
    return isinstance(value, int | float) and not isinstance(value, bool)


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else f"{text[:40]}...{text[-10:]} ({len(text)} characters)"


def _describe(shape: tuple[int, ...]) -> str:
    if shape == ():
        return "a number"
    if len(shape) == 1:
        return f"{shape[0]} numbers"
    return f"a {shape[0]}x{shape[1]} array of numbers"


def _inertia(table: _Table) -> tuple[np.ndarray, str]:
    """The inertia (moments or tensor) and the key it was given under."""
    if table.has("principal_moments") == table.has("inertia_tensor"):
        table.fail("give exactly one of principal_moments and inertia_tensor")
    if table.has("principal_moments"):
        return table.quantity("principal_moments", "moment_of_inertia", (3,)), "principal_moments"
    return table.quantity("inertia_tensor", "moment_of_inertia", (3, 3)), "inertia_tensor"


def _checked(table: _Table, key: str | None, build, *args, **kwargs):
    """``build(*args, **kwargs)``, its InputError and InertiaWarning named after the key."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", InertiaWarning)
        try:
            result = build(*args, **kwargs)
        except ScenarioFileError:
            raise
        except InputError as exc:
            table.fail(_without_inertia_name(str(exc)), key)
    for warning in caught:
        if issubclass(warning.category, InertiaWarning):
            text = _without_inertia_name(str(warning.message))
            where = table.where(key)
            warnings.warn(f"{table.file.name}: {where}: {text}", ScenarioFileWarning, stacklevel=2)
        else:
            warnings.warn_explicit(
                warning.message, warning.category, warning.filename, warning.lineno
            )
    return result


def _without_inertia_name(message: str) -> str:
    """A message of ``attitude.inertia`` without its own name for the field: the file's
    key path replaces it."""
    return message.removeprefix("inertia_change.").removeprefix("inertia: ")


def _attitude(table: _Table) -> Rotation | None:
    given = [key for key in ("quaternion", "matrix") if table.has(key)]
    if len(given) > 1:
        table.fail("give one of quaternion and matrix, not both")
    if not given:
        return None
    if given[0] == "quaternion":
        q = table.quantity("quaternion", "dimensionless", (4,))
        norm = float(np.linalg.norm(q))
        if abs(norm - 1.0) > 1e-6:
            table.fail(f"quaternion must have unit norm, got |q| = {norm:.9g}", "quaternion")
        return Rotation.from_quat(q, scalar_first=True)
    a = table.quantity("matrix", "dimensionless", (3, 3))
    if np.max(np.abs(a @ a.T - np.eye(3))) > 1e-6 or np.linalg.det(a) < 0:
        table.fail(f"matrix must be a rotation (orthonormal, det +1), got {a.tolist()}", "matrix")
    return Rotation.from_matrix(a)


def _rate(table: _Table, required: bool) -> dict[str, np.ndarray]:
    given = [k for k in ("angular_velocity", "angular_momentum") if table.has(k)]
    if len(given) > 1:
        table.fail("give one of angular_velocity and angular_momentum, not both")
    if not given:
        if required:
            table.fail("missing angular_velocity (rad/s) or angular_momentum (N m s)")
        return {}
    return {given[0]: table.quantity(given[0], given[0], (3,))}


def _event_epoch(table: _Table, scale: str):
    """The event's epoch: a ``Time``, or its offset in TT seconds exactly as written."""
    if table.has("epoch") == table.has("offset"):
        table.fail("give exactly one of epoch (ISO 8601) and offset (seconds after the epoch)")
    if table.has("epoch"):
        return table.epoch("epoch", scale)
    return table.quantity("offset", "time", ())


def _events(root: _Table, scale: str) -> list:
    events = []
    for table in root.tables("events"):
        kind = table.choice("type", ("angular_impulse", "inertia_change", "attitude_reset"))
        common = ("type", "epoch", "offset", "label")
        label = table.string("label", required=False, default="")
        at = _event_epoch(table, scale)
        if kind == "angular_impulse":
            table.allow(*common, "impulse", "frame")
            impulse = table.quantity("impulse", "angular_momentum", (3,))
            frame = table.choice("frame", ("body", "inertial"), default="body")
            events.append(_checked(table, None, AngularImpulse, at, impulse, frame, label))
        elif kind == "inertia_change":
            table.allow(*common, "principal_moments", "inertia_tensor")
            inertia, key = _inertia(table)
            events.append(_checked(table, key, InertiaChange, at, inertia, label))
        else:
            table.allow(*common, "quaternion", "matrix", "angular_velocity", "angular_momentum")
            attitude = _attitude(table)
            rate = _rate(table, required=attitude is None)
            events.append(_checked(table, None, AttitudeReset, at, attitude, label=label, **rate))
    return events


def _pointing(root: _Table) -> PointingSpec:
    table = root.table("pointing", required=False)
    if table is None:
        return PointingSpec()
    table.allow("body_vectors", "tle", "interval_precision")
    vectors = []
    for item in table.tables("body_vectors"):
        item.allow("name", "vector", "sun_exclusion_half_angle", "kind")
        name = item.string("name")
        vector = item.quantity("vector", "dimensionless", (3,))
        if not np.linalg.norm(vector) > 0:
            item.fail(f"must be a non-zero vector, got {vector.tolist()}", "vector")
        exclusion_deg = item.quantity(
            "sun_exclusion_half_angle", "angle", (), required=False, to="deg"
        )
        if exclusion_deg is not None and not 0.0 < exclusion_deg < 180.0:
            item.fail(
                f"must be between 0 and 180 deg, got {exclusion_deg!r} deg",
                "sun_exclusion_half_angle",
            )
        kind = item.choice(
            "kind", ("panel", "instrument", "star_tracker", "other"), default="other"
        )
        exclusion = None if exclusion_deg is None else math.radians(exclusion_deg)
        vectors.append(
            _checked(item, None, BodyVector, name, vector, exclusion, kind, exclusion_deg)
        )
    names = [v.name for v in vectors]
    if len(set(names)) != len(names):
        table.fail(f"body vector names must be unique, got {names}", "body_vectors")
    tle = None
    if table.has("tle"):
        lines = table.raw("tle")
        if not (
            isinstance(lines, list) and len(lines) == 2 and all(isinstance(s, str) for s in lines)
        ):
            table.fail(f"expected the two lines of a TLE, got {_short(lines)}", "tle")
        tle = tuple(lines)
    precision = table.positive("interval_precision", "time", required=False)
    if precision is None:
        return PointingSpec(vectors, tle)
    return PointingSpec(vectors, tle, precision)


def read_document(path: Path) -> dict[str, Any]:
    """The TOML document at ``path``; ScenarioFileError for anything that is not one."""
    try:
        with open(path, "rb") as stream:
            data = stream.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        raise ScenarioFileError(f"{path}: cannot read: {exc.strerror or exc}") from None
    if len(data) > MAX_FILE_BYTES:
        raise ScenarioFileError(
            f"{path.name}: larger than {MAX_FILE_BYTES // 1024} KiB: not a scenario file"
        )
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        kind = "UTF-16" if data[:2] in (b"\xff\xfe", b"\xfe\xff") else "binary or not UTF-8"
        raise ScenarioFileError(
            f"{path.name}: not a TOML file: TOML is UTF-8 text, this is {kind} (byte {exc.start})"
        ) from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioFileError(f"{path.name}: not valid TOML: {exc}") from None
    except RecursionError:
        raise ScenarioFileError(f"{path.name}: not valid TOML: nested too deeply") from None


def load_scenario(path: str | Path) -> ScenarioFile:
    """Read and check a scenario file; raises :class:`ScenarioFileError`."""
    path = Path(path)
    return scenario_from_document(path, read_document(path))


def scenario_from_document(path: Path, document: dict[str, Any]) -> ScenarioFile:
    """Check a TOML document as :func:`load_scenario` checks a file (``path`` names it in
    the errors): a Monte Carlo sample is built from its document through this one path.

    A ``[dispersions]`` table is let through unread: ``attitude.dispersions`` reads it.
    """
    root = _Table(path, "", document)
    root.allow(
        "scenario", "spacecraft", "initial_state", "events", "output", "pointing", "dispersions"
    )

    meta = root.table("scenario")
    meta.allow("name", "epoch", "time_scale")
    scale = meta.choice("time_scale", SCALES, default="utc")
    epoch = meta.epoch("epoch", scale)
    name = meta.string("name")

    craft = root.table("spacecraft")
    craft.allow("name", "principal_moments", "inertia_tensor")
    craft_name = craft.string("name")
    inertia, key = _inertia(craft)
    spacecraft = _checked(craft, key, Spacecraft, craft_name, inertia)

    initial = root.table("initial_state")
    initial.allow("quaternion", "matrix", "angular_velocity", "angular_momentum")
    attitude = _attitude(initial)
    if attitude is None:
        initial.fail("missing quaternion (w, x, y, z, body -> ICRF) or matrix")
    rate = _rate(initial, required=True)
    state = _checked(initial, None, InitialState, attitude, **rate)

    events = _events(root, scale)

    output = root.table("output")
    output.allow("start", "stop", "duration", "step")
    if output.has("stop") == output.has("duration"):
        output.fail("give exactly one of stop (ISO 8601) and duration (seconds)")
    stop = output.epoch("stop", scale, required=False)
    duration = output.positive("duration", "time", required=False)
    start = output.epoch("start", scale, required=False)
    step = output.positive("step", "time", required=False)
    try:
        scenario = Scenario(
            name,
            spacecraft,
            epoch,
            state,
            events,
            stop=stop,
            duration=duration,
            start=start,
            step=step,
        )
    except InputError as exc:
        end = "stop" if stop is not None else "duration"
        raise ScenarioFileError(f"{path.name}: {_scenario_key(str(exc), end)}") from None
    return ScenarioFile(path, scenario, _pointing(root), document)


def _scenario_key(message: str, end: str) -> str:
    """A Scenario's message with its key as the file spells it (``output.step: ...``).

    ``end``: the key that gave the end of the span, ``stop`` or ``duration``.
    """
    head, _, rest = message.partition(" ")
    key = head.removesuffix(":")
    if key == "epoch":
        return f"scenario.epoch: {rest}"
    if key in ("start", "step", "duration", "stop"):
        return f"output.{end if key == 'stop' else key}: {rest}"
    if message.startswith("the span"):
        return f"output.{end}: {message}"
    return message
