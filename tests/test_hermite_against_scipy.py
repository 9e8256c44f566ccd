"""attitude.base.hermite against scipy's CubicHermiteSpline on the same nodes."""

import numpy as np
import pytest
from scipy.interpolate import CubicHermiteSpline

from attitude.base.hermite import UniformCubicHermite


def test_the_interpolant_is_scipys_on_equally_spaced_nodes():
    rng = np.random.default_rng(7)
    nodes = np.linspace(-130.0, 8000.0, 137)
    values, derivatives = rng.normal(size=(137, 3)) * 7e6, rng.normal(size=(137, 3)) * 7e3
    ours = UniformCubicHermite(nodes[0], nodes[1] - nodes[0], values, derivatives)
    theirs = CubicHermiteSpline(nodes, values, derivatives, axis=0)
    t = np.concatenate([rng.uniform(nodes[0], nodes[-1], 5000), nodes])
    scale = np.max(np.abs(values))
    assert np.max(np.abs(ours(t) - theirs(t))) < 1e-13 * scale
    assert ours(np.array(nodes[-1])).shape == (3,)  # a scalar time: one vector


def test_a_cubic_is_reproduced_exactly():
    nodes = np.linspace(0.0, 10.0, 6)
    ours = UniformCubicHermite(0.0, 2.0, nodes**3 - nodes, 3.0 * nodes**2 - 1.0)
    t = np.linspace(0.0, 10.0, 101)
    np.testing.assert_allclose(ours(t), t**3 - t, rtol=1e-13, atol=1e-12)


@pytest.mark.parametrize(
    ("values", "derivatives", "spacing"),
    [
        (np.zeros((1, 3)), np.zeros((1, 3)), 1.0),
        (np.zeros((4, 3)), np.zeros((4, 2)), 1.0),
        (np.zeros((4, 3)), np.zeros((4, 3)), 0.0),
    ],
)
def test_bad_nodes_are_refused(values, derivatives, spacing):
    with pytest.raises(ValueError):
        UniformCubicHermite(0.0, spacing, values, derivatives)
