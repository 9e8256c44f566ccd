"""Our elliptic kernels against mpmath at high precision.

mpmath evaluates the same functions at the same float arguments with 30+ extra
digits (``m = 1 − mc`` is formed in mpmath, so mc = 1e-15 keeps its digits).  The
tolerance is a few ulps of the value plus a few ulps of |u| times the derivative:
for |u| beyond a period the float argument reduction cannot do better than the
rounding of the period K itself (the result is exact for an argument within a few
ulps of u).
"""

import math

import mpmath as mp
import numpy as np
import pytest

from attitude.elliptic.functions import (
    NEAR_ONE_MC,
    complete_first_kind,
    complete_first_kind_near_one,
    elliptic_f,
    elliptic_pi,
    elliptic_pi_complete,
    jacobi_amplitude,
    jacobi_sn_cn_dn,
    pi_minus_f_near_one,
    reduced_sn_cn_dn,
    reduced_sn_cn_dn_near_one,
)

EPS = np.finfo(float).eps
# m near 0, 0.5 and 1: the Dzhanibekov regime lives at mc < 1e-10.
MC_VALUES = [1.0, 1.0 - 1e-12, 0.9, 0.5, 0.1, 1e-3, 1e-6, 1e-10, 1e-13, 1e-15, 1e-16]


def mp_parameter(mc):
    """m = 1 − mc in mpmath, with enough digits to keep those of mc."""
    mp.mp.dps = 40 + max(0, int(-math.log10(mc))) if mc > 0 else 40
    return 1 - mp.mpf(mc)


def arguments(K, rng):
    """Small, moderate and large arguments, including the quarter and half periods."""
    return np.concatenate(
        [
            [0.0, 1e-9, -3e-5, 2e-4, 0.5, K / 2, K * (1 - 1e-12), K, -K, 2 * K, 3 * K + 0.25],
            rng.uniform(-4 * K, 4 * K, 25),
            [1e3 * K + 0.3, -1e5 * K - 0.7, 12345.678],
        ]
    )


@pytest.mark.parametrize("mc", MC_VALUES)
def test_jacobi_sn_cn_dn(mc):
    rng = np.random.default_rng(17)
    m = mp_parameter(mc)
    K = float(complete_first_kind(mc))
    u = arguments(K, rng)
    sn, cn, dn = jacobi_sn_cn_dn(u, mc)
    for i, x in enumerate(u):
        s, c, d = (mp.ellipfun(f, mp.mpf(x), m=m) for f in ("sn", "cn", "dn"))
        derivatives = (abs(c * d), abs(s * d), abs(m * s * c))
        for ours, exact, deriv in zip((sn[i], cn[i], dn[i]), (s, c, d), derivatives, strict=True):
            tolerance = 8 * EPS * abs(exact) + 4 * EPS * (1 + abs(x)) * deriv
            assert abs(ours - exact) <= tolerance, (mc, x, ours, exact)


@pytest.mark.parametrize("mc", [1e-3, 1e-15, 1e-30, 1e-100])
def test_cn_and_dn_keep_relative_accuracy_near_the_quarter_period(mc):
    """Near u = K, cn and dn are both small (dn(K) = √mc); they keep their digits.

    Relative accuracy, up to the rounding of K itself (a few ulps of K times the
    derivative): without the quarter-period shift, dn would have only absolute
    accuracy there (relative errors of 1e-12 at mc = 1e-30 and of 100% at 1e-100).
    """
    m = mp_parameter(mc)
    K = float(complete_first_kind(mc))
    u = K * np.array([0.6, 0.8, 0.9, 0.99, 0.999])
    _sn, cn, dn = reduced_sn_cn_dn(u, mc)
    for i, x in enumerate(u):
        s, c, d = (mp.ellipfun(f, mp.mpf(x), m=m) for f in ("sn", "cn", "dn"))
        assert abs(cn[i] - c) <= 16 * EPS * abs(c) + 4 * EPS * K * abs(s * d)
        assert abs(dn[i] - d) <= 16 * EPS * abs(d) + 4 * EPS * K * abs(m * s * c)


def test_separatrix_parameter_gives_hyperbolic_functions():
    u = np.linspace(-30, 30, 61)
    sn, cn, dn = jacobi_sn_cn_dn(u, 0.0)
    np.testing.assert_allclose(sn, np.tanh(u), rtol=1e-15, atol=0)
    np.testing.assert_allclose(cn, 1 / np.cosh(u), rtol=1e-15, atol=0)
    np.testing.assert_array_equal(cn, dn)


