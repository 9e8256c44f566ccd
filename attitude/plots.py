"""The report's figures (PNG), drawn with matplotlib's object API on an Agg canvas.

No pyplot and no global backend: a library must not change its caller's matplotlib
state.  Long series are reduced to at most a few thousand points per curve by
keeping the minimum and the maximum of each bin, so that no extreme disappears.
"""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from numpy.typing import NDArray

from attitude.vectors import basis_across

__all__ = [
    "plot_angular_velocity",
    "plot_eclipse",
    "plot_polhode",
    "plot_sun_angles",
    "time_axis",
    "time_unit",
]

_MAX_POINTS = 4000
_DPI = 110


def time_unit(span_s: float) -> tuple[float, str]:
    """A readable time unit for a span: its length in seconds and the axis label."""
    for limit, unit_s, unit in (
        (600.0, 1.0, "s"),
        (3 * 3600.0, 60.0, "min"),
        (3 * 86400.0, 3600.0, "h"),
    ):
        if span_s <= limit:
            return unit_s, f"time since the epoch ({unit})"
    return 86400.0, "time since the epoch (days)"


def time_axis(seconds: NDArray[np.float64]) -> tuple[NDArray[np.float64], str]:
    """Times in a readable unit (s, min, h or days) and the axis label."""
    unit_s, label = time_unit(float(seconds[-1] - seconds[0]) if seconds.size else 0.0)
    return seconds / unit_s, label


def _envelope(x: NDArray[np.float64], y: NDArray[np.float64]) -> tuple[NDArray, NDArray]:
    """At most ~_MAX_POINTS points: the min and max of each bin, in time order."""
    if x.size <= _MAX_POINTS:
        return x, y
    bins = _MAX_POINTS // 2
    edges = np.linspace(0, x.size, bins + 1).astype(int)
    xs, ys = [], []
    for a, b in itertools.pairwise(edges):
        if b <= a:
            continue
        segment = y[a:b]
        lo, hi = a + int(np.nanargmin(segment)), a + int(np.nanargmax(segment))
        for k in sorted({lo, hi}):
            xs.append(x[k])
            ys.append(y[k])
    return np.array(xs), np.array(ys)


def _save(figure: Figure, path: Path) -> str:
    FigureCanvasAgg(figure)
    figure.savefig(path, dpi=_DPI)
    return path.name


def _bands(x, y, bins: int = 600):
    """Bin centres, minima and maxima of y: the range a fast oscillation sweeps."""
    edges = np.linspace(0, x.size, min(bins, x.size) + 1).astype(int)
    centres = 0.5 * (x[edges[:-1]] + x[np.maximum(edges[1:] - 1, edges[:-1])])
    low = np.minimum.reduceat(y, edges[:-1])
    high = np.maximum.reduceat(y, edges[:-1])
    return centres, low, high


