"""What a law reads, at any epochs of its span: the orbit, the Sun and the Moon, the
Earth's rotation, each with its time derivatives (as :class:`attitude.base.jets.Jet`).

:class:`LawInputs` is made once per span (it samples the Sun and the Moon there, as the
pointing layer does: :class:`attitude.environment.ephemeris.SunMoonFromEarth`, nodes
every 600 s aligned on J2000); :meth:`LawInputs.at` gives :class:`InputsAt`, whose
quantities are computed on first use only, so a law pays for what it reads.

**Which Sun and Moon.**  The *apparent* places seen from the spacecraft: light time and
the aberration of the spacecraft's barycentric velocity (the Earth's 30 km/s plus its
own), the definition of the pointing layer
(:func:`attitude.environment.ephemeris.apparent_from_observer`, reproduced here on
jets: the same numbers to 1e-16, ``tests/test_law_inputs_against_pointing.py``).
Why: it is the direction a Sun sensor measures and the one the report's Sun angles
are computed from, so a Sun-pointed axis shows a Sun angle of zero in the report, not
the 25" of aberration a geometric Sun would leave; and the aberration turns with the
orbit (25" at the orbit's rate, 2.8e-8 rad/s in LEO), which is 10⁴ times the accuracy
asked of the rates: it is in the derivatives.  Without an orbit the observer is the
Earth's centre, as in the pointing layer.  The other directions (nadir, the Earth's
centre, the velocity, the orbit normal, ground sites, fixed directions) are
geometric: they are not seen through light.
"""

from __future__ import annotations

from functools import cached_property
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from attitude.base.errors import InputError
from attitude.base.jets import Jet, dot, matvec, norm, normalized, reciprocal, sqrt
from attitude.environment.earth_rotation import eop_note, itrs_to_gcrs
from attitude.environment.ephemeris import SunMoonFromEarth
from attitude.environment.timescales import SECONDS_PER_DAY, as_time, offline_time
from attitude.laws.orbit_derivatives import OrbitDerivatives, orbit_derivatives

__all__ = ["INPUTS", "InputsAt", "LawInputs", "apparent_vector"]

# What a law may need, with the words a refusal uses.
INPUTS = {
    "orbit": "an orbit ([pointing] tle, keplerian or oem)",
    "sun": "the Sun (DE421)",
    "moon": "the Moon (DE421)",
    "earth_rotation": "the Earth's rotation (IERS EOP)",
}
# Schwarzschild radius of the Sun (au), the speed of light (m/s), the au (m): ERFA's.
_SRS_AU = 1.97412574336e-8
_C_M_S = 299_792_458.0
_AU_M = 149_597_870_700.0
# An epoch this far outside the span (s) is still in it: TT seconds round at ~1e-12 s.
_SPAN_SLACK_S = 1e-6


class LawInputs:
    """The inputs of laws over [start_s, stop_s] TT seconds after ``epoch``.

    ``epoch``: ``astropy.time.Time`` (or ISO text, UTC); ``orbit``: an
    :class:`attitude.environment.orbit.Orbit` or None; ``needs``: which of
    :data:`INPUTS` will be read (the Sun and the Moon are sampled only if needed).
    """

    def __init__(
        self,
        epoch: Any,
        start_s: float,
        stop_s: float,
        orbit: Any = None,
        needs: frozenset[str] = frozenset(INPUTS),
    ) -> None:
        self.epoch = as_time(epoch)
        with offline_time():
            tt = self.epoch.tt
            self.jd1, self.jd2 = float(tt.jd1), float(tt.jd2)
        if not stop_s >= start_s:
            raise InputError(f"the span must end after it starts, got [{start_s}, {stop_s}] s")
        self.start_s, self.stop_s = float(start_s), float(stop_s)
        self.orbit = orbit
        self.needs = frozenset(needs)
        self._bodies: SunMoonFromEarth | None = None
        if self.needs & {"sun", "moon"}:
            self._bodies = SunMoonFromEarth(
                self.jd1,
                self.jd2 + self.start_s / SECONDS_PER_DAY,
                self.jd2 + self.stop_s / SECONDS_PER_DAY,
            )

    @property
    def bounds_jd2(self) -> tuple[float, float]:
        """The span as jd2 values (with :attr:`jd1`)."""
        return (
            self.jd2 + self.start_s / SECONDS_PER_DAY,
            self.jd2 + self.stop_s / SECONDS_PER_DAY,
        )

    def notes(self) -> list[str]:
        """What the user should know about the inputs over the span (EOP coverage)."""
        notes = []
        if "earth_rotation" in self.needs:
            note = eop_note(self.jd1, *self.bounds_jd2)
            if note:
                notes.append(note)
        return notes

    def at(self, seconds: ArrayLike) -> InputsAt:
        """The inputs at TT seconds after the epoch (a 1-D array inside the span)."""
        s = np.atleast_1d(np.asarray(seconds, dtype=np.float64))
        if s.ndim != 1:
            raise InputError(f"seconds must be a 1-D array, got shape {s.shape}")
        if not np.all(np.isfinite(s)):
            raise InputError("seconds must be finite")
        outside = (s < self.start_s - _SPAN_SLACK_S) | (s > self.stop_s + _SPAN_SLACK_S)
        if np.any(outside):
            raise InputError(
                f"t = {float(s[np.argmax(outside)])!r} s is outside the law's span "
                f"[{self.start_s!r}, {self.stop_s!r}] s"
            )
        return InputsAt(self, s)


