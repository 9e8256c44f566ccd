"""Orbit-relative frames (LVLH, RTN), the EME2000 frame bias, and Euler angles.

**LVLH** (local vertical, local horizontal), the convention of CCSDS (``LVLH`` in the
SANA registry of orbit-relative reference frames that the CCSDS navigation standards
refer to, https://sanaregistry.org/r/orbit_relative_reference_frames) and of W. Fehse,
*Automated Rendezvous and Docking of Spacecraft* (Cambridge University Press, 2003),
from the position r and the velocity v of the spacecraft relative to the Earth's
centre (GCRS):

    z = −r/|r|        (nadir, towards the Earth's centre)
    y = −h/|h|        (h = r × v: the negative orbit normal)
    x = y × z         (in the orbit plane, across the radius, on the side of v:
                       along v on a circular orbit, v's horizontal part otherwise)

so a spacecraft whose body axes are the LVLH axes points its +z at nadir and its +x
ahead.  Orekit names this frame ``LVLH_CCSDS`` and also ``VVLH``; STK's "VVLH" is the
same, so no separate VVLH is offered.  Orekit's own ``LVLH`` (x radial, z along h) is
a different frame: check which one a tool means.

**RTN** (radial, transverse, normal; ``RSW`` in the same registry, also called RIC;
Vallado, *Fundamentals of Astrodynamics and Applications*, 4th ed., 2013, §3.3):

    R = r/|r|,  N = h/|h|,  T = N × R.

Rotations are ``scipy.spatial.transform.Rotation`` objects that take coordinates in
the named frame to GCRS (ICRF axes) coordinates: their matrices' columns are the
frame's axes in ICRF.  The frames rotate with the orbit (an attitude given in LVLH
at an epoch is in the LVLH frame of that epoch).

**EME2000** (the mean equator and equinox of J2000.0, the frame of many OEM and AEM
files) differs from the ICRF/GCRS axes by the IAU 2000 frame bias, a rotation of 23.15 mas
(IERS Conventions 2010, IERS Technical Note 36, chapter 5: ξ0 = −16.617 mas,
η0 = −6.8192 mas, dα0 = −14.6 mas).  It is applied, not ignored: :func:`eme2000_to_icrf` is ERFA's
``bp06`` frame-bias matrix (transposed), which is independent of the date.
"""

from __future__ import annotations

import warnings

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError

__all__ = [
    "ORBIT_FRAMES",
    "eme2000_to_icrf",
    "euler_angles_deg",
    "lvlh_to_icrf",
    "orbit_frame_to_icrf",
    "rtn_to_icrf",
]

ORBIT_FRAMES = ("lvlh", "rtn")


def _unit(vectors: NDArray[np.float64], name: str) -> NDArray[np.float64]:
    norm = np.linalg.norm(vectors, axis=-1, keepdims=True)
    if not np.all(norm > 0.0):
        raise InputError(f"{name} is zero: the orbit frame is undefined (r ∥ v, or r = 0)")
    return vectors / norm


def _axes(r_m: ArrayLike, v_m_s: ArrayLike) -> tuple[NDArray[np.float64], ...]:
    r = np.asarray(r_m, dtype=np.float64)
    v = np.asarray(v_m_s, dtype=np.float64)
    radial = _unit(r, "the position")
    normal = _unit(np.cross(r, v), "the orbit normal r × v")
    return radial, normal, np.cross(normal, radial)


def lvlh_to_icrf(r_m: ArrayLike, v_m_s: ArrayLike) -> Rotation:
    """The rotation taking LVLH coordinates to GCRS/ICRF coordinates (see the module
    notes): columns (x, y, z) = (T, −N, −R).  ``r_m``, ``v_m_s``: (3,) or (n, 3)."""
    radial, normal, transverse = _axes(r_m, v_m_s)
    return Rotation.from_matrix(np.stack([transverse, -normal, -radial], axis=-1))


def rtn_to_icrf(r_m: ArrayLike, v_m_s: ArrayLike) -> Rotation:
    """The rotation taking RTN coordinates to GCRS/ICRF coordinates: columns (R, T, N)."""
    radial, normal, transverse = _axes(r_m, v_m_s)
    return Rotation.from_matrix(np.stack([radial, transverse, normal], axis=-1))


def orbit_frame_to_icrf(frame: str, r_m: ArrayLike, v_m_s: ArrayLike) -> Rotation:
    """:func:`lvlh_to_icrf` or :func:`rtn_to_icrf`, by name (one of :data:`ORBIT_FRAMES`)."""
    if frame == "lvlh":
        return lvlh_to_icrf(r_m, v_m_s)
    if frame == "rtn":
        return rtn_to_icrf(r_m, v_m_s)
    raise InputError(f"frame must be one of {', '.join(ORBIT_FRAMES)}, got {frame!r}")


def eme2000_to_icrf() -> Rotation:
    """The rotation taking EME2000 (mean J2000.0) coordinates to ICRF/GCRS coordinates:
    the transpose of ERFA ``bp06``'s frame-bias matrix (GCRS → mean J2000), 23 mas."""
    import erfa

    bias, _, _ = erfa.bp06(2451545.0, 0.0)  # the bias does not depend on the date
    return Rotation.from_matrix(np.asarray(bias).T)


def euler_angles_deg(rotation: Rotation, sequence: str) -> NDArray[np.float64]:
    """Euler angles (degrees) of ``rotation`` in ``sequence``, as scipy's ``as_euler``:
    upper case (``"ZYX"``) for intrinsic rotations about the rotating axes, lower case
    (``"zyx"``) for extrinsic ones about the fixed axes; ``rotation`` =
    R(a1) R(a2) R(a3) for an intrinsic sequence.  At gimbal lock (the middle angle at
    ±90° for a Tait–Bryan sequence, 0 or 180° for a proper Euler one) the first and
    third angles are not unique: scipy sets the third to 0, silently here."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="Gimbal lock detected")
        # scipy-stubs types ``seq`` as a Literal of the 24 sequences; scipy takes any
        # str and refuses a bad one itself.
        return rotation.as_euler(sequence, degrees=True)  # type: ignore[call-overload]
