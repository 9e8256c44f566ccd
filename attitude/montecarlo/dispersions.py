"""Dispersions: the ``[dispersions]`` table of a scenario file, and the samples drawn from it.

A Monte Carlo sample is an ordinary scenario document: a copy of the nominal one in
which the dispersed keys hold drawn values, in SI units, written back as TOML floats
(``repr``: they read back as the same doubles).  ``attitude montecarlo`` builds every
sample's scenario from its document with
:func:`attitude.files.scenario_reader.scenario_from_document`,
the reader of ``attitude run``, so a sample written out as a file
(``--emit-scenario``) runs to the same numbers.  The table (``docs/scenarios.md``)::

    [dispersions]
    seed = 2027
    samples = 1000
    [dispersions.spacecraft]
    principal_moments = { distribution = "normal", relative_sigma = 0.05 }
    principal_axes = { distribution = "normal", sigma = { value = 1.0, unit = "deg" } }
    [dispersions.initial_state]
    attitude = { distribution = "normal", sigma = { value = 0.5, unit = "deg" } }
    angular_velocity = { distribution = "uniform", half_width = { value = 0.1, unit = "deg/s" } }
    [[dispersions.events]]
    event = 0
    time = { distribution = "uniform", half_width = 0.5 }
    impulse_magnitude = { distribution = "truncated_normal", relative_sigma = 0.1,
                          truncation = 3.0 }
    impulse_direction = { distribution = "normal", sigma = { value = 2.0, unit = "deg" } }
    [dispersions.pointing]
    tle_epoch = { distribution = "normal", sigma = 0.5 }

What each draw means:

- **Scalar and per-component deviations** (moments, rate, time, magnitude, TLE epoch):
  each component independently N(0, σ²), uniform on [−h, h], or N(0, σ²) cut at
  ±truncation·σ (``scipy.stats.truncnorm``).  ``relative_*`` scales are fractions of
  the nominal value: I' = I (1 + ε).
- **Rotations** (attitude, principal axes): a rotation vector δ in body axes, isotropic:
  normal means each component N(0, σ²), so the angle |δ| has the χ distribution with
  3 degrees of freedom times σ (median 1.54 σ, 99 % below 3.37 σ); truncated normal
  cuts |δ| at truncation·σ; uniform fills the ball |δ| ≤ h.  The attitude becomes
  R' = R exp(δ): δ turns the body before R takes it to the frame the file gives the
  attitude in (ICRF, or the orbit's LVLH or RTN, which stays the sample's frame: a
  nadir-pointing body stays dispersed about nadir on a dispersed orbit).  An attitude
  read from an AEM file is written as the ICRF quaternion it gives.
- **Directions** (impulse direction): a tilt vector θ across the nominal direction n
  (two components, the same three laws in the plane), n' = exp(θ) n; the tilt angle is
  |θ|, Rayleigh-distributed for the normal law (median 1.18 σ, 99 % below 3.03 σ).
- **Inertia**: the principal moments are scaled as above and the principal axes turned
  by a small rotation E (body axes): T' = E Vᵀ diag(I') V Eᵀ, with V the nominal body →
  principal rotation, symmetrized.  T' is positive definite and physical exactly when
  I' is, so a draw of I' with a moment ≤ 0 or breaking the triangle inequality
  (I_a + I_b < I_c) is drawn again from the same stream, up to :data:`MAX_DRAWS` times;
  the number of draws is recorded.  Dispersed moments are thus conditioned on being
  physical; a nominal body that breaks the inequality is refused.
- **TLE epoch** (along-track timing): SGP4 is a function of the time since the element
  set's epoch, so moving the epoch by s seconds puts the spacecraft where the nominal
  orbit has it s seconds earlier.  The TLE writes its epoch to 1e-8 day, so s is
  rounded to 0.864 ms and the applied value recorded.

Reproducibility: the draws of sample k for the quantity at key K come from a generator
of its own, ``SeedSequence(seed, spawn_key=(k, crc32(K)))`` (numpy's spawned streams),
never from a shared stream: a sample is the same whatever the number of workers, the
batch size, the other samples, or which other quantities are dispersed.
"""

from __future__ import annotations

