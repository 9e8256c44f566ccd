"""``fit_spin_state`` on telemetry as it comes: against the fit of the same telemetry
clean (the same numbers), or against the truth, or refused with one line that names
what is wrong.  Gaps, outliers, unsorted and duplicated times, quaternion sign flips,
a frozen sensor, an arc shorter than one period, noise alone, a steady spin, partly
missing rows, bad norms, absurd magnitudes, units and epochs."""

import astropy.units as u
import numpy as np
import pytest
from astropy.time import Time, TimeDelta
from fit_cases import BODIES, Q0

from attitude import EulerSolver, FitRefused, InputError, fit_spin_state

BODY = BODIES["generic"]


def _telemetry(seed=31, every=5):
    rng = np.random.default_rng(seed)
    ω = BODY.gyro(rng)
    q = np.full((BODY.times.size, 4), np.nan)
    q[::every] = BODY.quaternions(rng, BODY.times[::every])
    return BODY.times.copy(), ω, q


def _fit(t, ω=None, q=None, **options):
    options.setdefault("gyro_sigma", BODY.gyro_sigma if ω is not None else None)
    options.setdefault("attitude_sigma", BODY.attitude_sigma if q is not None else None)
    return fit_spin_state(t, angular_velocity=ω, quaternions=q, **options)


def test_outliers_are_flagged_and_do_not_move_the_fit():
    t, ω, q = _telemetry()
    clean = _fit(t, ω, q)
    rng = np.random.default_rng(32)
    bad = rng.choice(t.size, size=7, replace=False)
    ω_bad = ω.copy()
    ω_bad[bad] += 50.0 * BODY.gyro_sigma * rng.choice([-1.0, 1.0], size=(7, 3))
    q_bad = q.copy()
    fixes = np.flatnonzero(np.isfinite(q[:, 0]))[[3, 20]]
    q_bad[fixes] = [0.0, 1.0, 0.0, 0.0]  # attitude fixes that are plainly wrong
    fit = _fit(t, ω_bad, q_bad)
    assert sorted(np.flatnonzero(~fit.residuals["gyro"]["inlier"])) == sorted(bad)
    assert np.count_nonzero(~fit.residuals["attitude"]["inlier"]) == 2
    Δ = np.abs(fit.parameter_values - clean.parameter_values) / clean.parameter_sigma
    assert np.all(Δ < 0.5)  # the outliers barely move it
    assert 0.8 < fit.reduced_chi2 < 1.2


def test_unsorted_and_exactly_repeated_rows_give_the_same_fit():
    t, ω, q = _telemetry()
    clean = _fit(t, ω, q)
    rng = np.random.default_rng(33)
    order = rng.permutation(t.size)
    repeat = rng.choice(t.size, size=20, replace=False)
    t2 = np.concatenate([t[order], t[repeat]])
    ω2 = np.vstack([ω[order], ω[repeat]])
    q2 = np.vstack([q[order], q[repeat]])
    fit = _fit(t2, ω2, q2)
    np.testing.assert_allclose(fit.parameter_values, clean.parameter_values, rtol=1e-9, atol=1e-12)
    assert any("sorted" in note for note in fit.notes)
    assert any("repeated rows kept once" in note for note in fit.notes)


def test_two_readings_at_one_time_are_refused_naming_both_rows():
    t, ω, q = _telemetry()
    t[11] = t[10]
    with pytest.raises(InputError, match=r"rows 10 and 11 .* same time"):
        _fit(t, ω, q)


def test_quaternion_sign_flips_change_nothing():
    t, ω, q = _telemetry()
    clean = _fit(t, ω, q)
    flipped = q.copy()
    flipped[1::2] *= -1.0
    fit = _fit(t, ω, flipped)
    np.testing.assert_allclose(fit.parameter_values, clean.parameter_values, rtol=1e-9, atol=1e-12)


def test_a_frozen_gyro_is_left_out():
    t, ω, _ = _telemetry()
    ω[100:140] = ω[100]  # the gyro repeats its reading for 80 s
    fit = _fit(t, ω)
    assert any("frozen sensor" in note for note in fit.notes)
    assert fit.residuals["gyro"]["t"].size == t.size - 39
    np.testing.assert_array_less(
        np.abs(fit.inertia_ratios[1:] - BODY.ratios[1:]), 5 * fit.inertia_ratios_sigma[1:]
    )


def test_gaps_are_allowed_and_noted():
    t, ω, _ = _telemetry()
    keep = (t < 200.0) | (t > 450.0)
    fit = _fit(t[keep], ω[keep])
    assert any("largest gap" in note for note in fit.notes)
    np.testing.assert_array_less(
        np.abs(fit.inertia_ratios[1:] - BODY.ratios[1:]), 5 * fit.inertia_ratios_sigma[1:]
    )