@pytest.mark.parametrize("mc", [1.0, 0.5, 1e-6, 1e-15])
def test_amplitude_inverts_mpmath_elliptic_f(mc):
    """am is the inverse of F: mpmath's F of our amplitude gives back u."""
    rng = np.random.default_rng(3)
    m = mp_parameter(mc)
    K = float(complete_first_kind(mc))
    u = np.concatenate([rng.uniform(-5 * K, 5 * K, 30), [K, 2 * K, -3 * K]])
    am = jacobi_amplitude(u, mc)
    for x, φ in zip(u, am, strict=True):
        # dF/dφ = 1/dn, so an error of δ in φ moves F by δ/dn; compare in u.
        back = mp.ellipf(mp.mpf(φ), m)
        dn = float(mp.sqrt(1 - m * mp.sin(mp.mpf(φ)) ** 2))
        assert abs(back - x) <= 8 * EPS * (1 + abs(x)) + 8 * EPS * abs(φ) / dn, (mc, x)


@pytest.mark.parametrize("mc", [1.0, 0.5, 1e-8, 1e-15])
def test_amplitude_is_continuous_and_increasing(mc):
    K = float(complete_first_kind(mc))
    u = np.linspace(-7 * K, 7 * K, 200_001)
    am = jacobi_amplitude(u, mc)
    steps = np.diff(am)
    assert np.all(steps > 0)
    # The largest step is bounded by max(dam/du) = max(dn) = 1 times the grid step.
    assert steps.max() <= (u[1] - u[0]) * (1 + 1e-9)


@pytest.mark.parametrize("mc", [1.0, 0.5, 1e-3, 1e-9, 1e-15])
def test_complete_first_kind(mc):
    m = mp_parameter(mc)
    assert abs(complete_first_kind(mc) - mp.ellipk(m)) <= 4 * EPS * mp.ellipk(m)


@pytest.mark.parametrize("mc", [1.0, 0.5, 1e-3, 1e-9, 1e-15])
def test_elliptic_f_any_amplitude(mc):
    m = mp_parameter(mc)
    for φ in [0.3, -1.2, math.pi / 2, 2.0, -3.0, 10.5, 100.25, -1234.5]:
        exact = mp.ellipf(mp.mpf(φ), m)
        assert abs(elliptic_f(φ, mc) - exact) <= 8 * EPS * abs(exact), (mc, φ)


@pytest.mark.parametrize("mc", [1.0, 0.5, 1e-3, 1e-9, 1e-15])
@pytest.mark.parametrize("n", [-50.0, -2.0, -0.3, 0.0, 0.4, 0.9])
def test_elliptic_pi_any_amplitude(mc, n):
    m = mp_parameter(mc)
    """Π = F + (Π − F): accurate to a few ulps of the larger of |Π| and |F|.

    For n ≪ 0 and φ past π/2 the two parts nearly cancel (Π(φ) ≈ 1 while F ≈ 2K),
    so the error is measured against |F| there.
    """
    for φ in [0.3, -1.2, math.pi / 2, 2.0, -3.0, 10.5, 100.25, -1234.5]:
        exact = mp.ellippi(n, mp.mpf(φ), m)
        scale = max(abs(exact), abs(mp.ellipf(mp.mpf(φ), m)))
        assert abs(elliptic_pi(φ, n, mc) - exact) <= 16 * EPS * scale, (mc, n, φ)
    complete = mp.ellippi(n, m)
    scale = max(abs(complete), mp.ellipk(m))
    assert abs(elliptic_pi_complete(n, mc) - complete) <= 16 * EPS * scale


def test_vectorized_over_parameter_and_argument():
    mc = np.array([[1.0], [0.5], [1e-12]])
    u = np.array([0.1, 2.0, -7.0, 40.0])
    sn, _cn, dn = jacobi_sn_cn_dn(u, mc)
    assert sn.shape == (3, 4)
    for i in range(3):
        row = jacobi_sn_cn_dn(u, mc[i, 0])
        np.testing.assert_allclose(sn[i], row[0], rtol=0, atol=4 * EPS)
        np.testing.assert_allclose(dn[i], row[2], rtol=0, atol=4 * EPS)


@pytest.mark.parametrize("bad", [-1e-3, 1.5, float("nan")])
def test_parameter_outside_zero_one_is_refused(bad):
    with pytest.raises(ValueError, match="mc"):
        jacobi_sn_cn_dn(1.0, bad)


def test_characteristic_at_or_above_one_is_refused():
    with pytest.raises(ValueError, match="n must be < 1"):
        elliptic_pi(1.0, 1.0, 0.5)


# ----------------------------------------------------------------- m within 2^-128 of 1


