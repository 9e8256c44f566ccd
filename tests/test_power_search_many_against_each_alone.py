"""``first_below_many`` (the power search of many pieces at once) against
``first_below`` on each piece alone, on functions with a known Lipschitz bound
(|d/dt (c + A cos(ωt))| ≤ A ω): the same first times, bit for bit, and the same value
at each piece's start; and the first time against the exact first crossing of the
threshold (arccos), which it may precede by at most the precision, never follow."""

import math

import numpy as np

from attitude.envelope.power import _CHUNK_NODES, _SAG, first_below, first_below_many

# (offset, amplitude, ω rad/s, a, b): crossing early, late, at the start, never, an
# empty piece, and one of more cells than a run holds (searched alone in runs).
PIECES = [
    (0.6, 0.5, 0.01, 0.0, 3600.0),
    (0.6, 0.5, 0.001, 100.0, 3000.0),
    (0.2, 0.05, 0.02, 50.0, 900.0),
    (0.9, 0.1, 0.05, 0.0, 3600.0),
    (0.6, 0.5, 0.01, 700.0, 700.0),
    (0.6, 0.5, 3.0, 10.0, 3600.0),
]
THRESHOLD = 0.3
PRECISION = 1e-3


def _f(piece, t):
    c, amplitude, ω, _, _ = piece
    return c + amplitude * np.cos(ω * t)


def test_many_pieces_against_each_alone_and_the_exact_crossing():
    precision = np.full(len(PIECES), PRECISION)
    a = np.array([p[3] for p in PIECES])
    b = np.array([p[4] for p in PIECES])
    lipschitz = np.array([p[1] * p[2] for p in PIECES])

    def f(which, t):
        out = np.empty(t.size)
        for i in np.unique(which):
            out[which == i] = _f(PIECES[i], t[which == i])
        return out

    found, at_start = first_below_many(f, a, b, lipschitz, THRESHOLD, precision)
    for i, piece in enumerate(PIECES):
        alone = first_below(
            lambda t, p=piece: _f(p, t), a[i], b[i], lipschitz[i], THRESHOLD, PRECISION
        )
        assert (alone is None and math.isnan(found[i])) or alone == found[i], (i, alone, found[i])
        assert at_start[i] == _f(piece, np.array([a[i]]))[0]
        # The exact first crossing of c + A cos(ωt) = threshold after a.
        c, amplitude, ω = piece[:3]
        if _f(piece, np.array([a[i]]))[0] <= THRESHOLD:
            assert found[i] == a[i]
            continue
        ratio = (THRESHOLD - c) / amplitude
        if abs(ratio) > 1.0:
            assert math.isnan(found[i])
            continue
        base = math.acos(ratio)  # crossings at ±base + 2πk, over ω
        times = [
            (s * base + 2.0 * math.pi * k) / ω
            for k in range(-1, int(b[i] * ω / (2 * math.pi)) + 2)
            for s in (1.0, -1.0)
        ]
        exact = min((x for x in times if a[i] <= x <= b[i]), default=math.inf)
        if math.isinf(exact):
            assert math.isnan(found[i])
        else:
            assert exact - PRECISION <= found[i] <= exact, (i, found[i], exact)
    outcomes = [
        "start" if found[i] == a[i] else "never" if math.isnan(found[i]) else "later"
        for i in range(len(PIECES))
    ]
    assert {"start", "later", "never"} <= set(outcomes)
    assert (b[-1] - a[-1]) * lipschitz[-1] / (2.0 * _SAG) > _CHUNK_NODES  # searched alone
