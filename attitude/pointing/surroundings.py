"""The Sun, the Moon and the Earth seen from the spacecraft, at any times of a span.

:class:`SunMoonEarth` samples what the spacecraft sees around it over a span:
the Sun and the Moon as their apparent places from the spacecraft (light time, and the
aberration of its barycentric velocity:
:func:`attitude.environment.ephemeris.apparent_from_observer`),
from DE421 sampled every 600 s and interpolated (:class:`attitude.environment.ephemeris
.SunMoonFromEarth`, 2e-10 rad for the Moon), and, on an orbit, the Earth: its angular
radius, nadir, and the Earth's shadow (:func:`attitude.pointing.eclipse.shadow_angles`).  The
orbit is evaluated at every epoch by its source, never interpolated here.
:meth:`SunMoonEarth.at` gives them as :class:`Surroundings`.

The angles between a body vector's direction and these (:func:`vector_angles`) use
Kahan's formula, accurate at every angle (:func:`unit_angle`).  Both the samples
(:mod:`attitude.pointing.sampling`) and the search (:mod:`attitude.pointing.search`)
compute their angles here, so that a value found by the search is the value a sample
at the same time gives.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from attitude.environment.earth import angular_radius
from attitude.environment.ephemeris import SunMoonFromEarth, apparent_from_observer
from attitude.environment.timescales import SECONDS_PER_DAY, offline_time
from attitude.pointing.eclipse import fraction_from_angles, shadow_angles
from attitude.pointing.spec import PointingSpec
from attitude.trajectory.trajectory import Trajectory

__all__ = [
    "SunMoonEarth",
    "Surroundings",
    "assemble",
    "moon_hidden",
    "norm",
    "scenario_jd",
    "unit_angle",
    "vector_angles",
]


def scenario_jd(trajectory: Trajectory) -> tuple[float, float]:
    """The scenario epoch's two-part TT Julian date."""
    with offline_time():
        tt = trajectory.scenario.epoch.tt
        return float(tt.jd1), float(tt.jd2)


@dataclass
class Surroundings:
    """The Sun, the Moon and the Earth seen from the spacecraft at some times (GCRS).

    Directions are unit vectors from the spacecraft (apparent places).  On an orbit,
    ``position_m``/``velocity_m_s`` (from the Earth's centre) and the Earth: its
    angular radius (solid Earth) and the shadow's angles (:func:`attitude.pointing.eclipse
    .shadow_angles`); at the Earth's centre these are None and the Sun is always lit.
    """

    sun_direction: NDArray[np.float64]
    moon_direction: NDArray[np.float64]
    sunlit_fraction: NDArray[np.float64]
    position_m: NDArray[np.float64] | None = None
    velocity_m_s: NDArray[np.float64] | None = None
    earth_angular_radius_rad: NDArray[np.float64] | None = None
    limb_angular_radius_rad: NDArray[np.float64] | None = None
    shadow_angles: tuple[NDArray[np.float64], ...] | None = None
    nadir: NDArray[np.float64] | None = None  # unit vector to the Earth's centre


