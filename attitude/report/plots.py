"""The report's figures (PNG), drawn with matplotlib's object API on an Agg canvas.

No pyplot and no global backend: a library must not change its caller's matplotlib
state.  Every figure stays readable at any span:

- A long series is drawn as its envelope: the minimum and the maximum within each
  pixel column of the time axis (:class:`Envelope`, filled chunk by chunk while the
  series is computed), a band with its two edges, never millions of points: no
  extreme is lost, and a 30-day run at 1 s draws 900 columns, not 2.6 million points.
  A series with fewer samples than columns is drawn as its samples.
- A figure can add a zoom panel (:class:`Zoom`) on something that happens: an event, a
  Sun exclusion, an eclipse entry, a flip; its samples are computed densely for it
  (``attitude.report.figures``), not taken from the output grid.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from attitude.base.vectors import basis_across

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = [
    "PIXEL_COLUMNS",
    "PNG_OPTIONS",
    "Envelope",
    "Zoom",
    "plot_angular_velocity",
    "plot_eclipse",
    "plot_polhode",
    "plot_sun_angles",
    "time_axis",
    "time_unit",
]

# 9 in at 100 dpi: 900 pixels across, the text (in points) as large relative to the
# figure as at any dpi; fewer pixels to rasterise and to encode than at 110 dpi (-17 %).
_DPI = 100
# zlib's fastest level for the PNGs (savefig's options, for the figures drawn elsewhere;
# this module's own are written by _png): the encoding is a fifth of a figure's time
# at the default level (6), a tenth at this one, for files about 15 % larger.
PNG_OPTIONS: dict[str, Any] = {"pil_kwargs": {"compress_level": 1}}
_ZLIB_LEVEL = 1
# At least the width of the axes in pixels (9 in at 100 dpi, less the margins).
PIXEL_COLUMNS = 900


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


class Envelope:
    """The minimum and maximum of named series in each of ``columns`` equal bins of
    [start_s, stop_s], accumulated over any number of :meth:`add` calls.

    While no more than ``keep`` samples have been added, they are also kept as they
    are, to be drawn as lines (:meth:`samples`).  Memory: a few arrays of ``columns``.
    """

    def __init__(
        self,
        start_s: float,
        stop_s: float,
        names: Sequence[str],
        columns: int = PIXEL_COLUMNS,
        keep: int = PIXEL_COLUMNS,
    ) -> None:
        self.start_s, self.stop_s = float(start_s), float(stop_s)
        self.edges = np.linspace(self.start_s, self.stop_s, columns + 1)
        self.names = list(names)
        self.low = {name: np.full(columns, np.inf) for name in self.names}
        self.high = {name: np.full(columns, -np.inf) for name in self.names}
        self.count = np.zeros(columns, dtype=np.int64)
        self._keep = keep
        self._kept: list[tuple[NDArray, dict[str, NDArray]]] | None = [] if keep else None
        self._kept_size = 0

    def column(self, seconds: NDArray[np.float64]) -> NDArray[np.intp]:
        """The column of each time (the ends of the span fall in the first and last)."""
        index = np.searchsorted(self.edges, seconds, side="right") - 1
        return np.clip(index, 0, self.count.size - 1)

    def add(
        self,
        seconds: NDArray[np.float64],
        values: dict[str, NDArray[np.float64]],
        columns: NDArray[np.intp] | None = None,
    ) -> None:
        """Add samples: ``values[name]`` at ``seconds`` (TT s), for every name;
        ``columns``: their columns, when the caller says (a column's closed interval
        ends on its right edge, which :meth:`column` gives to the next)."""
        seconds = np.asarray(seconds, dtype=np.float64)
        if seconds.size == 0:
            return
        index = self.column(seconds) if columns is None else np.asarray(columns)
        order = None if np.all(index[1:] >= index[:-1]) else np.argsort(index, kind="stable")
        if order is not None:
            index = index[order]
        starts = np.flatnonzero(np.concatenate(([True], index[1:] != index[:-1])))
        where = index[starts]
        self.count[where] += np.diff(np.append(starts, index.size))
        for name in self.names:
            v = np.asarray(values[name], dtype=np.float64)
            v = v if order is None else v[order]
            low, high = np.minimum.reduceat(v, starts), np.maximum.reduceat(v, starts)
            self.low[name][where] = np.minimum(self.low[name][where], low)
            self.high[name][where] = np.maximum(self.high[name][where], high)
        if self._kept is not None:
            self._kept_size += seconds.size
            if self._kept_size > self._keep:
                self._kept = None  # too many to draw as points: the envelope it is
            else:
                self._kept.append((seconds, {n: np.asarray(values[n]) for n in self.names}))

    def samples(self) -> tuple[NDArray, dict[str, NDArray]] | None:
        """The samples themselves, in time order, if few enough were added; else None."""
        if not self._kept:
            return None
        t = np.concatenate([t for t, _ in self._kept])
        order = np.argsort(t, kind="stable")
        return t[order], {
            n: np.concatenate([v[n] for _, v in self._kept])[order] for n in self.names
        }

    def filled(self) -> NDArray[np.bool_]:
        return self.count > 0

    def centres(self) -> NDArray[np.float64]:
        return 0.5 * (self.edges[:-1] + self.edges[1:])


@dataclass
class Zoom:
    """A zoom panel: ``series`` (name → values) at ``seconds`` (TT s), a title, times
    to mark with vertical lines (an event, an interval's ends) and spans to shade."""

    seconds: NDArray[np.float64]
    series: dict[str, NDArray[np.float64]]
    title: str
    marks_s: Sequence[float] = ()
    shaded_s: Sequence[tuple[float, float]] = field(default_factory=list)


def _panels(rows: int, height_in: float) -> tuple[Figure, list]:
    """A 9-inch-wide figure of ``rows`` panels, with fixed margins (a layout engine,
    constrained or tight, measures every text and redraws: 40% of a figure's time),
    each with its ticks and grid (:func:`_ticks`)."""
    from matplotlib.figure import Figure  # here: a run without plots never loads matplotlib

    height = height_in * rows + 0.6
    figure = Figure(figsize=(9.0, height), dpi=_DPI)
    inch = 1.0 / height
    figure.subplots_adjust(
        left=0.085, right=0.98, bottom=0.55 * inch, top=1.0 - 0.4 * inch, hspace=0.85 / height_in
    )
    panels = list(figure.subplots(rows, 1, squeeze=False)[:, 0])
    for axes in panels:
        _ticks(axes)
    return figure, panels


def _ticks(axes) -> None:
    """The axes' ticks, tick labels, axis labels and grid, drawn by
    ``attitude.report.ticks`` (matplotlib's own axis drawing was over half of the
    figures' time): the same ticks, in the same places."""
    from attitude.report.ticks import Ticks

    Ticks(axes, grid_alpha=0.3)


def _title(axes, text: str) -> None:
    """An axes' title at its usual place, just above the axes: placed there, not found
    there by matplotlib, which measures every tick label of the y axis (for an offset
    text that could reach the title) at each drawing, a tenth of a figure's time.  No
    axis of these figures has tick labels or an offset text under the title's middle."""
    axes.set_title(text, y=1.0)


def _save(figure: Figure, path: Path) -> str:
    """The figure as an opaque RGB PNG (its background is white: the alpha channel of
    matplotlib's own PNG says nothing).

    The text is drawn without hinting: the font's hinting program, run for every glyph
    of every label, was a third of the text's time, and the text most of a figure's;
    unhinted glyphs at 100 dpi read the same.  (rcParams set for this drawing only, and
    restored: a library does not change its caller's matplotlib state.)"""
    import matplotlib
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    figure.set_dpi(_DPI)
    canvas = FigureCanvasAgg(figure)
    with matplotlib.rc_context({"text.hinting": "no_hinting"}):
        canvas.draw()
    rgb = np.asarray(canvas.buffer_rgba())[:, :, :3]
    path.write_bytes(_png(rgb, _DPI))
    return path.name


def _png(rgb: NDArray[np.uint8], dpi: int) -> bytes:
    """An 8-bit RGB PNG of ``rgb`` (rows from the top), every row under the "Up" filter
    (PNG spec., 9.2: each byte less the byte above it), deflated by zlib at its fastest.

    Written here rather than by Pillow, which tries all five filters on every row and
    keeps the best (four tenths of the encoding's time): for a figure, whose rows mostly
    repeat the row above, "Up" alone compresses as well (the same size within 1 %)."""
    import zlib

    height, width, _ = rgb.shape
    rows = np.empty((height, 1 + 3 * width), dtype=np.uint8)
    rows[:, 0] = 2  # the filter type: Up
    flat = rgb.reshape(height, 3 * width)
    rows[0, 1:] = flat[0]  # the row above the first is zeros
    np.subtract(flat[1:], flat[:-1], out=rows[1:, 1:])  # modulo 256, as the spec. says

    def chunk(kind: bytes, data: bytes) -> bytes:
        body = kind + data
        return len(data).to_bytes(4, "big") + body + zlib.crc32(body).to_bytes(4, "big")

    per_metre = round(dpi / 0.0254)
    header = width.to_bytes(4, "big") + height.to_bytes(4, "big") + bytes([8, 2, 0, 0, 0])
    return b"".join(
        (
            b"\x89PNG\r\n\x1a\n",
            chunk(b"IHDR", header),
            chunk(b"pHYs", per_metre.to_bytes(4, "big") * 2 + b"\x01"),
            chunk(b"IDAT", zlib.compress(rows.tobytes(), _ZLIB_LEVEL)),
            chunk(b"IEND", b""),
        )
    )


def _draw_envelope(
    axes, envelope: Envelope, unit_s: float, colors: dict[str, str], scale=None
) -> list:
    """Each series as its samples (few: lines) or its band with edges (many); returns
    the legend's handles for the bands (the lines carry their own labels)."""
    from matplotlib.patches import Patch

    from attitude.report.bands import BAND_ALPHA, Bands

    scale = scale or {}
    kept = envelope.samples()
    if kept is not None:
        t, values = kept
        for name in envelope.names:
            axes.plot(
                t / unit_s,
                values[name] * scale.get(name, 1.0),
                color=colors[name],
                linewidth=1.0,
                label=name,
            )
        return []
    filled = envelope.filled()
    if not np.any(filled):
        return []
    x = envelope.centres()[filled] / unit_s
    series = []
    for name in envelope.names:
        k = scale.get(name, 1.0)
        low, high = envelope.low[name][filled] * k, envelope.high[name][filled] * k
        series.append((low, high, colors[name]))
    axes.add_artist(Bands(x, series, edges=False))
    axes.add_artist(Bands(x, series, edges=True))
    least = min(float(np.min(low)) for low, _, _ in series)
    most = max(float(np.max(high)) for _, high, _ in series)
    axes.update_datalim([(x[0], least), (x[-1], most)])
    axes.autoscale_view()
    return [
        Patch(facecolor=colors[name], alpha=BAND_ALPHA, linewidth=0, label=name)
        for name in envelope.names
    ]


def _legend(axes, bands: list, **options) -> None:
    """The axes' legend: the bands' handles first, then its labelled artists'."""
    handles, _ = axes.get_legend_handles_labels()
    axes.legend(handles=[*bands, *handles], **options)


def _shade(axes, spans_s: Sequence[tuple[float, float]], unit_s: float, low, high, label=None):
    """Shade time spans (eclipses) as one collection, merged per pixel column when many."""
    if not spans_s:
        return
    spans = np.asarray(spans_s, dtype=np.float64) / unit_s
    x = np.ravel(np.column_stack([spans[:, 0], spans[:, 0], spans[:, 1], spans[:, 1]]))
    inside = (
        np.ravel(
            np.column_stack(
                [
                    np.zeros(len(spans)),
                    np.ones(len(spans)),
                    np.ones(len(spans)),
                    np.zeros(len(spans)),
                ]
            )
        )
        > 0
    )
    axes.fill_between(x, low, high, where=inside, color="0.88", zorder=0, linewidth=0, label=label)


def _zoom_panel(axes, zoom: Zoom, colors: dict[str, str], ylabel: str, scale=None) -> float:
    """The zoom's series on ``axes``; returns its time unit (s), which a caller's own
    marks on the panel must use: the axis shows the time since the epoch, so the unit
    follows the zoom's distance from the epoch as well as its span."""
    span = float(zoom.seconds[-1] - zoom.seconds[0]) if zoom.seconds.size > 1 else 0.0
    unit_s, label = time_unit(max(span, float(np.max(np.abs(zoom.seconds[[0, -1]])))))
    scale = scale or {}
    for name, values in zoom.series.items():
        axes.plot(
            zoom.seconds / unit_s,
            values * scale.get(name, 1.0),
            color=colors.get(name, "k"),
            linewidth=1.2,
            label=name,
        )
    for mark in zoom.marks_s:
        axes.axvline(mark / unit_s, color="0.3", linestyle=":", linewidth=1.0)
    axes.set_xlim(zoom.seconds[0] / unit_s, zoom.seconds[-1] / unit_s)
    axes.set_xlabel(label)
    axes.set_ylabel(ylabel)
    _title(axes, zoom.title)
    return unit_s


def plot_angular_velocity(
    path: Path,
    envelope: Envelope,
    events_s: Sequence[float] = (),
    zoom: Zoom | None = None,
    title: str = "",
) -> str:
    """Body angular velocity components (deg/s; ``envelope`` in rad/s, series "x", "y",
    "z"), the events as vertical lines, and an optional zoom panel."""
    rows = 2 if zoom is not None else 1
    figure, panels = _panels(rows, 3.8)
    axes = panels[0]
    unit_s, label = time_unit(envelope.stop_s - envelope.start_s)
    colors = {name: f"C{i}" for i, name in enumerate(envelope.names)}
    degrees = dict.fromkeys(envelope.names, 180.0 / np.pi)
    bands = _draw_envelope(axes, envelope, unit_s, colors, degrees)
    for event in events_s:
        axes.axvline(event / unit_s, color="0.4", linestyle=":", linewidth=1.0)
    axes.set_xlim(envelope.start_s / unit_s, envelope.stop_s / unit_s)
    axes.set_xlabel(label)
    axes.set_ylabel("body angular velocity (deg/s)")
    _title(axes, title or "Angular velocity in body axes (band: range in each pixel column)")
    _legend(axes, bands, loc="upper right", fontsize="small", ncols=3)
    if zoom is not None:
        _zoom_panel(panels[1], zoom, colors, "body angular velocity (deg/s)", degrees)
    return _save(figure, path)


def _sun_angle_guides(
    axes,
    limits_deg: dict[str, float | None],
    colors: dict[str, str],
    shaded_s: Sequence[tuple[float, float]],
    unit_s: float,
) -> None:
    """What a Sun-angle panel is read against: each vector's exclusion limit (dashed, in
    its colour), the eclipses shaded, and the full 0-180° range."""
    from matplotlib.ticker import FixedLocator

    for name, limit in limits_deg.items():
        if limit is not None:
            axes.axhline(
                limit,
                color=colors.get(name, "k"),
                linestyle="--",
                linewidth=1.0,
                label=f"{name} exclusion ({limit:g}°)",
            )
    _shade(axes, shaded_s, unit_s, 0.0, 180.0, "eclipse")
    axes.set_ylim(0.0, 180.0)
    # (set_yticks would make the seven tick objects that attitude.report.ticks does
    # without)
    axes.yaxis.set_major_locator(FixedLocator(list(range(0, 181, 30))))


def plot_sun_angles(
    path: Path,
    envelope: Envelope,
    limits_deg: dict[str, float | None],
    shadow_s: Sequence[tuple[float, float]] = (),
    zoom: Zoom | None = None,
    title: str = "",
) -> str:
    """Sun angle of each body vector (deg), with its exclusion limit (dashed), the
    eclipses shaded, and an optional zoom panel."""
    figure, panels = _panels(2 if zoom is not None else 1, 3.6)
    colors = {name: f"C{i}" for i, name in enumerate(envelope.names)}
    top = panels[0]
    unit_s, label = time_unit(envelope.stop_s - envelope.start_s)
    bands = _draw_envelope(top, envelope, unit_s, colors)
    _sun_angle_guides(top, limits_deg, colors, shadow_s, unit_s)
    top.set_xlim(envelope.start_s / unit_s, envelope.stop_s / unit_s)
    top.set_xlabel(label)
    top.set_ylabel("angle from the Sun (deg)")
    _title(top, title or "Sun angle on the body vectors (band: range in each pixel column)")
    _legend(top, bands, loc="upper right", fontsize="small", ncols=2)
    if zoom is not None:
        zoom_unit_s = _zoom_panel(panels[1], zoom, colors, "angle from the Sun (deg)")
        _sun_angle_guides(panels[1], limits_deg, colors, zoom.shaded_s, zoom_unit_s)
    return _save(figure, path)


def plot_eclipse(
    path: Path,
    envelope: Envelope | None,
    passes: Sequence[tuple[float, float, float]] = (),
    zoom: Zoom | None = None,
    span_s: tuple[float, float] = (0.0, 1.0),
    title: str = "",
) -> str:
    """Eclipses: the visible fraction of the Sun's disc (``envelope``, series "sunlit")
    over a short span, or each pass's shadow and umbra durations (``passes``: start,
    shadow s, umbra s) over a long one; and an optional zoom panel on an entry."""
    rows = 2 if zoom is not None else 1
    figure, panels = _panels(rows, 3.2)
    axes = panels[0]
    unit_s, label = time_unit(span_s[1] - span_s[0])
    if envelope is not None:
        _draw_envelope(axes, envelope, unit_s, {"sunlit": "tab:orange"})
        axes.set_ylim(-0.05, 1.05)
        axes.set_ylabel("Sun disc visible")
        _title(axes, title or "Eclipses (conical shadow: umbra and penumbra)")
    else:
        starts = np.array([p[0] for p in passes]) / unit_s
        axes.plot(
            starts,
            [p[1] / 60.0 for p in passes],
            ".-",
            color="tab:orange",
            markersize=3,
            linewidth=0.8,
            label="shadow (umbra + penumbra)",
        )
        axes.plot(
            starts,
            [p[2] / 60.0 for p in passes],
            ".-",
            color="0.25",
            markersize=3,
            linewidth=0.8,
            label="umbra",
        )
        axes.set_ylabel("eclipse duration (min)")
        axes.set_ylim(0.0, 1.15 * max((p[1] / 60.0 for p in passes), default=1.0))
        axes.legend(loc="best", fontsize="small")
        _title(axes, title or f"Eclipses: the duration of each of the {len(passes)} passes")
    axes.set_xlim(span_s[0] / unit_s, span_s[1] / unit_s)
    axes.set_xlabel(label)
    if zoom is not None:
        _zoom_panel(panels[1], zoom, {"sunlit": "tab:orange"}, "Sun disc visible")
        panels[1].set_ylim(-0.05, 1.05)
    return _save(figure, path)


def _momentum_directions(
    paths: Sequence[tuple[int, NDArray[np.float64]]],
) -> list[tuple[int, NDArray[np.float64]]]:
    """Each segment's unit momentum directions, where there is momentum (none at rest).
    Scaled by the largest component first, so that no square overflows (|h| of 1e160
    is a valid state)."""
    directions = []
    for k, h_body in paths:
        scale = np.max(np.abs(h_body), axis=1, keepdims=True)
        moving = scale[:, 0] > 0.0
        if np.any(moving):
            d = h_body[moving] / scale[moving]
            directions.append((k, d / np.linalg.norm(d, axis=1, keepdims=True)))
    return directions


@dataclass(frozen=True)
class _MeanView:
    """The azimuthal equidistant view from the mean direction of the momentum: a unit
    vector d is drawn at (θ cos φ, θ sin φ), θ its angle (deg) from ``mean`` and φ its
    azimuth about it (from ``e1`` towards ``e2``); ``radius_deg``: the largest θ."""

    mean: NDArray[np.float64]
    e1: NDArray[np.float64]
    e2: NDArray[np.float64]
    radius_deg: float

    @classmethod
    def of(cls, directions: list[tuple[int, NDArray[np.float64]]]) -> _MeanView:
        every = np.concatenate([d for _, d in directions])
        mean = np.mean(every, axis=0)
        # A motion symmetric about the origin (a flip) has no mean: view from its start.
        mean = mean / np.linalg.norm(mean) if np.linalg.norm(mean) > 1e-6 else every[0]
        e1, e2 = basis_across(mean)
        radius = float(np.degrees(np.max(np.arccos(np.clip(every @ mean, -1.0, 1.0)))))
        return cls(mean, e1, e2, radius)

    def xy(self, d: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        angle = np.degrees(np.arccos(np.clip(d @ self.mean, -1.0, 1.0)))
        azimuth = np.arctan2(d @ self.e2, d @ self.e1)
        return angle * np.cos(azimuth), angle * np.sin(azimuth)


def _unit_sphere(sphere) -> None:
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 37), np.linspace(0, np.pi, 19))
    sphere.plot_wireframe(
        np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v), color="0.85", linewidth=0.5
    )


