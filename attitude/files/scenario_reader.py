"""Scenario files: the TOML format (``docs/scenarios.md``) read into a Scenario.

Every error names the file, the key path and the value, e.g.
``dzhanibekov.toml: events[1].impulse: expected 3 numbers, got [0.0, 1.0]``; unknown
keys are refused (a misspelt key would otherwise be silently ignored).

Numbers are in SI units (s, kg m², N m s, rad/s) unless given as a table with a
unit, ``{ value = [0, 30, 0], unit = "deg/s" }``, read by ``astropy.units`` and
converted strictly (``Hz`` is refused as ambiguous, see ``attitude.base.quantities``).
An angle (``sun_exclusion_half_angle``, an inclination) must carry its unit: a bare 3
would be 171.9° in radians, or 3° to a reader of a data sheet.  Numbers are TOML numbers:
booleans and strings are refused, not read as 1 or parsed.  Warnings (a body that
breaks the triangle inequality) are :class:`ScenarioFileWarning`, one line naming the
file and the key.

An attitude may be given in an orbit frame (``frame = "lvlh"`` or ``"rtn"``, in
``[initial_state]`` and in attitude resets) or read from an AEM file (``aem = "..."``):
it is resolved to ICRF here, at load time, with the orbit of ``[pointing]`` at the
state's epoch, so that the scenario layer below only ever sees body → ICRF.  Files
(``oem``, ``aem``) are read relative to the scenario file's folder.
"""

from __future__ import annotations

import math
import tomllib
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal, NoReturn, TypedDict, overload

import numpy as np
from scipy.spatial.transform import Rotation

from attitude.base.errors import NO_VALUE, InertiaWarning, InputError
from attitude.base.quantities import convert_unit
from attitude.environment.frames import ORBIT_FRAMES, orbit_frame_to_icrf
from attitude.environment.keplerian import KeplerianOrbit
from attitude.environment.oem import OemOrbit
from attitude.environment.orbit import Orbit, TleOrbit
from attitude.environment.timescales import SCALES, as_time, time_from_tt_seconds
from attitude.files.aem_reader import attitude_from_aem
from attitude.files.law_reader import read_law, read_rotation, read_sites, read_slew, read_wheels
from attitude.outputs.aem_sampling import check_tolerance
from attitude.outputs.formats import DEFAULT_FORMATS, OutputChoice, parse_formats
from attitude.pointing.spec import KINDS, BodyVector, PointingSpec
from attitude.scenario.events import AngularImpulse, AttitudeReset, InertiaChange
from attitude.scenario.modes import MODE_EVENTS, ControlLoss, ControlResume, ModeChange
from attitude.scenario.scenario import InitialState, Scenario
from attitude.scenario.spacecraft import Spacecraft
from attitude.scenario.torques import Burn, ScenarioTorques

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


# attitude.scenario.events.InertiaChange's name for the inertia it checks.
_INERTIA_CHANGE = "inertia_change.inertia"


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
    outputs: OutputChoice = field(default_factory=OutputChoice)
    # The TOML document as read: attitude.montecarlo.dispersions reads its [dispersions] table
    # and writes each Monte Carlo sample as a copy of it.
    document: dict[str, Any] = field(default_factory=dict)