import math
import zlib
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.base.vectors import basis_across
from attitude.files.law_reader import read_rotation
from attitude.files.scenario_reader import ScenarioFile, ScenarioFileError
from attitude.files.scenario_reader import (
    _Table as Table,  # the reader's own errors: file, key, value
)
from attitude.scenario.events import AngularImpulse
from attitude.solver.inertia import violates_triangle_inequality

__all__ = [
    "DISTRIBUTIONS",
    "MAX_DRAWS",
    "MAX_SAMPLES",
    "Dispersions",
    "Distribution",
    "Sample",
    "draw_sample",
    "read_dispersions",
]

DISTRIBUTIONS = ("normal", "uniform", "truncated_normal")
# Draws of one sample's inertia (or impulse magnitude) until it is physical.
MAX_DRAWS = 100
# The largest sample count a table may ask for (the per-sample table of 1e7 rows and a
# hundred columns is already several GB).
MAX_SAMPLES = 10_000_000
# The largest seed: a TOML integer is 64-bit signed (TOML 1.0), so the file's seed
# cannot be larger, and --seed, which replaces it, follows the same rule (numpy would
# take any; statistics.json then holds a seed that int64 readers take too).
MAX_SEED = 2**63 - 1
# Rotation and cone scales beyond this are not "small": the rotation vector wraps.
_MAX_ANGLE_RAD = math.pi
_AXES = "xyz"


@dataclass(frozen=True)
class Distribution:
    """A zero-mean deviation: ``kind`` in :data:`DISTRIBUTIONS`, ``scale`` the σ (normal,
    truncated normal) or half width (uniform) in SI units or as a fraction (``relative``),
    a number or one per component; ``truncation``: the cut, in σ."""

    kind: str
    scale: float | NDArray[np.float64]
    truncation: float | None = None
    relative: bool = False

    def components(self, rng: np.random.Generator, size: int) -> NDArray[np.float64]:
        """``size`` independent deviations (each component with its own scale)."""
        if self.kind == "normal":
            unit = rng.standard_normal(size)
        elif self.kind == "uniform":
            unit = rng.uniform(-1.0, 1.0, size)
        else:
            from scipy.stats import truncnorm

            c = self._cut()
            unit = np.asarray(truncnorm.rvs(-c, c, size=size, random_state=rng), dtype=np.float64)
        return unit * self.scale

    def isotropic(self, rng: np.random.Generator, dimension: int) -> NDArray[np.float64]:
        """A vector in ``dimension`` (2 or 3) dimensions whose law does not depend on its
        direction: Gaussian (σ per component), cut at truncation·σ, or uniform in the ball."""
        if self.kind == "normal":
            return self.scale * rng.standard_normal(dimension)
        direction = rng.standard_normal(dimension)
        direction /= np.linalg.norm(direction)
        u = rng.uniform()
        if self.kind == "uniform":
            return self.scale * u ** (1.0 / dimension) * direction
        from scipy.stats import chi

        law = chi(dimension)  # |x|/σ of a Gaussian vector; inverse CDF of its cut part
        return self.scale * float(law.ppf(u * law.cdf(self._cut()))) * direction

    def _cut(self) -> float:
        """The truncation, in σ, of the truncated normal law."""
        if self.truncation is None:
            raise ValueError(f"a {self.kind} law has no truncation")
        return self.truncation

    def describe(self, unit: str = "") -> str:
        scale = np.atleast_1d(self.scale)
        shown = ", ".join(f"{s:.6g}" for s in scale)
        shown = f"[{shown}]" if scale.size > 1 else shown
        what = {"normal": "σ", "uniform": "±", "truncated_normal": "σ"}[self.kind]
        text = f"{self.kind} {what} {shown}{' ' + unit if unit else ''}"
        if self.relative:
            text = f"{self.kind} {what} {shown} (relative)"
        if self.truncation is not None:
            text += f", cut at ±{self.truncation:g} σ"
        return text


@dataclass(frozen=True)
class EventDispersion:
    """The dispersions of ``events[index]``: its time, impulse magnitude and direction."""

    index: int
    time: Distribution | None = None
    magnitude: Distribution | None = None
    direction: Distribution | None = None


