"""Every splitting's coefficients against the exact exponential: the published orders.

For linear vector fields A and B (matrices) the flows are matrix exponentials, and a
composition ∏ exp(a_i h A) exp(b_i h B) of classical order p differs from exp(h(A + B))
by O(h^{p+1}) for *generic* A and B: the order conditions are identities in the free
Lie algebra, which random matrices satisfy no more than they must.  mpmath at 60 digits
computes both sides, so that slopes up to h^11 are measurable.

- classical order: random 4×4 A, B; the local error falls as h^{p+1};
- the RKN order (SRKN_11^b): block matrices A = [[0, P], [0, 0]], B = [[0, 0], [Q, 0]],
  for which [B, [B, [B, A]]] = 0, as for a torque independent of ω;
- generalized orders (r1, r2): B scaled by ε; the O(ε) part of the error falls as
  h^{r1+1}, and the O(ε²) part (ε-Richardson: e(2ε) − 2e(ε)) as h^{r2+1}.

The dependent coefficients (those fixed by Σa = Σb = 1) are recomputed at 60 digits,
so that the 15- or 40-digit published values leave no O(εh) consistency error.
"""

import mpmath as mp
import numpy as np
import pytest

from attitude.torques.splitting import COMPOSITIONS, DEFAULT_BY_ORDER, composition

DIGITS = 60


def _exact_coefficients(values):
    """The symmetric coefficients with the middle one(s) fixed by Σ = 1 at 60 digits."""
    values = [mp.mpf(v) for v in values]
    nonzero = [i for i, v in enumerate(values) if v != 0]
    middle = nonzero[len(nonzero) // 2 - (1 - len(nonzero) % 2) : len(nonzero) // 2 + 1]
    rest = sum(v for i, v in enumerate(values) if i not in middle)
    for i in middle:
        values[i] = (1 - rest) / len(middle)
    return values


def _local_error(method, h, A, B):
    flows = _exact_coefficients(method.flows)
    kicks = _exact_coefficients(method.kicks)
    product = mp.eye(A.rows)
    for j, b in enumerate(kicks):
        if b != 0:
            product = mp.expm(B * (b * h)) * product
        if j < len(flows):
            product = mp.expm(A * (flows[j] * h)) * product
    return mp.mnorm(product - mp.expm((A + B) * h), 1)


def _slope(f, h):
    return float(mp.log(f(h) / f(h / 2), 2))


@pytest.fixture(scope="module")
def matrices():
    rng = np.random.default_rng(2013)
    with mp.workdps(DIGITS):
        A = mp.matrix(rng.normal(size=(4, 4)).tolist())
        B = mp.matrix(rng.normal(size=(4, 4)).tolist())
        P, Q = rng.normal(size=(2, 2)), rng.normal(size=(2, 2))
        A_rkn, B_rkn = mp.zeros(4, 4), mp.zeros(4, 4)
        for i in range(2):
            for j in range(2):
                A_rkn[i, 2 + j] = P[i, j]
                B_rkn[2 + i, j] = Q[i, j]
    return A, B, A_rkn, B_rkn


@pytest.mark.parametrize("name", sorted(COMPOSITIONS))
def test_classical_order(matrices, name):
    A, B, A_rkn, B_rkn = matrices
    method = COMPOSITIONS[name]
    with mp.workdps(DIGITS):
        if method.needs_rkn:
            slope = _slope(lambda h: _local_error(method, h, A_rkn, B_rkn), mp.mpf("0.05"))
            generic = _slope(lambda h: _local_error(method, h, A, B), mp.mpf("0.02"))
            assert abs(generic - 5.0) < 0.1, generic  # order 4 without the RKN structure
        else:
            slope = _slope(lambda h: _local_error(method, h, A, B), mp.mpf("0.02"))
    assert abs(slope - (method.order + 1)) < 0.1, (name, slope)


@pytest.mark.parametrize("name", [n for n, c in COMPOSITIONS.items() if c.generalized_order])
def test_generalized_orders(matrices, name):
    A, B, _, _ = matrices
    method = COMPOSITIONS[name]
    r1, r2, _ = method.generalized_order
    with mp.workdps(DIGITS):
        ε = mp.mpf("1e-20")
        # At h = 0.4: smaller steps bring the ε h^11 term down to the rounding of the
        # coefficients to doubles (their residual in the lower order conditions).
        first = _slope(lambda h: _local_error(method, h, A, ε * B), mp.mpf("0.4"))
        ε = mp.mpf("1e-8")

        def second(h):
            return abs(
                _local_error(method, h, A, 2 * ε * B) - 2 * _local_error(method, h, A, ε * B)
            )

        second_slope = _slope(second, mp.mpf("0.2"))
    assert abs(first - (r1 + 1)) < 0.7, (name, first)
    assert abs(second_slope - (r2 + 1)) < 0.7, (name, second_slope)


def test_defaults_by_order():
    for order, name in DEFAULT_BY_ORDER.items():
        assert composition(order).name == name and COMPOSITIONS[name].order == order
    assert composition(method="yoshida").order == 4
    for method in COMPOSITIONS.values():
        assert abs(sum(method.flows) - 1.0) < 1e-15 and abs(sum(method.kicks) - 1.0) < 1e-15
        assert method.flows == method.flows[::-1] and method.kicks == method.kicks[::-1]