class _Table:
    """A TOML table with its key path, for reading typed values with clear errors."""

    def __init__(
        self, file: Path, path: str, data: Any, written: dict[str, _Written] | None = None
    ) -> None:
        self.file, self.path = file, path
        # What the file wrote for each quantity read so far (full key path: its text and
        # whether it carries a unit), shared by every table of one document: errors
        # echo a value in the unit the user gave it, not in SI.
        self.written: dict[str, _Written] = {} if written is None else written
        if not isinstance(data, dict):
            self.fail(f"expected a table, got {data!r}")
        self.data = data

    def where(self, key: str | None = None) -> str:
        return self.path if key is None else (f"{self.path}.{key}" if self.path else key)

    def fail(self, message: str, key: str | None = None, value: Any = NO_VALUE) -> NoReturn:
        """Raise the file's error: ``message`` about ``key`` of this table (the table
        itself when None), holding ``value``."""
        where = self.where(key) or None
        raise ScenarioFileError(
            _as_written(message, self.written.get(where or "")),
            key=where,
            file=self.file.name,
            value=value,
        )

    def written_text(self, key: str, bare_unit: str = "") -> str:
        """The value of quantity ``key`` as the file writes it (``-1 deg/s``, ``-5.0``),
        a bare number followed by ``bare_unit``, the SI unit it is read in, if given."""
        written = self.written[self.where(key)]
        return written.text if written.has_unit or not bare_unit else f"{written.text} {bare_unit}"

    def refuse(
        self, exc: InputError, key: str | None = None, keys: dict[str, str] | None = None
    ) -> NoReturn:
        """Raise ``exc``, an error of a builder given this table's values, as the file's:
        under the key it names (a key of this table, or mapped to one by ``keys``, from
        the builder's own name for it), else under ``key``."""
        if exc.key is None:
            self.fail(exc.reason, key, exc.value)
        self.fail(exc.reason, (keys or {}).get(exc.key, exc.key), exc.value)

    def allow(self, *keys: str) -> None:
        unknown = sorted(set(self.data) - set(keys))
        if unknown:
            self.fail(
                f"unknown key; expected one of: {', '.join(keys)}",
                unknown[0],
                self.data[unknown[0]],
            )

    def has(self, key: str) -> bool:
        return key in self.data

    @overload
    def table(self, key: str, required: Literal[True] = True) -> _Table: ...
    @overload
    def table(self, key: str, required: bool) -> _Table | None: ...
    def table(self, key: str, required: bool = True) -> _Table | None:
        if key not in self.data:
            if required:
                self.fail("missing table", key)
            return None
        return _Table(self.file, self.where(key), self.data[key], self.written)

    def tables(self, key: str) -> list[_Table]:
        value = self.data.get(key, [])
        if not isinstance(value, list):
            self.fail(f"expected an array of tables [[{key}]], got {value!r}", key, value)
        return [
            _Table(self.file, f"{self.where(key)}[{i}]", item, self.written)
            for i, item in enumerate(value)
        ]

    def raw(self, key: str, required: bool = True, default: Any = None) -> Any:
        if key not in self.data:
            if required:
                self.fail("missing key", key)
            return default
        return self.data[key]

    @overload
    def string(self, key: str, required: Literal[True] = True, default: None = None) -> str: ...
    @overload
    def string(self, key: str, required: bool, default: str) -> str: ...
    @overload
    def string(self, key: str, required: bool, default: None = None) -> str | None: ...
    def string(self, key: str, required: bool = True, default: str | None = None) -> str | None:
        value = self.raw(key, required, default)
        if value is not None and not isinstance(value, str):
            self.fail(f"expected a string, got {_short(value)}", key, value)
        if value is not None and not value.isprintable():
            self.fail(f"expected one line of printable text, got {_short(value)}", key, value)
        return value

    def choice(self, key: str, choices: tuple[str, ...], default: str | None = None) -> str:
        value = self.string(key, default is None, default)
        if value not in choices:
            self.fail(f"expected one of {', '.join(choices)}, got {value!r}", key, value)
        return value

    def quantity(
        self,
        key: str,
        kind: str,
        shape: tuple[int, ...],
        required: bool = True,
        to: str | None = None,
        unit_needed: bool | None = None,
    ):
        """A number or array in SI units, or ``{ value = ..., unit = "..." }``; finite.

        ``kind``: a key of ``SI_UNITS``; ``to``: another unit of that kind to convert
        to (e.g. "deg").  An angle must be given with its unit, and so must any
        quantity read with ``unit_needed`` (a slew's limits, written in deg/s on data
        sheets); a dimensionless value (quaternion, matrix, direction) takes none.
        """
        value = self.raw(key, required)
        if value is None:
            return None
        unit = None
        if isinstance(value, dict):
            sub = _Table(self.file, self.where(key), value, self.written)
            sub.allow("value", "unit")
            unit = sub.string("unit")
            value = sub.raw("value")
            if kind == "dimensionless":
                self.fail(f"takes no unit (it is a pure number), got unit {unit!r}", key, unit)
        elif unit_needed or (unit_needed is None and kind == "angle"):
            what, example, bare = _UNIT_NEEDED[kind]
            self.fail(
                f'{what} needs its unit, e.g. {{ value = {value!r}, unit = "{example}" }} '
                f"(a bare number would be read as {bare})",
                key,
                value,
            )
        self.written[self.where(key)] = _Written(
            _short(value) if unit is None else f"{_short(value)} {unit}", unit is not None
        )
        if not _is_numbers(value):
            self.fail(f"expected {_describe(shape)}, got {_short(value)}", key, value)
        try:
            array = np.array(value, dtype=float)
        except OverflowError:
            self.fail(f"a number is beyond the float range (1.8e308): {_short(value)}", key, value)
        except (TypeError, ValueError):
            self.fail(f"expected {_describe(shape)}, got {_short(value)}", key, value)
        if array.shape != shape:
            self.fail(f"expected {_describe(shape)}, got {_short(value)}", key, value)
        if not np.all(np.isfinite(array)):
            self.fail(f"expected finite numbers, got {_short(value)}", key, value)
        if unit is not None:
            try:
                array = np.asarray(convert_unit(array, unit, kind, "", to), dtype=float)
            except InputError as exc:
                self.fail(exc.reason, key, exc.value)
            if not np.all(np.isfinite(array)):
                self.fail(f"{value!r} {unit} is beyond the float range in SI units", key, value)
        return array if shape else float(array)

    def boolean(self, key: str, default: bool) -> bool:
        value = self.raw(key, required=False, default=default)
        if not isinstance(value, bool):
            self.fail(f"expected true or false, got {_short(value)}", key, value)
        return value

    def file_path(self, key: str) -> Path:
        """A file named by a string key, relative to the scenario file's folder."""
        text = self.string(key)
        if not text:
            self.fail("expected a file name, got an empty string", key, text)
        return self.file.parent / Path(text).expanduser()

    def epoch(self, key: str, scale: str, required: bool = True):
        value = self.string(key, required)
        if value is None:
            return None
        try:
            return as_time(value, scale, name=key)
        except InputError as exc:
            self.fail(exc.reason, key, value)

    def positive(self, key: str, kind: str, required: bool = True, unit_needed: bool | None = None):
        value = self.quantity(key, kind, (), required, unit_needed=unit_needed)
        if value is not None and not value > 0.0:
            self.fail(f"must be positive, got {self.written_text(key)}", key, value)
        return value