@dataclass(frozen=True)
class Dispersions:
    """A parsed ``[dispersions]`` table, with the nominal values the draws start from."""

    seed: int
    samples: int
    moments: Distribution | None = None
    axes: Distribution | None = None
    attitude: Distribution | None = None
    rate: Distribution | None = None
    rate_key: str = "angular_velocity"  # the initial state's rate key (the one given)
    events: tuple[EventDispersion, ...] = ()
    tle_epoch: Distribution | None = None
    # Nominal values, SI (from the loaded scenario, as the reader computed them).
    nominal: dict[str, Any] = field(default_factory=dict, repr=False)

    def distributions(self) -> list[Distribution]:
        """Every distribution the draws use."""
        found = [self.moments, self.axes, self.attitude, self.rate, self.tle_epoch]
        found += [d for e in self.events for d in (e.time, e.magnitude, e.direction)]
        return [d for d in found if d is not None]

    def parameter_names(self) -> list[str]:
        """The table's columns for the drawn parameters, in the order drawn."""
        names = []
        if self.moments is not None or self.axes is not None:
            names += [f"spacecraft.moment_{i}_kg_m2" for i in (1, 2, 3)]
        if self.moments is not None:
            names += [f"spacecraft.moment_{i}_relative_error" for i in (1, 2, 3)]
            names.append("spacecraft.inertia_draws")
        if self.axes is not None:
            names += [f"spacecraft.axes_rotation_{c}_deg" for c in _AXES]
        if self.attitude is not None:
            names += [f"initial_state.attitude_error_{c}_deg" for c in _AXES]
            names.append("initial_state.attitude_error_deg")
        if self.rate is not None:
            unit = _RATE_UNITS[self.rate_key]
            names += [f"initial_state.{self.rate_key}_{c}_{unit}" for c in _AXES]
            names += [f"initial_state.{self.rate_key}_error_{c}_{unit}" for c in _AXES]
        for item in self.events:
            key = f"events[{item.index}]"
            if item.time is not None:
                names += [f"{key}.offset_s", f"{key}.time_shift_s"]
            if item.magnitude is not None or item.direction is not None:
                names += [f"{key}.impulse_{c}_N_m_s" for c in _AXES]
            if item.magnitude is not None:
                names += [f"{key}.impulse_relative_error", f"{key}.impulse_draws"]
            if item.direction is not None:
                names.append(f"{key}.impulse_tilt_deg")
        if self.tle_epoch is not None:
            names.append("pointing.tle_epoch_shift_s")
        return names

    def describe(self) -> list[str]:
        """One line per dispersed quantity, for ``attitude check`` and the report."""
        lines = []
        if self.moments is not None:
            lines.append(f"spacecraft.principal_moments: {self.moments.describe()}")
        if self.axes is not None:
            lines.append(f"spacecraft.principal_axes: {_angle_text(self.axes)}")
        if self.attitude is not None:
            lines.append(f"initial_state.attitude: {_angle_text(self.attitude)}")
        if self.rate is not None:
            rate, unit = self.rate, "N m s"
            if self.rate_key == "angular_velocity":  # in deg/s, as check shows rates
                rate = Distribution(rate.kind, np.degrees(rate.scale), rate.truncation)
                unit = "deg/s"
            lines.append(f"initial_state.{self.rate_key}: {rate.describe(unit)}")
        for item in self.events:
            key = f"events[{item.index}]"
            if item.time is not None:
                lines.append(f"{key}.time: {item.time.describe('s')}")
            if item.magnitude is not None:
                lines.append(f"{key}.impulse_magnitude: {item.magnitude.describe()}")
            if item.direction is not None:
                lines.append(f"{key}.impulse_direction: {_angle_text(item.direction)}")
        if self.tle_epoch is not None:
            lines.append(f"pointing.tle_epoch: {self.tle_epoch.describe('s')}")
        return lines


_RATE_UNITS = {"angular_velocity": "rad_s", "angular_momentum": "N_m_s"}


def _angle_text(distribution: Distribution) -> str:
    degrees = Distribution(
        distribution.kind, math.degrees(float(distribution.scale)), distribution.truncation
    )
    return degrees.describe("deg")


# ---------------------------------------------------------------------------- reading


