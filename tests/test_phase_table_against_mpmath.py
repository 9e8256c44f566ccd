"""The table of ψ's periodic part (attitude.elliptic.phase_table) against mpmath and the formula.

``EulerSolver`` takes the periodic part of ψ from a piecewise Chebyshev table when a
call asks for many times (``backends.TABLE_MIN_SAMPLES``).  A table is only
acceptable if it is as exact as the formula it replaces:

- per(r) from the table and from the formula (``Elliptic.periodic_angle``), both
  against mpmath at 40+ digits with the same float constants, from mc ≈ 0.5 down to
  just above 2^-128 (the regular kernels' range), on both sides of the separatrix and
  for a nearly symmetric body (n ≈ −1e4): the table's error is no larger than the
  formula's (both a few units of 2^-52 times the largest term of the formula);
- the fit also works on the near-one formula (mc = 1e-300 and 1e-616), where the
  solver keeps the formula since it has no R_J to save;
- the attitude through the table against a 25-digit Taylor integration over a flip,
  and against the formula's attitude at the same times out to 1e6 periods.
"""

import math

import mpmath as mp
import numpy as np
import pytest
from reference_models import integrate_mpmath, state_with_delta2
from scipy.spatial.transform import Rotation

from attitude import EulerSolver
from attitude.elliptic.phase_table import PiecewiseChebyshev
from attitude.solver.backends import TABLE_MIN_SAMPLES as _TABLE_MIN_SAMPLES
from attitude.solver.closed_form import Elliptic

ATTITUDE0 = Rotation.from_euler("ZYX", [10.0, 20.0, 30.0], degrees=True)


def _state_with_mc(target: float):
    """A state (1e-x, 1, 2e-x) of I = (1, 2, 3) whose mc is within a factor 2 of target."""
    low, high = -320.0, 0.0
    for _ in range(60):
        mid = 0.5 * (low + high)
        mc = EulerSolver([1.0, 2.0, 3.0], [10.0**mid, 1.0, 2.0 * 10.0**mid]).mc
        low, high = (mid, high) if mc < target else (low, mid)
    return [1.0, 2.0, 3.0], [10.0**low, 1.0, 2.0 * 10.0**low]


def _delta2_state(ratio):
    inertia = np.array([1.0, 2.0, 3.0])
    return inertia, state_with_delta2(inertia, ratio, weight=0.4, rng=np.random.default_rng(3))


STATES = {
    "far, case i": ([3.0, 1.0, 2.0], [0.6, -0.5, 0.4]),
    "far, case ii": ([3.0, 1.0, 2.0], [0.2, -0.3, 0.9]),
    "Dzhanibekov, mc 2e-6": ([100.0, 200.0, 300.0], [0.1, 200.0, 0.3]),
    "|Δ2|/G² = 1e-10, case ii": _delta2_state(1e-10),
    "|Δ2|/G² = -1e-10, case i": _delta2_state(-1e-10),
    "nearly symmetric, n = -1e4": ([2.0, 2.0001, 5.0], [0.5, 0.4, 0.001]),
    "mc just above 2^-128": _state_with_mc(2.0**-126),
}
SLOW = {"mc just above 2^-128"}


def _periodic_angle_mpmath(f: Elliptic, r: np.ndarray) -> list:
    """per(r) = C (Π − F)(am r) + κ_sign arctg(κ sc r) − s_u r in mpmath, with the
    formula's own float constants (so that only the evaluation is compared)."""
    digits = 40 + int(-math.log10(f.mc))
    with mp.workdps(digits):
        m = 1 - mp.mpf(f.mc)
        C, n, κ = mp.mpf(f.C), mp.mpf(f.n), mp.mpf(f.κ)
        s_u = mp.mpf(f.angle_rates()[0])
        out = []
        for x in r:
            x = mp.mpf(x)
            sn, cn = mp.ellipfun("sn", x, m=m), mp.ellipfun("cn", x, m=m)
            φ = mp.atan2(sn, cn)  # am x, for |x| ≤ K
            arc = φ + mp.atan((κ - 1) * sn * cn / (cn * cn + κ * sn * sn))
            out.append(C * (mp.ellippi(n, φ, m) - x) + f.κ_sign * arc - s_u * x)
        return out


def _errors(values: np.ndarray, reference: list, digits: int) -> np.ndarray:
    with mp.workdps(digits):
        return np.array(
            [float(abs(mp.mpf(float(v)) - ref)) for v, ref in zip(values, reference, strict=True)]
        )


