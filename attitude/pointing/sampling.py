"""Pointing samples: everything the time series needs, at any times.

:func:`pointing_samples` gives, at the times asked (an output grid, a chunk of it, a
zoom panel's window), the Sun and Moon directions, the lit fraction of the Sun's disc,
the Earth's angular radius, each body vector's Sun, Moon, nadir and limb angles, its
Sun incidence, its constraint flags and its right ascension and declination, and the
attitude in the orbit's LVLH frame (:mod:`attitude.environment.frames`).  It keeps nothing
between calls, so that a long output grid can be asked chunk by chunk, each chunk
giving the values it would give in one call.  Intervals and extrema are not found from
samples: :mod:`attitude.pointing.search` searches them on the exact motion.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np
from numpy.typing import NDArray

from attitude.base.errors import InputError
from attitude.environment.frames import euler_angles_deg, lvlh_to_icrf
from attitude.pointing.shared_surroundings import exact_surroundings
from attitude.pointing.spec import BodyVector, PointingSpec, for_scenario
from attitude.pointing.surroundings import Surroundings, moon_hidden, vector_angles
from attitude.trajectory.trajectory import Trajectory

__all__ = ["PointingSamples", "VectorSamples", "pointing_samples"]


@dataclass
class VectorSamples:
    """One body vector's pointing at the sample times (radians; flags as booleans).

    ``sun_violated``: the Sun inside the exclusion cone and the spacecraft not in
    umbra; ``moon_violated``: the Moon inside its cone and not hidden by the Earth;
    ``earth_limb_violated``: the vector less than the exclusion angle above the limb;
    ``sun_in_view``: the Sun inside the inclusion cone and the spacecraft not in umbra.
    None where the constraint (or the orbit) is absent.
    """

    vector: BodyVector
    sun_angle_rad: NDArray[np.float64]
    cos_incidence: NDArray[np.float64]
    moon_angle_rad: NDArray[np.float64]
    right_ascension_rad: NDArray[np.float64]
    declination_rad: NDArray[np.float64]
    nadir_angle_rad: NDArray[np.float64] | None = None
    earth_limb_angle_rad: NDArray[np.float64] | None = None
    sun_violated: NDArray[np.bool_] | None = None
    moon_violated: NDArray[np.bool_] | None = None
    earth_limb_violated: NDArray[np.bool_] | None = None
    sun_in_view: NDArray[np.bool_] | None = None


@dataclass
class PointingSamples:
    """The pointing at ``seconds`` (TT s since the epoch): see :func:`pointing_samples`.

    ``q_body_to_lvlh``: (w, x, y, z), scalar first, w ≥ 0, the rotation taking body
    coordinates to LVLH coordinates; ``lvlh_euler_deg``: the same rotation as Euler
    angles in ``lvlh_euler_sequence`` (degrees).
    """

    seconds: NDArray[np.float64]
    on_orbit: bool
    sun_direction_icrf: NDArray[np.float64]
    moon_direction_icrf: NDArray[np.float64]
    sunlit_fraction: NDArray[np.float64]
    vectors: list[VectorSamples]
    earth_angular_radius_rad: NDArray[np.float64] | None = None
    q_body_to_lvlh: NDArray[np.float64] | None = None
    lvlh_euler_deg: NDArray[np.float64] | None = None
    lvlh_euler_sequence: str | None = None


def _right_ascension(icrf: NDArray[np.float64]) -> NDArray[np.float64]:
    """Right ascension in [0, 2π): mod 2π of a tiny negative angle rounds to 2π itself."""
    ra = np.mod(np.arctan2(icrf[:, 1], icrf[:, 0]), 2.0 * math.pi)
    return np.where(ra >= 2.0 * math.pi, 0.0, ra)


def _vector_samples(vector: BodyVector, icrf: NDArray[np.float64], env: Surroundings):
    """A body vector's quantities from its ICRF direction and the surroundings."""
    angles = vector_angles(icrf, env)
    item = VectorSamples(
        vector=vector,
        sun_angle_rad=angles["sun_angle"],
        cos_incidence=angles["cos_incidence"],
        moon_angle_rad=angles["moon_angle"],
        right_ascension_rad=_right_ascension(icrf),
        declination_rad=np.arcsin(np.clip(icrf[:, 2], -1.0, 1.0)),
        nadir_angle_rad=angles.get("nadir_angle"),
        earth_limb_angle_rad=angles.get("earth_limb_angle"),
    )
    if vector.sun_exclusion_half_angle_rad is not None:
        # In umbra the Sun is hidden: it blinds nothing.
        item.sun_violated = (item.sun_angle_rad < vector.sun_exclusion_half_angle_rad) & (
            env.sunlit_fraction > 0.0
        )
    if vector.moon_exclusion_half_angle_rad is not None:
        hidden = moon_hidden(env)
        item.moon_violated = item.moon_angle_rad < vector.moon_exclusion_half_angle_rad
        if hidden is not None:
            item.moon_violated &= hidden <= 0.0
    limb_angle = item.earth_limb_angle_rad  # None at the Earth's centre
    if vector.earth_limb_exclusion_angle_rad is not None and limb_angle is not None:
        item.earth_limb_violated = limb_angle < vector.earth_limb_exclusion_angle_rad
    if vector.sun_inclusion_half_angle_rad is not None:
        # In umbra the Sun is hidden: the sensor sees nothing.
        item.sun_in_view = (item.sun_angle_rad < vector.sun_inclusion_half_angle_rad) & (
            env.sunlit_fraction > 0.0
        )
    return item


