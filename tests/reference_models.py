"""Independent references for the tests: nothing here uses the package's own code.

- ``integrate_dop853``: Euler's equations and the attitude kinematics integrated
  numerically with scipy's DOP853 at tight tolerances.
- ``integrate_mpmath``: the same equations with mpmath's Taylor integrator
  (``mpmath.odefun``) at 25 significant digits.
- ``half_period_mpmath``: the closed-form half period 2K/|λ| of m(t) at high
  precision, from mpmath's complete elliptic integral.
- ``astropy_apparent_sun``: the apparent Sun from astropy's own ephemeris (ERFA
  epv00), independent of the JPL DE421 the package reads through skyfield.

Equations (body angular momentum m, body angular velocity ω = m/I, scalar-first
quaternion q taking body to inertial coordinates):
    dm/dt = m × ω                      (torque-free Euler equations)
    dq/dt = ½ q ⊗ (0, ω)               (kinematics of a body → inertial quaternion)
"""

from __future__ import annotations

import mpmath as mp
import numpy as np
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation


def _rhs(t, y, inertia):
    m = y[:3]
    w0, x, yy, z = y[3:]
    ω1, ω2, ω3 = m / inertia
    return np.array(
        [
            m[1] * ω3 - m[2] * ω2,
            m[2] * ω1 - m[0] * ω3,
            m[0] * ω2 - m[1] * ω1,
            0.5 * (-x * ω1 - yy * ω2 - z * ω3),
            0.5 * (w0 * ω1 + yy * ω3 - z * ω2),
            0.5 * (w0 * ω2 + z * ω1 - x * ω3),
            0.5 * (w0 * ω3 + x * ω2 - yy * ω1),
        ]
    )


def integrate_dop853(inertia, m0, attitude0, t_eval, rtol=1e-13, atol=1e-15):
    """Body momentum (N, 3) and attitude (Rotation stack) at ``t_eval`` (from t = 0)."""
    inertia = np.asarray(inertia, dtype=float)
    y0 = np.concatenate([np.asarray(m0, dtype=float), attitude0.as_quat(scalar_first=True)])
    t_eval = np.asarray(t_eval, dtype=float)
    scale = max(np.linalg.norm(m0), 1e-300)
    sol = solve_ivp(
        _rhs,
        (0.0, float(t_eval[-1])),
        y0,
        method="DOP853",
        t_eval=t_eval,
        rtol=rtol,
        atol=np.concatenate([np.full(3, atol * scale), np.full(4, atol)]),
        args=(inertia,),
    )
    assert sol.success, sol.message
    return sol.y[:3].T, Rotation.from_quat(sol.y[3:].T, scalar_first=True)


def integrate_mpmath(inertia, m0, q0_scalar_first, times, digits=25):
    """mpmath Taylor integration; returns a list of (m, q) float lists, one per time.

    The equations are made dimensionless (m/G, time in units of min(I)/G) so that
    mpmath's step control sees rates of order one whatever the body's scale.
    ``times`` all ≥ 0 or all ≤ 0 (mpmath integrates forward; backward is done as
    forward in s = −t with the derivative negated).
    """
    direction = -1 if any(t < 0 for t in times) else 1
    with mp.workdps(digits):
        G = mp.sqrt(sum(mp.mpf(float(v)) ** 2 for v in m0))
        unit_time = min(mp.mpf(float(v)) for v in inertia) / G
        moments = [mp.mpf(float(v)) / (G * unit_time) for v in inertia]  # dimensionless

        def F(s, y):
            m1, m2, m3, a, b, c, d = y
            ω1, ω2, ω3 = m1 / moments[0], m2 / moments[1], m3 / moments[2]
            derivative = [
                m2 * ω3 - m3 * ω2,
                m3 * ω1 - m1 * ω3,
                m1 * ω2 - m2 * ω1,
                (-b * ω1 - c * ω2 - d * ω3) / 2,
                (a * ω1 + c * ω3 - d * ω2) / 2,
                (a * ω2 + d * ω1 - b * ω3) / 2,
                (a * ω3 + b * ω2 - c * ω1) / 2,
            ]
            return [direction * v for v in derivative]

        y0 = [mp.mpf(float(v)) / G for v in m0] + [mp.mpf(float(v)) for v in q0_scalar_first]
        solution = mp.odefun(F, 0, y0)
        out = []
        for t in times:
            y = solution(direction * mp.mpf(float(t)) / unit_time)
            out.append(([float(v * G) for v in y[:3]], [float(v) for v in y[3:]]))
        return out