def plot_sun_angles(
    path: Path,
    seconds: NDArray[np.float64],
    angles_deg: dict[str, NDArray[np.float64]],
    limits_deg: dict[str, float | None],
    eclipse: NDArray[np.bool_] | None = None,
    zoom_s: tuple[float, float] | None = None,
    bin_s: float | None = None,
    title: str = "",
) -> str:
    """Sun angle of each body vector, with its exclusion limit (dashed).

    Top: the whole span, each vector as the band it sweeps within each time bin of
    ``bin_s`` seconds or more (two turns of a spinning body: shorter bins would cut
    turns and alias).  Bottom, if ``zoom_s`` is given: the curves themselves over
    that window (a few turns).
    """
    rows = 2 if zoom_s is not None else 1
    figure = Figure(figsize=(9.0, 3.6 * rows + 0.6), layout="constrained")
    panels = figure.subplots(rows, 1, squeeze=False)[:, 0]
    colors = {name: f"C{i}" for i, name in enumerate(angles_deg)}

    def decorate(axes, t, label, shade):
        for name, limit in limits_deg.items():
            if limit is not None:
                axes.axhline(
                    limit,
                    color=colors.get(name, "k"),
                    linestyle="--",
                    linewidth=1.0,
                    label=f"{name} exclusion ({limit:g}°)",
                )
        if shade is not None and np.any(shade):
            axes.fill_between(
                t, 0, 180, where=shade, color="0.88", step="mid", label="eclipse", zorder=0
            )
        axes.set_ylim(0.0, 180.0)
        axes.set_yticks(np.arange(0, 181, 30))
        axes.set_xlabel(label)
        axes.set_ylabel("angle from the Sun (deg)")
        axes.grid(alpha=0.3)

    t, label = time_axis(seconds)
    top = panels[0]
    span = float(seconds[-1] - seconds[0])
    bins = 600 if not bin_s else int(np.clip(span / bin_s, 20, 600))
    for name, angle in angles_deg.items():
        centres, low, high = _bands(t, angle, bins)
        top.fill_between(centres, low, high, color=colors[name], alpha=0.4, label=name)
    decorate(top, t, label, eclipse)
    top.set_title(title or "Sun angle on the body vectors (band: range swept in each time bin)")
    top.legend(loc="upper right", fontsize="small", ncols=2)
    if zoom_s is not None:
        window = (seconds >= zoom_s[0]) & (seconds <= zoom_s[1])
        unit_s, zoom_label = time_unit(zoom_s[1] - zoom_s[0])
        tz = seconds[window] / unit_s
        bottom = panels[1]
        for name, angle in angles_deg.items():
            bottom.plot(tz, angle[window], color=colors[name], linewidth=1.2, label=name)
        decorate(bottom, tz, zoom_label, None if eclipse is None else eclipse[window])
        bottom.set_title(f"Zoom on {zoom_s[1] - zoom_s[0]:.4g} s from {zoom_s[0]:.6g} s")
    return _save(figure, path)


def plot_angular_velocity(
    path: Path, seconds: NDArray[np.float64], ω_rad_s: NDArray[np.float64], events_s=(), title=""
) -> str:
    """Body angular velocity components (deg/s), with the events as vertical lines."""
    figure = Figure(figsize=(9.0, 4.8), layout="constrained")
    axes = figure.add_subplot()
    unit_s, label = time_unit(float(seconds[-1] - seconds[0]))
    t = seconds / unit_s
    for i, axis in enumerate("xyz"):
        x, y = _envelope(t, np.degrees(ω_rad_s[:, i]))
        axes.plot(x, y, linewidth=1.0, label=f"ω {axis}")
    for event in events_s:
        axes.axvline(event / unit_s, color="0.4", linestyle=":", linewidth=1.0)
    axes.set_xlabel(label)
    axes.set_ylabel("body angular velocity (deg/s)")
    axes.set_title(title or "Angular velocity in body axes")
    axes.grid(alpha=0.3)
    axes.legend(loc="upper right", fontsize="small")
    return _save(figure, path)


