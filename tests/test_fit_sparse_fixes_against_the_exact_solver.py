"""Sparse fixes days apart, no guess: the global start (attitude.estimation.global_start)
against the exact solver's motion sampled at the fixes, with noise.

Radar or ground-based fixes a day apart, each with the rates and the attitude at its
time, were refused as "too sparse for the linear first guess".  Now:

- fixes at irregular intervals decide the number of turns between them: one family,
  the truth within its stated σ;
- fixes at the same time each day do not (every family that turns a whole number of
  times more per day fits them as well): every family within the noise is reported,
  each with its covariance, the truth among them, and the fit says it cannot decide;
- what the fixes cannot show is refused: one fix, a torque between them.
"""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from attitude import AngularImpulse, EulerSolver, FitRefused, fit_spin_state

DAY = 86400.0
J = np.array([100.0, 200.0, 260.0])
ω0 = np.array([0.05, 0.02, 0.03])  # a 267 s body period: ~320 turns a day
Q0 = Rotation.from_rotvec([0.3, -0.2, 0.5])
σ_ω, σ_θ = 1e-5, 1e-3  # rad/s, rad: a radar's rates and a ground station's attitude


def _fixes(days, seed, solver=None):
    solver = solver or EulerSolver(J, J * ω0, Q0)
    t = np.asarray(days, dtype=float) * DAY
    rng = np.random.default_rng(seed)
    ω = solver.angular_velocity(t) + σ_ω * rng.standard_normal((t.size, 3))
    noise = Rotation.from_rotvec(σ_θ * rng.standard_normal((t.size, 3)))
    return t, ω, (solver.attitude(t) * noise).as_quat(scalar_first=True)


def _fit(t, ω, q):
    return fit_spin_state(t, angular_velocity=ω, quaternions=q, gyro_sigma=σ_ω, attitude_sigma=σ_θ)


def _holds_the_truth(family, k=3.0) -> bool:
    return bool(
        np.all(np.abs(family.inertia_ratios - J / J[0]) <= k * family.inertia_ratios_sigma + 1e-15)
        and np.all(np.abs(family.angular_velocity - ω0) <= k * family.angular_velocity_sigma)
        and np.all(np.abs((family.attitude.inv() * Q0).as_rotvec()) <= k * family.attitude_sigma)
    )


def test_fixes_at_irregular_intervals_decide_one_family():
    fit = _fit(*_fixes([0.0, 1.0, 2.1, 2.9], seed=1))
    assert not fit.ambiguous and fit.families == [fit]
    assert _holds_the_truth(fit)
    assert any("global start from 4 fixes" in note for note in fit.notes)
    # The ratios to a part in a thousand from four fixes three days apart.
    assert np.all(fit.inertia_ratios_sigma[1:] < 2e-3 * fit.inertia_ratios[1:])


def test_fixes_at_the_same_time_each_day_report_every_family():
    """Three fixes exactly a day apart: a family turning a whole number of times more a
    day fits them too.  All are reported, within the noise, each with its own
    covariance, and the truth is one of them."""
    fit = _fit(*_fixes([0.0, 1.0, 2.0], seed=1))
    assert fit.ambiguous
    assert fit.families[0] is fit
    assert sum(_holds_the_truth(f) for f in fit.families) == 1
    for family in fit.families:
        assert family.families is fit.families
        assert family.covariance.shape == (8, 8)
        assert np.all(np.linalg.eigvalsh(family.covariance) > 0.0)
        assert family.goodness.p_value > 1e-3  # each fits within the noise
        assert "do not decide between" in family.observability[0]
    # Distinct families: their ratios further apart than their σ.
    ratios = sorted(f.inertia_ratios[1] for f in fit.families)
    σ = max(f.inertia_ratios_sigma[1] for f in fit.families)
    assert np.all(np.diff(ratios) > σ)
    assert "families of solutions fit within the noise" in fit.summary()


def test_what_the_fixes_cannot_show_is_refused():
    t, ω, q = _fixes([0.0], seed=2)
    with pytest.raises(FitRefused, match="too few"):
        _fit(t, ω, q)
    # An impulse between the fixes that the fit is not told of: the fixes' momentum and
    # energy are not conserved.
    before = EulerSolver(J, J * ω0, Q0)
    t1 = 1.5 * DAY
    after = EulerSolver(
        J, before.angular_momentum(t1) + np.array([3.0, -2.0, 1.0]), before.attitude(t1), t1
    )
    first, second = _fixes([0.0, 1.0], 3, before), _fixes([2.1, 2.9], 4, after)
    t, ω, q = (np.concatenate([a, b]) for a, b in zip(first, second, strict=True))
    with pytest.raises(FitRefused, match="not conserved"):
        _fit(t, ω, q)
    # Across a known impulse the global start does not search: a guess is needed.
    impulse = AngularImpulse(t1, [3.0, -2.0, 1.0])
    with pytest.raises(FitRefused, match="give a guess"):
        fit_spin_state(
            t,
            angular_velocity=ω,
            quaternions=q,
            gyro_sigma=σ_ω,
            attitude_sigma=σ_θ,
            impulses=[impulse],
        )


@pytest.mark.slow  # 20 s of CPU: the same families on a grid twice as fine
@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_the_families_against_a_search_twice_as_fine(seed, monkeypatch):
    """The grid's spacing finds every family: on a grid of 0.15 rad (against 0.3), the
    same families of three daily fixes."""
    import attitude.estimation.global_start as global_start

    data = _fixes([0.0, 1.0, 2.0], seed=seed)
    found = sorted(round(float(f.inertia_ratios[1]), 7) for f in _fit(*data).families)
    monkeypatch.setattr(global_start, "GRID_PHASE_RAD", 0.5 * global_start.GRID_PHASE_RAD)
    monkeypatch.setattr(global_start, "MAX_GRID", 10 * global_start.MAX_GRID)
    finer = sorted(round(float(f.inertia_ratios[1]), 7) for f in _fit(*data).families)
    assert found == finer
