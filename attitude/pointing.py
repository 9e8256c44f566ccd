"""Pointing: where the Sun (and the Earth) fall on the spacecraft's body vectors.

Body vectors are directions fixed in the body (panel normals, instrument
boresights, star tracker axes), declared in the scenario.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from attitude.errors import InputError
from attitude.quantities import as_vector3

__all__ = ["BodyVector", "PointingSpec"]

KINDS = ("panel", "instrument", "star_tracker", "other")


@dataclass(frozen=True)
class BodyVector:
    """A named direction fixed in body axes (normalized on construction).

    ``sun_exclusion_half_angle_rad``: the Sun must stay outside this cone about the
    vector (a star tracker or a sensitive instrument); None for no constraint.
    ``kind``: 'panel' (its Sun incidence is reported), 'instrument', 'star_tracker'
    or 'other'.
    """

    name: str
    vector: NDArray[np.float64]
    sun_exclusion_half_angle_rad: float | None = None
    kind: str = "other"

    def __post_init__(self) -> None:
        vector = as_vector3(self.vector, "angle", f"body vector {self.name!r}")
        norm = np.linalg.norm(vector)
        if not norm > 0.0:
            raise InputError(f"body vector {self.name!r} must be non-zero, got {vector.tolist()}")
        object.__setattr__(self, "vector", vector / norm)
        if self.kind not in KINDS:
            raise InputError(
                f"body vector {self.name!r}: kind must be one of {KINDS}, got {self.kind!r}"
            )


@dataclass(frozen=True)
class PointingSpec:
    """What pointing outputs a scenario asks for.

    ``tle``: the two lines of a TLE placing the spacecraft on an orbit (None: the
    spacecraft is taken at the Earth's centre, and only Sun directions are computed).
    ``interval_precision_s``: the precision to which interval ends are refined.
    """

    body_vectors: list[BodyVector] = field(default_factory=list)
    tle: tuple[str, str] | None = None
    interval_precision_s: float = 1e-3

    def __post_init__(self) -> None:
        if not self.interval_precision_s > 0.0:
            raise InputError(
                f"interval_precision must be positive, got {self.interval_precision_s!r} s"
            )

    @property
    def is_empty(self) -> bool:
        return not self.body_vectors and self.tle is None

    def describe(self) -> dict[str, Any]:
        return {
            "body_vectors": [
                {
                    "name": v.name,
                    "vector_body": v.vector.tolist(),
                    "kind": v.kind,
                    "sun_exclusion_half_angle_deg": None
                    if v.sun_exclusion_half_angle_rad is None
                    else float(np.degrees(v.sun_exclusion_half_angle_rad)),
                }
                for v in self.body_vectors
            ],
            "orbit": "TLE" if self.tle else "Earth centre",
            "interval_precision_s": self.interval_precision_s,
        }
