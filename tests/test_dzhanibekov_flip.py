"""The Джанибеков effect: a body spun near its intermediate axis flips periodically.

For |Δ2|/G² from 1e-3 down to 1e-14, on both sides of the separatrix, the
intermediate-axis component m2 of our solution must
- alternate: zero, extremum of one sign, zero, extremum of the other sign, ...;
- reach the extremum |m2| = B21 (case i) or B23 (case ii) of the closed form;
- change sign every half period of m(t), 2K/|λ| (the reference's τ = 4K/B is the
  full period), with K(mc) computed by mpmath at 60 digits: to 1e-9 relative.

The times are found by root finding on our own output (no use of our K or λ):
zeros of m2, and extrema of m2, which are the zeros of m1 m3 since
dm2/dt = m3 m1 (1/I1 − 1/I3).
"""

import itertools

import mpmath as mp
import numpy as np
import pytest
from reference_models import half_period_mpmath, mp_invariants, state_with_delta2
from scipy.optimize import brentq

from attitude import EulerSolver

RATIOS = [-1e-3, 1e-3, -1e-6, 1e-6, -1e-9, 1e-9, -1e-12, 1e-12, -1e-14, 1e-14]
# A wing-nut-like body; the user's axes hold the moments in no particular order.
INERTIA = np.array([3.0, 1.0, 2.2])  # the intermediate axis is body z
SORTED = np.sort(INERTIA)


def _body_state(ratio):
    x = state_with_delta2(SORTED, ratio, weight=0.02)  # start close to the e2 axis
    order = np.argsort(INERTIA)
    m0 = np.empty(3)
    m0[order] = 5.0 * x
    return m0


def _roots(function, t):
    """All sign changes of ``function`` sampled on ``t``, refined by brentq."""
    values = function(t)
    roots = []
    for k in np.flatnonzero(np.sign(values[:-1]) * np.sign(values[1:]) < 0):
        roots.append(brentq(function, t[k], t[k + 1], xtol=1e-13, rtol=1e-15))
    return np.array(roots)


@pytest.mark.parametrize("ratio", RATIOS)
def test_flips_alternate_and_are_spaced_by_the_closed_form_half_period(ratio):
    m0 = _body_state(ratio)
    solver = EulerSolver(INERTIA, m0)
    intermediate = int(np.argsort(INERTIA)[1])
    others = [i for i in range(3) if i != intermediate]
    half_period = half_period_mpmath(INERTIA, m0)

    # Sample finely enough to see every flip: a flip lasts a few I/G.
    t = np.linspace(0.0, 6.5 * half_period, 40_000)

    def m2(times):
        return solver.angular_momentum(times)[..., intermediate]

    def m1_m3(times):
        m = solver.angular_momentum(times)
        return m[..., others[0]] * m[..., others[1]]

    zeros = _roots(m2, t)
    extrema = _roots(m1_m3, t)
    assert len(zeros) >= 6

    spacing = np.diff(zeros)
    np.testing.assert_allclose(spacing, half_period, rtol=1e-9, atol=0)

    # Alternation: exactly one extremum between consecutive zeros, signs alternating,
    # and each at the closed-form amplitude.
    (I1, I2, I3), (δ1, δ2, δ3), G = mp_invariants(INERTIA, m0)
    if δ2 < 0:
        amplitude = float(G * mp.sqrt(I2 * δ1 / (I2 - I1)))  # B21
    else:
        amplitude = float(G * mp.sqrt(I2 * δ3 / (I2 - I3)))  # B23
    signs = []
    for a, b in itertools.pairwise(zeros):
        inside = extrema[(extrema > a) & (extrema < b)]
        assert len(inside) == 1, (a, b, inside)
        value = m2(inside[0])
        assert abs(abs(value) - amplitude) <= 1e-12 * amplitude
        # Symmetry of the flip: the extremum lies halfway between the zeros.
        assert abs(inside[0] - 0.5 * (a + b)) <= 1e-9 * (b - a)
        signs.append(np.sign(value))
    assert all(s1 == -s2 for s1, s2 in itertools.pairwise(signs))


def test_period_property_is_twice_the_flip_spacing():
    m0 = _body_state(-1e-12)
    solver = EulerSolver(INERTIA, m0)
    assert solver.period == pytest.approx(2.0 * half_period_mpmath(INERTIA, m0), rel=1e-12)


def test_on_the_separatrix_there_is_a_single_passage_and_no_return():
    """Δ2 = 0 exactly: the intermediate component goes from −G to +G once."""
    inertia = [2.0, 3.0, 6.0]  # δ2 = −x1²/2 + x3²/2 vanishes exactly for |m1| = |m3|
    solver = EulerSolver(inertia, [1.0, -3.0, 1.0])
    assert solver.formula == "iii"
    assert solver.period == float("inf")
    m = solver.angular_momentum(np.linspace(-200.0, 200.0, 4001))
    G = np.sqrt(11.0)
    assert np.all(np.diff(m[:, 1]) >= 0)
    assert m[0, 1] == pytest.approx(-G, abs=1e-12) and m[-1, 1] == pytest.approx(G, abs=1e-12)
    assert (
        len(_roots(lambda t: solver.angular_momentum(t)[..., 1], np.linspace(-200, 200, 4001))) == 1
    )