def _draw_on_sphere(sphere, directions: list[tuple[int, NDArray[np.float64]]]) -> None:
    """The paths on the unit sphere, with the body axes, each path's start marked."""
    for k, d in directions:
        color = f"C{int(k) % 10}"
        sphere.plot(d[:, 0], d[:, 1], d[:, 2], linewidth=1.2, color=color)
        sphere.scatter(*d[0], s=12, color=color)
    for i, name in enumerate("xyz"):
        tip = np.eye(3)[i] * 1.15
        sphere.plot([0, tip[0]], [0, tip[1]], [0, tip[2]], color="k", linewidth=0.8)
        sphere.text(*tip, f"body {name}")
    sphere.set_box_aspect((1, 1, 1))
    sphere.set_axis_off()
    sphere.set_title("on the unit sphere")  # a 3D axes places its own


def _draw_from_mean(flat, directions: list[tuple[int, NDArray[np.float64]]]) -> None:
    """The paths seen from their mean direction, so that a small nutation cone is as
    readable as a flip; the body axes that fall within the view, for orientation."""
    view = _MeanView.of(directions)
    for k, d in directions:
        color = f"C{int(k) % 10}"
        x, y = view.xy(d)
        flat.plot(x, y, linewidth=1.0, color=color, label=f"segment {int(k)}")
        flat.plot(x[0], y[0], "o", color=color, markersize=4)
    for i, name in enumerate("xyz"):
        [x], [y] = view.xy(np.eye(3)[i : i + 1])
        if math.hypot(x, y) <= 1.2 * view.radius_deg + 0.5:
            flat.plot(x, y, "k+", markersize=9)
            flat.annotate(
                f"body {name}", (x, y), textcoords="offset points", xytext=(4, 4), fontsize="small"
            )
    flat.set_aspect("equal", adjustable="datalim")
    flat.set_xlabel("angle from the mean direction (deg)")
    flat.set_ylabel("angle from the mean direction (deg)")
    _title(flat, "seen from the mean direction")
    if len(directions) > 1:
        flat.legend(loc="best", fontsize="small")