@dataclass(frozen=True)
class _Written:
    """A quantity as the file writes it: its text (``-1 deg/s``, ``[0.0, 1.0]``) and
    whether that carries a unit."""

    text: str
    has_unit: bool


# The quantities that need a unit: what each is called, an example unit, and how a
# bare number would be read.
_UNIT_NEEDED = {
    "angle": ("an angle", "deg", "radians"),
    "angular_velocity": ("a rate", "deg/s", "rad/s"),
    "angular_acceleration": ("an angular acceleration", "deg/s2", "rad/s²"),
}


def _as_written(message: str, written: _Written | None) -> str:
    """``message`` about a quantity given with a unit, with that value as the file
    writes it when the message does not already say it (a builder's check says the
    value in SI: ``got 0.0174533 rad/s`` for 1 deg/s)."""
    if written is None or not written.has_unit or written.text in message:
        return message
    return f"{message} (given as {written.text})"


def _is_numbers(value: Any) -> bool:
    """True for a TOML number or nested arrays of them (not booleans, not strings)."""
    if isinstance(value, list):
        return all(_is_numbers(item) for item in value)
    return isinstance(value, int | float) and not isinstance(value, bool)


def _short(value: Any) -> str:
    """``value`` as a line shows it: a float as its repr, or its %g where that is
    the same number and shorter (1e9 read from TOML is 1e+09, not 1000000000.0); a
    long text cut in the middle."""
    text = _number_text(value) if isinstance(value, float) else repr(value)
    return text if len(text) <= 60 else f"{text[:40]}...{text[-10:]} ({len(text)} characters)"


def _number_text(value: float) -> str:
    text, short = repr(value), f"{value:g}"
    return short if len(text) > 10 and len(short) < len(text) and float(short) == value else text


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