@pytest.mark.parametrize(
    "name", [pytest.param(n, marks=pytest.mark.slow) if n in SLOW else n for n in STATES]
)
def test_the_table_is_as_exact_as_the_formula_against_mpmath(name):
    inertia, momentum = STATES[name]
    f = EulerSolver(inertia, momentum)._formula
    assert isinstance(f, Elliptic) and not f.parameter.near_one
    table = PiecewiseChebyshev.fit(f.periodic_angle, -f.K, f.K)
    assert table is not None
    r = np.random.default_rng(5).uniform(-f.K, f.K, 60 if name in SLOW else 40)
    formula, largest = f.periodic_angle(r)
    reference = _periodic_angle_mpmath(f, r)
    digits = 40 + int(-math.log10(f.mc))
    unit = 2.0**-52 * largest  # the rounding of the formula's largest term
    formula_error = _errors(formula, reference, digits) / unit
    table_error = _errors(table(r), reference, digits) / unit
    # Measured: the formula up to 5.2 units, the table up to 3.8 (rms 0.9 both).
    assert formula_error.max() <= 8.0
    assert table_error.max() <= max(8.0, formula_error.max())
    assert np.sqrt(np.mean(table_error**2)) <= 1.5 * np.sqrt(np.mean(formula_error**2)) + 0.3
    assert table.max_error <= 8.0 * table.rounding  # its own check between the nodes


@pytest.mark.slow
@pytest.mark.parametrize("x", [1e-150, 2.0**-1022])
def test_the_fit_works_on_the_near_one_formula(x):
    """x G off the intermediate axis: mc ≈ 1e-300, and mc ≈ 1e-616 below the float range
    (ln mc ≈ −1418, exact from the integers).  The solver keeps the formula there (it
    has no R_J to save), but a table of it would be as exact."""
    f = EulerSolver([1.0, 2.0, 3.0], [x, 1.0, 2.0 * x])._formula
    assert f.parameter.near_one
    table = PiecewiseChebyshev.fit(f.periodic_angle, -f.K, f.K, max_pieces=8192)
    assert table is not None and table.max_error <= 8.0 * table.rounding
    r = np.random.default_rng(6).uniform(-f.K, f.K, 2000)
    formula, largest = f.periodic_angle(r)
    assert np.max(np.abs(table(r) - formula)) <= 8.0 * 2.0**-52 * largest


@pytest.mark.parametrize("name", ["Dzhanibekov, mc 2e-6", "|Δ2|/G² = 1e-10, case ii"])
def test_attitude_through_the_table_against_25_digit_integration(name):
    """Over 0.6 period, a flip included, the table path (an array of >= the threshold)
    against mpmath's Taylor integration: the bound of the formula's own test."""
    inertia, momentum = STATES[name]
    solver = EulerSolver(inertia, momentum, ATTITUDE0)
    span = 0.6 * solver.period
    t = np.linspace(0.0, span, max(_TABLE_MIN_SAMPLES, 20_000))
    q = solver.attitude_quaternion(t)
    assert solver._table is not None  # the table was used
    picks = np.linspace(0, t.size - 1, 7).astype(int)[1:]
    reference = integrate_mpmath(inertia, momentum, ATTITUDE0.as_quat(scalar_first=True), t[picks])
    for k, (_, q_ref) in zip(picks, reference, strict=True):
        error = (
            Rotation.from_quat(q[k], scalar_first=True).inv()
            * Rotation.from_quat(q_ref, scalar_first=True)
        ).magnitude()
        assert error <= 1e-13


# The SLOW states' regular-kernel edge is covered by the mpmath test above.
@pytest.mark.parametrize("name", [name for name in STATES if name not in SLOW])
def test_attitude_through_the_table_equals_the_formula_out_to_1e6_periods(name):
    """Table and formula at the same times, from t0 to 1e6 periods: they differ by the
    rounding of ψ's terms (the table's ω τ against the formula's sum of a secular term
    and j complete integrals, each rounded) and of the table, nothing more."""
    inertia, momentum = STATES[name]
    solver = EulerSolver(inertia, momentum, ATTITUDE0)
    f = solver._formula
    rng = np.random.default_rng(8)
    t = np.sort(
        np.concatenate(
            [
                rng.uniform(0.0, 3.0 * solver.period, 10_000),
                solver.period * 10.0 ** rng.uniform(0.0, 6.0, 10_000),
            ]
        )
    )
    with_table = solver.attitude_quaternion(t)
    assert solver._table is not None
    formula = np.concatenate(  # below the threshold: the formula
        [solver.attitude_quaternion(part) for part in np.array_split(t, 8)]
    )
    difference = np.linalg.norm(with_table - formula, axis=1)  # ≈ the angle, small
    _, Ω = f.angle_rates()
    τ = t - solver.t0
    _, largest = f.periodic_angle(np.linspace(-f.K, f.K, 101))
    # The terms each path rounds: Ω τ and ψ's secular and complete terms (~ψ_rate τ and
    # C (Π − K) j with j ~ λ τ / 2K), and the periodic part's largest term.
    scale = np.abs(Ω * τ) + np.abs(f.ψ_rate * τ) + abs(f.C * f.Π_minus_K * f.λ / f.K) * τ
    bound = 2.0**-52 * (8.0 * largest + 2.0 * scale)  # measured: up to 0.42 of it
    assert np.all(difference <= bound), float(np.max(difference / bound))
