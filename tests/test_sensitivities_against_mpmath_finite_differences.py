"""The sensitivities of the exact flow (attitude.solver.sensitivities) against finite
differences of the flow in extended precision: Jadczyk's closed form in mpmath at 50
digits (tests/mpmath_flow.py, a derivation independent of the package's), central
differences of 1e-20 of each input.  Where that reference does not reach (symmetric
bodies, the separatrix, spins exactly about an axis), against the variational
equations integrated with the motion itself by DOP853 at rtol 1e-13, which uses
Euler's equations and nothing of the closed form; and the covariance against the
exact flow of sampled states."""

import mpmath_flow
import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from attitude import EulerSolver, FlowSensitivities, InputError, flow_sensitivities

Q0 = Rotation.from_rotvec([0.3, -0.2, 0.5])


def _relative_error(ours, reference):
    """Per time, the largest difference over the largest reference element."""
    scale = np.abs(reference).max(axis=(1, 2))
    return np.abs(ours - reference).max(axis=(1, 2)) / scale


@pytest.mark.parametrize(
    "moments, ω0",
    [
        ([100.0, 200.0, 300.0], [0.05, 0.02, 0.03]),  # case ii
        ([300.0, 100.0, 200.0], [-0.05, 0.02, -0.03]),  # axes in another order, ii
        ([100.0, 200.0, 300.0], [0.0005, 0.02, 0.0]),  # case i
        ([200.0, 300.0, 100.0], [0.02, -0.01, 0.04]),
        ([100.0, 200.0, 300.0], [1e-3, 1.0, 1e-3]),  # Dzhanibekov, mc = 2e-6
    ],
)
def test_closed_form_sensitivities_against_mpmath(moments, ω0):
    J = np.array(moments)
    m0 = J * np.array(ω0)
    solver = EulerSolver(J, m0, Q0)
    t = np.array([0.0, 7.3, 0.4 * solver.period, 2.7 * solver.period])
    sens = flow_sensitivities(solver, t)
    assert sens.method == "closed form"
    reference = mpmath_flow.jacobian(J, m0, Q0.as_quat(scalar_first=True), t)
    assert np.all(_relative_error(sens.jacobian, reference) < 1e-12)


@pytest.mark.parametrize("offset", [1e-8, 1e-12])
def test_next_to_the_separatrix_against_mpmath(offset):
    """Δ2/G² of 1e-8 and 1e-12 (mc 4e-9 and 4e-13): the derivatives grow as 1/mc over a
    period, and keep their digits."""
    J = np.array([100.0, 200.0, 300.0])
    w1 = 0.01
    w3 = w1 * np.sqrt(100.0 * 100.0 / (300.0 * 100.0)) * (1.0 + offset)
    m0 = J * np.array([w1, 0.02, w3])
    solver = EulerSolver(J, m0, Q0)
    assert solver.mc < 1e-8
    t = np.array([0.0, 7.3, 0.4 * solver.period, 2.7 * solver.period])
    sens = flow_sensitivities(solver, t)
    reference = mpmath_flow.jacobian(J, m0, Q0.as_quat(scalar_first=True), t, dps=60)
    assert np.all(_relative_error(sens.jacobian, reference) < 1e-10)


def test_long_times_against_mpmath():
    """1e5 and 1e6 s (hundreds to thousands of periods): the secular growth is exact."""
    J = np.array([100.0, 200.0, 300.0])
    m0 = J * np.array([0.05, 0.02, 0.03])
    solver = EulerSolver(J, m0)
    t = np.array([1e5, 1e6])
    sens = flow_sensitivities(solver, t)
    reference = mpmath_flow.jacobian(J, m0, [1.0, 0.0, 0.0, 0.0], t, dps=60)
    assert np.all(_relative_error(sens.jacobian, reference) < 1e-10)


def _variational_reference(J, m0, q0, times):
    """Euler's equations, the kinematics and the variational equations of both,
    integrated together by DOP853 at rtol 1e-13: (N, 6, 9) in the convention of
    flow_sensitivities (rows δθ body, m; columns δθ0 body, m0, J)."""

    def skew(v):
        return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])

    def rhs(t, y):
        m, Z = y[:3], y[3:].reshape(9, 9)
        ω = m / J
        M = np.zeros((9, 9))
        M[0:3, 0:3] = -skew(ω)
        M[0:3, 3:6] = np.diag(1.0 / J)
        M[0:3, 6:9] = -np.diag(m / J**2)
        M[3:6, 3:6] = -skew(ω) + skew(m) @ np.diag(1.0 / J)
        M[3:6, 6:9] = -skew(m) @ np.diag(m / J**2)
        return np.concatenate([np.cross(m, ω), (M @ Z).ravel()])

    y0 = np.concatenate([m0, np.eye(9).ravel()])
    solution = solve_ivp(rhs, (0.0, times[-1]), y0, "DOP853", times, rtol=1e-13, atol=1e-16)
    return solution.y[3:].T.reshape(-1, 9, 9)[:, :6, :]