def _checked(
    table: _Table,
    key: str | None,
    build,
    *args,
    keys: dict[str, str] | None = None,
    **kwargs,
):
    """``build(*args, **kwargs)``, its InputError and InertiaWarning as the file's: under
    the key of ``table`` they name (``keys`` maps a builder's own name for a value to
    the table's key), else under ``key``."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", InertiaWarning)
        try:
            result = build(*args, **kwargs)
        except ScenarioFileError:
            raise
        except InputError as exc:
            table.refuse(exc, key, keys)
    for warning in caught:
        message = warning.message
        if isinstance(message, InertiaWarning):
            named = (keys or {}).get(message.key, message.key) if message.key else key
            text = f"{table.file.name}: {table.where(named)}: {message.reason}"
            warnings.warn(text, ScenarioFileWarning, stacklevel=2)
        else:
            warnings.warn_explicit(message, warning.category, warning.filename, warning.lineno)
    return result


def _attitude_in_icrf(table: _Table, orbit: Orbit | None, at) -> Rotation | None:
    """The table's attitude (quaternion or matrix, or ``aem``) as body → ICRF at the
    epoch ``at`` (a ``Time``): a ``frame = "lvlh"``/``"rtn"`` attitude is composed with
    the orbit frame there, an AEM file is read at that epoch."""
    frame = table.choice("frame", ("icrf", *ORBIT_FRAMES), default="icrf")
    attitude = read_rotation(table, "body -> the table's frame", False)
    if table.has("aem"):
        if attitude is not None:
            table.fail("give one of quaternion, matrix and aem, not two")
        if frame != "icrf":
            table.fail(
                "an AEM file states its own frame: frame applies to quaternion or matrix",
                "frame",
                frame,
            )
        path = table.file_path("aem")
        try:
            attitude, notes = attitude_from_aem(path, at)
        except InputError as exc:
            table.refuse(exc, "aem")
        for note in notes:
            warnings.warn(
                f"{table.file.name}: {table.where('aem')}: {note}",
                ScenarioFileWarning,
                stacklevel=2,
            )
        return attitude
    if frame == "icrf" or attitude is None:
        if frame != "icrf":
            table.fail(f"frame = {frame!r} without a quaternion or matrix to place in it", "frame")
        return attitude
    if orbit is None:
        table.fail(
            f"frame = {frame!r} needs an orbit: give [pointing] a tle, an oem or "
            "[pointing.keplerian]",
            "frame",
        )
    try:
        r, v = orbit.position_velocity(at)
    except InputError as exc:  # the orbit's source cannot place the attitude: its key
        raise ScenarioFileError(
            f"{table.where('frame')} = {frame!r} needs the orbit at {at.isot} "
            f"{at.scale.upper()}: {exc.reason}",
            key=orbit.key,
            file=table.file.name,
            value=exc.value,
        ) from None
    return orbit_frame_to_icrf(frame, r, v) * attitude


class _Rate(TypedDict, total=False):
    """The rate of an initial state or an attitude reset, as InitialState takes it."""

    angular_velocity: np.ndarray
    angular_momentum: np.ndarray


def _rate(table: _Table, required: bool) -> _Rate:
    given = [k for k in ("angular_velocity", "angular_momentum") if table.has(k)]
    if len(given) > 1:
        table.fail("give one of angular_velocity and angular_momentum, not both")
    if not given:
        if required:
            table.fail("missing angular_velocity (rad/s) or angular_momentum (N m s)")
        return {}
    value = table.quantity(given[0], given[0], (3,))
    if given[0] == "angular_velocity":
        return {"angular_velocity": value}
    return {"angular_momentum": value}


def _event_epoch(table: _Table, scale: str):
    """The event's epoch: a ``Time``, or its offset in TT seconds exactly as written."""
    if table.has("epoch") == table.has("offset"):
        table.fail("give exactly one of epoch (ISO 8601) and offset (seconds after the epoch)")
    if table.has("epoch"):
        return table.epoch("epoch", scale)
    return table.quantity("offset", "time", ())


def _event_time(at, epoch):
    """An event's epoch as a ``Time``: given, or the offset in TT seconds after ``epoch``."""
    return at if not isinstance(at, float) else time_from_tt_seconds(epoch, at)


