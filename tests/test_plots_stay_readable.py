"""The figures stay readable at any span, and the motion is drawn as it is.

- The per-pixel-column envelope, gathered chunk by chunk in any order, holds exactly
  the minimum and maximum of the samples in each column (against a direct loop).
- A run's figures hold no line of more than a few thousand points, however many
  samples the run has (the figures are captured as they are saved).
- The angular velocity's envelope, from the exact solution, covers the range of a
  dense direct sampling of it in every column to 1e-4 of its amplitude (a tenth of a
  pixel), and no more.
- The polhode of a symmetric top whose momentum is exactly 60° from its axis is drawn
  at 60° everywhere, even with an output step equal to the body period (which puts
  every output sample on the same point of the cone).
- The zoom panels are on something that happens: the event, the first Sun exclusion,
  the first eclipse entry.
"""

import math
import re
from pathlib import Path

import numpy as np
import pytest
from matplotlib.lines import Line2D

import attitude.report.plots
from attitude.cli.main import main
from attitude.files.scenario_reader import load_scenario
from attitude.report.figures import angular_velocity_envelope, polhode_paths
from attitude.report.plan import plan_run
from attitude.report.plots import Envelope

ROOT = Path(__file__).parents[1]


def test_the_envelope_holds_each_columns_min_and_max():
    rng = np.random.default_rng(3)
    t = np.sort(rng.uniform(0.0, 1000.0, 50_000))
    y = np.sin(t) * rng.uniform(0.5, 2.0, t.size)
    envelope = Envelope(0.0, 1000.0, ["y"], columns=300, keep=0)
    start = 0
    while start < t.size:  # chunks of random sizes, one of them shuffled
        stop = start + int(rng.integers(1, 5000))
        order = rng.permutation(np.arange(start, min(stop, t.size)))
        envelope.add(t[order], {"y": y[order]})
        start = stop
    column = np.minimum((t / 1000.0 * 300).astype(int), 299)
    for k in range(300):
        inside = y[column == k]
        assert envelope.count[k] == inside.size
        assert envelope.low["y"][k] == inside.min() and envelope.high["y"][k] == inside.max()
    assert envelope.samples() is None


def _spinner(tmp_path: Path, duration: float) -> Path:
    text = (ROOT / "scenarios" / "spinner_thruster_pulse.toml").read_text()
    text = re.sub(r"(?m)^duration = .*$", f"duration = {duration!r}", text, count=1)
    text = re.sub(r"(?m)^step = .*$", "step = 1.0", text, count=1)
    path = tmp_path / "spinner.toml"
    path.write_text(text)
    return path


def test_no_figure_draws_the_samples_of_a_long_run(tmp_path, monkeypatch):
    figures = {}
    save = attitude.report.plots._save

    def capture(figure, path):
        figures[path.name] = figure
        return save(figure, path)

    monkeypatch.setattr(attitude.report.plots, "_save", capture)
    path = _spinner(tmp_path, 6 * 3600.0)  # 21601 samples, 13 turns a minute, 4 eclipses
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--formats", "plots", "--quiet"]) == 0
    assert set(figures) == {
        "angular_velocity.png",
        "polhode.png",
        "sun_angles.png",
        "eclipse.png",
    }
    for name, figure in figures.items():
        lines = [a for axes in figure.axes for a in axes.get_children() if isinstance(a, Line2D)]
        assert lines, name
        assert max(len(line.get_xdata()) for line in lines) <= 2 * 2049, name
    # Every figure but the polhode zooms on something that happens.
    titles = {name: [axes.get_title() for axes in figure.axes] for name, figure in figures.items()}
    assert any("the first event, at +600 s" in t for t in titles["angular_velocity.png"])
    assert any("the first Sun exclusion" in t for t in titles["sun_angles.png"])
    assert any("the first eclipse entry" in t for t in titles["eclipse.png"])


