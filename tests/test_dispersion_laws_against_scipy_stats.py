"""The drawn deviations follow the laws docs/scenarios.md states, tested with
Kolmogorov-Smirnov against scipy.stats over 2000 samples.

- a rotation (the initial attitude) with normal σ: each component N(0, σ²), and the
  angle |δ|/σ follows χ with 3 degrees of freedom; truncated at c σ: that law cut at c;
  uniform with half width h: (|δ|/h)³ uniform on [0, 1] (uniform in the ball);
- a direction (the impulse) with normal σ: the tilt angle |θ|/σ is Rayleigh, and the
  angle between the nominal and the drawn impulse, computed here, is the tilt recorded;
- relative deviations (moments, impulse magnitude) normal, truncated normal, uniform;
- per-component rates, each with its own half width; event times;
- samples are independent of each other (no correlation between sample k and k + 1).
The seeds are fixed, so the test is deterministic; its thresholds (p > 1e-3) would
catch a σ off by a few percent.
"""

import numpy as np
import pytest
from scipy import stats

from attitude.base.vectors import angle_between
from attitude.files.scenario_reader import load_scenario
from attitude.montecarlo.dispersions import draw_sample, read_dispersions

SCENARIO = """
[scenario]
name = "laws"
epoch = "2027-06-21T00:00:00"
[spacecraft]
name = "body"
principal_moments = [100.0, 200.0, 250.0]
[initial_state]
quaternion = [0.5, 0.5, 0.5, 0.5]
angular_velocity = [0.01, 0.02, 0.3]
[[events]]
type = "angular_impulse"
offset = 5.0
impulse = [3.0, -4.0, 12.0]
[output]
duration = 10.0
[dispersions]
seed = 2027
samples = 2000
[dispersions.spacecraft]
principal_moments = {{ distribution = "{moments}", {moments_scale} }}
[dispersions.initial_state]
attitude = {{ distribution = "{attitude}", {attitude_scale} }}
angular_velocity = {{ distribution = "uniform", half_width = [0.001, 0.002, 0.004] }}
[[dispersions.events]]
event = 0
time = {{ distribution = "normal", sigma = 0.25 }}
impulse_magnitude = {{ distribution = "normal", relative_sigma = 0.05 }}
impulse_direction = {{ distribution = "normal", sigma = {{ value = 1.5, unit = "deg" }} }}
"""

LAWS = {  # the moments' scale, the attitude's
    "normal": ("relative_sigma = 0.04", "sigma = { value = 2.0, unit = 'deg' }"),
    "truncated_normal": (
        "relative_sigma = 0.04, truncation = 1.5",
        "sigma = { value = 2.0, unit = 'deg' }, truncation = 1.5",
    ),
    "uniform": ("relative_half_width = 0.04", "half_width = { value = 2.0, unit = 'deg' }"),
}


def _draws(tmp_path, law: str) -> list[dict]:
    moments_scale, attitude_scale = LAWS[law]
    text = SCENARIO.format(
        moments=law, moments_scale=moments_scale, attitude=law, attitude_scale=attitude_scale
    )
    path = tmp_path / "laws.toml"
    path.write_text(text)
    loaded = load_scenario(path)
    dispersions = read_dispersions(loaded)
    return [draw_sample(dispersions, loaded.document, k) for k in range(dispersions.samples)]


def _column(samples, name) -> np.ndarray:
    return np.array([s.parameters[name] for s in samples])


def _ks(values, cdf) -> float:
    return stats.kstest(values, cdf).pvalue


@pytest.mark.parametrize("law", LAWS)
def test_rotation_and_relative_laws(tmp_path, law):
    samples = _draws(tmp_path, law)
    σ = 2.0  # deg
    δ = np.column_stack([_column(samples, f"initial_state.attitude_error_{c}_deg") for c in "xyz"])
    angle = _column(samples, "initial_state.attitude_error_deg")
    assert np.allclose(np.linalg.norm(δ, axis=1), angle, rtol=1e-12)
    ε = _column(samples, "spacecraft.moment_2_relative_error")
    if law == "normal":
        for c in range(3):
            assert _ks(δ[:, c] / σ, stats.norm.cdf) > 1e-3
        assert _ks(angle / σ, stats.chi(3).cdf) > 1e-3
        assert _ks(ε / 0.04, stats.norm.cdf) > 1e-3
    elif law == "truncated_normal":
        law3 = stats.chi(3)
        assert angle.max() <= 1.5 * σ * (1 + 1e-12)
        assert _ks(angle / σ, lambda x: law3.cdf(x) / law3.cdf(1.5)) > 1e-3
        assert np.abs(ε).max() <= 1.5 * 0.04 * (1 + 1e-12)
        assert _ks(ε / 0.04, stats.truncnorm(-1.5, 1.5).cdf) > 1e-3
    else:
        assert angle.max() <= σ * (1 + 1e-12)
        assert _ks((angle / σ) ** 3, stats.uniform.cdf) > 1e-3
        assert _ks(ε, stats.uniform(-0.04, 0.08).cdf) > 1e-3
    # Independent samples: no correlation between neighbours.
    assert abs(np.corrcoef(ε[:-1], ε[1:])[0, 1]) < 0.08
    assert abs(np.corrcoef(angle[:-1], angle[1:])[0, 1]) < 0.08


def test_direction_rate_time_and_magnitude_laws(tmp_path):
    samples = _draws(tmp_path, "normal")
    nominal = np.array([3.0, -4.0, 12.0])
    impulse = np.column_stack([_column(samples, f"events[0].impulse_{c}_N_m_s") for c in "xyz"])
    tilt = _column(samples, "events[0].impulse_tilt_deg")
    assert np.allclose(np.degrees(angle_between(impulse, nominal)), tilt, atol=1e-9)
    assert _ks(tilt / 1.5, stats.rayleigh.cdf) > 1e-3
    scale = np.linalg.norm(impulse, axis=1) / np.linalg.norm(nominal)
    ε = _column(samples, "events[0].impulse_relative_error")
    assert np.allclose(scale, 1.0 + ε, rtol=1e-13)
    assert _ks(ε / 0.05, stats.norm.cdf) > 1e-3
    for c, half in zip("xyz", (0.001, 0.002, 0.004), strict=True):
        error = _column(samples, f"initial_state.angular_velocity_error_{c}_rad_s")
        assert np.abs(error).max() <= half
        assert _ks(error, stats.uniform(-half, 2 * half).cdf) > 1e-3
    shift = _column(samples, "events[0].time_shift_s")
    assert np.array_equal(_column(samples, "events[0].offset_s"), 5.0 + shift)
    assert _ks(shift / 0.25, stats.norm.cdf) > 1e-3