class InputsAt:
    """The inputs at some epochs; every quantity is computed on first use."""

    def __init__(self, inputs: LawInputs, seconds: NDArray[np.float64]) -> None:
        self.inputs = inputs
        self.seconds = seconds
        self.jd1 = np.full(seconds.shape, inputs.jd1)
        self.jd2 = inputs.jd2 + seconds / SECONDS_PER_DAY

    @cached_property
    def orbit(self) -> OrbitDerivatives:
        """Position (order 3) and velocity (order 2) jets; at the Earth's centre, at
        rest, without an orbit."""
        if self.inputs.orbit is None:
            zero = Jet.constant(np.zeros((self.seconds.size, 3)), 3)
            return OrbitDerivatives(zero, zero.truncated(2), "none")
        return orbit_derivatives(self.inputs.orbit, self.jd1, self.jd2, self.inputs.bounds_jd2)

    @property
    def position(self) -> Jet:
        return self.orbit.position

    @property
    def velocity(self) -> Jet:
        return self.orbit.velocity

    @cached_property
    def itrs_to_gcrs(self) -> Jet:
        """C (ITRS → GCRS) and its derivatives up to the third."""
        return itrs_to_gcrs(self.jd1, self.jd2, order=3)

    @cached_property
    def position_itrs(self) -> Jet:
        """The spacecraft's ITRS position, order 3 (Cᵀ r)."""
        return matvec(Jet(np.swapaxes(self.itrs_to_gcrs.c, -1, -2)), self.position)

    @cached_property
    def _ephemeris(self) -> dict[str, NDArray[np.float64]]:
        if self.inputs._bodies is None:
            raise InputError("the Sun and the Moon were not sampled for this span")
        return self.inputs._bodies.derivatives(self.jd2, order=3)

    def apparent(self, body: str) -> Jet:
        """The apparent ``body`` ("sun" or "moon") from the spacecraft, GCRS, metres,
        order 2 (see the module notes)."""
        ephemeris = self._ephemeris
        return apparent_vector(
            ephemeris[body],
            ephemeris["sun"],
            ephemeris["earth"],
            self.position.truncated(2),
            self.velocity,
        )


def apparent_vector(
    body: NDArray[np.float64],
    sun: NDArray[np.float64],
    earth: NDArray[np.float64],
    position: Jet,
    velocity: Jet,
) -> Jet:
    """The apparent position of a body from an observer near the Earth, with its first
    two derivatives: :func:`attitude.environment.ephemeris.apparent_from_observer` on jets.

    ``body``, ``sun``: astrometric positions from the geocentre and their derivatives
    0–3 (4, n, 3); ``earth``: the Earth's barycentric position, derivatives 0–3;
    ``position``, ``velocity``: the observer's, from the geocentre, jets of order 2.
    Light time first (N = A − r − V (|A − r| − |A|)/c, V the body's barycentric
    velocity), then ERFA ``ab``'s relativistic aberration (IERS Conventions 2010,
    SOFA ``iauAb``: p = p̂ √(1−β²) + w₁ β + w₂ (β − (p̂·β) p̂), w₁ = 1 + p̂·β/(1 + √(1−β²)),
    w₂ = SRS/s, s the Sun's distance in au), normalized and scaled by |N|.
    """
    A = Jet.from_derivatives(body[:3])
    V = Jet.from_derivatives(body[1:4] + earth[1:4])
    earth_velocity = Jet.from_derivatives(earth[1:4])
    S = Jet.from_derivatives(sun[:3])
    natural = A - position
    delay = (norm(natural) - norm(A)) * (1.0 / _C_M_S)
    natural = natural - V * delay.column()
    distance = norm(natural)
    p_nat = natural * reciprocal(distance).column()
    beta = (earth_velocity + velocity) * (1.0 / _C_M_S)
    bm1 = sqrt(1.0 - dot(beta, beta))
    p_dot_v = dot(p_nat, beta)
    w1 = 1.0 + p_dot_v / (1.0 + bm1)
    w2 = reciprocal(norm(S - position)) * (_SRS_AU * _AU_M)
    p = p_nat * bm1.column() + beta * w1.column() + (beta - p_nat * p_dot_v.column()) * w2.column()
    return normalized(p) * distance.column()
