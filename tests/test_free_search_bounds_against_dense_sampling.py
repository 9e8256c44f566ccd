"""The bounds the torque-free search rests on, against dense sampling.

Nothing found between nodes can be missed only if the bounds hold: a body vector's
rate |ḋ| and bend |d̈| over a segment (``vector_motion``), the two-parabola bounds of
a function between two nodes from its values, slopes and a bound on its bend
(``_bounds``), the range of a periodic table over any window (``_PeriodicRange``), and
the spherical-triangle envelope |σ − β| ≤ angle ≤ σ + β (``_envelope``).  Each is
checked here against the sampled function itself: chords and second differences of the
exact attitude 1 ms apart, and values 1000 times denser than the cells.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from attitude.files.scenario_reader import load_scenario
from attitude.pointing.free_search import (
    FreePiece,
    _bounds,
    _envelope,
    _PeriodicRange,
    free_plan,
    vector_motion,
)
from attitude.pointing.shared_surroundings import shared_surroundings
from attitude.pointing.spec import BodyVector, PointingSpec, for_scenario
from attitude.scenario.scenario import InitialState, Scenario
from attitude.scenario.spacecraft import Spacecraft
from attitude.trajectory.trajectory import propagate

ROOT = Path(__file__).parents[1]


def _tumbler(duration: float = 300.0):
    craft = Spacecraft("tumbler", [100.0, 200.0, 300.0])
    state = InitialState(Rotation.identity(), angular_velocity=[0.001, 1.0, 0.001])
    scenario = Scenario("tumbler", craft, "2027-03-20T12:00:00", state, duration=duration, step=1.0)
    return propagate(scenario)


def _cases():
    out = {"tumbler": _tumbler()}
    for name in ("spinner_thruster_pulse", "dzhanibekov_t_handle", "tumbling_defunct_satellite"):
        out[name] = propagate(load_scenario(ROOT / "scenarios" / f"{name}.toml").scenario)
    return out


CASES = _cases()
VECTORS = [
    ("x", np.array([1.0, 0.0, 0.0])),
    ("z", np.array([0.0, 0.0, 1.0])),
    ("oblique", np.array([1.0, 2.0, -2.0]) / 3.0),
]


@pytest.mark.parametrize("name", list(CASES))
def test_rate_and_bend_against_chords_and_second_differences(name):
    trajectory = CASES[name]
    segment = trajectory.segments[-1]
    stop = min(segment.end_s, segment.start_s + 600.0)
    motion = vector_motion(segment.solver, VECTORS, segment.start_s, stop)
    h = 1e-3
    τ = np.arange(segment.start_s + h, stop - h, h)
    attitude = trajectory.attitude(τ)
    for vector_name, b in VECTORS:
        d = attitude.apply(b)
        rate = np.linalg.norm(np.diff(d, axis=0), axis=1) / h
        bend = np.linalg.norm(d[2:] - 2.0 * d[1:-1] + d[:-2], axis=1) / (h * h)
        assert np.max(rate) <= motion[vector_name].rate * (1.0 + 1e-6), vector_name
        # Second differences carry rounding of ~4e-16/h² ≈ 4e-10.
        assert np.max(bend) <= motion[vector_name].bend * (1.0 + 1e-6) + 1e-9, vector_name


def test_the_bounds_between_nodes_against_dense_values():
    # f = Σ a_k cos(w_k t + p_k): |f''| ≤ Σ |a_k| w_k²; on random cells, every value of
    # a sampling 1000 times denser lies within the bounds from the ends' values and slopes.
    rng = np.random.default_rng(7)
    a, w, p = rng.normal(size=6), rng.uniform(0.1, 3.0, 6), rng.uniform(0, 2 * np.pi, 6)

    def f(t):
        return np.sum(a * np.cos(np.multiply.outer(t, w) + p), axis=-1)

    def df(t):
        return -np.sum(a * w * np.sin(np.multiply.outer(t, w) + p), axis=-1)

    M = float(np.sum(np.abs(a) * w * w))
    starts = rng.uniform(0.0, 100.0, 400)
    widths = rng.uniform(0.01, 1.5, 400)
    low, high = _bounds(f(starts), df(starts), f(starts + widths), df(starts + widths), widths, M)
    inside = starts[:, None] + widths[:, None] * np.linspace(0.0, 1.0, 1001)[None, :]
    values = f(inside)
    assert np.all(values.max(axis=1) <= high + 1e-12)
    assert np.all(values.min(axis=1) >= low - 1e-12)
    # And they are bounds worth having: within M h²/4 of the values.
    assert np.all(high - values.max(axis=1) <= 0.25 * M * widths**2 + 1e-12)


def test_the_periodic_range_against_brute_force():
    rng = np.random.default_rng(3)
    values = np.cumsum(rng.normal(size=1000))
    table = _PeriodicRange(values, start_s=5.0, spacing=0.5, periodic=True, slack=0.0)
    t0 = rng.uniform(-200.0, 2000.0, 300)
    t1 = t0 + rng.uniform(0.0, 800.0, 300)
    low, high = table.over(t0, t1)
    for a, b, lo, hi in zip(t0, t1, low, high, strict=True):
        first, last = math.floor((a - 5.0) / 0.5), math.ceil((b - 5.0) / 0.5)
        window = values[np.arange(first, last + 1) % values.size]
        assert lo == window.min() and hi == window.max()


@pytest.mark.parametrize("name", ["tumbler", "spinner_thruster_pulse"])
def test_the_envelope_against_sampled_angles(name):
    # For each cell of 2 s, the Sun's angle to each vector, sampled every 2 ms, lies
    # within the envelope the search takes for that cell.
    trajectory = CASES[name]
    segment = trajectory.segments[-1]
    spec = PointingSpec([BodyVector(n, b) for n, b in VECTORS])
    spec = for_scenario(spec, trajectory.scenario)
    start = segment.start_s
    stop = min(segment.end_s, start + 200.0)
    shared = shared_surroundings(trajectory, spec, start, stop)
    plan = free_plan(segment.solver, spec, shared, start, stop)
    assert plan is not None
    pieces = [FreePiece(segment.solver, plan, start, stop)]
    cells = np.arange(start, stop - 2.0, 2.0)
    axis = segment.solver.inertial_angular_momentum
    axis = axis / np.linalg.norm(axis)
    τ = cells[:, None] + np.linspace(0.0, 2.0, 1001)[None, :]
    sun = shared.exact(τ.ravel()).sun_direction
    attitude = trajectory.attitude(τ.ravel())
    σ = np.arccos(np.clip(sun @ axis, -1.0, 1.0)).reshape(τ.shape)
    for vector_name, b in VECTORS:
        angle = np.arccos(np.clip(np.sum(attitude.apply(b) * sun, axis=1), -1.0, 1.0))
        angle = angle.reshape(τ.shape)
        low, high = _envelope(
            pieces,
            np.zeros(cells.size, dtype=np.intp),
            vector_name,
            "sun",
            σ[:, 0],
            σ[:, -1],
            cells,
            cells + 2.0,
        )
        assert np.all(angle.min(axis=1) >= low - 1e-9), vector_name
        assert np.all(angle.max(axis=1) <= high + 1e-9), vector_name
