"""Conservation laws at any time, out to a million periods.

Torque-free motion conserves the inertial angular momentum R(t) m(t), the kinetic
energy ½ Σ mj²/Ij and |m|.  A closed form has no drift: these hold to rounding at
t = 1e6 periods as at t = 0 (an integrator's errors grow with t).
"""

import numpy as np
import pytest
from reference_models import state_with_delta2
from scipy.spatial.transform import Rotation

from attitude import EulerSolver


def _states():
    rng = np.random.default_rng(99)
    states = []
    for k in range(60):
        inertia = rng.uniform(0.5, 50.0, 3)
        if k % 3 == 0:
            ratio = rng.choice([-1.0, 1.0]) * 10 ** rng.uniform(-14, -3)
            x = state_with_delta2(np.sort(inertia), ratio, weight=0.3, rng=rng)
            m0 = np.empty(3)
            m0[np.argsort(inertia)] = x
        else:
            m0 = rng.normal(size=3)
        states.append((inertia, m0 * 10 ** rng.uniform(-3, 4), Rotation.random(random_state=k)))
    return states


@pytest.mark.parametrize("inertia, m0, attitude0", _states())
def test_invariants_hold_to_a_million_periods(inertia, m0, attitude0):
    solver = EulerSolver(inertia, m0, attitude0, t0=12.5)
    rng = np.random.default_rng(1)
    t = 12.5 + solver.period * np.concatenate(
        [rng.uniform(-10, 10, 100), rng.uniform(-1e6, 1e6, 100), [1e6, -1e6]]
    )
    m = solver.angular_momentum(t)
    H = solver.attitude(t).apply(m)
    H0 = attitude0.apply(m0)
    G = np.linalg.norm(m0)
    T = 0.5 * np.sum(m0**2 / inertia)
    assert np.max(np.linalg.norm(H - H0, axis=1)) <= 1e-13 * G
    assert np.max(np.abs(np.linalg.norm(m, axis=1) - G)) <= 1e-14 * G
    assert np.max(np.abs(0.5 * np.sum(m**2 / inertia, axis=1) - T)) <= 1e-14 * T
    assert solver.angular_momentum_norm == pytest.approx(G, rel=1e-15)
    assert solver.kinetic_energy == pytest.approx(T, rel=1e-15)
    np.testing.assert_allclose(solver.inertial_angular_momentum, H0, rtol=0, atol=1e-15 * G)