def _integer_error(value: Any, low: int, high: int) -> str | None:
    """Why ``value`` is not a whole number in [low, high] (one rule for the file's keys
    and the command line's options), or None."""
    if not isinstance(value, int) or isinstance(value, bool):
        return f"expected a whole number, got {value!r}"
    if not low <= value <= high:
        return f"must be between {low} and {high:,}, got {value!r}"
    return None


def _integer(table: Table, key: str, low: int, high: int) -> int:
    value = table.raw(key)
    error = _integer_error(value, low, high)
    if error:
        table.fail(error, key, value)
    return value


def _option(value: Any, option: str, low: int, high: int) -> int:
    """A command-line option's whole number, by the rule of the file's key it replaces."""
    error = _integer_error(value, low, high)
    if error:
        raise ScenarioFileError(error, key=option, value=value)
    return value


def _distribution(
    table: Table,
    key: str,
    kind: str,
    *,
    relative: bool = False,
    per_component: bool = False,
    isotropic: bool = False,
) -> Distribution | None:
    """The distribution at ``table.key`` (None if absent), its scale in SI units of
    ``kind`` (a fraction if ``relative``), one number or three (``per_component``)."""
    sub = table.table(key, required=False)
    if sub is None:
        return None
    name = sub.choice("distribution", DISTRIBUTIONS)
    scale_key = ("relative_" if relative else "") + ("half_width" if name == "uniform" else "sigma")
    keys = ["distribution", scale_key] + (["truncation"] if name == "truncated_normal" else [])
    sub.allow(*keys)
    raw = sub.raw(scale_key)
    given = raw.get("value") if isinstance(raw, dict) else raw
    shape = (3,) if per_component and isinstance(given, list) else ()
    scale = sub.quantity(scale_key, "dimensionless" if relative else kind, shape)
    if not np.all(np.asarray(scale) > 0.0):
        sub.fail(
            f"must be positive (leave {table.where(key)} out to keep the nominal value), "
            f"got {sub.written_text(scale_key)}",
            scale_key,
        )
    if relative and not np.all(np.asarray(scale) < 1.0):
        sub.fail(
            f"is a fraction of the nominal value and must be below 1 (100 %), got "
            f"{sub.written_text(scale_key)}",
            scale_key,
        )
    if isotropic and float(scale) > _MAX_ANGLE_RAD:
        sub.fail(
            f"must be at most 180 deg (a small rotation), got {sub.written_text(scale_key)}",
            scale_key,
        )
    truncation = None
    if name == "truncated_normal":
        truncation = sub.quantity("truncation", "dimensionless", ())
        if not 0.01 <= truncation <= 100.0:
            sub.fail(f"is in σ and must be between 0.01 and 100, got {truncation!r}", "truncation")
    return Distribution(name, scale, truncation, relative)


def read_dispersions(
    loaded: ScenarioFile, samples: int | None = None, seed: int | None = None
) -> Dispersions:
    """The ``[dispersions]`` table of ``loaded`` (a :class:`ScenarioFileError` naming the
    file, the key and the value for anything wrong); ``samples`` and ``seed`` replace
    the table's own (the command line's ``--samples`` and ``--seed``)."""
    root = Table(loaded.path, "", loaded.document)
    table = root.table("dispersions", required=False)
    if table is None:
        raise ScenarioFileError(
            "missing table: add one with the seed, the sample "
            "count and what to disperse (docs/scenarios.md)",
            key="dispersions",
            file=loaded.path.name,
        )
    table.allow("seed", "samples", "spacecraft", "initial_state", "events", "pointing")
    seed, samples = _seed_and_samples(table, seed, samples)
    nominal = _nominal_values(loaded, root)
    moments, axes_rotation = _spacecraft_dispersions(table, loaded)
    attitude, rate, rate_key = _initial_state_dispersions(table, loaded, nominal)
    events = _event_dispersions(table, loaded, nominal)
    tle_epoch = _pointing_dispersions(table, loaded, nominal)
    return Dispersions(
        seed,
        samples,
        moments,
        axes_rotation,
        attitude,
        rate,
        rate_key,
        events,
        tle_epoch,
        nominal,
    )


