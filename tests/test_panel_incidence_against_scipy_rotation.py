"""The envelope's panel incidence (``attitude.envelope.power.mean_incidence``: the
rotation matrix of each quaternion written row by row) against scipy's
``Rotation.apply`` of the same quaternions: (1/k) Σ max(cos θ_p, 0) to rounding, for
random attitudes, panels and Sun directions, both signs of the cosines."""

import numpy as np
from scipy.spatial.transform import Rotation

from attitude.envelope.power import mean_incidence


def test_mean_incidence_against_scipy_rotation_apply():
    rng = np.random.default_rng(21)
    rotations = Rotation.random(2000, random_state=rng)
    q = rotations.as_quat(scalar_first=True)
    panels = rng.normal(size=(3, 3))
    panels /= np.linalg.norm(panels, axis=1, keepdims=True)
    sun = rng.normal(size=(2000, 3))
    sun /= np.linalg.norm(sun, axis=1, keepdims=True)
    cosines = np.stack([np.einsum("ij,ij->i", rotations.apply(b), sun) for b in panels])
    expected = np.mean(np.maximum(cosines, 0.0), axis=0)
    assert (cosines < 0.0).any() and (cosines > 0.0).any()
    np.testing.assert_allclose(mean_incidence(q, panels, sun), expected, rtol=0, atol=2e-15)
    # Alone or among others: the same bits (element by element).
    alone = np.array([mean_incidence(q[i : i + 1], panels, sun[i : i + 1])[0] for i in range(50)])
    assert np.array_equal(alone, mean_incidence(q, panels, sun)[:50])
