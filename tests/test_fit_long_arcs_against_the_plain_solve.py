"""A long arc is fitted with bounded work and memory, to the answer of the plain solve.

A million gyro samples took 87.6 s of CPU and 2.46 GB at their peak (each stage of the
growing arc a least squares on every sample so far; the last one's Jacobian and the
flow's sensitivities, (N, 6, 9), all in memory at once).  Now a stage is fitted on every
k-th sample (at most ``STAGE_SAMPLES``), and beyond ``CHUNKED_ABOVE`` samples the last
solve is Gauss–Newton on the Jacobian's R factor accumulated stretch by stretch.  Both
against the plain paths, with the thresholds lowered so that a short arc takes them:
the same solution and covariance."""

import numpy as np
from scipy.spatial.transform import Rotation

import attitude.estimation.model as model_module
import attitude.estimation.solve as solve
from attitude import EulerSolver, fit_spin_state

MOMENTS = np.array([100.0, 200.0, 260.0])
ω0 = np.array([0.05, 0.02, 0.03])
Q0 = Rotation.from_rotvec([0.3, -0.2, 0.5])


def _telemetry():
    solver = EulerSolver(MOMENTS, MOMENTS * ω0, Q0)
    t = np.arange(0.0, 3000.0, 1.0)
    rng = np.random.default_rng(3)
    ω = solver.angular_velocity(t) + 1e-4 * rng.standard_normal((t.size, 3))
    q = np.full((t.size, 4), np.nan)
    fixes = slice(None, None, 10)
    noise = Rotation.from_rotvec(1e-4 * rng.standard_normal((t[fixes].size, 3)))
    q[fixes] = (solver.attitude(t[fixes]) * noise).as_quat(scalar_first=True)
    return t, ω, q


def _fit(t, ω, q):
    return fit_spin_state(
        t, angular_velocity=ω, quaternions=q, gyro_sigma=1e-4, attitude_sigma=1e-4
    )


def test_the_chunked_last_solve_against_the_plain_one(monkeypatch):
    t, ω, q = _telemetry()
    plain = _fit(t, ω, q)
    monkeypatch.setattr(solve, "CHUNKED_ABOVE", 1_000)
    monkeypatch.setattr(solve, "CHUNK_SAMPLES", 800)
    monkeypatch.setattr(model_module, "_CHUNK", 700)  # the sensitivities in chunks too
    chunked = _fit(t, ω, q)
    # Both at their minimum to far below σ (the plain one stops at scipy's tolerances).
    difference = (chunked.parameter_values - plain.parameter_values) / plain.parameter_sigma
    assert np.max(np.abs(difference)) < 1e-4
    scale = np.max(np.abs(plain.covariance))
    np.testing.assert_allclose(chunked.covariance, plain.covariance, rtol=0, atol=1e-5 * scale)
    assert abs(chunked.reduced_chi2 - plain.reduced_chi2) < 1e-8


def test_thinned_stages_reach_the_same_fit(monkeypatch):
    """Stages on every k-th sample: the last solve on all of them ends where stages on
    every sample do."""
    t, ω, q = _telemetry()
    plain = _fit(t, ω, q)
    monkeypatch.setattr(solve, "STAGE_SAMPLES", 400)
    thinned = _fit(t, ω, q)
    difference = (thinned.parameter_values - plain.parameter_values) / plain.parameter_sigma
    assert np.max(np.abs(difference)) < 1e-3