def plot_polhode(
    path: Path, h_body: NDArray[np.float64], segments: NDArray[np.int_], title: str = ""
) -> str:
    """The angular momentum direction in body axes (the polhode).

    Left: on the unit sphere, with the body axes.  Right: seen from its mean direction
    (azimuthal equidistant: distance from the centre = angle from the mean
    direction), so that a small nutation cone is as readable as a flip.
    """
    figure = Figure(figsize=(11.0, 5.2), layout="constrained")
    sphere = figure.add_subplot(1, 2, 1, projection="3d")
    flat = figure.add_subplot(1, 2, 2)
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 37), np.linspace(0, np.pi, 19))
    sphere.plot_wireframe(
        np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v), color="0.85", linewidth=0.5
    )
    # Directions only where there is momentum (none at rest), scaled first so that no
    # square overflows (|h| of 1e160 is a valid state).
    scale = np.max(np.abs(h_body), axis=1, keepdims=True)
    moving = scale[:, 0] > 0.0
    if not np.any(moving):
        flat.text(0.5, 0.5, "at rest: no angular momentum", ha="center", va="center")
        flat.set_axis_off()
        sphere.set_axis_off()
        figure.suptitle(title or "Angular momentum direction in body axes (polhode)")
        return _save(figure, path)
    segments = segments[moving]
    direction = h_body[moving] / scale[moving]
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    mean = np.mean(direction, axis=0)
    mean = mean / np.linalg.norm(mean) if np.linalg.norm(mean) > 1e-6 else direction[0]
    e1, e2 = basis_across(mean)
    step = max(1, direction.shape[0] // 5000)  # 3-D lines are slow to draw; 5000 is plenty
    radius = float(np.degrees(np.max(np.arccos(np.clip(direction @ mean, -1.0, 1.0)))))
    for k in np.unique(segments):
        d = direction[segments == k][::step]
        color = f"C{int(k) % 10}"
        sphere.plot(d[:, 0], d[:, 1], d[:, 2], linewidth=1.2, color=color)
        sphere.scatter(*d[0], s=12, color=color)
        angle = np.degrees(np.arccos(np.clip(d @ mean, -1.0, 1.0)))
        azimuth = np.arctan2(d @ e2, d @ e1)
        flat.plot(
            angle * np.cos(azimuth),
            angle * np.sin(azimuth),
            linewidth=1.0,
            color=color,
            label=f"segment {int(k)}",
        )
        flat.plot(
            angle[0] * np.cos(azimuth[0]),
            angle[0] * np.sin(azimuth[0]),
            "o",
            color=color,
            markersize=4,
        )
    for i, name in enumerate("xyz"):
        tip = np.eye(3)[i] * 1.15
        sphere.plot([0, tip[0]], [0, tip[1]], [0, tip[2]], color="k", linewidth=0.8)
        sphere.text(*tip, f"body {name}")
        axis_angle = np.degrees(np.arccos(np.clip(np.eye(3)[i] @ mean, -1.0, 1.0)))
        if axis_angle <= 1.2 * radius + 0.5:  # the body axes within the view, for orientation
            az = np.arctan2(np.eye(3)[i] @ e2, np.eye(3)[i] @ e1)
            flat.plot(axis_angle * np.cos(az), axis_angle * np.sin(az), "k+", markersize=9)
            flat.annotate(
                f"body {name}",
                (axis_angle * np.cos(az), axis_angle * np.sin(az)),
                textcoords="offset points",
                xytext=(4, 4),
                fontsize="small",
            )
    sphere.set_box_aspect((1, 1, 1))
    sphere.set_axis_off()
    sphere.set_title("on the unit sphere")
    flat.set_aspect("equal", adjustable="datalim")
    flat.set_xlabel("angle from the mean direction (deg)")
    flat.set_ylabel("angle from the mean direction (deg)")
    flat.grid(alpha=0.3)
    flat.set_title("seen from the mean direction")
    if np.unique(segments).size > 1:
        flat.legend(loc="best", fontsize="small")
    figure.suptitle(title or "Angular momentum direction in body axes (polhode)")
    return _save(figure, path)


def plot_eclipse(path: Path, seconds: NDArray[np.float64], sunlit_fraction, title: str = "") -> str:
    """The fraction of the Sun's disc seen from the spacecraft (0 in umbra)."""
    figure = Figure(figsize=(9.0, 3.2), layout="constrained")
    axes = figure.add_subplot()
    t, label = time_axis(seconds)
    x, y = _envelope(t, sunlit_fraction)
    axes.plot(x, y, linewidth=1.0, color="tab:orange")
    axes.set_ylim(-0.05, 1.05)
    axes.set_xlabel(label)
    axes.set_ylabel("Sun disc visible")
    axes.set_title(title or "Eclipses (conical shadow: umbra and penumbra)")
    axes.grid(alpha=0.3)
    return _save(figure, path)
