"""The Earth's rotation: ITRS → GCRS with its time derivatives, offline; geodetic sites.

**Model** (IERS Conventions 2010, IERS Technical Note 36, chapter 5, the CIO-based
transformation): a vector's ITRS coordinates become GCRS coordinates by

    C(t) = Q(t) · R3(−θ(t)) · W(t),

- Q: the celestial motion of the CIP, from its GCRS coordinates X, Y (the IAU
  2006/2000A series of IERS TN 36 eq. 5.16, ERFA ``xy06``) plus the observed offsets
  dX, dY of the IERS, and the CIO locator s (ERFA ``s06``): ERFA ``c2ixys``
  (transposed: CIRS → GCRS).  The series, as the Conventions give them (and Orekit
  uses), rather than X, Y read off the precession-nutation matrix (``xys06a``), which
  differ by up to 5e-12 rad;
- θ: the Earth rotation angle of UT1, ERFA ``era00`` (IERS TN 36 eq. 5.15);
- W: polar motion xp, yp and the TIO locator s': ERFA ``pom00`` and ``sp00``
  (transposed: ITRS → TIRS).

**Earth orientation parameters**: ``finals2000A.all`` as the ``astropy-iers-data``
package ships it (the IERS rapid-service file: the final Bulletin B values where they
exist, Bulletin A otherwise, and a year of predictions), read by astropy's
``IERS_A`` reader: nothing is downloaded.  UT1 − TAI (continuous across leap seconds),
xp, yp, dX and dY are interpolated by the cubic Lagrange polynomial through the four
daily values around each epoch, in TT, as the IERS's own ``interp.f`` and Orekit's
``EOPHistory`` (degree 3) do.  The sub-daily tidal terms of UT1 and of the pole
(< 0.1 ms and < 0.5 mas: a few centimetres on the ground) are not added, as
Orekit's "simple EOP" leaves them out.  Outside the table (before 1973-01-02 or after
its last prediction, about a year after the package's release), the table's first or
last values are held: :func:`eop_note` says so, with the span.

**Derivatives.**  Q and W change over days (precession, nutation, polar motion): they
are computed on whole TT hours from J2000 and joined by cubic Lagrange polynomials
through the 4 hours around each epoch (TEME of :mod:`attitude.environment.orbit` is
treated the same way: 4e-13 rad), and their derivatives are those of these
polynomials.  θ is computed at every epoch, and its rate is the ERA rate times
dUT1/dTT: ``θ̇ = 2π · 1.00273781191135448 / 86400 s · (1 + d(UT1 − TAI)/dt)``, with the
derivative of the interpolated UT1 − TAI (−LOD/86400 s), so that the rate is the exact
derivative of the rotation this module gives.  :func:`itrs_to_gcrs` returns C as a
:class:`attitude.base.jets.Jet` (C, Ċ, C̈, …).

**Sites**: geodetic latitude, longitude and height on the WGS 84 ellipsoid (ERFA
``gd2gc`` and ``eform``): :func:`geodetic_to_itrs`.
"""

from __future__ import annotations

import math
import threading

import numpy as np
from numpy.typing import NDArray

from attitude.base.jets import Jet, matmul, sin_cos
from attitude.environment.timescales import SECONDS_PER_DAY

__all__ = [
    "ERA_RATE_RAD_S",
    "WGS84_FLATTENING",
    "WGS84_SEMI_MAJOR_AXIS_M",
    "eop_note",
    "eop_span_mjd",
    "eop_values",
    "geodetic_to_itrs",
    "itrs_to_gcrs",
]

# d(ERA)/d(UT1) in rad per second of UT1 (IERS TN 36 eq. 5.15).
ERA_RATE_RAD_S = 2.0 * math.pi * 1.00273781191135448 / SECONDS_PER_DAY
# WGS 84 (ERFA eform(1): NIMA TR8350.2), the ellipsoid of sites and of geodetic nadir.
WGS84_SEMI_MAJOR_AXIS_M = 6378137.0
WGS84_FLATTENING = 1.0 / 298.257223563
# TT − TAI, s (exact by definition).
_TT_MINUS_TAI_S = 32.184
_MJD_ZERO_JD = 2400000.5
# Hourly nodes of Q and W, counted from J2000 (JD 2451545.0 TT); at most this many kept.
_NODE_ORIGIN_JD = 2451545.0
_NODE_STEP_S = 3600.0
_NODE_CACHE = 20_000
_MAS_RAD = math.pi / 180.0 / 3.6e6
_ARCSEC_RAD = math.pi / 180.0 / 3600.0

_lock = threading.Lock()
_eop: dict[str, NDArray[np.float64]] | None = None
_nodes: dict[int, tuple[NDArray[np.float64], NDArray[np.float64]]] = {}