def _seed_and_samples(table: Table, seed: int | None, samples: int | None) -> tuple[int, int]:
    """The seed and the sample count: the command line's if given, else the table's."""
    if seed is None:
        seed = _integer(table, "seed", 0, MAX_SEED)
    else:
        seed = _option(seed, "--seed", 0, MAX_SEED)
    if samples is None:
        samples = _integer(table, "samples", 1, MAX_SAMPLES)
    else:
        samples = _option(samples, "--samples", 1, MAX_SAMPLES)
    return seed, samples


def _nominal_values(loaded: ScenarioFile, root: Table) -> dict[str, Any]:
    """The nominal inertia and attitude the draws start from, SI, as the reader computed
    them (the rate, the events and the TLE are added where they are dispersed)."""
    axes = loaded.scenario.spacecraft.principal_axes
    nominal: dict[str, Any] = {
        "moments": axes.moments,
        "body_to_principal": axes.body_to_principal.as_matrix(),
        "tensor_given": "inertia_tensor" in loaded.document.get("spacecraft", {}),
        "attitude": loaded.scenario.initial_state.attitude,
    }
    if loaded.document.get("initial_state", {}).get("frame", "icrf") != "icrf":
        # The attitude in the orbit frame the file gives it in (the reader refuses a
        # frame with an AEM file, so it is a quaternion or a matrix).
        nominal["attitude"] = read_rotation(
            root.table("initial_state"), "body -> the table's frame", False
        )  # the attitude as the file gives it
    return nominal


def _spacecraft_dispersions(
    table: Table, loaded: ScenarioFile
) -> tuple[Distribution | None, Distribution | None]:
    """``[dispersions.spacecraft]``: the moments' and the principal axes' distributions."""
    craft = table.table("spacecraft", required=False)
    if craft is None:
        return None, None
    craft.allow("principal_moments", "principal_axes")
    moments = _distribution(craft, "principal_moments", "", relative=True, per_component=True)
    axes_rotation = _distribution(craft, "principal_axes", "angle", isotropic=True)
    nominal_moments = loaded.scenario.spacecraft.principal_axes.moments
    if moments is not None and violates_triangle_inequality(nominal_moments):
        craft.fail(
            f"the nominal moments {nominal_moments.tolist()} kg m² break the triangle "
            "inequality: no body near them is physical",
            "principal_moments",
        )
    return moments, axes_rotation


def _initial_state_dispersions(
    table: Table, loaded: ScenarioFile, nominal: dict[str, Any]
) -> tuple[Distribution | None, Distribution | None, str]:
    """``[dispersions.initial_state]``: the attitude's and the rate's distributions, and
    the rate's key (the one the initial state gives)."""
    attitude = rate = None
    rate_key = "angular_velocity"
    initial = table.table("initial_state", required=False)
    if initial is None:
        return attitude, rate, rate_key
    initial.allow("attitude", "angular_velocity", "angular_momentum")
    state = loaded.scenario.initial_state
    if state.law is not None:
        initial.fail(
            "the initial state is a law ([initial_state.law]): it sets the attitude and the "
            "rate, and has nothing to disperse"
        )
    attitude = _distribution(initial, "attitude", "angle", isotropic=True)
    for key in ("angular_velocity", "angular_momentum"):
        if not initial.has(key):
            continue
        if getattr(state, key) is None:
            other = "angular_momentum" if key == "angular_velocity" else "angular_velocity"
            initial.fail(f"the initial state gives {other}: disperse that instead", key)
        rate = _distribution(initial, key, key, per_component=True)
        rate_key = key
        nominal["rate"] = getattr(state, key)
    return attitude, rate, rate_key


def _pointing_dispersions(
    table: Table, loaded: ScenarioFile, nominal: dict[str, Any]
) -> Distribution | None:
    """``[dispersions.pointing]``: the TLE epoch's distribution."""
    pointing = table.table("pointing", required=False)
    if pointing is None:
        return None
    pointing.allow("tle_epoch")
    tle_epoch = _distribution(pointing, "tle_epoch", "time")
    if tle_epoch is not None and loaded.pointing.tle is None:
        pointing.fail("the scenario has no [pointing] tle to disperse", "tle_epoch")
    nominal["tle"] = loaded.pointing.tle
    return tle_epoch