@pytest.mark.parametrize("mc", [1e-100, 1e-300, 2e-308, 1e-310, 1e-320])
def test_general_kernels_keep_accuracy_for_tiny_and_subnormal_mc(mc):
    """For its float argument, however small, the AGM kernel stays accurate.

    (What a subnormal mc loses is its own digits, as a rounded physical ratio: that is
    why the solver switches to ln mc below NEAR_ONE_MC; see the next tests.)
    """
    m = mp_parameter(mc)
    K = float(complete_first_kind(mc))
    assert abs(K - mp.ellipk(m)) <= 4 * EPS * K
    u = np.array([0.5, K / 3, K / 2, 0.7 * K, 0.999 * K, 1.7 * K, -2.3 * K])
    sn, cn, dn = jacobi_sn_cn_dn(u, mc)
    for i, x in enumerate(u):
        s, c, d = (mp.ellipfun(f, mp.mpf(x), m=m) for f in ("sn", "cn", "dn"))
        # Relative accuracy, up to the argument's rounding (|u| ≤ 3K ≈ 1100 here).
        for ours, exact, deriv in ((sn[i], s, c * d), (cn[i], c, s * d), (dn[i], d, m * s * c)):
            assert abs(ours - exact) <= 16 * EPS * abs(exact) + 4 * EPS * abs(x) * abs(deriv)


def _mp_near_one(log_mc):
    """m = 1 − e^log_mc in mpmath with 40 digits beyond those of mc."""
    mp.mp.dps = 40 + int(-log_mc / math.log(10))
    return 1 - mp.exp(mp.mpf(log_mc))


# ln mc from just below NEAR_ONE_MC to far below the float range (mc = 1e-700).
NEAR_ONE_LOG_MC = [
    math.log(NEAR_ONE_MC) - 0.5,
    math.log(1e-60),
    math.log(1e-300),
    -400 * math.log(10),
    -700 * math.log(10),
]


@pytest.mark.parametrize("log_mc", NEAR_ONE_LOG_MC)
def test_near_one_kernels_against_mpmath(log_mc):
    """sn, cn, dn and K from ln mc, to a few ulps, where mc may have no float at all."""
    m = _mp_near_one(log_mc)
    K = float(complete_first_kind_near_one(log_mc))
    assert abs(K - mp.ellipk(m)) <= 2 * EPS * K
    r = K * np.array([0.0, 1e-6, 0.1, -0.3, 0.5 - 1e-9, 0.5 + 1e-9, -0.6, 0.8, 0.99, -1.0, 1.0])
    sn, cn, dn = reduced_sn_cn_dn_near_one(r, log_mc, K)
    for i, x in enumerate(r):
        s, c, d = (mp.ellipfun(f, mp.mpf(x), m=m) for f in ("sn", "cn", "dn"))
        # A few ulps, plus the rounding of r (and of K: a few ulps of K) times the
        # derivative; values below the float range (~1e-308) come out as 0.
        derivatives = (abs(c * d), abs(s * d), abs(m * s * c))
        for ours, exact, deriv in zip((sn[i], cn[i], dn[i]), (s, c, d), derivatives, strict=True):
            tolerance = 8 * EPS * abs(exact) + 4 * EPS * K * deriv + 1e-300
            assert abs(ours - exact) <= tolerance, (x, ours, exact)


@pytest.mark.parametrize("log_mc", NEAR_ONE_LOG_MC)
@pytest.mark.parametrize("n", [-40.0, -2.0, -0.3, -1e-3])
def test_near_one_pi_minus_f_against_mpmath(log_mc, n):
    """Π(am u, n) − u for u = 2jK + r, against mpmath's Π on its own amplitude."""
    m = _mp_near_one(log_mc)
    K = float(complete_first_kind_near_one(log_mc))
    for j, fraction in [(0, 0.0), (0, 0.2), (0, -0.45), (0, 0.7), (0, -0.999), (1, 0.3), (-3, 0.9)]:
        r = fraction * K
        sn, _cn, _dn = reduced_sn_cn_dn_near_one(r, log_mc, K)
        ours = pi_minus_f_near_one(j, r, sn, n, K)
        φ = mp.asin(mp.ellipfun("sn", mp.mpf(r), m=m))  # am r, in [−π/2, π/2] for |r| ≤ K
        exact = mp.ellippi(n, φ, m) - r + 2 * j * (mp.ellippi(n, m) - mp.ellipk(m))
        # A few ulps of the terms that make it up (|u| and the complete integrals).
        scale = abs(n / (1 - n)) * (abs(r) + 2 * abs(j) * K + 1)
        assert abs(ours - exact) <= 8 * EPS * scale, (j, fraction, ours, exact)