class SunMoonEarth:
    """What the spacecraft sees around it over [start_s, stop_s]: the Sun, the Moon
    and, on an orbit, the Earth, at any TT seconds in that span (:meth:`at`).

    The Sun and the Moon are sampled once for the span (:class:`attitude.environment.ephemeris
    .SunMoonFromEarth`, nodes aligned on J2000, so that any split of a span into
    chunks gives the same values); the orbit is its source's, at every epoch.
    """

    def __init__(
        self,
        trajectory: Trajectory | None,
        spec: PointingSpec,
        start_s: float,
        stop_s: float,
        jd: tuple[float, float] | None = None,
    ) -> None:
        self.spec = spec
        # The scenario epoch's TT Julian date: the trajectory's, or ``jd`` when given.
        if jd is None:
            if trajectory is None:
                raise TypeError("SunMoonEarth needs a trajectory or the epoch's jd")
            jd = scenario_jd(trajectory)
        self._jd1, self._jd2 = jd
        self._bodies = SunMoonFromEarth(
            self._jd1,
            self._jd2 + start_s / SECONDS_PER_DAY,
            self._jd2 + stop_s / SECONDS_PER_DAY,
        )

    def at(self, seconds: NDArray[np.float64]) -> Surroundings:
        return assemble(self.spec, self.fields(seconds))

    def fields(self, seconds: NDArray[np.float64]) -> dict[str, NDArray[np.float64]]:
        """What :func:`assemble` builds the surroundings from, at TT ``seconds``: the
        apparent unit directions of the Sun (``sun``) and the Moon (``moon``) from the
        spacecraft and, on an orbit, its position ``r`` and velocity ``v`` (GCRS, from
        the Earth's centre, the orbit's source at every epoch) and the apparent Sun
        from the Earth's centre, ``sun_from_earth`` (metres: the shadow's axis)."""
        seconds = np.asarray(seconds, dtype=np.float64)
        jd2 = self._jd2 + seconds / SECONDS_PER_DAY
        bodies = self._bodies.at(jd2)
        orbit = self.spec.orbit
        if orbit is None:
            r = v = np.zeros((seconds.size, 3))
        else:
            r, v = orbit.state_tt(np.full(seconds.size, self._jd1), jd2)
        earth_m_s = bodies["earth_velocity_m_s"]
        sun_distance = np.linalg.norm(bodies["sun_m"] - r, axis=-1)
        sun = apparent_from_observer(
            bodies["sun_m"], bodies["sun_velocity_m_s"], earth_m_s, r, v, sun_distance
        )
        moon = apparent_from_observer(
            bodies["moon_m"], bodies["moon_velocity_m_s"], earth_m_s, r, v, sun_distance
        )
        sun /= np.linalg.norm(sun, axis=-1, keepdims=True)
        moon /= np.linalg.norm(moon, axis=-1, keepdims=True)
        if orbit is None:
            return {"sun": sun, "moon": moon}
        # The shadow's axis is the apparent Sun from the Earth's centre (attitude.pointing.eclipse).
        zeros = np.zeros_like(r)
        sun_from_earth = apparent_from_observer(
            bodies["sun_m"],
            bodies["sun_velocity_m_s"],
            earth_m_s,
            zeros,
            zeros,
            np.linalg.norm(bodies["sun_m"], axis=-1),
        )
        return {"sun": sun, "moon": moon, "r": r, "v": v, "sun_from_earth": sun_from_earth}


def assemble(spec: PointingSpec, fields: dict[str, NDArray[np.float64]]) -> Surroundings:
    """The :class:`Surroundings` from the ``fields`` of :meth:`SunMoonEarth.fields` (or
    of an interpolation of them: :mod:`attitude.pointing.shared_surroundings`)."""
    sun, moon = fields["sun"], fields["moon"]
    if "r" not in fields:
        return Surroundings(sun, moon, np.ones(sun.shape[0]))
    r, v = fields["r"], fields["v"]
    a, b, c = shadow_angles(r, fields["sun_from_earth"])
    height = spec.earth_limb_atmosphere_height_m
    return Surroundings(
        sun,
        moon,
        fraction_from_angles(a, b, c),
        r,
        v,
        b,
        b if height == 0.0 else angular_radius(r, height),
        (a, b, c),
        -r / norm(r)[:, None],
    )


def moon_hidden(env: Surroundings) -> NDArray[np.float64] | None:
    """> 0 where the Moon's centre is behind the Earth's disc (None at the Earth's
    centre): the Earth's angular radius minus the Moon's angle from nadir."""
    if env.earth_angular_radius_rad is None or env.nadir is None:
        return None
    return env.earth_angular_radius_rad - unit_angle(env.moon_direction, env.nadir)


def norm(v: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.sqrt(np.einsum("ij,ij->i", v, v))


def unit_angle(u: NDArray[np.float64], v: NDArray[np.float64]) -> NDArray[np.float64]:
    """The angle between unit vectors (n, 3): 2 atan2(|u − v|, |u + v|), accurate at
    every angle like atan2(|u × v|, u·v), and cheaper (W. Kahan, "How Futile are
    Mindless Assessments of Roundoff in Floating-Point Computation?", 2006)."""
    return 2.0 * np.arctan2(norm(u - v), norm(u + v))


def vector_angles(icrf: NDArray[np.float64], env: Surroundings) -> dict[str, NDArray]:
    """A body vector's angles (radians) and Sun incidence from its ICRF direction."""
    cos_sun = np.sum(icrf * env.sun_direction, axis=-1)
    angles = {
        "sun_angle": unit_angle(icrf, env.sun_direction),
        "sun_cosine": cos_sun,
        "cos_incidence": np.maximum(cos_sun, 0.0) * env.sunlit_fraction,
        "moon_angle": unit_angle(icrf, env.moon_direction),
    }
    if env.nadir is not None and env.limb_angular_radius_rad is not None:
        angles["nadir_angle"] = unit_angle(icrf, env.nadir)
        angles["earth_limb_angle"] = angles["nadir_angle"] - env.limb_angular_radius_rad
    return angles