def _event_dispersions(
    table: Table, loaded: ScenarioFile, nominal: dict[str, Any]
) -> tuple[EventDispersion, ...]:
    scenario = loaded.scenario
    # Each event's offset (TT s after the epoch) as the reader computed it, by its index
    # in the file: an event given by its ISO epoch is written back as this offset.
    offsets = dict(zip(scenario.event_indices, (t for t, _ in scenario.events), strict=True))
    by_index = dict(zip(scenario.event_indices, (e for _, e in scenario.events), strict=True))
    found = []
    seen: set[int] = set()
    for item in table.tables("events"):
        item.allow("event", "time", "impulse_magnitude", "impulse_direction")
        if not offsets:
            item.fail("the scenario has no [[events]] to disperse")
        index = _integer(item, "event", 0, len(offsets) - 1)
        if index in seen:
            item.fail(f"events[{index}] is dispersed twice", "event")
        seen.add(index)
        event = by_index[index]
        time = _distribution(item, "time", "time")
        magnitude = _distribution(item, "impulse_magnitude", "", relative=True)
        direction = _distribution(item, "impulse_direction", "angle", isotropic=True)
        if (magnitude or direction) and event.kind != "angular_impulse":
            key = "impulse_magnitude" if magnitude else "impulse_direction"
            item.fail(f"events[{index}] is an {event.kind}, not an angular_impulse", key)
        if (
            direction is not None
            and isinstance(event, AngularImpulse)
            and not np.any(event.impulse)
        ):
            item.fail(f"events[{index}].impulse is zero: it has no direction", "impulse_direction")
        nominal[f"events[{index}]"] = {
            "offset": offsets[index],
            "impulse": getattr(event, "impulse", None),
        }
        found.append(EventDispersion(index, time, magnitude, direction))
    return tuple(found)


# ---------------------------------------------------------------------------- drawing


@dataclass
class Sample:
    """Sample ``index``: its drawn parameters (the table's columns) and its document."""

    index: int
    parameters: dict[str, float]
    document: dict[str, Any]
    error: str | None = None  # a draw that could not be made physical


def _generator(seed: int, index: int, key: str) -> np.random.Generator:
    """The stream of sample ``index`` for the quantity at ``key`` (see the module doc)."""
    sequence = np.random.SeedSequence(seed, spawn_key=(index, zlib.crc32(key.encode())))
    return np.random.Generator(np.random.PCG64(sequence))


def _floats(values: Any) -> Any:
    """Python floats (nested lists) for the TOML document."""
    return np.asarray(values, dtype=float).tolist()


def _copy_for_sample(document: dict[str, Any]) -> dict[str, Any]:
    """A copy of each table a sample changes (their values are replaced, never changed
    in place): the nominal document stays as read.  The ``[dispersions]`` table is left out."""
    doc = {key: value for key, value in document.items() if key != "dispersions"}
    for key in ("spacecraft", "initial_state", "pointing"):
        if key in doc:
            doc[key] = dict(doc[key])
    if "events" in doc:
        doc["events"] = [dict(event) for event in doc["events"]]
    return doc


def _record(parameters: dict[str, float], name: str, values: Any) -> None:
    """One column for a scalar; one per axis (``name`` formatted with x, y, z) for a vector."""
    values = np.atleast_1d(np.asarray(values, dtype=float))
    if values.size == 1:
        parameters[name] = float(values[0])
        return
    for c, value in zip(_AXES, values, strict=True):
        parameters[name.format(c)] = float(value)


def draw_sample(dispersions: Dispersions, document: dict[str, Any], index: int) -> Sample:
    """Sample ``index``: the nominal ``document`` with its dispersed keys drawn."""
    doc = _copy_for_sample(document)
    parameters: dict[str, float] = {}
    error = None
    if dispersions.moments is not None or dispersions.axes is not None:
        error = _draw_inertia(dispersions, index, doc["spacecraft"], parameters)
    _draw_initial_state(dispersions, index, doc["initial_state"], parameters)
    for item in dispersions.events:
        event_error = _draw_event(dispersions, index, item, doc["events"][item.index], parameters)
        error = error or event_error
    if dispersions.tle_epoch is not None:
        _draw_tle_epoch(dispersions, index, doc["pointing"], parameters)
    return Sample(index, parameters, doc, error)


