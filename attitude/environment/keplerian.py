"""An orbit from Keplerian elements at an epoch: two-body motion, or with J2's secular drift.

Two-body (Vallado, *Fundamentals of Astrodynamics and Applications*, 4th ed., 2013,
§2.2–2.3): the mean anomaly advances at n = √(μ/a³); Kepler's equation
M = E − e sin E is solved by Newton's method (all epochs at once, from Danby's
starting value, to machine precision); in the perifocal frame (P towards perigee, Q 90° ahead in the
orbit plane)

    r = a (cos E − e) P + a √(1 − e²) sin E Q,
    v = √(μa)/|r| (− sin E P + √(1 − e²) cos E Q),

and P, Q are rotated to the frame of the elements by R3(−Ω) R1(−i) R3(−ω) (Vallado
eq. 2-102 "PQW → IJK").

With ``j2=True``, the secular rates of the node, the perigee and the mean anomaly
caused by the Earth's oblateness (Vallado §9.6, eqs. 9-41 to 9-43, first order in J2):

    Ω̇ = −(3/2) n J2 (R/p)² cos i,
    ω̇ = (3/4) n J2 (R/p)² (4 − 5 sin² i),
    Ṁ = n + (3/4) n J2 (R/p)² √(1 − e²) (2 − 3 sin² i),      p = a (1 − e²),

with the elements taken as mean elements; the periodic terms of J2 (kilometres in
LEO) are not modelled.  The drift is about the frame's z axis (the equator of the
frame the elements are in, not the equator of date: 0.3° apart by 2025, which tilts
the axis the node turns about by that much).  The velocity is the derivative of this
position: the rotating node and perigee included.

:meth:`KeplerianOrbit.derivatives_tt` gives the position's time derivatives up to the
jerk (what the attitude laws differentiate): the same formulas carried through Taylor
jets (:mod:`attitude.base.jets`), Kepler's equation solved on the jet by Newton steps,
each of which doubles the number of exact derivatives.  They are exact derivatives of
the positions :meth:`KeplerianOrbit.state_tt` gives, not of a different model.

Elements are in the ICRF (GCRS axes) or in EME2000, which is rotated to the ICRF by
the frame bias (:func:`attitude.environment.frames.eme2000_to_icrf`, 23 mas).  μ and J2 are those of
:mod:`attitude.environment.earth`.  ``tests/test_keplerian_against_numerical_integration.py``
compares the two-body orbit with scipy's DOP853 at rtol 1e-13.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from attitude.base.errors import InputError
from attitude.base.jets import Jet, sin_cos
from attitude.base.quantities import as_si_scalar
from attitude.environment.earth import (
    EARTH_EQUATORIAL_RADIUS_M,
    GM_EARTH_M3_S2,
    HILL_RADIUS_M,
    J2_EARTH,
)
from attitude.environment.frames import eme2000_to_icrf
from attitude.environment.orbit import Orbit, tt_jd
from attitude.environment.timescales import SECONDS_PER_DAY, as_time, offline_time

__all__ = ["KeplerianOrbit", "solve_kepler"]

FRAMES = ("ICRF", "EME2000")


def solve_kepler(mean_anomaly: NDArray[np.float64], e: float) -> NDArray[np.float64]:
    """The eccentric anomaly E with E − e sin E = M (radians, 0 ≤ e < 1), by Newton's
    method from Danby's E₀ = M + 0.85 e sgn(sin M) (M reduced to [−π, π]; J. M. A.
    Danby, *Fundamentals of Celestial Mechanics*, 2nd ed., Willmann-Bell, 1988, on the
    solution of Kepler's equation), which converges for every e < 1, to machine
    precision (``tests/test_keplerian_against_numerical_integration.py`` up to e = 0.999)."""
    M = np.remainder(np.asarray(mean_anomaly, dtype=np.float64) + math.pi, 2 * math.pi) - math.pi
    E = M + 0.85 * e * np.sign(np.sin(M))
    for _ in range(50):
        step = (E - e * np.sin(E) - M) / (1.0 - e * np.cos(E))
        E = E - step
        if np.all(np.abs(step) <= 4e-16 * (1.0 + np.abs(E))):
            break
    return E


def _within_a_turn(angle_rad: float, key: str) -> float:
    """``angle_rad`` if it lies within one turn either way, else :class:`InputError`.

    An orientation angle of 1e20° is no orientation: floats that large are 16384°
    apart, so nothing of the angle the user meant is left; within ±360° an angle is
    held to 1e-15 rad, and every orientation can be written."""
    if not abs(angle_rad) <= 2.0 * math.pi * (1.0 + 1e-15):
        raise InputError(
            f"{math.degrees(angle_rad):.6g} deg is more than a turn: give the angle "
            "within -360 to 360 deg",
            key=key,
            value=math.degrees(angle_rad),
        )
    return angle_rad


class KeplerianOrbit(Orbit):
    """An orbit from classical elements at ``epoch`` (``Time`` or ISO text, UTC).

    ``semi_major_axis_m``; ``eccentricity`` in [0, 1); ``inclination``,
    ``raan`` (right ascension of the ascending node), ``argument_of_perigee`` and one of
    ``mean_anomaly``/``true_anomaly``: radians or angle Quantities.  ``frame``: "ICRF"
    or "EME2000".  ``j2``: add the secular drift of J2 (see the module notes).
    Bad elements raise :class:`InputError` naming the element.
    """

    key = "pointing.keplerian"

    def __init__(
        self,
        epoch: Any,
        semi_major_axis_m: Any,
        eccentricity: Any,
        inclination: Any,
        raan: Any,
        argument_of_perigee: Any,
        *,
        mean_anomaly: Any = None,
        true_anomaly: Any = None,
        frame: str = "ICRF",
        j2: bool = False,
        name: str | None = None,
    ) -> None:
        self.epoch = as_time(epoch, name="epoch")
        if not self.epoch.isscalar:
            raise InputError("one epoch, got an array", key="epoch")
        self.a = as_si_scalar(semi_major_axis_m, "length", "semi_major_axis")
        self.e = as_si_scalar(eccentricity, "dimensionless", "eccentricity")
        if not 0.0 <= self.e < 1.0:
            raise InputError(
                f"must be in [0, 1) (a closed orbit), got {self.e!r}",
                key="eccentricity",
                value=self.e,
            )
        perigee = self.a * (1.0 - self.e)
        if not perigee > EARTH_EQUATORIAL_RADIUS_M:
            raise InputError(
                f"the perigee, a (1 - e) = {perigee / 1e3:.1f} km from the "
                f"Earth's centre, is inside the Earth ({EARTH_EQUATORIAL_RADIUS_M / 1e3:g} km)",
                key="semi_major_axis",
                value=self.a,
            )
        apogee = self.a * (1.0 + self.e)
        if not apogee < HILL_RADIUS_M:
            raise InputError(
                f"the apogee, a (1 + e) = {apogee / 1e3:.4g} km from the Earth's centre, is "
                f"beyond the Earth's Hill sphere ({HILL_RADIUS_M / 1e3:.3g} km), where the "
                "Sun's pull dominates: no orbit about the Earth reaches there",
                key="semi_major_axis",
                value=self.a,
            )
        self.i = as_si_scalar(inclination, "angle", "inclination")
        if not 0.0 <= self.i <= math.pi:
            raise InputError(
                f"must be between 0 and 180 deg, got {math.degrees(self.i):g} deg",
                key="inclination",
                value=math.degrees(self.i),
            )
        self.raan = _within_a_turn(as_si_scalar(raan, "angle", "raan"), "raan")
        self.argp = _within_a_turn(
            as_si_scalar(argument_of_perigee, "angle", "argument_of_perigee"),
            "argument_of_perigee",
        )
        if (mean_anomaly is None) == (true_anomaly is None):
            raise InputError("give exactly one of mean_anomaly and true_anomaly")
        if mean_anomaly is not None:
            self.m0 = _within_a_turn(
                as_si_scalar(mean_anomaly, "angle", "mean_anomaly"), "mean_anomaly"
            )
        else:
            ν = _within_a_turn(as_si_scalar(true_anomaly, "angle", "true_anomaly"), "true_anomaly")
            E = 2.0 * math.atan2(
                math.sqrt(1.0 - self.e) * math.sin(ν / 2), math.sqrt(1.0 + self.e) * math.cos(ν / 2)
            )
            self.m0 = E - self.e * math.sin(E)
        if frame not in FRAMES:
            raise InputError(
                f"must be one of {', '.join(FRAMES)}, got {frame!r}", key="frame", value=frame
            )
        self.frame = frame
        self.j2 = bool(j2)
        self.name = name
        self.n = math.sqrt(GM_EARTH_M3_S2 / self.a**3)
        self.raan_rate = self.argp_rate = 0.0
        self.mean_anomaly_rate = self.n
        if self.j2:
            p = self.a * (1.0 - self.e**2)
            k = self.n * J2_EARTH * (EARTH_EQUATORIAL_RADIUS_M / p) ** 2
            sin2 = math.sin(self.i) ** 2
            self.raan_rate = -1.5 * k * math.cos(self.i)
            self.argp_rate = 0.75 * k * (4.0 - 5.0 * sin2)
            self.mean_anomaly_rate = self.n + 0.75 * k * math.sqrt(1.0 - self.e**2) * (
                2.0 - 3.0 * sin2
            )
        self._bias = eme2000_to_icrf().as_matrix() if frame == "EME2000" else None
        jd1, jd2 = tt_jd(self.epoch)
        self._epoch_jd = (float(jd1[0]), float(jd2[0]))

    def describe(self) -> str:
        with offline_time():
            epoch = self.epoch.utc.isot
        model = "two-body + J2 secular" if self.j2 else "two-body"
        return (
            f"Keplerian elements ({model}, {self.frame}), a = {self.a / 1e3:.6g} km, "
            f"e = {self.e:.6g}, i = {math.degrees(self.i):.6g} deg, epoch {epoch} UTC"
        )

    def state_tt(self, jd1, jd2):
        """Position (m) and velocity (m/s), GCRS, at TT Julian dates jd1 + jd2."""
        dt = (
            (np.asarray(jd1, dtype=np.float64) - self._epoch_jd[0])
            + (np.asarray(jd2, dtype=np.float64) - self._epoch_jd[1])
        ) * SECONDS_PER_DAY
        M = self.m0 + self.mean_anomaly_rate * dt
        raan = self.raan + self.raan_rate * dt
        argp = self.argp + self.argp_rate * dt
        E = solve_kepler(M, self.e)
        cos_E, sin_E = np.cos(E), np.sin(E)
        root = math.sqrt(1.0 - self.e**2)
        x_p = self.a * (cos_E - self.e)
        y_q = self.a * root * sin_E
        radius = self.a * (1.0 - self.e * cos_E)
        # dE/dt = Ṁ / (1 − e cos E): the perifocal velocity at the anomaly's own rate.
        rate = self.mean_anomaly_rate * self.a / radius
        vx_p = -self.a * sin_E * rate
        vy_q = self.a * root * cos_E * rate
        P, Q, W = _perifocal_axes(raan, self.i, argp)
        r = x_p[:, None] * P + y_q[:, None] * Q
        v = vx_p[:, None] * P + vy_q[:, None] * Q
        if self.j2:
            # The node turns about z, the perigee about the orbit normal W.
            z = np.array([0.0, 0.0, 1.0])
            v = v + self.raan_rate * np.cross(z, r) + self.argp_rate * np.cross(W, r)
        if self._bias is not None:
            r = r @ self._bias.T
            v = v @ self._bias.T
        return r, v

    def derivatives_tt(self, jd1, jd2, order: int = 3) -> NDArray[np.float64]:
        """The position and its first ``order`` time derivatives at the TT Julian dates
        jd1 + jd2, GCRS: an array ``[r, ṙ, r̈, …]`` of shape (order + 1, n, 3), in m,
        m/s, m/s², m/s³ (see the module notes: exact, not differenced)."""
        dt = (
            (np.asarray(jd1, dtype=np.float64) - self._epoch_jd[0])
            + (np.asarray(jd2, dtype=np.float64) - self._epoch_jd[1])
        ) * SECONDS_PER_DAY
        # M reduced to [−π, π) as solve_kepler reduces it, so that E − e sin E = M holds
        # for the value the Newton steps start from.
        M0 = np.remainder(self.m0 + self.mean_anomaly_rate * dt + math.pi, 2 * math.pi) - math.pi
        M = Jet.linear(M0, self.mean_anomaly_rate, order)
        raan = Jet.linear(self.raan + self.raan_rate * dt, self.raan_rate, order)
        argp = Jet.linear(self.argp + self.argp_rate * dt, self.argp_rate, order)
        # E − e sin E = M on the jet: from the exact value, each Newton step doubles
        # the number of exact Taylor coefficients (1, 2, 4, ...).
        E = Jet.constant(solve_kepler(M.value, self.e), order)
        exact = 1
        while exact < order + 1:
            sin_E, cos_E = sin_cos(E)
            E = E - (E - sin_E * self.e - M) / (1.0 - cos_E * self.e)
            exact = 2 * exact
        sin_E, cos_E = sin_cos(E)
        x_p = (cos_E - self.e) * self.a
        y_q = sin_E * (self.a * math.sqrt(1.0 - self.e**2))
        sO, cO = sin_cos(raan)
        sw, cw = sin_cos(argp)
        ci, si = math.cos(self.i), math.sin(self.i)
        # The columns P, Q of R3(−Ω) R1(−i) R3(−ω), as in _perifocal_axes.
        P = [cO * cw - sO * sw * ci, sO * cw + cO * sw * ci, sw * si]
        Q = [-(cO * sw) - sO * cw * ci, -(sO * sw) + cO * cw * ci, cw * si]
        r = np.stack([(x_p * p + y_q * q).c for p, q in zip(P, Q, strict=True)], axis=-1)
        if self._bias is not None:
            r = r @ self._bias.T
        return Jet(r).derivatives()


def _perifocal_axes(raan, i: float, argp):
    """P, Q, W (unit vectors, shape (n, 3)) of the perifocal frame in the elements'
    frame: the columns of R3(−Ω) R1(−i) R3(−ω)."""
    cO, sO = np.cos(raan), np.sin(raan)
    cw, sw = np.cos(argp), np.sin(argp)
    ci, si = math.cos(i), math.sin(i)
    P = np.stack([cO * cw - sO * sw * ci, sO * cw + cO * sw * ci, sw * si * np.ones_like(cw)], -1)
    Q = np.stack([-cO * sw - sO * cw * ci, -sO * sw + cO * cw * ci, cw * si * np.ones_like(cw)], -1)
    W = np.stack(
        [sO * si * np.ones_like(cO), -cO * si * np.ones_like(cO), ci * np.ones_like(cO)], -1
    )
    W = np.broadcast_to(W, P.shape)
    return P, Q, W
