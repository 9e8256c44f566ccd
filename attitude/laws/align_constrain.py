"""The general attitude law, align-and-constrain, and what every law is and gives.

**Align and constrain** (the two-vector or TRIAD attitude; M. D. Shuster and S. D.
Oh, "Three-axis attitude determination from vector observations", *J. Guidance and
Control* 4(1), 1981, the TRIAD frame; Orekit's ``AlignedAndConstrained``): a primary
body vector b₁ is put exactly on a primary direction d₁(t), and a secondary body
vector b₂ as close as it can then be to a secondary direction d₂(t): the plane of
(b₁, b₂) goes onto the plane of (d₁, d₂), with b₂ on d₂'s side of d₁.  With the
orthonormal triads

    T = [d̂₁, n̂, d̂₁ × n̂],  n̂ = (d₁ × d₂)/|d₁ × d₂|      (the directions, ICRF)
    B = [b̂₁, m̂, b̂₁ × m̂],  m̂ = (b₁ × b₂)/|b₁ × b₂|      (the body vectors, body axes)

the attitude (body → ICRF) is R = T Bᵀ.  b₂ lies exactly on d₂ only when the angle
(b₁, b₂) equals the angle (d₁, d₂); otherwise it is at the nearest angle the primary
allows.

**Rates, analytic.**  The directions come as jets (value, first and second derivative,
:mod:`attitude.base.jets`), so T's columns e_k do too, through the normalizations and
cross products.  For an orthonormal frame ė_k = ω × e_k, hence

    ω = ½ Σ_k e_k × ė_k,    α = ω̇ = ½ Σ_k e_k × ë_k        (inertial axes),

and in body axes ω_B = Rᵀ ω, α_B = Rᵀ α (the body-axes derivative of ω_B is Rᵀ ω̇,
since ω × ω = 0).  ω_B is what the body carries into free motion, I·ω_B its momentum.
No finite difference is taken (except of an orbit source that has no analytic
derivatives: :mod:`attitude.laws.orbit_derivatives`); the accuracy is that of the
inputs' derivatives and of rounding (``tests/test_law_rates_against_mpmath.py``).

**Degenerate cases** (never a NaN):

- body vectors parallel (within :data:`PARALLEL_LIMIT_RAD`): refused when the law is
  made (:class:`attitude.base.errors.InputError`);
- the same direction twice, or a direction and its opposite, or geodetic nadir with
  the Earth's centre (within 0.2° of each other everywhere): refused when the law is
  made;
- the two directions parallel at some epoch (within :data:`PARALLEL_LIMIT_RAD`, where
  rounding alone would turn the attitude about d₁ by more than 1e-10 rad and the rate
  about d₁ exceeds 10⁶ times the directions' own rates): :class:`DegenerateLawError`
  naming the epoch, the law and the angle.  :meth:`BoundLaw.separation` gives the angle
  at any epochs, so that a run can find its least value over a span beforehand;
- a direction with no length (the ground velocity of a geostationary orbit):
  :class:`DegenerateLawError` too.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.base.jets import Jet, cross, normalized
from attitude.environment.timescales import (
    as_time,
    iso_texts,
    offline_time,
    time_from_tt_seconds,
    tt_seconds,
)
from attitude.laws.directions import Direction, FixedDirection, Opposite, direction
from attitude.laws.inputs import INPUTS, InputsAt, LawInputs

__all__ = [
    "PARALLEL_LIMIT_RAD",
    "AlignConstrainLaw",
    "AttitudeLaw",
    "BoundLaw",
    "DegenerateLawError",
    "LawState",
    "body_vector",
]

# Below this angle two vectors count as parallel (see the module notes).
PARALLEL_LIMIT_RAD = 1e-6
_AXES = {"x": 0, "y": 1, "z": 2}


class DegenerateLawError(InputError):
    """A law is undefined at an epoch: its two directions are parallel there, or one
    has no length.  The message names the law, the epoch and the reason."""


@dataclass(frozen=True)
class LawState:
    """A law's attitude and its derivatives at some epochs.

    ``seconds``: TT seconds after the epoch the law was bound to; ``attitude``: body →
    ICRF (scipy ``Rotation``, one per epoch); ``angular_velocity`` (rad/s) and
    ``angular_acceleration`` (rad/s²): body axes, (n, 3).
    """

    seconds: NDArray[np.float64]
    attitude: Rotation
    angular_velocity: NDArray[np.float64]
    angular_acceleration: NDArray[np.float64]

    @property
    def angular_velocity_inertial(self) -> NDArray[np.float64]:
        """ω in ICRF axes, (n, 3) rad/s."""
        return self.attitude.apply(self.angular_velocity)

    @property
    def angular_acceleration_inertial(self) -> NDArray[np.float64]:
        """ω̇ in ICRF axes (the same vector as the body-axes one, rotated), (n, 3)."""
        return self.attitude.apply(self.angular_acceleration)


def body_vector(value: Any, name: str) -> NDArray[np.float64]:
    """A body vector as a unit 3-vector: ``"x"``, ``"+y"``, ``"-z"``, or 3 numbers."""
    if isinstance(value, str):
        text = value.strip().lower()
        sign = -1.0 if text.startswith("-") else 1.0
        axis = text.lstrip("+-")
        if axis not in _AXES:
            raise InputError(
                f"{name}: expected x, y, z with an optional sign, or 3 numbers, got {value!r}"
            )
        unit = np.zeros(3)
        unit[_AXES[axis]] = sign
        return unit
    from attitude.base.quantities import as_vector3

    v = as_vector3(value, "dimensionless", name)
    length = float(np.linalg.norm(v))
    if not length > 0.0:
        raise InputError(f"{name}: a body vector must not be zero, got {v.tolist()}")
    return v / length


def _angle(u: NDArray[np.float64], v: NDArray[np.float64]) -> float:
    return float(np.arctan2(np.linalg.norm(np.cross(u, v)), np.dot(u, v)))


class AttitudeLaw(ABC):
    """What every attitude law is: a rule giving, from the inputs it names (:attr:`needs`,
    among :data:`attitude.laws.inputs.INPUTS`), the attitude at any epoch with its
    angular velocity and acceleration.

    Use :meth:`bind` to fix the epoch, span and orbit once and evaluate many times
    (:class:`BoundLaw`), or :meth:`state` for a one-off evaluation at astropy Times.
    """

    name: str = "law"

    @property
    @abstractmethod
    def needs(self) -> frozenset[str]:
        """The inputs the law reads (keys of :data:`attitude.laws.inputs.INPUTS`)."""

    @abstractmethod
    def evaluate(self, at: InputsAt) -> LawState:
        """The state at ``at``'s epochs."""

    @abstractmethod
    def describe(self) -> str:
        """The law in one line (for ``check`` and the summary)."""

    def check_inputs(self, orbit: Any = None, key: str = "law") -> None:
        """Refuse, in one line naming ``key``, a law that needs an orbit when there is
        none.  (The Sun, the Moon and the Earth's rotation are always available.)"""
        if "orbit" in self.needs and orbit is None:
            raise InputError(
                f"the {self.name} law ({self.describe()}) needs {INPUTS['orbit']}, "
                "and the scenario has none",
                key=key,
            )

    def bind(
        self, epoch: Any, start_s: float, stop_s: float, orbit: Any = None, key: str = "law"
    ) -> BoundLaw:
        """The law over [start_s, stop_s] TT seconds after ``epoch`` (a ``Time``), on
        ``orbit`` (None: the spacecraft at the Earth's centre, for laws that need no
        orbit).  Refuses a law that needs an orbit when there is none."""
        self.check_inputs(orbit, key)
        return BoundLaw(self, LawInputs(epoch, start_s, stop_s, orbit, self.needs), key)

    def state(self, times: Any, orbit: Any = None, *, epoch: Any = None) -> LawState:
        """The state at ``times``: ``astropy.time.Time`` (any shape, flattened), or TT
        seconds after ``epoch``.  ``LawState.seconds`` count from ``epoch`` (default:
        the first of ``times``)."""
        if epoch is None:
            if isinstance(times, str) or hasattr(times, "jd1"):
                times = as_time(times, name="times")
                epoch = times.ravel()[0] if times.ndim else times
            else:
                raise InputError("times: give astropy Times, or seconds with an epoch")
        epoch = as_time(epoch, name="epoch")
        if hasattr(times, "jd1"):
            seconds = np.ravel(tt_seconds(times, epoch))
        else:
            from attitude.base.quantities import as_si_array

            seconds = np.ravel(as_si_array(times, "time", "times"))
        if seconds.size == 0:
            raise InputError("times: no epoch given")
        bound = self.bind(epoch, float(seconds.min()), float(seconds.max()), orbit)
        return bound.state(seconds)