def _draw_inertia(
    d: Dispersions, index: int, craft: dict[str, Any], parameters: dict[str, float]
) -> str | None:
    """The moments I' = I (1 + ε), drawn again until physical, and the axes turned by E:
    T' = E Vᵀ diag(I') V Eᵀ (module doc), written to ``craft``; the error if no draw
    of the moments was physical."""
    nominal = d.nominal
    moments = nominal["moments"]
    error = None
    if d.moments is not None:
        rng = _generator(d.seed, index, "spacecraft.principal_moments")
        for draws in range(1, MAX_DRAWS + 1):  # noqa: B007 (the count is recorded)
            ε = d.moments.components(rng, 3)
            moments = nominal["moments"] * (1.0 + ε)
            if _physical(moments):
                break
        else:
            error = (
                f"spacecraft.principal_moments: no physical draw in {MAX_DRAWS} tries "
                f"(last {moments.tolist()} kg m²)"
            )
    for i, value in enumerate(moments, start=1):
        parameters[f"spacecraft.moment_{i}_kg_m2"] = float(value)
    if d.moments is not None:
        for i, value in enumerate(ε, start=1):
            parameters[f"spacecraft.moment_{i}_relative_error"] = float(value)
        parameters["spacecraft.inertia_draws"] = float(draws)
    if d.axes is not None or nominal["tensor_given"]:
        turn = np.eye(3)
        if d.axes is not None:
            δ = d.axes.isotropic(_generator(d.seed, index, "spacecraft.principal_axes"), 3)
            _record(parameters, "spacecraft.axes_rotation_{}_deg", np.degrees(δ))
            turn = Rotation.from_rotvec(δ).as_matrix()
        v = nominal["body_to_principal"]  # principal = V body
        tensor = turn @ v.T @ np.diag(moments) @ v @ turn.T
        craft.pop("principal_moments", None)
        craft["inertia_tensor"] = _floats(0.5 * (tensor + tensor.T))
    else:
        craft["principal_moments"] = _floats(moments)
    return error


def _draw_initial_state(
    d: Dispersions, index: int, state: dict[str, Any], parameters: dict[str, float]
) -> None:
    """The attitude R' = R exp(δ) in the file's frame, and the rate plus its deviation,
    written to ``state``."""
    nominal = d.nominal
    if d.attitude is not None:
        δ = d.attitude.isotropic(_generator(d.seed, index, "initial_state.attitude"), 3)
        _record(parameters, "initial_state.attitude_error_{}_deg", np.degrees(δ))
        parameters["initial_state.attitude_error_deg"] = math.degrees(float(np.linalg.norm(δ)))
        attitude = nominal["attitude"] * Rotation.from_rotvec(δ)  # in the file's frame
        state.pop("matrix", None)
        state.pop("aem", None)  # an AEM's attitude: written as the ICRF quaternion it gave
        state["quaternion"] = _floats(attitude.as_quat(scalar_first=True))
    if d.rate is not None:
        key = d.rate_key
        deviation = d.rate.components(_generator(d.seed, index, f"initial_state.{key}"), 3)
        rate = nominal["rate"] + deviation
        unit = _RATE_UNITS[key]
        _record(parameters, f"initial_state.{key}_{{}}_{unit}", rate)
        _record(parameters, f"initial_state.{key}_error_{{}}_{unit}", deviation)
        state[key] = _floats(rate)