def test_an_arc_shorter_than_one_period_is_refused():
    t, ω, _ = _telemetry()
    short = t < 0.6 * BODY.solver.period
    with pytest.raises(FitRefused, match="less than one period"):
        _fit(t[short], ω[short])


def test_noise_alone_is_refused():
    rng = np.random.default_rng(34)
    ω = BODY.gyro_sigma * rng.standard_normal((BODY.times.size, 3))
    with pytest.raises(FitRefused, match="noise only"):
        _fit(BODY.times, ω)


def test_a_steady_spin_is_refused():
    rng = np.random.default_rng(35)
    solver = EulerSolver(BODY.moments, BODY.moments * np.array([0.0, 0.0, 0.05]))
    ω = solver.angular_velocity(BODY.times) + BODY.gyro_sigma * rng.standard_normal(
        (BODY.times.size, 3)
    )
    with pytest.raises(FitRefused, match="steady spin"):
        _fit(BODY.times, ω)


def test_bad_rows_are_refused_with_the_row_and_the_value():
    t, ω, q = _telemetry()
    bad = ω.copy()
    bad[7, 1] = np.nan
    with pytest.raises(InputError, match=r"row 7: angular_velocity .* partly missing"):
        _fit(t, bad)
    bad = ω.copy()
    bad[9, 2] = np.inf
    with pytest.raises(InputError, match=r"row 9: angular_velocity .* not finite"):
        _fit(t, bad)
    bad_q = q.copy()
    bad_q[5] = [1.0, 0.1, 0.0, 0.0]
    with pytest.raises(InputError, match=r"row 5: quaternion .* norm 1.00498"):
        _fit(t, ω, bad_q)
    bad_t = t.copy()
    bad_t[3] = np.nan
    with pytest.raises(InputError, match="must be finite"):
        _fit(bad_t, ω)
    with pytest.raises(InputError, match=r"shape \(350, 3\)"):
        _fit(t, ω[:-1])
    with pytest.raises(InputError, match="give angular_velocity, quaternions or both"):
        fit_spin_state(t)
    with pytest.raises(InputError, match="no samples"):
        fit_spin_state([], angular_velocity=np.empty((0, 3)))
    with pytest.raises(InputError, match="numeric"):
        fit_spin_state(t, angular_velocity=[["a", "b", "c"]] * t.size)
    with pytest.raises(InputError, match="gyro_sigma: must be positive"):
        _fit(t, ω, gyro_sigma=-1.0)
    with pytest.raises(InputError, match="every reading is missing"):
        fit_spin_state(t, angular_velocity=np.full_like(ω, np.nan))


def test_absurd_magnitudes_are_refused_not_returned_as_nan():
    t, ω, _ = _telemetry()
    with pytest.raises(InputError, match=r"reaches 5\.\d+e\+298 rad/s"):
        _fit(t, ω * 1e300, gyro_sigma=1e296)
    # A slow, weak body: the rates scaled by 1e-200 and time by 1e200 is the same motion.
    fit = _fit(t * 1e200, ω * 1e-200, gyro_sigma=BODY.gyro_sigma * 1e-200)
    np.testing.assert_array_less(
        np.abs(fit.inertia_ratios[1:] - BODY.ratios[1:]), 5 * fit.inertia_ratios_sigma[1:]
    )


def test_units_and_epochs_give_the_same_fit():
    t, ω, q = _telemetry()
    clean = _fit(t, ω, q)
    epoch = Time("2026-01-01T00:00:00", scale="utc")
    times = epoch + TimeDelta(t, format="sec")
    fit = fit_spin_state(
        times,
        angular_velocity=(ω * u.rad / u.s).to(u.deg / u.s),
        quaternions=q,
        gyro_sigma=(BODY.gyro_sigma * u.rad / u.s).to(u.deg / u.s),
        attitude_sigma=(BODY.attitude_sigma * u.rad).to(u.arcsec),
    )
    np.testing.assert_allclose(fit.parameter_values, clean.parameter_values, rtol=1e-8, atol=1e-12)
    assert abs((fit.epoch - epoch).sec) < 1e-9
    with pytest.raises(InputError, match="Hz"):
        fit_spin_state(t, angular_velocity=ω * u.Hz, gyro_sigma=1e-4)


def test_symmetric_axes_are_refused_about_their_symmetry_axis():
    rng = np.random.default_rng(36)
    J = np.array([100.0, 100.0, 180.0])
    solver = EulerSolver(J, J * np.array([0.03, 0.01, 0.04]), Q0)
    ω = solver.angular_velocity(BODY.times) + 1e-4 * rng.standard_normal((BODY.times.size, 3))
    with pytest.raises(FitRefused, match="principal axes are not determined"):
        _fit(BODY.times, ω, principal_axes=True)
