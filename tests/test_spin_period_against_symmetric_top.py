"""The spin-period analysis against the closed form of the free symmetric top.

``attitude.trajectory.motion`` measures the spin period numerically: the mean rate at
which a body axis across the spin axis turns about the angular momentum H, over one
period of m(t), on the closed-form attitude.  For a symmetric top that rate is known in
closed form (Landau & Lifshitz, *Mechanics*, §33; Goldstein, *Classical Mechanics*,
§5.6).  With Euler angles (φ, θ, ψ) whose z axis is H, the symmetry axis keeps the angle
θ to H and

    φ̇ = G/I⊥                      (precession of the symmetry axis about H)
    ψ̇ = G cos θ (1/Is − 1/I⊥)      (rotation of the body about its symmetry axis)

with Is the symmetric moment and I⊥ the transverse one.  A body axis b across the
symmetry axis has the azimuth φ + atan2(cos θ sin ψ, cos ψ) about H; over one turn of ψ
the second term gains ±2π with ψ, so b turns about H at the mean rate φ̇ + ψ̇ and the
spin period is

    2π / (G/I⊥ + G cos θ (1/Is − 1/I⊥)).

Nothing in the package computes this expression: the test compares the measured period
with it for oblate and prolate tops over a range of tilts θ.
"""

import math

import numpy as np
import pytest

from attitude import InitialState, Scenario, Spacecraft, analyze, propagate

G = 40.0  # N m s


def _spin_period(inertia, momentum):
    scenario = Scenario(
        "symmetric top",
        Spacecraft("top", inertia),
        "2030-01-01T00:00:00",
        InitialState.from_quaternion([1.0, 0.0, 0.0, 0.0], angular_momentum=momentum),
        duration=10.0,
    )
    [segment] = analyze(propagate(scenario))
    return segment


@pytest.mark.parametrize("tilt_deg", [3.0, 20.0, 45.0, 70.0, 88.0])
@pytest.mark.parametrize(
    ("shape", "inertia", "symmetry_axis"),
    [
        ("oblate", (100.0, 100.0, 180.0), 2),  # Is = 180 about z, I⊥ = 100
        ("prolate", (50.0, 200.0, 200.0), 0),  # Is = 50 about x, I⊥ = 200
    ],
)
def test_spin_period_is_the_symmetric_top_closed_form(shape, inertia, symmetry_axis, tilt_deg):
    θ = math.radians(tilt_deg)
    Is, I_perp = inertia[symmetry_axis], inertia[(symmetry_axis + 1) % 3]
    momentum = np.zeros(3)
    momentum[symmetry_axis] = G * math.cos(θ)
    momentum[(symmetry_axis + 1) % 3] = G * math.sin(θ)

    motion = _spin_period(inertia, momentum)

    # The analysis takes the symmetry axis as the spin axis, at the constant tilt θ.
    np.testing.assert_allclose(
        np.abs(motion.spin_axis_body), np.eye(3)[symmetry_axis], rtol=0, atol=1e-15
    )
    assert motion.nutation_min_rad == pytest.approx(θ, rel=1e-12)
    expected_s = 2 * math.pi / (G / I_perp + G * math.cos(θ) * (1 / Is - 1 / I_perp))
    assert motion.spin_period_s == pytest.approx(expected_s, rel=1e-10), shape


def test_the_closed_form_is_not_the_rate_about_the_symmetry_axis():
    """The check can fail: the naive 2π/ω_s (ω_s the rate about the symmetry axis)
    differs from the measured period by far more than the tolerance above."""
    inertia, θ = (100.0, 100.0, 180.0), math.radians(45.0)
    motion = _spin_period(inertia, [G * math.sin(θ), 0.0, G * math.cos(θ)])
    naive_s = 2 * math.pi / (G * math.cos(θ) / inertia[2])
    assert abs(motion.spin_period_s / naive_s - 1) > 0.1