class BoundLaw:
    """A law bound to an epoch, a span and an orbit: evaluate it at TT seconds after
    the epoch, inside the span.  :attr:`notes` says what the user should know about
    the inputs (the Earth orientation table's coverage)."""

    def __init__(self, law: AttitudeLaw, inputs: LawInputs, key: str = "law") -> None:
        self.law = law
        self.inputs = inputs
        self.key = key

    @property
    def epoch(self):
        return self.inputs.epoch

    @property
    def notes(self) -> list[str]:
        return [f"{self.key}: {note}" for note in self.inputs.notes()]

    def at(self, seconds: ArrayLike) -> InputsAt:
        return self.inputs.at(seconds)

    def state(self, seconds: ArrayLike) -> LawState:
        """Attitude, angular velocity and acceleration (body axes) at TT seconds."""
        at = self.inputs.at(seconds)
        try:
            return self.law.evaluate(at)
        except DegenerateLawError as error:
            raise error.located(key=self.key) from None

    def attitude(self, seconds: ArrayLike) -> Rotation:
        return self.state(seconds).attitude

    def separation(self, seconds: ArrayLike) -> NDArray[np.float64]:
        """For an align-and-constrain law, the angle (rad) between its primary and
        secondary directions at TT seconds: the law is undefined where it reaches
        :data:`PARALLEL_LIMIT_RAD`, and its rate about the primary grows as it shrinks."""
        law = self.law
        if not isinstance(law, AlignConstrainLaw):
            raise InputError(f"the {law.name} law has no pair of directions", key=self.key)
        at = self.inputs.at(seconds)
        d1 = law.primary.vector(at).value
        d2 = law.secondary.vector(at).value
        return np.arctan2(np.linalg.norm(np.cross(d1, d2), axis=-1), np.sum(d1 * d2, axis=-1))

    def epoch_text(self, seconds: float) -> str:
        """An epoch as ISO text in the epoch's scale (for messages)."""
        return _epoch_text(self.inputs.epoch, seconds)