def _table() -> dict[str, NDArray[np.float64]]:
    """The EOP columns, read once: node epochs (TT, days since MJD 0), UT1 − TAI (s),
    xp, yp, dX, dY (rad)."""
    global _eop
    with _lock:
        if _eop is None:
            import erfa
            from astropy.utils import iers

            table = iers.IERS_A.open(iers.IERS_A_FILE)
            mjd = np.asarray(table["MJD"].to_value("d"), dtype=np.float64)
            year, month, day, _ = erfa.jd2cal(_MJD_ZERO_JD, mjd)
            tai_utc = erfa.dat(year, month, day, 0.0)

            def column(name: str, unit: str, scale: float) -> NDArray[np.float64]:
                values = np.ma.filled(table[name].to_value(unit), np.nan).astype(np.float64)
                # The far predictions leave dX and dY blank: no offset there.
                return np.where(np.isfinite(values), values, 0.0) * scale

            _eop = {
                "mjd_tt": mjd + (tai_utc + _TT_MINUS_TAI_S) / SECONDS_PER_DAY,
                "ut1_tai": column("UT1_UTC", "s", 1.0) - tai_utc,
                "xp": column("PM_x", "arcsec", _ARCSEC_RAD),
                "yp": column("PM_y", "arcsec", _ARCSEC_RAD),
                "dx": column("dX_2000A", "mas", _MAS_RAD),
                "dy": column("dY_2000A", "mas", _MAS_RAD),
            }
        return _eop


def eop_span_mjd() -> tuple[float, float]:
    """The first and last days (MJD, UTC) of the EOP table."""
    table = _table()
    return float(np.floor(table["mjd_tt"][0])), float(np.floor(table["mjd_tt"][-1]))


def eop_note(jd1: float, first_jd2: float, last_jd2: float) -> str | None:
    """A sentence when part of the TT span jd1 + [first_jd2, last_jd2] lies outside
    the EOP table (the end values are then held), else None."""
    first, last = eop_span_mjd()
    start = (jd1 - _MJD_ZERO_JD) + first_jd2
    stop = (jd1 - _MJD_ZERO_JD) + last_jd2
    if first <= start and stop <= last + 1.0:
        return None
    import erfa

    def day(mjd: float) -> str:
        y, m, d, _ = erfa.jd2cal(_MJD_ZERO_JD, mjd)
        return f"{int(y):04d}-{int(m):02d}-{int(d):02d}"

    return (
        f"the Earth's orientation (UT1, polar motion) is tabulated from {day(first)} to "
        f"{day(last)} (astropy-iers-data's finals2000A.all): outside, the table's end "
        "values are held (UT1 − UTC is always within 0.9 s: up to 400 m along the equator)"
    )


def _lagrange(x: NDArray[np.float64], nodes: NDArray[np.float64], order: int, step: float):
    """Jets (in seconds) of the 4 cubic Lagrange weights at ``x`` (days or node units,
    one per epoch) for the nodes ``nodes`` (n, 4) in the same unit, ``step`` seconds a
    unit: weight_j(x + τ) = Π_{m≠j} (x − x_m + τ/step)/(x_j − x_m)."""
    weights = []
    for j in range(4):
        product = Jet.constant(np.ones_like(x), order)
        for m in range(4):
            if m != j:
                factor = Jet.linear(x - nodes[:, m], 1.0 / step, order)
                product = product * factor / (nodes[:, j] - nodes[:, m])
        weights.append(product)
    return weights


def eop_values(
    jd1: NDArray[np.float64], jd2: NDArray[np.float64], order: int = 0
) -> dict[str, Jet]:
    """UT1 − TAI (s), xp, yp, dX, dY (rad) at the TT Julian dates jd1 + jd2, as jets
    of ``order`` (derivatives per second), interpolated as the module notes say."""
    table = _table()
    nodes = table["mjd_tt"]
    mjd = (np.asarray(jd1, dtype=np.float64) - _MJD_ZERO_JD) + np.asarray(jd2, dtype=np.float64)
    inside = (mjd >= nodes[0]) & (mjd <= nodes[-1])
    held = np.clip(mjd, nodes[0], nodes[-1])
    # The 4 nodes around each epoch: k − 1 … k + 2 with nodes[k] ≤ t < nodes[k + 1].
    k = np.clip(np.searchsorted(nodes, held, side="right") - 1, 1, nodes.size - 3)
    index = k[:, None] + np.arange(-1, 3)[None, :]
    weights = _lagrange(held, nodes[index], order, SECONDS_PER_DAY)
    out = {}
    for name in ("ut1_tai", "xp", "yp", "dx", "dy"):
        values = table[name][index]
        jet = sum(
            (w * values[:, j] for j, w in enumerate(weights)), Jet.constant(0.0 * held, order)
        )
        if not np.all(inside):  # held values do not change
            jet.c[1:, ~inside] = 0.0
        out[name] = jet
    return out