def test_the_rate_envelope_covers_the_exact_motion(tmp_path):
    loaded = load_scenario(_spinner(tmp_path, 3000.0))
    plan = plan_run(loaded.scenario)
    envelope = angular_velocity_envelope(plan.trajectory, plan.motion, 0.0, 3000.0, columns=100)
    t = np.linspace(0.0, 3000.0, 3_000_001)  # 1000 a second: 2000 a turn of the nutation
    ω = plan.trajectory.angular_velocity(t)
    # Each column's closed interval [edge k, edge k + 1]: its right edge is its own too.
    first = np.searchsorted(t, envelope.edges[:-1], side="left")
    stop = np.searchsorted(t, envelope.edges[1:], side="right")
    for i, axis in enumerate("xyz"):
        low = np.array([ω[a:b, i].min() for a, b in zip(first, stop, strict=True)])
        high = np.array([ω[a:b, i].max() for a, b in zip(first, stop, strict=True)])
        scale = np.max(np.abs(ω[:, i])) + 1e-300
        assert np.all(envelope.low[axis] <= low + 1e-4 * scale), axis
        assert np.all(envelope.high[axis] >= high - 1e-4 * scale), axis
        assert np.all(envelope.low[axis] >= low - 1e-6 * scale), axis
        assert np.all(envelope.high[axis] <= high + 1e-6 * scale), axis


def test_the_polhode_of_a_60_degree_nutation_is_drawn_at_60_degrees(tmp_path):
    """A symmetric top (I = 10, 10, 20 kg m²) with its momentum 60° from its axis: m(t)
    circles the body z axis at exactly 60°.  The output step is the body period, so
    every output sample falls on the same point of the circle."""
    G = 2.0
    h = G * np.array([math.sin(math.radians(60.0)), 0.0, math.cos(math.radians(60.0))])
    text = f"""
[scenario]
name = "60 degree nutation"
epoch = "2027-06-21T00:00:00"
[spacecraft]
name = "top"
principal_moments = [10.0, 10.0, 20.0]
[initial_state]
quaternion = [1.0, 0.0, 0.0, 0.0]
angular_momentum = [{float(h[0])!r}, {float(h[1])!r}, {float(h[2])!r}]
[output]
duration = 2000.0
step = 10.0
"""
    path = tmp_path / "top.toml"
    path.write_text(text)
    loaded = load_scenario(path)
    period = plan_run(loaded.scenario).motion[0].period_s
    path.write_text(text.replace("step = 10.0", f"step = {float(period)!r}"))
    loaded = load_scenario(path)
    plan = plan_run(loaded.scenario)
    # (The grid's last epoch is the stop, off the step.)
    output = plan.trajectory.angular_momentum(loaded.scenario.output_seconds()[:-1])
    spread = np.ptp(np.degrees(np.arctan2(output[:, 1], output[:, 0])))
    assert spread < 1e-6  # the output grid sees one point of the cone
    [(_, drawn)] = polhode_paths(plan.trajectory, plan.motion, 0.0, 2000.0)
    angle = np.degrees(np.arccos(drawn[:, 2] / np.linalg.norm(drawn, axis=1)))
    np.testing.assert_allclose(angle, 60.0, atol=1e-9)
    azimuth = np.unwrap(np.arctan2(drawn[:, 1], drawn[:, 0]))
    assert np.ptp(azimuth) == pytest.approx(2.0 * math.pi, rel=1e-9)  # the whole circle


def test_the_zoom_shades_its_eclipse_on_its_own_time_axis(tmp_path, monkeypatch):
    """A zoom 300 s long but 5000 s after the epoch is drawn in minutes (its axis shows
    the time since the epoch); its eclipse, 5100-5200 s, must be shaded at 85-86.7 min
    on that axis, inside the panel, not at 5100 "min"."""
    figures = []
    save = attitude.report.plots._save
    monkeypatch.setattr(
        attitude.report.plots, "_save", lambda f, p: figures.append(f) or save(f, p)
    )
    envelope = Envelope(0.0, 10_000.0, ["panel"], columns=100, keep=0)
    t = np.linspace(0.0, 10_000.0, 1001)
    envelope.add(t, {"panel": 90.0 + 30.0 * np.sin(t / 500.0)})
    seconds = np.linspace(5000.0, 5300.0, 301)
    zoom = attitude.report.plots.Zoom(
        seconds, {"panel": 90.0 + 0.0 * seconds}, "Zoom", shaded_s=[(5100.0, 5200.0)]
    )
    attitude.report.plots.plot_sun_angles(
        tmp_path / "sun.png", envelope, {"panel": 30.0}, [(5100.0, 5200.0)], zoom
    )
    [figure] = figures
    panel = figure.axes[1]
    assert panel.get_xlabel() == "time since the epoch (min)"
    [shade] = [c for c in panel.collections if c.get_label() == "eclipse"]
    x = np.concatenate([path.vertices[:, 0] for path in shade.get_paths()])
    np.testing.assert_allclose([x.min(), x.max()], [5100.0 / 60.0, 5200.0 / 60.0])
    low, high = panel.get_xlim()
    assert low <= x.min() and x.max() <= high