def _same_or_opposite(a: Direction, b: Direction) -> str | None:
    """Why two directions cannot make a pair, or None."""
    base_a = a.inner if isinstance(a, Opposite) else a
    base_b = b.inner if isinstance(b, Opposite) else b
    if base_a == base_b:
        return "they are the same direction" if type(a) is type(b) else "they are opposite"
    names = {base_a.name, base_b.name}
    if names == {"nadir", "earth_centre"} and not isinstance(base_a, FixedDirection):
        return "geodetic nadir and the Earth's centre are within 0.2 deg of each other everywhere"
    if isinstance(base_a, FixedDirection) and isinstance(base_b, FixedDirection):
        angle = _angle(base_a.unit, base_b.unit)
        if min(angle, math.pi - angle) < PARALLEL_LIMIT_RAD:
            return f"the two fixed directions are {math.degrees(angle):.3g} deg apart"
    return None


class AlignConstrainLaw(AttitudeLaw):
    """Primary body vector on the primary direction; secondary body vector as close as
    possible to the secondary direction (see the module notes).

    Body vectors: ``"x"``, ``"-y"``, … or 3 numbers (body axes, any length).
    Directions: a name of :data:`attitude.laws.directions.NAMED_DIRECTIONS` (``"sun"``,
    ``"moon"``, ``"nadir"``, ``"earth_centre"``, ``"velocity"``, ``"orbit_normal"``,
    ``"ground_velocity"``, with ``-`` for the opposite), a :class:`GroundSite`,
    :class:`CelestialTarget` or :class:`FixedDirection`, or a fixed ICRF 3-vector.
    """

    name = "align_constrain"

    def __init__(
        self,
        primary_axis: Any,
        primary_direction: Any,
        secondary_axis: Any,
        secondary_direction: Any,
    ) -> None:
        self.primary_axis = body_vector(primary_axis, "primary_axis")
        self.secondary_axis = body_vector(secondary_axis, "secondary_axis")
        angle = _angle(self.primary_axis, self.secondary_axis)
        if min(angle, math.pi - angle) < PARALLEL_LIMIT_RAD:
            raise InputError(
                f"{self.name}: the primary and secondary body vectors are parallel "
                f"({math.degrees(angle):.6g} deg apart): the rotation about the primary "
                "would be undefined"
            )
        self.primary = direction(primary_direction)
        self.secondary = direction(secondary_direction)
        why = _same_or_opposite(self.primary, self.secondary)
        if why:
            raise InputError(
                f"{self.name}: the primary direction ({self.primary.describe()}) and the "
                f"secondary direction ({self.secondary.describe()}) cannot make a pair: {why}"
            )
        m = np.cross(self.primary_axis, self.secondary_axis)
        m /= np.linalg.norm(m)
        # The body triad B (columns), constant.
        self._body = np.stack([self.primary_axis, m, np.cross(self.primary_axis, m)], axis=-1)

    @property
    def needs(self) -> frozenset[str]:
        return self.primary.needs | self.secondary.needs

    def describe(self) -> str:
        return (
            f"body {_vector_text(self.primary_axis)} on {self.primary.describe()}, body "
            f"{_vector_text(self.secondary_axis)} towards {self.secondary.describe()}"
        )

    def parameters(self) -> dict[str, Any]:
        """The law's definition as plain values (for summaries and files)."""
        return {
            "primary_axis": self.primary_axis.tolist(),
            "primary_direction": self.primary.describe(),
            "secondary_axis": self.secondary_axis.tolist(),
            "secondary_direction": self.secondary.describe(),
        }

    def evaluate(self, at: InputsAt) -> LawState:
        d1 = self.primary.vector(at)
        d2 = self.secondary.vector(at)
        self._check(at, d1, d2)
        e1 = normalized(d1)
        e2 = normalized(cross(d1, d2))
        e3 = cross(e1, e2)
        triad = (e1, e2, e3)
        omega = 0.5 * sum(np.cross(e.c[0], e.c[1]) for e in triad)
        alpha = sum(np.cross(e.c[0], e.c[2]) for e in triad)  # ½ Σ e × ë, ë = 2 c₂
        target = np.stack([e.value for e in triad], axis=-1)  # T, (n, 3, 3)
        matrix = target @ self._body.T
        body_from_icrf = np.swapaxes(matrix, -1, -2)
        return LawState(
            at.seconds,
            Rotation.from_matrix(matrix),
            np.einsum("nij,nj->ni", body_from_icrf, omega),
            np.einsum("nij,nj->ni", body_from_icrf, alpha),
        )

    def _check(self, at: InputsAt, d1: Jet, d2: Jet) -> None:
        """Raise :class:`DegenerateLawError` at the first epoch where a direction has no
        length or the two are parallel."""
        n1 = np.linalg.norm(d1.value, axis=-1)
        n2 = np.linalg.norm(d2.value, axis=-1)
        for which, lengths in (("primary", n1), ("secondary", n2)):
            bad = ~(lengths > 0.0) | ~np.isfinite(lengths)
            if np.any(bad):
                raise DegenerateLawError(
                    f"the {self.name} law is undefined at {_epoch(at, int(np.argmax(bad)))}: "
                    f"the {which} direction ({getattr(self, which).describe()}) has no length there"
                )
        sin_angle = np.linalg.norm(np.cross(d1.value, d2.value), axis=-1) / (n1 * n2)
        bad = sin_angle < math.sin(PARALLEL_LIMIT_RAD)
        if np.any(bad):
            index = int(np.argmax(bad))
            cosine = float(np.dot(d1.value[index], d2.value[index]) / (n1[index] * n2[index]))
            angle = math.atan2(float(sin_angle[index]), cosine)
            raise DegenerateLawError(
                f"the {self.name} law is undefined at {_epoch(at, index)}: its primary "
                f"direction ({self.primary.describe()}) and secondary direction "
                f"({self.secondary.describe()}) are {angle:.3g} rad apart (parallel "
                f"within {PARALLEL_LIMIT_RAD:g} rad), so the rotation about the primary is not set"
            )


def _epoch_text(epoch: Any, seconds: float) -> str:
    """``seconds`` TT after ``epoch`` as ISO text in the epoch's scale."""
    with offline_time():
        when = getattr(time_from_tt_seconds(epoch, seconds), epoch.scale)
    return f"{iso_texts(when)} {epoch.scale.upper()}"


def _epoch(at: InputsAt, index: int) -> str:
    """The ``index``-th epoch of ``at``, for messages."""
    seconds = float(at.seconds[index])
    return f"{_epoch_text(at.inputs.epoch, seconds)} (t = {seconds:.9g} s)"


def _vector_text(v: NDArray[np.float64]) -> str:
    for axis, index in _AXES.items():
        for sign in (1.0, -1.0):
            if v[index] == sign and np.count_nonzero(v) == 1:
                return f"{'+' if sign > 0 else '-'}{axis}"
    return np.array2string(v, precision=6, separator=", ")
