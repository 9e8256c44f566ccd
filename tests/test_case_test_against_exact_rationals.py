"""The exact case test against exact rational arithmetic (``fractions.Fraction``).

A float is a dyadic rational, so Δj = Σ_k m_k² (I_k − I_j)/I_k of the float inputs is a
rational that ``Fraction`` computes exactly, with no reference to the package's own
integers or double-double.  The sign of Δ2 picks the case ([Leroy]: i below zero, ii
above, iii on the separatrix), and mc, δ1 = Δ1/G², δ3 = Δ3/G² are ratios of such
rationals, whose correctly rounded floats ``float(Fraction)`` gives.  Against them:

- one state (``invariants`` on floats: the exact integers): the sign, and mc, δ1, δ3
  correctly rounded, bit for bit;
- a batch (``invariants`` on arrays: double-double with its error bound, the integers
  where the bound leaves the sign or mc's rounding in doubt): the sign and mc bit for
  bit, δ1 and δ3 within an ulp (faithful);
- the numba backend's case test (double-double alone): wherever it says ``certain``,
  the sign and mc bit for bit and δ1, δ3 within an ulp;
- the case each front end chooses (``EulerSolver.formula``, the batch of ``advance``).

On random states of any magnitude (components and moments from 1e-150 to 1e150, one
component tiny beside the others, subnormal components), on states a few ulps from the
separatrix (the float nearest to a root of Δ2 = 0 and its neighbours: Δ2 a relative
1e-16 of its terms, so its sign is decided far below the float rounding), and on states
exactly on it.
"""

import math
from fractions import Fraction

import numpy as np
import pytest

from attitude import EulerSolver
from attitude.base.float_math import FLOAT
from attitude.solver.invariants import invariants


def _exact(I1, I2, I3, m1, m2, m3):
    """(sign of Δ2, δ1, δ3, mc) as exact rationals (mc None on the separatrix)."""
    I1, I2, I3, m1, m2, m3 = (Fraction(v) for v in (I1, I2, I3, m1, m2, m3))
    s1, s2, s3 = m1 * m1, m2 * m2, m3 * m3
    D1 = s2 * (I2 - I1) / I2 + s3 * (I3 - I1) / I3
    D2 = s1 * (I1 - I2) / I1 + s3 * (I3 - I2) / I3
    D3 = s1 * (I1 - I3) / I1 + s2 * (I2 - I3) / I2
    G2 = s1 + s2 + s3
    sign = (D2 > 0) - (D2 < 0)
    if sign < 0:
        mc = D2 * (I3 - I1) / (D3 * (I2 - I1))
    elif sign > 0:
        mc = D2 * (I3 - I1) / (D1 * (I3 - I2))
    else:
        mc = None
    return sign, D1 / G2, D3 / G2, mc


def _within_an_ulp(value: float, exact: Fraction) -> bool:
    rounded = float(exact)
    return value == rounded or value in (
        math.nextafter(rounded, math.inf),
        math.nextafter(rounded, -math.inf),
    )


def _random_states(rng, count):
    """Sorted distinct moments and momenta of any magnitude (half of them within the
    SI values of spacecraft, the others anywhere), some components tiny."""
    states = []
    for k in range(count):
        wide = k % 2 == 1
        inertia = np.sort(rng.uniform(0.5, 5.0, 3)) * (
            10.0 ** rng.uniform(-100, 100) if wide else 1
        )
        m = rng.normal(size=3) * 10.0 ** (rng.uniform(-150, 150) if wide else rng.uniform(-6, 6))
        if k % 5 == 1:  # one component far below the others
            m[rng.integers(3)] *= 10.0 ** rng.uniform(-200, -20)
        if k % 7 == 2:  # a subnormal component
            m[rng.integers(3)] = rng.choice([-1.0, 1.0]) * 2.0**-1060 * rng.uniform(1, 2)
        states.append((*inertia.tolist(), *m.tolist()))
    return states


def _near_separatrix_states(rng, count):
    """m3 the float nearest to the root of Δ2 = 0 for random I, m1, m2, and its
    neighbours up to 3 ulps away: Δ2 within a few ulps of its terms, of either sign
    (Δ2 in floats, m1²(I1 − I2)/I1 + m3²(I3 − I2)/I3, has the wrong sign or zero for
    about a third of them: test_float_delta2_would_fail_here)."""
    states = []
    while len(states) < count:
        I1, I2, I3 = np.sort(rng.uniform(0.5, 5.0, 3)).tolist()
        scale = 10.0 ** rng.uniform(-60, 60)
        m1, m2 = rng.normal() * scale, rng.normal() * scale
        root = math.sqrt(m1 * m1 * (I2 - I1) / I1 * I3 / (I3 - I2))
        m3 = rng.choice([-1.0, 1.0]) * root
        for _ in range(int(rng.integers(-3, 4))):
            m3 = math.nextafter(m3, math.inf)
        states.append(tuple(float(v) for v in (I1, I2, I3, m1, m2, m3)))
    return states