@pytest.mark.parametrize(
    "moments, m0, method",
    [
        ([100.0, 100.0, 300.0], [5.0, 2.0, 9.0], "closed form"),  # I1 = I2
        ([100.0, 300.0, 300.0], [5.0, 6.0, 9.0], "closed form"),  # I2 = I3
        ([2.0, 3.0, 6.0], [0.1, 0.05, 0.1], "variational equations"),  # exactly the separatrix
        ([100.0, 200.0, 300.0], [5.0, 0.0, 0.0], "equilibrium"),  # spin about axis 1
        ([100.0, 200.0, 300.0], [0.0, 0.0, 9.0], "equilibrium"),  # spin about axis 3
        ([100.0, 100.0, 100.0], [5.0, 2.0, 9.0], "equilibrium"),  # the sphere
        ([100.0, 200.0, 300.0], [0.0, 0.0, 0.0], "equilibrium"),  # rest
    ],
)
def test_every_case_against_the_variational_equations(moments, m0, method):
    J, m0 = np.array(moments), np.array(m0)
    solver = EulerSolver(J, m0, Q0)
    t = np.array([0.0, 3.0, 40.0, 150.0])
    sens = flow_sensitivities(solver, t)
    assert sens.method == method
    reference = _variational_reference(J, m0, Q0, t)
    scale = max(np.abs(reference).max(), 1.0)
    assert np.abs(sens.jacobian - reference).max() < 1e-9 * scale


def test_times_before_t0_and_momentum_only():
    J = np.array([100.0, 200.0, 300.0])
    m0 = J * np.array([0.05, 0.02, 0.03])
    solver = EulerSolver(J, m0, Q0, t0=50.0)
    t = np.array([-100.0, 50.0, 400.0])
    full = flow_sensitivities(solver, t)
    reference = mpmath_flow.jacobian(J, m0, Q0.as_quat(scalar_first=True), t - 50.0)
    assert np.all(_relative_error(full.jacobian, reference) < 1e-12)
    rates_only = flow_sensitivities(solver, t, attitude=False)
    np.testing.assert_array_equal(rates_only.jacobian[:, 3:], full.jacobian[:, 3:])
    assert np.all(np.isnan(rates_only.jacobian[:, :3])) and rates_only.attitude is None


def test_covariance_against_the_exact_flow_of_sampled_states():
    """Σ(t) = Φ Σ0 Φᵀ against the sample covariance of 4000 states drawn from Σ0 and
    flowed exactly: within the sampling error (a few per cent) while Σ0 is small."""
    rng = np.random.default_rng(7)
    J = np.array([100.0, 200.0, 300.0])
    m0 = J * np.array([0.05, 0.02, 0.03])
    solver = EulerSolver(J, m0, Q0)
    t = np.array([300.0])
    Σ0 = np.diag([1e-6] * 3 + [1e-4] * 3 + [1e-3] * 3) ** 2 * 1e4
    predicted = flow_sensitivities(solver, t).covariance(Σ0)[0]
    draws = rng.multivariate_normal(np.zeros(9), Σ0, size=4000)
    nominal_q = solver.attitude(t)[0]
    samples = []
    for d in draws:
        s = EulerSolver(J + d[6:], m0 + d[3:6], Q0 * Rotation.from_rotvec(d[:3]))
        q = s.attitude(t)[0]
        samples.append(
            np.concatenate([(nominal_q.inv() * q).as_rotvec(), s.angular_momentum(t)[0]])
        )
    sample = np.cov(np.array(samples).T)
    σ = np.sqrt(np.diag(predicted))
    assert np.all(np.abs(np.sqrt(np.diag(sample)) / σ - 1.0) < 0.06)
    correlation = sample / np.outer(np.sqrt(np.diag(sample)), np.sqrt(np.diag(sample)))
    assert np.all(np.abs(correlation - predicted / np.outer(σ, σ)) < 0.06)


def test_bad_input_is_refused():
    tensor = np.array([[100.0, 10.0, 0.0], [10.0, 200.0, 0.0], [0.0, 0.0, 300.0]])
    with pytest.raises(InputError, match="principal axes along the body axes"):
        flow_sensitivities(EulerSolver(tensor, [1.0, 2.0, 3.0]), [1.0])
    with pytest.raises(InputError, match="EulerSolver"):
        flow_sensitivities("solver", [1.0])
    solver = EulerSolver([1.0, 2.0, 3.0], [1.0, 2.0, 3.0])
    with pytest.raises(InputError, match="1-D"):
        flow_sensitivities(solver, np.zeros((2, 2)))
    with pytest.raises(InputError):
        flow_sensitivities(solver, [np.nan])
    with pytest.raises(InputError, match="6 x 6"):
        flow_sensitivities(solver, [1.0]).covariance(np.eye(4))
    assert isinstance(flow_sensitivities(solver, 1.0), FlowSensitivities)
