"""attitude.solver.free_flow.advance against scipy's DOP853 at rtol 1e-13, state by state.

One batch of 60 random bodies and states (moments in any order, both sides of the
separatrix with |Δ2|/G² ≥ 1e-3, where DOP853 is itself within 1e-10: see
test_against_numerical_integration.py; symmetric bodies and the sphere among them),
each with its own attitude and its own step of up to 3 periods, forward or backward;
DOP853 integrates Euler's equations and the kinematics of each state over its step.
"""

import numpy as np
from reference_models import integrate_dop853, mp_invariants
from scipy.spatial.transform import Rotation

from attitude.solver.free_flow import advance


def _states(count=60, seed=31):
    rng = np.random.default_rng(seed)
    moments, momentum = [], []
    while len(moments) < count:
        inertia = rng.uniform(0.5, 20.0, 3)
        k = len(moments)
        if k % 10 == 3:
            inertia[1] = inertia[0]
        elif k % 10 == 7:
            inertia[:] = inertia[0]
        m = rng.normal(size=3) * 10 ** rng.uniform(-1, 2)
        if np.ptp(inertia) > 0 and abs(float(mp_invariants(inertia, m, 30)[1][1])) < 1e-3:
            continue  # too close to the separatrix for DOP853 to be the authority
        moments.append(inertia)
        momentum.append(m)
    return np.array(moments), np.array(momentum)


def test_a_batch_of_steps_against_dop853():
    moments, momentum = _states()
    count = len(moments)
    rng = np.random.default_rng(32)
    q = Rotation.random(count, random_state=33).as_quat(scalar_first=True)
    G = np.linalg.norm(momentum, axis=1)
    # Up to 3 periods of m(t) (~ 2π I/G each, within a factor of a few), either way.
    dt = rng.uniform(0.2, 3.0, count) * 2 * np.pi * np.min(moments, axis=1) / G
    dt *= rng.choice([-1.0, 1.0], count)
    m_new, q_new = advance(moments, momentum, q, dt)
    for k in range(count):
        attitude0 = Rotation.from_quat(q[k], scalar_first=True)
        # integrate_dop853 goes from t = 0; a backward step is a forward one in −t.
        m_ref, attitude_ref = integrate_dop853(
            moments[k], momentum[k], attitude0, np.array([0.0, dt[k]])
        )
        assert np.linalg.norm(m_new[k] - m_ref[-1]) <= 1e-11 * G[k], k
        ours = Rotation.from_quat(q_new[k], scalar_first=True)
        assert (ours.inv() * attitude_ref[-1]).magnitude() <= 1e-11, k