def _events(root: _Table, scale: str, epoch, orbit: Orbit | None, sites: dict) -> list:
    events = []
    for table in root.tables("events"):
        kind = table.choice(
            "type", ("angular_impulse", "inertia_change", "attitude_reset", *MODE_EVENTS)
        )
        common = ("type", "epoch", "offset", "label")
        label = table.string("label", required=False, default="")
        at = _event_epoch(table, scale)
        if kind in MODE_EVENTS:
            events.append(_mode_event(table, kind, common, at, label, sites))
        elif kind == "angular_impulse":
            table.allow(*common, "impulse", "frame")
            impulse = table.quantity("impulse", "angular_momentum", (3,))
            frame = table.choice("frame", ("body", "inertial"), default="body")
            events.append(_checked(table, None, AngularImpulse, at, impulse, frame, label))
        elif kind == "inertia_change":
            table.allow(*common, "principal_moments", "inertia_tensor")
            inertia, key = _inertia(table)
            events.append(
                _checked(table, key, InertiaChange, at, inertia, label, keys={_INERTIA_CHANGE: key})
            )
        else:
            table.allow(
                *common,
                "quaternion",
                "matrix",
                "frame",
                "aem",
                "angular_velocity",
                "angular_momentum",
            )
            attitude = _attitude_in_icrf(table, orbit, _event_time(at, epoch))
            rate = _rate(table, required=attitude is None)
            events.append(_checked(table, None, AttitudeReset, at, attitude, label=label, **rate))
    return events


def _mode_event(table: _Table, kind: str, common: tuple, at, label: str, sites: dict):
    """A mode_change, control_loss or control_resume (``attitude.files.law_reader``)."""
    if kind == "control_loss":
        table.allow(*common, "wheels")
        wheels = table.table("wheels", required=False)
        if wheels is None:
            return _checked(table, None, ControlLoss, at, label=label)
        return _checked(table, None, ControlLoss, at, read_wheels(wheels), label)
    table.allow(*common, "law", "slew")
    law = read_law(table.table("law"), sites)
    slew_table = table.table("slew", required=False)
    slew = None if slew_table is None else read_slew(slew_table)
    build = ModeChange if kind == "mode_change" else ControlResume
    return _checked(table, None, build, at, law, slew, label)


def _angle_deg(item: _Table, key: str, low: float, high: float) -> float | None:
    """An optional angle in degrees, with its unit, in [low, high) (low excluded if 0)."""
    value = item.quantity(key, "angle", (), required=False, to="deg")
    if value is not None and not (low <= value < high and (low < 0.0 or value > 0.0)):
        written = item.written_text(key)
        item.fail(f"must be between {low:g} and {high:g} deg, got {written}", key, value)
    return value


def _body_vector(item: _Table) -> BodyVector:
    item.allow(
        "name",
        "vector",
        "kind",
        "sun_exclusion_half_angle",
        "moon_exclusion_half_angle",
        "earth_limb_exclusion_angle",
        "sun_inclusion_half_angle",
    )
    name = item.string("name")
    vector = item.quantity("vector", "dimensionless", (3,))
    if not np.linalg.norm(vector) > 0:
        item.fail(f"must be a non-zero vector, got {vector.tolist()}", "vector")
    sun = _angle_deg(item, "sun_exclusion_half_angle", 0.0, 180.0)
    moon = _angle_deg(item, "moon_exclusion_half_angle", 0.0, 180.0)
    limb = _angle_deg(item, "earth_limb_exclusion_angle", -90.0, 180.0)
    inclusion = _angle_deg(item, "sun_inclusion_half_angle", 0.0, 180.0)
    if inclusion is not None and sun is not None and inclusion <= sun:
        item.fail(
            f"{inclusion!r} deg is within sun_exclusion_half_angle ({sun!r} deg): the Sun "
            "could never be inside the field of view and outside the exclusion cone",
            "sun_inclusion_half_angle",
        )
    kind = item.choice("kind", KINDS, default="other")

    def radians(degrees: float | None) -> float | None:
        return None if degrees is None else math.radians(degrees)

    return _checked(
        item,
        None,
        BodyVector,
        name,
        vector,
        radians(sun),
        kind,
        sun,
        moon_exclusion_half_angle_rad=radians(moon),
        moon_exclusion_half_angle_deg=moon,
        earth_limb_exclusion_angle_rad=radians(limb),
        earth_limb_exclusion_angle_deg=limb,
        sun_inclusion_half_angle_rad=radians(inclusion),
        sun_inclusion_half_angle_deg=inclusion,
    )


