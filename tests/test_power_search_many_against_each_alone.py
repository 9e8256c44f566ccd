"""``first_below_many`` (the power search of many runs of nodes at once) against
``first_below`` on each piece alone, on functions with a known Lipschitz bound
(|d/dt (c + A cos(ωt))| ≤ A ω): the same first times, bit for bit, whether a piece's
nodes go in one run or in runs of a few cells; the same value at each piece's start;
and the first time against the exact first crossing of the threshold (arccos), which
it may precede by at most the precision, never follow."""

import math

import numpy as np

from attitude.envelope.power import first_below, first_below_many, first_nodes

# (offset, amplitude, ω rad/s, a, b): crossing early, late, at the start, never, an
# empty piece.
PIECES = [
    (0.6, 0.5, 0.01, 0.0, 3600.0),
    (0.6, 0.5, 0.001, 100.0, 3000.0),
    (0.2, 0.05, 0.02, 50.0, 900.0),
    (0.9, 0.1, 0.05, 0.0, 3600.0),
    (0.6, 0.5, 0.01, 700.0, 700.0),
]
THRESHOLD = 0.3
PRECISION = 1e-3


def _f(piece, t):
    c, amplitude, ω, _, _ = piece
    return c + amplitude * np.cos(ω * t)


def _many(runs_of: int | None):
    """Every piece's first time by first_below_many, its nodes in runs of ``runs_of``
    cells (None: one run), the runs of a piece taken in order as the envelope does."""
    runs, owner = [], []
    for i, (_, amplitude, ω, a, b) in enumerate(PIECES):
        nodes = first_nodes(a, b, amplitude * ω)
        step = max(nodes.size - 1, 1) if runs_of is None else runs_of
        for start in range(0, max(nodes.size - 1, 1), step):
            runs.append(nodes[start : start + step + 1])
            owner.append(i)
    owner = np.array(owner)
    lipschitz = np.array([PIECES[i][1] * PIECES[i][2] for i in owner])

    def f(which, t):
        out = np.empty(t.size)
        for k in np.unique(which):
            out[which == k] = _f(PIECES[owner[k]], t[which == k])
        return out

    found, at_start = first_below_many(f, runs, lipschitz, THRESHOLD, np.full(len(runs), PRECISION))
    first = np.full(len(PIECES), np.nan)
    start = np.full(len(PIECES), np.nan)
    for k in range(len(runs) - 1, -1, -1):  # the first run with an answer wins
        if not math.isnan(found[k]):
            first[owner[k]] = found[k]
        start[owner[k]] = at_start[k]
    return first, start


def test_many_runs_against_each_piece_alone_and_the_exact_crossing():
    one_run, at_start = _many(None)
    in_runs, _ = _many(5)
    outcomes = set()
    for i, piece in enumerate(PIECES):
        c, amplitude, ω, a, b = piece
        alone = first_below(lambda t, p=piece: _f(p, t), a, b, amplitude * ω, THRESHOLD, PRECISION)
        for found in (one_run[i], in_runs[i]):
            assert (alone is None and math.isnan(found)) or alone == found, (i, alone, found)
        assert at_start[i] == _f(piece, np.array([a]))[0]
        # The exact first crossing of c + A cos(ωt) = threshold from a.
        if _f(piece, np.array([a]))[0] <= THRESHOLD:
            assert one_run[i] == a
            outcomes.add("start")
            continue
        ratio = (THRESHOLD - c) / amplitude
        crossings = (
            [
                (s * math.acos(ratio) + 2.0 * math.pi * k) / ω
                for k in range(-1, int(b * ω / (2 * math.pi)) + 2)
                for s in (1.0, -1.0)
            ]
            if abs(ratio) <= 1.0
            else []
        )
        exact = min((x for x in crossings if a <= x <= b), default=math.inf)
        if math.isinf(exact):
            assert math.isnan(one_run[i])
            outcomes.add("never")
        else:
            assert exact - PRECISION <= one_run[i] <= exact, (i, one_run[i], exact)
            outcomes.add("later")
    assert outcomes == {"start", "later", "never"}


def test_a_piece_of_more_cells_than_a_run_is_left_to_first_below():
    assert first_nodes(10.0, 3600.0, 1.5) is None  # 53 850 cells: searched alone, in runs
    assert first_nodes(10.0, 400.0, 1.5).size == 5851
