"""Small Monte Carlo scenarios for the tests: a 5 rpm spinner knocked by a thruster pulse,
five minutes at 5 s, a star tracker with a 35° Sun exclusion, every kind of dispersion."""

from pathlib import Path

SPINNER = """
[scenario]
name = "Spinner, dispersed"
epoch = "2027-06-21T00:00:00"

[spacecraft]
name = "Spinner"
principal_moments = [850.0, 900.0, 1200.0]

[initial_state]
quaternion = [0.9238795325112867, 0.0, 0.3826834323650898, 0.0]
angular_velocity = { value = [0.0, 0.0, 30.0], unit = "deg/s" }

[[events]]
type = "angular_impulse"
epoch = "2027-06-21T00:01:00"
impulse = [18.0, 0.0, 0.0]

[output]
duration = 300.0
step = 5.0

[pointing]
[[pointing.body_vectors]]
name = "star_tracker"
vector = [0.766044443118978, 0.0, 0.642787609686539]
kind = "star_tracker"
sun_exclusion_half_angle = { value = 35.0, unit = "deg" }

[[pointing.body_vectors]]
name = "top_panel"
vector = [0.0, 0.0, 1.0]
kind = "panel"
"""

DISPERSIONS = """
[dispersions]
seed = {seed}
samples = {samples}

[dispersions.spacecraft]
principal_moments = {{ distribution = "normal", relative_sigma = 0.05 }}
principal_axes = {{ distribution = "normal", sigma = {{ value = 1.0, unit = "deg" }} }}

[dispersions.initial_state]
attitude = {{ distribution = "normal", sigma = {{ value = 2.0, unit = "deg" }} }}
angular_velocity = {{ distribution = "uniform", half_width = {{ value = 0.5, unit = "deg/s" }} }}

[[dispersions.events]]
event = 0
time = {{ distribution = "uniform", half_width = {time_half_width} }}
impulse_magnitude = {{ distribution = "truncated_normal", relative_sigma = 0.1, truncation = 3.0 }}
impulse_direction = {{ distribution = "normal", sigma = {{ value = 2.0, unit = "deg" }} }}
"""


def write_spinner(
    folder: Path, samples: int = 12, seed: int = 7, time_half_width: float = 1.0, extra: str = ""
) -> Path:
    """The dispersed spinner as a file in ``folder``; ``time_half_width`` (s) spreads the
    thruster pulse's time (beyond 60 s, some samples fire it before the epoch)."""
    path = folder / "spinner.toml"
    path.write_text(
        SPINNER
        + DISPERSIONS.format(seed=seed, samples=samples, time_half_width=time_half_width)
        + extra
    )
    return path
