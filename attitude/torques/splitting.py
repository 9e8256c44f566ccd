"""Splitting compositions: the coefficients that join the free flow and the torque kick.

The motion under a torque is split into two parts whose flows are both exact:

- F, the free flow: the torque-free rigid body (``attitude.solver.free_flow.advance``), which
  also advances the clock;
- K, the kick: the torque Γ with the attitude and the clock frozen, m ← m + h Γ.

One step of size h of a composition with flow coefficients a_0 … a_{s−1} and kick
coefficients b_0 … b_s is, in the order the maps are applied,

    K(b_0 h) F(a_0 h) K(b_1 h) F(a_1 h) … K(b_{s−1} h) F(a_{s−1} h) K(b_s h),

with Σ a = Σ b = 1.  A method that starts and ends with a flow has b_0 = b_s = 0.
The kick j acts at the clock time t + c_j h, c_j = a_0 + … + a_{j−1}.

Every set below is symmetric (time-reversible) and was checked in
``tests/test_splitting_against_matrix_exponentials.py``: the local error of the
composition of exp(a h A) and exp(b h B), against exp(h(A + B)) for random matrices in
60-digit arithmetic, falls with the published order.  The orders of the generalized
methods are those of a near-integrable problem A + εB: an error O(ε h^{r1} + ε² h^{r2} +
ε³ h^{r3}).  A torque is such a perturbation of the free rigid body: ε is the ratio of
the torque to the rate at which the free motion turns the momentum, |Γ| / (|m| |ω|)
(about 1e-3 for a tumbler at 3°/s on a 7000 km orbit, 4e-6 for a 5 rpm spinner).

References
----------
[Yoshida1990] H. Yoshida, "Construction of higher order symplectic integrators",
    Phys. Lett. A 150 (1990) 262–268, doi:10.1016/0375-9601(90)90092-3.
[BlanesMoan2002] S. Blanes, P. C. Moan, "Practical symplectic partitioned Runge–Kutta and
    Runge–Kutta–Nyström methods", J. Comput. Appl. Math. 142 (2002) 313–330,
    doi:10.1016/S0377-0427(01)00492-7.
[Blanes2013] S. Blanes, F. Casas, A. Farrés, J. Laskar, J. Makazaga, A. Murua, "New
    families of symplectic splitting methods for numerical integration in dynamical
    astronomy", Appl. Numer. Math. 68 (2013) 58–72, doi:10.1016/j.apnum.2013.01.003.
[Farres2013] A. Farrés, J. Laskar, S. Blanes, F. Casas, J. Makazaga, A. Murua, "High
    precision symplectic integrators for the Solar System", Celest. Mech. Dyn. Astron.
    116 (2013) 141–174, doi:10.1007/s10569-013-9479-6 (the same coefficients to 40 digits).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from attitude.base.errors import InputError

__all__ = ["COMPOSITIONS", "DEFAULT_BY_ORDER", "Composition", "composition"]


@dataclass(frozen=True)
class Composition:
    """One splitting method: its coefficients, its order and where they come from.

    ``flows``: a_0 … a_{s−1}; ``kicks``: b_0 … b_s (see the module docstring).
    ``order``: the classical order.  ``generalized_order``: (r1, r2, r3) for a method
    whose error is O(ε h^{r1} + ε² h^{r2} + ε³ h^{r3}) on A + εB, or None.
    ``needs_rkn``: the order holds only if [B, [B, [B, A]]] = 0, which is the case when
    every torque is independent of the angular velocity (then the kick field does not
    depend on m while the free flow is quadratic in m).
    """

    name: str
    order: int
    flows: tuple[float, ...]
    kicks: tuple[float, ...]
    reference: str
    generalized_order: tuple[int, int, int] | None = None
    needs_rkn: bool = False

    def __post_init__(self) -> None:
        if len(self.kicks) != len(self.flows) + 1:
            raise ValueError(f"{self.name}: need one kick more than flows")
        for label, values in (("flows", self.flows), ("kicks", self.kicks)):
            if abs(sum(values) - 1.0) > 1e-14:
                raise ValueError(f"{self.name}: {label} sum to {sum(values)!r}, not 1")

    @property
    def kick_clock(self) -> NDArray[np.float64]:
        """c_j = a_0 + … + a_{j−1}: the clock of kick j, as a fraction of the step."""
        return np.concatenate([[0.0], np.cumsum(self.flows)])


def _symmetric(half: list[float], middle: str) -> list[float]:
    """half + its mirror image; ``middle`` 'once' keeps the last element single."""
    if middle == "once":
        return half + half[-2::-1]
    return half + half[::-1]


def _strang() -> Composition:
    return Composition(
        name="strang",
        order=2,
        flows=(1.0,),
        kicks=(0.5, 0.5),
        reference="Strang splitting, kick–flow–kick (the Störmer–Verlet form)",
    )


def _yoshida() -> Composition:
    # [Yoshida1990] eq. (5.5)–(5.6): the symmetric triple jump x1, x0, x1 of Strang,
    # x1 = 1/(2 − 2^{1/3}), x0 = 1 − 2 x1.  Consecutive kicks are merged.
    x1 = 1.0 / (2.0 - 2.0 ** (1.0 / 3.0))
    x0 = 1.0 - 2.0 * x1
    return Composition(
        name="yoshida",
        order=4,
        flows=(x1, x0, x1),
        kicks=(x1 / 2, (x1 + x0) / 2, (x0 + x1) / 2, x1 / 2),
        reference="[Yoshida1990] triple jump of Strang",
    )


def _srkn6() -> Composition:
    # [BlanesMoan2002] Table 3, SRKN_6^b: the kicks (b) at both ends.  It is of order 4
    # for any splitting (the RKN condition only enters at order 5); its error constants
    # were optimized for B a potential.
    b1, b2, b3 = 0.0829844064174052, 0.396309801498368, -0.0390563049223486
    b4 = 1.0 - 2.0 * (b1 + b2 + b3)
    a1, a2 = 0.245298957184271, 0.604872665711080
    a3 = 0.5 - (a1 + a2)
    return Composition(
        name="srkn6",
        order=4,
        flows=tuple(_symmetric([a1, a2, a3], "twice")),
        kicks=tuple(_symmetric([b1, b2, b3, b4], "once")),
        reference="[BlanesMoan2002] Table 3, SRKN_6^b",
    )


def _srkn11() -> Composition:
    # [BlanesMoan2002] Table 3, SRKN_11^b: order 6 when [B,[B,[B,A]]] = 0 (torques
    # independent of ω), order 4 otherwise.
    b = [0.0414649985182624, 0.198128671918067, -0.0400061921041533]
    b += [0.0752539843015807, -0.0115113874206879]
    b.append(0.5 - sum(b))
    a = [0.123229775946271, 0.290553797799558, -0.127049212625417]
    a += [-0.246331761062075, 0.357208872795928]
    a.append(1.0 - 2.0 * sum(a))
    return Composition(
        name="srkn11",
        order=6,
        flows=tuple(_symmetric(a, "once")),
        kicks=tuple(_symmetric(b, "twice")),
        reference="[BlanesMoan2002] Table 3, SRKN_11^b",
        needs_rkn=True,
    )


def _aba864() -> Composition:
    # [Blanes2013] ABA(8,6,4), tabulated to 40 digits in [Farres2013]: 8 flows, 7 kicks.
    a = [0.0711334264982231177779387300061549964174, 0.241153427956640098736487795326289649618]
    a += [0.521411761772814789212136078067994229991, -0.333698616227678005726562603400438876027]
    b = [0.183083687472197221961703757166430291072, 0.310782859898574869507522291054262796375]
    b += [-0.0265646185119588006972121379164987592663, 0.0653961422823734184559721793911134363710]
    return Composition(
        name="aba864",
        order=4,
        flows=tuple(_symmetric(a, "twice")),
        kicks=(0.0, *_symmetric(b, "once"), 0.0),
        reference="[Blanes2013] ABA(8,6,4)",
        generalized_order=(8, 6, 4),
    )


def _aba1064() -> Composition:
    # [Blanes2013] ABA(10,6,4), tabulated to 40 digits in [Farres2013]: 9 flows, 8 kicks.
    a = [0.03809449742241219545697532230863756534060, 0.1452987161169137492940200726606637497442]
    a += [0.2076276957255412507162056113249882065158, 0.4359097036515261592231548624010651844006]
    a += [-0.6538612258327867093807117373907094120024]
    b = [0.09585888083707521061077150377145884776921, 0.2044461531429987806805077839164344779763]
    b += [0.2170703479789911017143385924306336714532, -0.01737538195906509300561788011852699719871]
    return Composition(
        name="aba1064",
        order=4,
        flows=tuple(_symmetric(a, "once")),
        kicks=(0.0, *_symmetric(b, "twice"), 0.0),
        reference="[Blanes2013] ABA(10,6,4)",
        generalized_order=(10, 6, 4),
    )


COMPOSITIONS: dict[str, Composition] = {
    c.name: c for c in (_strang(), _yoshida(), _srkn6(), _srkn11(), _aba864(), _aba1064())
}

# What ``order=`` selects (measured in docs/torques.md): Strang; ABA(10,6,4), the best
# by far when the torque is a small perturbation (tumblers, spinners) and as good as
# SRKN_6^b when it is not; SRKN_11^b, the best when the torque is not small (a
# gravity-gradient-stabilized body).
DEFAULT_BY_ORDER = {2: "strang", 4: "aba1064", 6: "srkn11"}


def composition(order: int | None = None, method: str | None = None) -> Composition:
    """The composition named ``method``, or the default one of classical ``order``."""
    if method is not None:
        if method not in COMPOSITIONS:
            raise InputError(f"method must be one of {sorted(COMPOSITIONS)}, got {method!r}")
        chosen = COMPOSITIONS[method]
        if order is not None and chosen.order != order:
            raise InputError(f"method {method!r} is of order {chosen.order}, not {order}")
        return chosen
    if order not in DEFAULT_BY_ORDER:
        raise InputError(f"order must be one of {sorted(DEFAULT_BY_ORDER)}, got {order!r}")
    return COMPOSITIONS[DEFAULT_BY_ORDER[order]]