def _keplerian(table: _Table, scale: str, epoch, name: str) -> KeplerianOrbit:
    table.allow(
        "epoch",
        "semi_major_axis",
        "eccentricity",
        "inclination",
        "raan",
        "argument_of_perigee",
        "mean_anomaly",
        "true_anomaly",
        "frame",
        "j2",
    )
    at = table.epoch("epoch", scale, required=False)
    at = epoch if at is None else at
    if table.has("mean_anomaly") == table.has("true_anomaly"):
        table.fail("give exactly one of mean_anomaly and true_anomaly")
    anomaly = "mean_anomaly" if table.has("mean_anomaly") else "true_anomaly"
    elements = {
        "semi_major_axis_m": table.positive("semi_major_axis", "length"),
        "eccentricity": table.quantity("eccentricity", "dimensionless", ()),
        "inclination": table.quantity("inclination", "angle", ()),
        "raan": table.quantity("raan", "angle", ()),
        "argument_of_perigee": table.quantity("argument_of_perigee", "angle", ()),
        anomaly: table.quantity(anomaly, "angle", ()),
    }
    frame = table.choice("frame", ("ICRF", "EME2000"), default="ICRF")
    j2 = table.boolean("j2", default=False)
    # KeplerianOrbit names each element by its key here (semi_major_axis, raan...).
    return _checked(table, None, KeplerianOrbit, at, frame=frame, j2=j2, name=name, **elements)


def _orbit(table: _Table, scale: str, epoch, name: str) -> Orbit | None:
    """The orbit of ``[pointing]``: one of tle, oem and [pointing.keplerian], or None."""
    given = [key for key in ("tle", "oem", "keplerian") if table.has(key)]
    if len(given) > 1:
        table.fail(f"give one orbit: {' or '.join(given)}, not both")
    if not given:
        return None
    if given[0] == "tle":
        lines = table.raw("tle")
        if not (
            isinstance(lines, list) and len(lines) == 2 and all(isinstance(s, str) for s in lines)
        ):
            table.fail(f"expected the two lines of a TLE, got {_short(lines)}", "tle", lines)
        return _checked(table, "tle", TleOrbit, *lines, name)
    if given[0] == "oem":
        return _checked(table, "oem", OemOrbit, table.file_path("oem"), name)
    return _keplerian(table.table("keplerian"), scale, epoch, name)


def _pointing(root: _Table, scale: str, epoch, name: str) -> PointingSpec:
    table = root.table("pointing", required=False)
    if table is None:
        return PointingSpec()
    table.allow(
        "body_vectors",
        "tle",
        "oem",
        "keplerian",
        "interval_precision",
        "earth_limb_atmosphere_height",
        "lvlh_euler_sequence",
    )
    vectors = [_body_vector(item) for item in table.tables("body_vectors")]
    names = [v.name for v in vectors]
    if len(set(names)) != len(names):
        table.fail(f"body vector names must be unique, got {names}", "body_vectors", names)
    orbit = _orbit(table, scale, epoch, name)
    options: dict[str, Any] = {}
    precision = table.positive("interval_precision", "time", required=False)
    if precision is not None:
        options["interval_precision_s"] = precision
    height = table.quantity("earth_limb_atmosphere_height", "length", (), required=False)
    if height is not None:
        options["earth_limb_atmosphere_height_m"] = height
    sequence = table.string("lvlh_euler_sequence", required=False)
    if sequence is not None:
        options["lvlh_euler_sequence"] = sequence
    spec = _checked(table, None, PointingSpec, vectors, orbit, **options)
    _checked(table, None, spec.check_orbit)
    return spec


def _burn(table: _Table, scale: str) -> Burn:
    table.allow("epoch", "offset", "duration", "torque", "frame", "label")
    at = _event_epoch(table, scale)
    duration = table.positive("duration", "time")
    torque = table.quantity("torque", "torque", (3,))
    frame = table.choice("frame", ("body", "inertial"), default="body")
    label = table.string("label", required=False, default="")
    return _checked(table, None, Burn, at, duration, torque, frame, label)