def _separatrix_states(rng):
    """Exactly on the separatrix: I = (2, 3, 6) and |m1| = |m3| (Δ2 = −m1²/2 + m3²/2),
    scaled by powers of two (exact), with any m2."""
    states = []
    for _ in range(60):
        scale = 2.0 ** int(rng.integers(-400, 400))
        a = rng.uniform(0.1, 3.0) * scale
        m = (rng.choice([-a, a]), rng.normal() * scale, rng.choice([-a, a]))
        states.append((2.0, 3.0, 6.0, *(float(v) for v in m)))
    states.append((2.0, 3.0, 6.0, 0.0, 1.0, 0.0))  # a spin about the intermediate axis
    return states


def _all_states():
    rng = np.random.default_rng(2027)
    return {
        "random": _random_states(rng, 1500),
        "near the separatrix": _near_separatrix_states(rng, 700),
        "on the separatrix": _separatrix_states(rng),
    }


STATES = _all_states()


@pytest.mark.parametrize("kind", list(STATES))
def test_one_state_is_exact(kind):
    for state in STATES[kind]:
        sign, δ1, δ3, mc = _exact(*state)
        inv = invariants(*state, xp=FLOAT)
        assert inv.sign == sign, state
        assert inv.δ1 == float(δ1) and inv.δ3 == float(δ3), state
        if mc is None:
            assert inv.mc == 0.0 and inv.log_mc == -math.inf, state
        else:
            assert inv.mc == float(mc), state
            if inv.mc >= 2.0**-1022:
                assert inv.log_mc == math.log(inv.mc), state
            else:  # below the normal range: from the integers (|ln mc| > 708)
                log_mc = math.log(mc.numerator) - math.log(mc.denominator)
                assert abs(inv.log_mc - log_mc) <= 1e-15 * abs(log_mc), state


@pytest.mark.parametrize("kind", list(STATES))
def test_a_batch_is_exact(kind):
    columns = np.array(STATES[kind]).T
    inv = invariants(*columns, xp=np)
    for k, state in enumerate(STATES[kind]):
        sign, δ1, δ3, mc = _exact(*state)
        assert inv.sign[k] == sign, state
        assert _within_an_ulp(inv.δ1[k], δ1) and _within_an_ulp(inv.δ3[k], δ3), state
        assert inv.mc[k] == (0.0 if mc is None else float(mc)), state


@pytest.mark.parametrize("kind", list(STATES))
def test_the_compiled_case_test_is_exact_where_it_says_certain(kind):
    from attitude.solver.numba_backend import _case_test

    certain_count = 0
    for state in STATES[kind]:
        sign_c, δ1_c, δ3_c, mc_c, certain = _case_test(*state)
        if not certain:
            continue
        certain_count += 1
        sign, δ1, δ3, mc = _exact(*state)
        assert sign_c == sign and mc is not None and mc_c == float(mc), state
        assert _within_an_ulp(δ1_c, δ1) and _within_an_ulp(δ3_c, δ3), state
    if kind == "random":  # it takes magnitudes within 2^±60: half of these
        assert certain_count > 500
    if kind == "on the separatrix":
        assert certain_count == 0


@pytest.mark.parametrize("kind", list(STATES))
def test_the_case_chosen_is_the_sign_of_the_exact_delta2(kind):
    """EulerSolver (one state, the integers) and advance's batch (the double-double and
    the integers) choose the formula of the exact sign; the moments in any order."""
    from attitude.solver.numpy_backend import ManyStates

    expected = {-1: "i", 1: "ii", 0: "iii"}
    rng = np.random.default_rng(5)
    moments, momenta, names = [], [], []
    for state in STATES[kind]:
        sign, *_ = _exact(*state)
        order = rng.permutation(3)
        inertia, m = np.array(state[:3])[order], np.array(state[3:])[order]
        if not math.isfinite(math.hypot(*m) / state[0]):
            continue  # |m|/I1 beyond the float range: refused (test_solver_bad_input)
        solver = EulerSolver(inertia, m)
        # A rate λ that underflows makes a state steady (docs/derivation.md §8).
        assert solver.formula in (expected[sign], "steady"), state
        moments.append(inertia)
        momenta.append(m)
        names.append(solver.formula)
    batch = ManyStates(np.array(moments), np.array(momenta))
    chosen = np.empty(len(names), dtype=object)
    for indices, formula in batch.groups:
        if formula.name == "elliptic":
            chosen[indices] = np.where(formula.case_ii, "ii", "i")
        else:
            chosen[indices] = formula.name
    assert list(chosen) == names


def test_float_delta2_would_fail_here():
    """The near-separatrix states are adversarial: Δ2 evaluated in floats (Leroy's
    two-term form) gets the sign wrong for many of them."""
    wrong = 0
    for I1, I2, I3, m1, m2, m3 in STATES["near the separatrix"]:
        sign, *_ = _exact(I1, I2, I3, m1, m2, m3)
        Δ2 = m1 * m1 * (I1 - I2) / I1 + m3 * m3 * (I3 - I2) / I3
        wrong += (Δ2 > 0) - (Δ2 < 0) != sign
    assert wrong > 0.1 * len(STATES["near the separatrix"])
