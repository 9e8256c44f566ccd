"""Scenario files: the TOML format (``docs/scenarios.md``) read into a Scenario.

Every error names the file, the key path and the value, e.g.
``dzhanibekov.toml: events[1].impulse: expected 3 numbers, got [0.0, 1.0]``; unknown
keys are refused (a misspelt key would otherwise be silently ignored).

Numbers are in SI units (s, kg m², N m s, rad/s) unless given as a table with a
unit, ``{ value = [0, 30, 0], unit = "deg/s" }``, read by ``astropy.units``.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from attitude.errors import InputError
from attitude.events import AngularImpulse, AttitudeReset, InertiaChange
from attitude.pointing import BodyVector, PointingSpec
from attitude.quantities import SI_UNITS
from attitude.scenario import InitialState, Scenario
from attitude.spacecraft import Spacecraft
from attitude.timescales import SCALES, as_time, time_from_tt_seconds

__all__ = ["ScenarioFile", "ScenarioFileError", "load_scenario"]


class ScenarioFileError(InputError):
    """A scenario file has a bad or missing key; the message says where and what."""


@dataclass
class ScenarioFile:
    """A loaded scenario file: the scenario and what to compute and write from it."""

    path: Path
    scenario: Scenario
    pointing: PointingSpec = field(default_factory=PointingSpec)


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
            self.fail(f"expected a string, got {value!r}", key)
        return value

    def choice(self, key: str, choices: tuple[str, ...], default: str | None = None) -> str:
        value = self.string(key, default is None, default)
        if value not in choices:
            self.fail(f"expected one of {', '.join(choices)}, got {value!r}", key)
        return value

    def quantity(self, key: str, kind: str, shape: tuple[int, ...], required: bool = True):
        """A number or array in SI units, or ``{ value = ..., unit = "..." }``; finite."""
        value = self.raw(key, required)
        if value is None:
            return None
        unit = None
        if isinstance(value, dict):
            sub = _Table(self.file, self.where(key), value)
            sub.allow("value", "unit")
            unit = sub.string("unit")
            value = sub.raw("value")
        try:
            array = np.array(value, dtype=float)
        except (TypeError, ValueError):
            self.fail(f"expected {_describe(shape)}, got {value!r}", key)
        if array.shape != shape:
            self.fail(f"expected {_describe(shape)}, got {value!r}", key)
        if not np.all(np.isfinite(array)):
            self.fail(f"expected finite numbers, got {value!r}", key)
        if unit is not None:
            from astropy import units as u

            try:
                array = (array * u.Unit(unit)).to_value(
                    u.Unit(SI_UNITS[kind]), equivalencies=u.dimensionless_angles()
                )
            except (ValueError, u.UnitsError):
                self.fail(
                    f"unit {unit!r} cannot be converted to {SI_UNITS[kind]} "
                    f"(a {kind.replace('_', ' ')})",
                    key,
                )
        return array if shape else float(array)

    def epoch(self, key: str, scale: str, required: bool = True):
        value = self.string(key, required)
        if value is None:
            return None
        try:
            return as_time(value, scale, name=self.where(key))
        except InputError:
            self.fail(f"not an ISO 8601 epoch (e.g. 2027-03-01T12:00:00): {value!r}", key)

    def positive(self, key: str, kind: str, required: bool = True):
        value = self.quantity(key, kind, (), required)
        if value is not None and not value > 0.0:
            self.fail(f"must be positive, got {value!r}", key)
        return value


def _describe(shape: tuple[int, ...]) -> str:
    if shape == ():
        return "a number"
    if len(shape) == 1:
        return f"{shape[0]} numbers"
    return f"a {shape[0]}x{shape[1]} array of numbers"


def _inertia(table: _Table) -> np.ndarray:
    if table.has("principal_moments") == table.has("inertia_tensor"):
        table.fail("give exactly one of principal_moments and inertia_tensor")
    if table.has("principal_moments"):
        return table.quantity("principal_moments", "moment_of_inertia", (3,))
    return table.quantity("inertia_tensor", "moment_of_inertia", (3, 3))


def _attitude(table: _Table) -> Rotation | None:
    given = [key for key in ("quaternion", "matrix") if table.has(key)]
    if len(given) > 1:
        table.fail("give one of quaternion and matrix, not both")
    if not given:
        return None
    if given[0] == "quaternion":
        q = table.quantity("quaternion", "angle", (4,))
        norm = float(np.linalg.norm(q))
        if abs(norm - 1.0) > 1e-6:
            table.fail(f"quaternion must have unit norm, got |q| = {norm:.9g}", "quaternion")
        return Rotation.from_quat(q, scalar_first=True)
    a = table.quantity("matrix", "angle", (3, 3))
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


def _event_epoch(table: _Table, epoch, scale: str):
    if table.has("epoch") == table.has("offset"):
        table.fail("give exactly one of epoch (ISO 8601) and offset (seconds after the epoch)")
    if table.has("epoch"):
        return table.epoch("epoch", scale)
    return time_from_tt_seconds(epoch, table.quantity("offset", "time", ()))


def _events(root: _Table, epoch, scale: str) -> list:
    events = []
    for table in root.tables("events"):
        kind = table.choice("type", ("angular_impulse", "inertia_change", "attitude_reset"))
        common = ("type", "epoch", "offset", "label")
        label = table.string("label", required=False, default="")
        at = _event_epoch(table, epoch, scale)
        try:
            if kind == "angular_impulse":
                table.allow(*common, "impulse", "frame")
                events.append(
                    AngularImpulse(
                        at,
                        table.quantity("impulse", "angular_momentum", (3,)),
                        table.choice("frame", ("body", "inertial"), default="body"),
                        label,
                    )
                )
            elif kind == "inertia_change":
                table.allow(*common, "principal_moments", "inertia_tensor")
                events.append(InertiaChange(at, _inertia(table), label))
            else:
                table.allow(*common, "quaternion", "matrix", "angular_velocity", "angular_momentum")
                attitude = _attitude(table)
                rate = _rate(table, required=attitude is None)
                events.append(AttitudeReset(at, attitude, label=label, **rate))
        except ScenarioFileError:
            raise
        except InputError as exc:
            table.fail(str(exc))
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
        vector = item.quantity("vector", "angle", (3,))
        if not np.linalg.norm(vector) > 0:
            item.fail(f"must be a non-zero vector, got {vector.tolist()}", "vector")
        exclusion = item.quantity("sun_exclusion_half_angle", "angle", (), required=False)
        if exclusion is not None and not 0.0 < exclusion < math.pi:
            item.fail(
                f"must be between 0 and 180 deg, got {exclusion!r} rad", "sun_exclusion_half_angle"
            )
        kind = item.choice(
            "kind", ("panel", "instrument", "star_tracker", "other"), default="other"
        )
        vectors.append(BodyVector(name, vector, exclusion, kind))
    names = [v.name for v in vectors]
    if len(set(names)) != len(names):
        table.fail(f"body vector names must be unique, got {names}", "body_vectors")
    tle = None
    if table.has("tle"):
        lines = table.raw("tle")
        if not (
            isinstance(lines, list) and len(lines) == 2 and all(isinstance(s, str) for s in lines)
        ):
            table.fail(f"expected the two lines of a TLE, got {lines!r}", "tle")
        tle = tuple(lines)
    precision = table.positive("interval_precision", "time", required=False)
    if precision is None:
        return PointingSpec(vectors, tle)
    return PointingSpec(vectors, tle, precision)


def load_scenario(path: str | Path) -> ScenarioFile:
    """Read and check a scenario file; raises :class:`ScenarioFileError`."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ScenarioFileError(f"{path}: cannot read: {exc.strerror}") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioFileError(f"{path.name}: not valid TOML: {exc}") from None
    root = _Table(path, "", data)
    root.allow("scenario", "spacecraft", "initial_state", "events", "output", "pointing")

    meta = root.table("scenario")
    meta.allow("name", "epoch", "time_scale")
    scale = meta.choice("time_scale", SCALES, default="utc")
    epoch = meta.epoch("epoch", scale)
    name = meta.string("name")

    craft = root.table("spacecraft")
    craft.allow("name", "principal_moments", "inertia_tensor")
    try:
        spacecraft = Spacecraft(craft.string("name"), _inertia(craft))
    except ScenarioFileError:
        raise
    except InputError as exc:
        craft.fail(str(exc))

    initial = root.table("initial_state")
    initial.allow("quaternion", "matrix", "angular_velocity", "angular_momentum")
    attitude = _attitude(initial)
    if attitude is None:
        initial.fail("missing quaternion (w, x, y, z, body -> ICRF) or matrix")
    state = InitialState(attitude, **_rate(initial, required=True))

    events = _events(root, epoch, scale)

    output = root.table("output")
    output.allow("start", "stop", "duration", "step")
    if output.has("stop") == output.has("duration"):
        output.fail("give exactly one of stop (ISO 8601) and duration (seconds)")
    try:
        scenario = Scenario(
            name,
            spacecraft,
            epoch,
            state,
            events,
            stop=output.epoch("stop", scale, required=False),
            duration=output.positive("duration", "time", required=False),
            start=output.epoch("start", scale, required=False),
            step=output.positive("step", "time", required=False),
        )
    except InputError as exc:
        raise ScenarioFileError(f"{path.name}: {exc}") from None
    return ScenarioFile(path, scenario, _pointing(root))