def _torques(root: _Table, scale: str, orbit: Orbit | None) -> ScenarioTorques | None:
    """``[torques]``: gravity gradient (on the orbit of ``[pointing]``), burns, the
    splitting's step or accuracy and order, the validity horizon's threshold."""
    table = root.table("torques", required=False)
    if table is None:
        return None
    table.allow("gravity_gradient", "burns", "step", "accuracy", "order", "horizon_threshold")
    gravity_gradient = table.boolean("gravity_gradient", default=False)
    if gravity_gradient and orbit is None:
        table.fail(
            "gravity gradient needs an orbit: give [pointing] a tle, an oem or "
            "[pointing.keplerian]",
            "gravity_gradient",
        )
    burns = [_burn(item, scale) for item in table.tables("burns")]
    if table.has("step") and table.has("accuracy"):
        table.fail("give step or accuracy, not both")
    options: dict[str, Any] = {
        "step": table.positive("step", "time", required=False),
        "accuracy": table.quantity("accuracy", "angle", (), required=False),
    }
    order = table.raw("order", required=False, default=4)
    if isinstance(order, bool) or order not in (2, 4, 6) or not isinstance(order, int):
        table.fail(
            f"expected 2, 4 or 6 (the splitting's order), got {_short(order)}", "order", order
        )
    threshold = table.quantity("horizon_threshold", "angle", (), required=False)
    if threshold is not None:
        options["horizon_threshold"] = threshold
    try:
        # True: the scenario's orbit, the one of [pointing] (given once, to the Scenario).
        return ScenarioTorques(gravity_gradient or None, tuple(burns), order=order, **options)
    except InputError as exc:  # its keys are the file's, from the root (torques.step)
        reason = _as_written(exc.reason, table.written.get(exc.key or ""))
        raise ScenarioFileError(
            reason, key=exc.key, file=table.file.name, value=exc.value
        ) from None


def read_document(path: Path) -> dict[str, Any]:
    """The TOML document at ``path``; ScenarioFileError for anything that is not one."""
    try:
        with open(path, "rb") as stream:
            data = stream.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        raise ScenarioFileError(f"cannot read: {exc.strerror or exc}", file=str(path)) from None
    if len(data) > MAX_FILE_BYTES:
        raise ScenarioFileError(
            f"larger than {MAX_FILE_BYTES // 1024} KiB: not a scenario file", file=path.name
        )
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        kind = "UTF-16" if data[:2] in (b"\xff\xfe", b"\xfe\xff") else "binary or not UTF-8"
        raise ScenarioFileError(
            f"not a TOML file: TOML is UTF-8 text, this is {kind} (byte {exc.start})",
            file=path.name,
        ) from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioFileError(f"not valid TOML: {exc}", file=path.name) from None
    except RecursionError:
        raise ScenarioFileError("not valid TOML: nested too deeply", file=path.name) from None


def load_scenario(path: str | Path) -> ScenarioFile:
    """Read and check a scenario file; raises :class:`ScenarioFileError`."""
    path = Path(path)
    return scenario_from_document(path, read_document(path))


def scenario_from_document(path: Path, document: dict[str, Any]) -> ScenarioFile:
    """Check a TOML document as :func:`load_scenario` checks a file (``path`` names it in
    the errors): a Monte Carlo sample is built from its document through this one path.

    A ``[dispersions]`` table is let through unread: ``attitude.montecarlo.dispersions`` reads it;
    so is ``[envelope]``: ``attitude.envelope.settings`` reads it.
    The tables are read in the order their errors are reported: [scenario],
    [spacecraft], [pointing] (the orbit: an attitude may be given in its frame),
    [initial_state], [[events]], [torques], [output].
    """
    root = _Table(path, "", document)
    root.allow(
        "scenario",
        "spacecraft",
        "initial_state",
        "events",
        "output",
        "pointing",
        "torques",
        "dispersions",
        "envelope",
        "sites",
    )
    name, scale, epoch = _scenario_table(root)
    spacecraft = _spacecraft(root)
    pointing = _pointing(root, scale, epoch, spacecraft.name)
    sites = read_sites(root)
    state = _initial_state(root, pointing.orbit, epoch, sites)
    events = _events(root, scale, epoch, pointing.orbit, sites)
    torques = _torques(root, scale, pointing.orbit)
    output = root.table("output")
    output.allow("start", "stop", "duration", "step", "formats", "aem_tolerance")
    span = _span(output, scale)
    try:
        scenario = Scenario(
            name, spacecraft, epoch, state, events, **span, torques=torques, orbit=pointing.orbit
        )
    except InputError as exc:
        end = "stop" if span["stop"] is not None else "duration"
        # Scenario's own names for its arguments, as the file spells them; its other
        # keys (events[0].offset, torques.step) are already the file's, from the root.
        keys = {
            "epoch": "scenario.epoch",
            "start": "output.start",
            "step": "output.step",
            "stop": f"output.{end}",
            "duration": "output.duration",
        }
        key = keys.get(exc.key or "", exc.key)
        reason = _as_written(exc.reason, root.written.get(key or ""))
        raise ScenarioFileError(reason, key=key, file=path.name, value=exc.value) from None
    return ScenarioFile(path, scenario, pointing, _outputs(output), document)