def pointing_samples(
    trajectory: Trajectory, spec: PointingSpec, seconds: NDArray[np.float64]
) -> PointingSamples:
    """The pointing of ``spec`` at ``seconds`` (TT s since the epoch, within the span).

    Everything the time-series columns need (see :class:`PointingSamples`,
    :class:`VectorSamples`); no intervals and no extrema
    (:func:`attitude.pointing.search.pointing_analysis`), and nothing kept between
    calls, so a long output grid can be asked chunk by chunk, each chunk giving the
    values it would have given in one call.
    """
    seconds = np.asarray(seconds, dtype=np.float64).ravel()
    if seconds.size == 0:
        raise InputError("seconds: no times to sample")
    spec = for_scenario(spec, trajectory.scenario)  # the scenario's orbit, if the spec has none
    if seconds.size == 1:
        # One epoch is evaluated as a pair and the first kept: numpy's one-row products
        # take another path (gemv), which can differ in the last bit, and a stream's
        # chunk of one epoch must give what the whole grid gives.
        return _first_row(pointing_samples(trajectory, spec, np.repeat(seconds, 2)))
    # The exact surroundings; their ephemeris from the shared surroundings of a search
    # over the span, when one was made (the same values).
    env = exact_surroundings(trajectory, spec, float(seconds.min()), float(seconds.max())).at(
        seconds
    )
    attitude = trajectory.attitude(seconds)
    result = PointingSamples(
        seconds=seconds,
        on_orbit=spec.on_orbit,
        sun_direction_icrf=env.sun_direction,
        moon_direction_icrf=env.moon_direction,
        sunlit_fraction=env.sunlit_fraction,
        vectors=[_vector_samples(v, attitude.apply(v.vector), env) for v in spec.body_vectors],
        earth_angular_radius_rad=env.earth_angular_radius_rad,
    )
    if env.position_m is not None and env.velocity_m_s is not None:
        body_to_lvlh = lvlh_to_icrf(env.position_m, env.velocity_m_s).inv() * attitude
        q = body_to_lvlh.as_quat(canonical=True, scalar_first=True)
        result.q_body_to_lvlh = np.atleast_2d(q)
        if spec.lvlh_euler_sequence is not None:
            result.lvlh_euler_sequence = spec.lvlh_euler_sequence
            result.lvlh_euler_deg = np.atleast_2d(
                euler_angles_deg(body_to_lvlh, spec.lvlh_euler_sequence)
            )
    return result


def _first_row(samples: PointingSamples) -> PointingSamples:
    """``samples`` at its first time only."""

    def first(value):
        return value[:1] if isinstance(value, np.ndarray) else value

    vectors = [
        VectorSamples(**{f.name: first(getattr(v, f.name)) for f in fields(VectorSamples)})
        for v in samples.vectors
    ]
    values = {f.name: first(getattr(samples, f.name)) for f in fields(PointingSamples)}
    return PointingSamples(**(values | {"vectors": vectors}))