def mp_invariants(inertia, m0, digits=60):
    """Sorted moments and δj = Δj/G² of a float state, in mpmath at ``digits``."""
    with mp.workdps(digits):
        order = np.argsort(inertia, kind="stable")
        I1, I2, I3 = (mp.mpf(float(inertia[k])) for k in order)
        x1, x2, x3 = (mp.mpf(float(m0[k])) for k in order)
        G2 = x1**2 + x2**2 + x3**2
        twoT = x1**2 / I1 + x2**2 / I2 + x3**2 / I3
        δ1, δ2, δ3 = ((G2 - twoT * Ij) / G2 for Ij in (I1, I2, I3))
        return (I1, I2, I3), (δ1, δ2, δ3), mp.sqrt(G2)


def half_period_mpmath(inertia, m0, digits=60):
    """2K/|λ|: the time between sign changes of the intermediate-axis momentum.

    Closed form of [Leroy] cases (i) and (ii) evaluated with mpmath: K from
    ``mpmath.ellipk(1 − mc)``, mc and λ from the invariants at ``digits`` digits.
    """
    with mp.workdps(digits):
        (I1, I2, I3), (δ1, δ2, δ3), G = mp_invariants(inertia, m0, digits)
        if δ2 < 0:
            mc = δ2 * (I3 - I1) / (δ3 * (I2 - I1))
            λ = G * mp.sqrt(δ3 * (I1 - I2) / (I1 * I2 * I3))
        else:
            mc = δ2 * (I3 - I1) / (δ1 * (I3 - I2))
            λ = G * mp.sqrt(δ1 * (I3 - I2) / (I1 * I2 * I3))
        return float(2 * mp.ellipk(1 - mc) / λ)


def flip_times_mpmath(inertia, m0, t_start, t_end, digits=60):
    """Zeros of the intermediate-axis momentum in [t_start, t_end] (t0 = 0), closed form.

    [Leroy] cases (i) and (ii) in mpmath at ``digits`` digits: with σ the sign of the
    component carrying dn, m2 = −B21 sn(λt − ν) (case i, λ = −σλ3, ν = F(φ|m),
    tan φ = (m2/m3)(B31/B21)) or −B23 sn(λt − ν|1/m) (case ii, λ = −σλ1,
    tan φ = (m2/m1)(B13/B23)), so m2 vanishes at t = (ν + 2jK)/λ.  The axes are sorted
    by a proper signed permutation (the middle one reversed for an odd permutation).
    """
    with mp.workdps(digits):
        order = np.argsort(inertia, kind="stable")
        odd = np.linalg.det(np.eye(3)[order]) < 0
        I1, I2, I3 = (mp.mpf(float(inertia[k])) for k in order)
        m1, m2, m3 = (mp.mpf(float(m0[k])) for k in order)
        if odd:
            m2 = -m2
        G2 = m1**2 + m2**2 + m3**2
        twoT = m1**2 / I1 + m2**2 / I2 + m3**2 / I3
        Δ1, Δ2, Δ3 = (G2 - twoT * Ij for Ij in (I1, I2, I3))
        if Δ2 < 0:
            σ = mp.sign(m1)
            B21 = mp.sqrt(I2 * Δ1 / (I2 - I1))
            B31 = mp.sqrt(I3 * Δ1 / (I3 - I1))
            mc = Δ2 * (I3 - I1) / (Δ3 * (I2 - I1))
            λ = -σ * mp.sqrt(Δ3 * (I1 - I2) / (I1 * I2 * I3))
            φ = mp.atan2(m2 * B31, m3 * B21)
        else:
            σ = mp.sign(m3)
            B13 = mp.sqrt(I1 * Δ3 / (I1 - I3))
            B23 = mp.sqrt(I2 * Δ3 / (I2 - I3))
            mc = Δ2 * (I3 - I1) / (Δ1 * (I3 - I2))
            λ = -σ * mp.sqrt(Δ1 * (I3 - I2) / (I1 * I2 * I3))
            φ = mp.atan2(m2 * B13, m1 * B23)
        ν = mp.ellipf(φ, 1 - mc)
        K = mp.ellipk(1 - mc)
        a, b = sorted((λ * t_start - ν, λ * t_end - ν))
        js = range(int(mp.ceil(a / (2 * K))), int(mp.floor(b / (2 * K))) + 1)
        return np.sort([float((ν + 2 * j * K) / λ) for j in js])