def _scenario_table(root: _Table) -> tuple[str, str, Any]:
    """[scenario]: its name, the time scale of the file's epochs, and its epoch."""
    meta = root.table("scenario")
    meta.allow("name", "epoch", "time_scale")
    scale = meta.choice("time_scale", SCALES, default="utc")
    epoch = meta.epoch("epoch", scale)
    return meta.string("name"), scale, epoch


def _spacecraft(root: _Table) -> Spacecraft:
    """[spacecraft]: its name and its inertia (principal moments or a tensor)."""
    craft = root.table("spacecraft")
    craft.allow("name", "principal_moments", "inertia_tensor")
    craft_name = craft.string("name")
    inertia, key = _inertia(craft)
    # Spacecraft names the name "name" and the inertia "inertia" (either key here).
    return _checked(craft, key, Spacecraft, craft_name, inertia, keys={"inertia": key})


def _initial_state(root: _Table, orbit: Orbit | None, epoch, sites: dict) -> InitialState:
    """[initial_state]: the attitude (in ICRF, from the frame or AEM file it is given
    in) and the rate (angular velocity or momentum); or [initial_state.law], the law the
    body starts under (``attitude.files.law_reader``)."""
    initial = root.table("initial_state")
    if initial.has("law"):
        others = sorted(set(initial.data) - {"law"})
        if others:
            initial.fail(
                f"give [initial_state.law] alone: the law sets the attitude and the rate "
                f"(got {others[0]!r} too)"
            )
        return _checked(initial, None, InitialState, law=read_law(initial.table("law"), sites))
    initial.allow("quaternion", "matrix", "frame", "aem", "angular_velocity", "angular_momentum")
    attitude = _attitude_in_icrf(initial, orbit, epoch)
    if attitude is None:
        initial.fail("missing quaternion (w, x, y, z, body -> ICRF) or matrix")
    rate = _rate(initial, required=True)
    return _checked(initial, None, InitialState, attitude, **rate)


def _span(output: _Table, scale: str) -> dict[str, Any]:
    """[output]'s span and step, as :class:`Scenario` takes them: exactly one of stop and
    duration, and the start and step if given."""
    if output.has("stop") == output.has("duration"):
        output.fail("give exactly one of stop (ISO 8601) and duration (seconds)")
    return {
        "stop": output.epoch("stop", scale, required=False),
        "duration": output.positive("duration", "time", required=False),
        "start": output.epoch("start", scale, required=False),
        "step": output.positive("step", "time", required=False),
    }


def _outputs(output: _Table) -> OutputChoice:
    """``formats`` (a list of names) and ``aem_tolerance`` (an angle, with its unit)."""
    formats = output.raw("formats", required=False, default=list(DEFAULT_FORMATS))
    if not isinstance(formats, list):
        output.fail(f"expected a list of format names, got {_short(formats)}", "formats")
    try:
        formats = parse_formats(formats, "formats")
    except InputError as exc:
        output.refuse(exc, "formats")
    tolerance = output.quantity("aem_tolerance", "angle", (), required=False)
    if tolerance is None:
        return OutputChoice(formats)
    try:
        check_tolerance(tolerance, "aem_tolerance")
    except InputError as exc:
        output.refuse(exc, "aem_tolerance")
    return OutputChoice(formats, tolerance)
