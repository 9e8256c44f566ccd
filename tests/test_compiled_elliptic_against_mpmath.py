"""The compiled elliptic kernels (attitude.elliptic.compiled) against mpmath.

mpmath evaluates the same functions at the same float arguments with 40 digits.  The
tolerances are ulps of the value, as in test_elliptic_against_mpmath.py for the numpy
kernels; K is also checked for bias (its mean signed error over many parameters),
since a torqued run sums the phase error of every flow.
"""

import math

import mpmath as mp
import numpy as np
import pytest

from attitude.elliptic.compiled import (
    AGM_LEVELS,
    agm,
    carlson_rf,
    carlson_rj,
    cel_pi_minus_k,
    complete_first_kind,
    reduced_sn_cn_dn,
)

EPS = np.finfo(float).eps
MC_VALUES = [1.0, 0.9, 0.5, 0.1, 1e-3, 1e-6, 1e-10, 1e-15, 1e-30, 2.0**-128]


def mp_parameter(mc):
    mp.mp.dps = 40 + max(0, int(-math.log10(mc)))
    return 1 - mp.mpf(mc)


def _K(mc):
    a_seq, b_seq = np.empty(AGM_LEVELS), np.empty(AGM_LEVELS)
    levels, c = agm(mc, a_seq, b_seq)
    return complete_first_kind(c), levels, c, a_seq, b_seq


@pytest.mark.parametrize("mc", MC_VALUES)
def test_complete_first_kind(mc):
    exact = mp.ellipk(mp_parameter(mc))
    assert abs(_K(mc)[0] - exact) <= 2 * EPS * exact


def test_complete_first_kind_is_unbiased():
    """The mean signed error over 400 parameters is a small fraction of an ulp (π/2
    rounded to a float alone gives −0.35 ulp, which a long torqued run would add up)."""
    rng = np.random.default_rng(11)
    errors = []
    for mc in rng.uniform(0.01, 1.0, 400):
        exact = mp.ellipk(mp_parameter(mc))
        errors.append(float((_K(mc)[0] - exact) / exact) / (EPS / 2))
    assert abs(np.mean(errors)) < 0.15, np.mean(errors)


@pytest.mark.parametrize("mc", MC_VALUES)
def test_reduced_sn_cn_dn(mc):
    """On |r| ≤ K, with the tolerance of the numpy kernels: a few ulps of the value
    plus a few ulps of |r| times the derivative."""
    m = mp_parameter(mc)
    K, levels, c, a_seq, b_seq = _K(mc)
    rng = np.random.default_rng(5)
    special = [0.0, 1e-9, -3e-5, 2e-4, 0.5, K / 2, K * (1 - 1e-12), -K]
    r_values = np.concatenate([special, rng.uniform(-K, K, 20)])
    for r in r_values:
        ours = reduced_sn_cn_dn(r, mc, K, levels, c, a_seq, b_seq)
        s, co, d = (mp.ellipfun(f, mp.mpf(r), m=m) for f in ("sn", "cn", "dn"))
        derivatives = (abs(co * d), abs(s * d), abs(m * s * co))
        for value, exact, deriv in zip(ours, (s, co, d), derivatives, strict=True):
            tolerance = 16 * EPS * abs(exact) + 4 * EPS * (1 + abs(r)) * deriv
            assert abs(value - exact) <= tolerance, (mc, r, value, exact)


@pytest.mark.parametrize("mc", MC_VALUES)
@pytest.mark.parametrize("n", [-1e4, -133.0, -2.0, -0.3, -1e-6, 0.4])
def test_cel_is_pi_minus_k(mc, n):
    m = mp_parameter(mc)
    exact = mp.ellippi(n, m) - mp.ellipk(m)
    assert abs(cel_pi_minus_k(math.sqrt(mc), n) - exact) <= 8 * EPS * abs(exact), (mc, n)


def test_carlson_rf_and_rj_on_the_flow_s_arguments():
    """R_F(c², c² + mc s², 1) (the phase) and R_J(c², dn², 1, c² + (1 − n) s²) (Π − F),
    as the flow forms them, over parameters down to 2^-128 and characteristics to −1e4."""
    rng = np.random.default_rng(7)
    for _ in range(300):
        mc = 2.0 ** rng.uniform(-128, 0)
        n = -(10.0 ** rng.uniform(-6, 4))
        c = rng.uniform(0.0, 1.0)
        x, s2 = c * c, 1.0 - c * c
        y, p = x + mc * s2, x + (1.0 - n) * s2
        mp.mp.dps = 40
        exact_f = mp.elliprf(x, y, 1)
        exact_j = mp.elliprj(x, y, 1, p)
        assert abs(carlson_rf(x, y, 1.0) - exact_f) <= 8 * EPS * exact_f, (x, y)
        assert abs(carlson_rj(x, y, 1.0, p) - exact_j) <= 8 * EPS * exact_j, (x, y, p)


@pytest.mark.parametrize(
    "x, y, z, p",
    [(0.0, 1e-300, 1.0, 1.0), (0.0, 1.0, 2.0, 1e-3), (1.0, 1.0, 1.0, 1.0), (3.0, 5.0, 7.0, 0.5)],
)
def test_carlson_at_the_edges_of_their_domain(x, y, z, p):
    """A zero argument, a tiny one, equal ones, and p below the others (where
    the R_C terms of R_J take their artanh branch)."""
    mp.mp.dps = 40
    assert abs(carlson_rf(x, y, z) - mp.elliprf(x, y, z)) <= 8 * EPS * mp.elliprf(x, y, z)
    exact = mp.elliprj(x, y, z, p)
    assert abs(carlson_rj(x, y, z, p) - exact) <= 8 * EPS * exact