def state_with_delta2(inertia_sorted, ratio, weight=0.5, rng=None):
    """A unit momentum x with δ2 = Δ2/G² = ``ratio`` (to rounding), sorted moments.

    δ2 = a x1² + b x3² with a = I12/I1 < 0 < b = I32/I3.  The non-dominant component
    takes the fraction ``weight`` of what the sphere leaves it, so the state is
    generic (both x1 and x3 non-zero, not at a turning point); random signs when
    ``rng`` is given.  Requires |ratio| < |a| (case i) or < b (case ii).
    """
    I1, I2, I3 = inertia_sorted
    a = (I1 - I2) / I1
    b = (I3 - I2) / I3
    if ratio < 0:
        x3_2 = weight * (1.0 + ratio / -a) / (1.0 + b / -a)
        x1_2 = (b * x3_2 - ratio) / -a
    else:
        x1_2 = weight * (1.0 - ratio / b) / (1.0 + -a / b)
        x3_2 = (ratio - a * x1_2) / b
    x2_2 = 1.0 - x1_2 - x3_2
    assert min(x1_2, x2_2, x3_2) >= 0.0, (x1_2, x2_2, x3_2)
    x = np.sqrt([x1_2, x2_2, x3_2])
    if rng is not None:
        x *= rng.choice([-1.0, 1.0], size=3)
    return x


def astropy_apparent_sun(times):
    """Apparent Sun direction (GCRS axes) and light-time distance (m), astropy's epv00.

    The astrometric vector (light time, one iteration) from ``get_body_barycentric``,
    then astropy's ICRS→GCRS transform applied to it *as a direction*, so that astropy
    adds the aberration only (``get_body("sun")`` keeps the Sun's distance and then
    applies a spurious self-deflection of several arcseconds; see docs/pointing.md, "The
    Sun's direction: which place, which frame").
    """
    from astropy import units as u
    from astropy.constants import c as speed_of_light
    from astropy.coordinates import (
        GCRS,
        ICRS,
        UnitSphericalRepresentation,
        get_body_barycentric,
        solar_system_ephemeris,
    )

    from attitude.environment.timescales import offline_time

    with offline_time(), solar_system_ephemeris.set("builtin"):
        earth = get_body_barycentric("earth", times)
        light_time = (get_body_barycentric("sun", times) - earth).norm() / speed_of_light
        astrometric = get_body_barycentric("sun", times - light_time) - earth
        direction = ICRS(astrometric.represent_as(UnitSphericalRepresentation))
        apparent = direction.transform_to(GCRS(obstime=times))
        return (
            np.moveaxis(apparent.cartesian.xyz.value, 0, -1),
            astrometric.norm().to_value(u.m),
        )