def _slow_matrices(hours: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Q (CIRS → GCRS) and W (ITRS → TIRS) at whole TT hours from J2000, (m, 3, 3)
    each, computed once per process and node."""
    import erfa

    keys = hours.astype(np.int64).tolist()
    with _lock:
        known = [_nodes.get(key) for key in keys]
    missing = sorted({key for key, node in zip(keys, known, strict=True) if node is None})
    if missing:
        whole, fraction = np.divmod(
            np.asarray(missing, dtype=np.float64) * _NODE_STEP_S, SECONDS_PER_DAY
        )
        jd1 = _NODE_ORIGIN_JD + whole
        jd2 = fraction / SECONDS_PER_DAY
        eop = eop_values(jd1, jd2)
        x, y = erfa.xy06(jd1, jd2)
        x = x + eop["dx"].value
        y = y + eop["dy"].value
        c2i = erfa.c2ixys(x, y, erfa.s06(jd1, jd2, x, y))
        pom = erfa.pom00(eop["xp"].value, eop["yp"].value, erfa.sp00(jd1, jd2))
        computed = {
            key: (np.asarray(q).T.copy(), np.asarray(w).T.copy())
            for key, q, w in zip(missing, c2i, pom, strict=True)
        }
        with _lock:
            if len(_nodes) + len(computed) > _NODE_CACHE:
                _nodes.clear()
            _nodes.update(computed)
        known = [
            node if node is not None else computed[key]
            for key, node in zip(keys, known, strict=True)
        ]
    nodes = [node for node in known if node is not None]
    return np.stack([q for q, _ in nodes]), np.stack([w for _, w in nodes])


def itrs_to_gcrs(jd1: NDArray[np.float64], jd2: NDArray[np.float64], order: int = 2) -> Jet:
    """The matrices C (n, 3, 3) taking ITRS coordinates to GCRS coordinates at the TT
    Julian dates jd1 + jd2, with their first ``order`` time derivatives (per second),
    as a :class:`attitude.base.jets.Jet` (see the module notes)."""
    import erfa

    jd1 = np.asarray(jd1, dtype=np.float64)
    jd2 = np.asarray(jd2, dtype=np.float64)
    # Q and W: cubic Lagrange through the 4 whole hours around each epoch.
    position = ((jd1 - _NODE_ORIGIN_JD) + jd2) * (SECONDS_PER_DAY / _NODE_STEP_S)
    below = np.floor(position)
    around = below[:, None] + np.arange(-1.0, 3.0)[None, :]
    weights = _lagrange(position, around, order, _NODE_STEP_S)
    needed, inverse = np.unique(around, return_inverse=True)
    q_nodes, w_nodes = _slow_matrices(needed)
    inverse = inverse.reshape(around.shape)
    zero = Jet.constant(np.zeros((jd1.size, 3, 3)), order)
    Q = sum((w.column().column() * q_nodes[inverse[:, j]] for j, w in enumerate(weights)), zero)
    W = sum((w.column().column() * w_nodes[inverse[:, j]] for j, w in enumerate(weights)), zero)
    # θ at every epoch, from UT1 = TAI + (UT1 − TAI); its derivatives from UT1 − TAI's.
    ut1_tai = eop_values(jd1, jd2, order)["ut1_tai"]
    theta_c = ut1_tai.c * ERA_RATE_RAD_S
    theta_c[0] = erfa.era00(jd1, jd2 + (ut1_tai.value - _TT_MINUS_TAI_S) / SECONDS_PER_DAY)
    if order >= 1:
        theta_c[1] += ERA_RATE_RAD_S
    sin_t, cos_t = sin_cos(Jet(theta_c))
    zeros = np.zeros_like(theta_c)
    ones = zeros.copy()
    ones[0] = 1.0
    R = Jet(
        np.stack(
            [
                np.stack([cos_t.c, -sin_t.c, zeros], axis=-1),
                np.stack([sin_t.c, cos_t.c, zeros], axis=-1),
                np.stack([zeros, zeros, ones], axis=-1),
            ],
            axis=-2,
        )
    )
    return matmul(matmul(Q, R), W)


def geodetic_to_itrs(
    latitude_rad: float, longitude_rad: float, height_m: float
) -> NDArray[np.float64]:
    """The ITRS position (m) of a point at geodetic latitude, longitude (radians, east
    positive) and height above the WGS 84 ellipsoid (ERFA ``gd2gc``)."""
    import erfa

    return np.asarray(erfa.gd2gc(1, longitude_rad, latitude_rad, height_m), dtype=np.float64)
