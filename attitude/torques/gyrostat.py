"""Wheels spinning at constant speed relative to the body: the gyrostat, split exactly.

A spacecraft whose reaction wheels keep a constant speed relative to the body (their
drive holds it; they are not locked) is a **gyrostat**: a rigid body carrying a
constant internal angular momentum h (body axes, N m s).  With I the inertia of the
whole spacecraft (wheels included, as rigid mass) and ω the body's angular velocity,
the spacecraft's total angular momentum in body axes is M = Iω + h, and Euler's
equations become (P. C. Hughes, *Spacecraft Attitude Dynamics*, Wiley 1986, ch. 3.6 and
ch. 7; J. Wittenburg, *Dynamics of Multibody Systems*, 2nd ed., Springer 2008, §4.3):

    dM/dt = M × ω + τ = M × I⁻¹(M − h) + τ,     dR/dt = R [ω]×,   ω = I⁻¹(M − h).

**The splitting.**  Write a = I⁻¹h (constant in the body).  The vector field is the sum
of three fields, each with an exact flow:

- A, the free rigid body of momentum M: dM/dt = M × I⁻¹M, dR/dt = R [I⁻¹M]× (the exact
  free flow, :mod:`attitude.solver.free_flow`);
- G, the **gyroscopic part**: dM/dt = −M × a = a × M, dR/dt = R [−a]×.  Its flow over
  w seconds is a rotation: M(w) = exp(w [a]×) M(0), the momentum turned about a by the
  angle |a| w, and R(w) = R(0) exp(−w [a]×), the body turned about the same axis by
  the opposite angle.  (Check: d/dw of each is the field; the sum of A and G gives
  dM/dt = M × I⁻¹M − M × I⁻¹h = M × ω and dR/dt = R [I⁻¹M − a]× = R [ω]×.)  G keeps
  the inertial momentum R M = R(0) exp(−w[a]×) exp(w[a]×) M(0) and |M| exactly: it is
  the body turning at the constant body rate −a while the momentum stays fixed in
  space;
- T, the external torques with the attitude frozen (:mod:`attitude.torques.models`).

In the Lie–Poisson form dM/dt = M × ∇H the gyrostat's energy is H = ½ M·I⁻¹M − a·M
(+ const; ½ ω·Iω = ½ (M − h)·I⁻¹(M − h)): A is the flow of ½ M·I⁻¹M and G of −a·M, so
each map is a Poisson map of the same structure, |M| is kept exactly by both, and the
energy error stays bounded as for any symplectic splitting (Hairer, Lubich, Wanner,
*Geometric Numerical Integration*, 2nd ed., Springer 2006, ch. IX).  Without external
torques a composition of A and G (:mod:`attitude.torques.splitting`) has its classical
order: 4 for the default ABA(10,6,4), 2 for Strang.  The near-integrable orders of
the generalized methods do not apply: a gyroscopic rate |a| is not small beside the
body's rate (a wheel of 0.3 N m s on a body holding nadir at 1 mrad/s dominates it),
and SRKN methods of order 6 need [G, [G, [G, A]]] = 0, which fails; order 6 is refused.

With external torques, each kick of the composition is G(w/2) T(w) G(w/2), Strang's
splitting of G + T, exact when the torque does not depend on the attitude (a burn in
body axes) and second order in w otherwise: the product of the gyroscopic rate and the
torque's attitude dependence then errs at order 2 (the step search by accuracy, which
compares runs at h and 2h, measures it).

``TorquedSolver(..., wheel_momentum=h)`` uses it (``tests/test_gyrostat_against_dop853.py``
compares it with DOP853 on these equations).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["Gyroscope"]

Components = tuple[Any, ...]  # floats, or equal-length 1-D arrays (a batch)


class Gyroscope:
    """The exact flow G of the gyroscopic term (module notes), in principal axes.

    ``wheel_momentum``: h in principal axes (3 floats, or 3 arrays of N values for a
    batch); ``moments``: the principal moments (likewise).  :attr:`rate` is a = I⁻¹h,
    rad/s.
    """

    def __init__(self, wheel_momentum: Components, moments: Components) -> None:
        self.momentum = tuple(wheel_momentum)
        self.rate = tuple(h / moment for h, moment in zip(wheel_momentum, moments, strict=True))
        a = self.rate
        scalar = all(isinstance(value, float) for value in a)
        self._xp: Any = math if scalar else np
        norm = (
            math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
            if scalar
            else np.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
        )
        self.speed = norm  # |a|, rad/s
        if scalar:
            safe: Any = norm if norm > 0.0 else 1.0
        else:
            safe = np.where(norm > 0.0, norm, 1.0)
        self.axis = (a[0] / safe, a[1] / safe, a[2] / safe)

    def turn(self, m: Components, q: Components, w: Any) -> tuple[Components, Components]:
        """(M, q) after G over ``w`` seconds: M turned about a by |a| w (Rodrigues), the
        attitude q (principal → inertial, scalar first) turned by −|a| w about a in the
        body (q ⊗ (cos(|a|w/2), −â sin(|a|w/2)))."""
        xp = self._xp if isinstance(w, float) else np
        k = self.axis
        angle = self.speed * w
        c, s = xp.cos(angle), xp.sin(angle)
        along = (k[0] * m[0] + k[1] * m[1] + k[2] * m[2]) * (1.0 - c)
        cross = (k[1] * m[2] - k[2] * m[1], k[2] * m[0] - k[0] * m[2], k[0] * m[1] - k[1] * m[0])
        m_new = tuple(m[i] * c + cross[i] * s + k[i] * along for i in range(3))
        half_c, half_s = xp.cos(0.5 * angle), xp.sin(0.5 * angle)
        # q ⊗ p with p = (half_c, −k half_s): the Hamilton product written out.
        pw, px, py, pz = half_c, -k[0] * half_s, -k[1] * half_s, -k[2] * half_s
        qw, qx, qy, qz = q
        q_new = (
            qw * pw - qx * px - qy * py - qz * pz,
            qw * px + qx * pw + qy * pz - qz * py,
            qw * py - qx * pz + qy * pw + qz * px,
            qw * pz + qx * py - qy * px + qz * pw,
        )
        return m_new, q_new

    def body_rate(self, m: Components, moments: Components) -> Components:
        """ω = I⁻¹(M − h), principal axes."""
        return tuple((m[i] - self.momentum[i]) / moments[i] for i in range(3))
