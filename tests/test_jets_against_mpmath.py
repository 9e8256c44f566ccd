"""Taylor jets (attitude.base.jets) against mpmath's numerical differentiation of the
same formulas at 40 digits: every operation the laws use, composed."""

import mpmath as mp
import numpy as np

from attitude.base.jets import (
    Jet,
    cross,
    dot,
    matmul,
    matvec,
    normalized,
    reciprocal,
    sin_cos,
    sqrt,
)

mp.mp.dps = 40
T0 = 0.37


def _curve(t):
    """A vector, a scalar and a matrix of time, in any arithmetic with sin and cos."""
    sin, cos = (mp.sin, mp.cos) if isinstance(t, mp.mpf) else (np.sin, np.cos)
    u = [1.0 + 0.3 * t + 0.2 * t * t, cos(2 * t), 0.5 * sin(t) - t**3]
    w = [sin(3 * t), 2.0 - t, 0.1 * t * t]
    return u, w


def _formula(u, w, ops):
    """normalize(u × w) · (M u) / √(u·u) + sin(u·w) / (1 + w·w), M a rotation by t."""
    cross_, dot_, normalized_, sqrt_, sin_, reciprocal_, matvec_ = ops
    n = normalized_(cross_(u, w))
    return dot_(n, matvec_(u)) * reciprocal_(sqrt_(dot_(u, u))) + sin_(dot_(u, w)) * reciprocal_(
        1.0 + dot_(w, w)
    )


def test_composed_formula_against_mpmath_diff():
    order = 3
    t = Jet.linear(np.array([T0]), 1.0, order)
    u = Jet(
        np.stack(
            [
                c.c
                for c in (
                    1.0 + t * 0.3 + t * t * 0.2,
                    sin_cos(t * 2.0)[1],
                    sin_cos(t)[0] * 0.5 - t * t * t,
                )
            ],
            axis=-1,
        )
    )
    w = Jet(np.stack([c.c for c in (sin_cos(t * 3.0)[0], 2.0 - t, t * t * 0.1)], axis=-1))
    s, c = sin_cos(t)
    zero, one = Jet.constant(np.zeros(1), order), Jet.constant(np.ones(1), order)
    rows = [[c, -s, zero], [s, c, zero], [zero, zero, one]]
    M = Jet(np.stack([np.stack([e.c for e in row], axis=-1) for row in rows], axis=-2))
    ops = (
        cross,
        dot,
        normalized,
        sqrt,
        lambda x: sin_cos(x)[0],
        reciprocal,
        lambda v: matvec(M, v),
    )
    ours = _formula(u, w, ops).derivatives()[:, 0]

    def reference(x):
        uu, ww = _curve(x)
        uu, ww = mp.matrix(uu), mp.matrix(ww)
        rot = mp.matrix([[mp.cos(x), -mp.sin(x), 0], [mp.sin(x), mp.cos(x), 0], [0, 0, 1]])

        def cross_(a, b):
            return mp.matrix(
                [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
            )

        def dot_(a, b):
            return sum(a[i] * b[i] for i in range(3))

        return _formula(
            uu,
            ww,
            (
                cross_,
                dot_,
                lambda a: a / mp.sqrt(dot_(a, a)),
                mp.sqrt,
                mp.sin,
                lambda a: 1 / a,
                lambda a: rot * a,
            ),
        )

    for k in range(order + 1):
        want = float(mp.diff(reference, mp.mpf(T0), k))
        assert abs(ours[k] - want) <= 1e-14 * max(1.0, abs(want)), (k, ours[k], want)


def test_matrix_products_and_derivative_shift():
    t = Jet.linear(np.array([0.2, -1.0]), 1.0, 3)
    s, c = sin_cos(t)
    m = Jet(np.stack([np.stack([c.c, -s.c], -1), np.stack([s.c, c.c], -1)], -2))  # R(t)
    product = matmul(m, m).derivatives()  # R(2t)
    for k in range(4):
        angle = 2 * np.array([0.2, -1.0]) + k * np.pi / 2
        want = 2.0**k * np.stack(
            [
                np.stack([np.cos(angle), -np.sin(angle)], -1),
                np.stack([np.sin(angle), np.cos(angle)], -1),
            ],
            -2,
        )
        assert np.max(np.abs(product[k] - want)) < 1e-14
    assert np.allclose(s.derivative().derivatives(), s.derivatives()[1:], rtol=0, atol=1e-16)
