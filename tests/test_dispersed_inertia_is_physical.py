"""Dispersed inertia is always physical: positive definite, symmetric, and within the
triangle inequality, over thousands of draws around bodies near its edge.

The tensors are the ones written into the samples' documents, checked here with
numpy's eigvalsh (not the draw's own moments), and each is read back by the scenario
reader without a warning.  The nominal bodies are chosen so that many draws break the
inequality or a moment goes negative and must be drawn again (counted in
``spacecraft.inertia_draws``); a nominal body that breaks it is refused.
"""

import warnings

import numpy as np
import pytest

from attitude.files.scenario_reader import ScenarioFileError, load_scenario, scenario_from_document
from attitude.montecarlo.dispersions import draw_sample, read_dispersions

BODY = """
[scenario]
name = "flat"
epoch = "2027-06-21T00:00:00"
[spacecraft]
name = "plate"
{inertia}
[initial_state]
quaternion = [1.0, 0.0, 0.0, 0.0]
angular_velocity = [0.01, 0.02, 0.3]
[output]
duration = 10.0
[dispersions]
seed = 5
samples = 4000
[dispersions.spacecraft]
principal_moments = {{ distribution = "{law}", {scale} }}
principal_axes = {{ distribution = "normal", sigma = {{ value = 10.0, unit = "deg" }} }}
"""

CASES = {
    # a near-flat plate: about half of the draws break the triangle inequality
    "plate_normal": ("principal_moments = [1.0, 1.0, 1.98]", "normal", "relative_sigma = 0.1"),
    # a wide uniform law: moments below zero and broken inequalities
    "uniform_90_percent": (
        "principal_moments = [2.0, 3.0, 4.0]",
        "uniform",
        "relative_half_width = 0.9",
    ),
    # a full tensor near the edge
    "tensor": (
        "inertia_tensor = [[1.5, 0.2, 0.0], [0.2, 1.5, 0.1], [0.0, 0.1, 2.9]]",
        "truncated_normal",
        "relative_sigma = 0.2, truncation = 3.0",
    ),
}


@pytest.mark.parametrize("case", CASES)
def test_dispersed_inertia_is_always_physical(case, tmp_path):
    inertia, law, scale = CASES[case]
    path = tmp_path / "plate.toml"
    path.write_text(BODY.format(inertia=inertia, law=law, scale=scale))
    loaded = load_scenario(path)
    dispersions = read_dispersions(loaded)
    redrawn = 0
    for k in range(dispersions.samples):
        sample = draw_sample(dispersions, loaded.document, k)
        assert sample.error is None
        tensor = np.array(sample.document["spacecraft"]["inertia_tensor"])
        assert np.array_equal(tensor, tensor.T)
        low, mid, high = np.linalg.eigvalsh(tensor)
        assert low > 0.0
        assert low + mid >= high * (1.0 - 1e-12), (k, low, mid, high)
        redrawn += sample.parameters["spacecraft.inertia_draws"] > 1
        if k % 200 == 0:  # read back by the scenario reader: no error, no warning
            with warnings.catch_warnings():
                warnings.simplefilter("error")
                scenario_from_document(path, sample.document)
    assert redrawn > 100  # the draws near the edge were exercised


def test_a_nominal_body_beyond_the_triangle_inequality_is_refused(tmp_path):
    path = tmp_path / "plate.toml"
    path.write_text(
        BODY.format(
            inertia="principal_moments = [1.0, 1.0, 2.5]",
            law="normal",
            scale="relative_sigma = 0.1",
        )
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the reader's own warning about the nominal body
        loaded = load_scenario(path)
    with pytest.raises(ScenarioFileError) as refused:
        read_dispersions(loaded)
    assert str(refused.value).startswith(
        "plate.toml: dispersions.spacecraft.principal_moments: the nominal moments"
    )
