"""The table backend: the numpy backend with ψ's periodic part from a table built once.

One state at many times.  ψ(τ) = Ω τ − s_u ν + per(r(τ)) (closed_form
``Elliptic.angle_rates``, ``periodic_angle``; docs/derivation.md §7.3a), where the
periodic part per(r) of the reduced phase r ∈ [−K, K] costs one Carlson R_J a sample
from its formula, about half the cost of an attitude.  It is analytic, so a piecewise
Chebyshev table of it (attitude.elliptic.phase_table), built once from the formula and
checked against it between the nodes, gives it to the formula's own rounding for a few
multiplications a sample.  The rest (m, P, Y, M) is the numpy backend's.

Takes the elliptic cases (i) and (ii) with a third-kind integral to save: n ≠ 0 (not a
symmetric body) and mc ≥ 2^-128 (the regular kernels).  Leaves the separatrix, steady
and rest, symmetric bodies and mc < 2^-128, whose ψ has no R_J (it costs a few
elementary functions), and a state whose table would not reach the formula's rounding
(``PiecewiseChebyshev.fit`` returns None): those take the numpy backend.

A table costs 1000 to 6000 evaluations of the formula: attitude.solver.backends
chooses it from ``TABLE_MIN_SAMPLES`` samples in one call.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from attitude.elliptic.phase_table import PiecewiseChebyshev
from attitude.solver import numpy_backend
from attitude.solver.closed_form import CaseFormula, Elliptic, Motion

__all__ = ["Table", "body_vectors", "quaternions", "table", "takes"]

# m(t) has no ψ, so nothing to tabulate: body vectors are the numpy backend's.
body_vectors = numpy_backend.body_vectors


@dataclass(frozen=True)
class Table:
    """A state's table of per(r), with Ω and per(r(t0)): ψ(τ) − ψ(t0) =
    Ω τ + per(r(τ)) − per(r(0))."""

    per: PiecewiseChebyshev
    Ω: float
    per_t0: float


def takes(formula: CaseFormula) -> bool:
    """Whether a table of this formula's ψ would save its R_J (the module docstring)."""
    return isinstance(formula, Elliptic) and not formula.parameter.near_one and formula.n != 0.0


def table(motion: Motion) -> Table | None:
    """The state's table, built at the first call (kept in ``motion.table``); None if
    the formula has none to build or the fit does not reach its rounding."""
    if motion.table is None:
        motion.table = False  # tried: a failed fit is not tried again
        f = motion.formula
        if takes(f):
            assert isinstance(f, Elliptic)
            per = PiecewiseChebyshev.fit(f.periodic_angle, -float(f.K), float(f.K))
            if per is not None:
                _, r0, *_ = f.phase(np.zeros(1), np)
                motion.table = Table(per, f.angle_rates()[1], float(per(r0)[0]))
    return motion.table or None


def quaternions(motion: Motion, times: NDArray[np.float64], columns: tuple) -> NDArray:
    """The attitude quaternions at the times ``times`` (1-D), as
    ``numpy_backend.quaternions``, with ψ's periodic part from the table (or by the
    numpy backend for a state the table leaves)."""
    tabulated = table(motion)
    if tabulated is None:
        return numpy_backend.quaternions(motion, times, columns)
    f = motion.formula
    assert isinstance(f, Elliptic)

    def chunk(τ: NDArray, out: NDArray) -> None:
        j, r, sn_r, cn_r, dn_r = f.phase(τ, np)
        a, b, c = f.momentum_of_phase(j, sn_r, cn_r, dn_r, np)
        del j, sn_r, cn_r, dn_r
        periodic = tabulated.per(r)
        del r
        periodic -= tabulated.per_t0
        half_ψ = tabulated.Ω * τ
        half_ψ += periodic
        half_ψ *= 0.5
        del periodic
        numpy_backend.write_quaternions(motion, a, b, c, half_ψ, out, columns)

    return numpy_backend.evaluate(chunk, lambda a, b: times[a:b] - motion.t0, times.size, 4)