def plot_polhode(
    path: Path, paths: Sequence[tuple[int, NDArray[np.float64]]], title: str = ""
) -> str:
    """The angular momentum direction in body axes (the polhode), one path per segment
    (``paths``: segment index, (n, 3) body momentum sampled densely over the motion).

    Left: on the unit sphere, with the body axes.  Right: seen from its mean direction
    (azimuthal equidistant: distance from the centre = angle from the mean
    direction), so that a small nutation cone is as readable as a flip.
    """
    from matplotlib.figure import Figure

    figure = Figure(figsize=(11.0, 5.2))
    figure.subplots_adjust(left=0.02, right=0.97, bottom=0.1, top=0.88, wspace=0.15)
    sphere = figure.add_subplot(1, 2, 1, projection="3d")
    flat = figure.add_subplot(1, 2, 2)
    _ticks(flat)
    figure.suptitle(title or "Angular momentum direction in body axes (polhode)")
    _unit_sphere(sphere)
    directions = _momentum_directions(paths)
    if not directions:
        flat.text(0.5, 0.5, "at rest: no angular momentum", ha="center", va="center")
        flat.set_axis_off()
        sphere.set_axis_off()
        return _save(figure, path)
    _draw_on_sphere(sphere, directions)
    _draw_from_mean(flat, directions)
    return _save(figure, path)