def _draw_event(
    d: Dispersions,
    index: int,
    item: EventDispersion,
    event: dict[str, Any],
    parameters: dict[str, float],
) -> str | None:
    """``events[item.index]``: its time shifted, its impulse scaled by 1 + ε (drawn again
    until positive) and tilted by θ across its direction, n' = exp(θ) n, written to
    ``event``; the error if no draw of the magnitude was positive."""
    key = f"events[{item.index}]"
    values = d.nominal[key]
    if item.time is not None:
        shift = float(item.time.components(_generator(d.seed, index, f"{key}.time"), 1)[0])
        event.pop("epoch", None)
        event["offset"] = values["offset"] + shift
        parameters[f"{key}.offset_s"] = event["offset"]
        parameters[f"{key}.time_shift_s"] = shift
    if item.magnitude is None and item.direction is None:
        return None
    impulse = values["impulse"]
    ε: float | None = None
    draws = 0
    tilt: NDArray[np.float64] | None = None
    error: str | None = None
    if item.magnitude is not None:
        rng = _generator(d.seed, index, f"{key}.impulse_magnitude")
        for draws in range(1, MAX_DRAWS + 1):  # noqa: B007 (the count is recorded)
            relative = float(item.magnitude.components(rng, 1)[0])
            if 1.0 + relative > 0.0:
                break
        else:
            error = f"{key}.impulse_magnitude: no positive draw in {MAX_DRAWS} tries"
        ε = relative
        impulse = impulse * (1.0 + relative)
    if item.direction is not None:
        rng = _generator(d.seed, index, f"{key}.impulse_direction")
        tilt = item.direction.isotropic(rng, 2)
        e1, e2 = basis_across(values["impulse"] / np.linalg.norm(values["impulse"]))
        impulse = Rotation.from_rotvec(tilt[0] * e1 + tilt[1] * e2).apply(impulse)
    _record(parameters, f"{key}.impulse_{{}}_N_m_s", impulse)
    if ε is not None:
        parameters[f"{key}.impulse_relative_error"] = ε
        parameters[f"{key}.impulse_draws"] = float(draws)
    if tilt is not None:
        parameters[f"{key}.impulse_tilt_deg"] = math.degrees(float(np.linalg.norm(tilt)))
    event["impulse"] = _floats(impulse)
    return error


def _draw_tle_epoch(
    d: Dispersions, index: int, pointing: dict[str, Any], parameters: dict[str, float]
) -> None:
    """The TLE epoch moved by s seconds (rounded to the 1e-8 day the line writes)."""
    law = d.tle_epoch
    if law is None:
        raise ValueError("the dispersions move no TLE epoch")
    shift = float(law.components(_generator(d.seed, index, "pointing.tle_epoch"), 1)[0])
    tle = d.nominal["tle"]
    line1, applied = shifted_tle_epoch(tle[0], shift)
    pointing["tle"] = [line1, tle[1]]
    parameters["pointing.tle_epoch_shift_s"] = applied


def _physical(moments: NDArray[np.float64]) -> bool:
    """Positive moments that satisfy the triangle inequality, exactly (no tolerance)."""
    low, mid, high = np.sort(moments)
    return bool(low > 0.0 and low + mid >= high)


def shifted_tle_epoch(line1: str, shift_s: float) -> tuple[str, float]:
    """TLE line 1 with its epoch moved by ``shift_s`` seconds (rounded to the 1e-8 day
    the line writes, across a year's end if need be) and its checksum recomputed; and
    the shift applied, s.  Columns 19–32 hold the epoch, YYDDD.DDDDDDDD (day 1.0 is
    1 January, 0 h); two-digit years 57–99 are 1957–1999, 00–56 are 2000–2056."""
    from sgp4.io import compute_checksum

    yy, days = int(line1[18:20]), float(line1[20:32])
    year = 1900 + yy if yy >= 57 else 2000 + yy
    start = _days_before(year) + days  # days since 1957 January 0
    moved = start + shift_s / 86400.0
    new_year = year
    while moved < _days_before(new_year) + 1.0:
        new_year -= 1
    while moved >= _days_before(new_year + 1) + 1.0:
        new_year += 1
    new_days = round(moved - _days_before(new_year), 8)
    if new_days >= _days_before(new_year + 1) - _days_before(new_year) + 1.0:
        new_days = round(new_days - (_days_before(new_year + 1) - _days_before(new_year)), 8)
        new_year += 1  # rounded up onto the next year's first instant
    if not 1957 <= new_year <= 2056:
        raise InputError(
            f"a shift of {shift_s:g} s moves the TLE epoch to {new_year}, "
            "which a TLE cannot write (1957-2056)",
            key="dispersions.pointing.tle_epoch",
            value=shift_s,
        )
    text = f"{line1[:18]}{new_year % 100:02d}{new_days:012.8f}{line1[32:68]}"
    applied = (_days_before(new_year) + new_days - start) * 86400.0
    return text + str(compute_checksum(text)), applied


def _days_before(year: int) -> int:
    """Days from 1957 January 0 to ``year`` January 0 (the Gregorian leap rule)."""
    return sum(
        366 if (y % 4 == 0 and y % 100 != 0) or y % 400 == 0 else 365 for y in range(1957, year)
    )
