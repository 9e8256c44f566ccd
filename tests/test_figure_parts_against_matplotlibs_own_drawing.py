"""The figures' cheap parts against what they replace, drawn by matplotlib itself.

- ``attitude.report.ticks.Ticks`` (the ticks, tick labels, grid, axis labels and offset
  texts of an axes, drawn as a few artists) against matplotlib's own axis drawing:
  the same pixels, exactly, over spans that need an offset or a scientific exponent.
- ``attitude.report.bands.Bands`` (the bands and their edges, rasterised per pixel
  column) against ``fill_between`` and ``plot`` of the same series: the same picture
  within a few levels of 255 on average, and no column's extreme lost (every pixel row
  between a column's least and largest value is painted).
- The report's PNG writer (``attitude.report.plots._png``) read back by Pillow: the
  canvas's pixels, exactly, and its resolution.
"""

from __future__ import annotations

import io

import matplotlib
import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from PIL import Image

from attitude.report.bands import BAND_ALPHA, EDGE_WIDTH_PT, Bands
from attitude.report.plots import _png
from attitude.report.ticks import Ticks


def _pixels(figure: Figure) -> np.ndarray:
    canvas = FigureCanvasAgg(figure)
    with matplotlib.rc_context({"text.hinting": "no_hinting"}):  # as the report draws
        canvas.draw()
    return np.asarray(canvas.buffer_rgba())[:, :, :3].astype(int)


def _axes_with_ticks(ours: bool, x_limits, y_limits, fixed_y=None) -> np.ndarray:
    figure = Figure(figsize=(6.0, 4.0), dpi=100)
    axes = figure.add_axes((0.15, 0.15, 0.8, 0.75))
    axes.plot(np.linspace(*x_limits, 50), np.linspace(*y_limits, 50))
    axes.set_xlim(*x_limits)
    axes.set_ylim(*y_limits)
    axes.set_xlabel("time since the epoch (min)")
    axes.set_ylabel("body angular velocity (deg/s)")
    if fixed_y is not None:
        axes.yaxis.set_major_locator(matplotlib.ticker.FixedLocator(fixed_y))
    if ours:
        Ticks(axes, grid_alpha=0.3)
    else:
        axes.grid(alpha=0.3)
    return _pixels(figure)


@pytest.mark.parametrize(
    ("x_limits", "y_limits", "fixed_y"),
    [
        ((0.0, 60.0), (-3.0, 31.0), None),
        ((0.0, 60.0), (0.0, 180.0), np.arange(0, 181, 30)),  # the Sun-angle panels
        ((10_000.0, 10_000.001), (1e-6, 3e-6), None),  # an offset and an exponent
        ((-2.2, 2.2), (-1.8, 1.8), None),  # negative labels: the minus sign
        ((0.0, 1e7), (-1e5, 1e5), None),
    ],
)
def test_the_ticks_are_the_pixels_of_matplotlibs_own_axis(x_limits, y_limits, fixed_y):
    theirs = _axes_with_ticks(False, x_limits, y_limits, fixed_y)
    ours = _axes_with_ticks(True, x_limits, y_limits, fixed_y)
    assert np.array_equal(ours, theirs)


def _bands(ours: bool, x, series) -> tuple[np.ndarray, Figure]:
    figure = Figure(figsize=(6.0, 3.0), dpi=100)
    axes = figure.add_axes((0.1, 0.1, 0.8, 0.8))
    axes.set_axis_off()
    if ours:
        axes.add_artist(Bands(x, series, edges=False))
        axes.add_artist(Bands(x, series, edges=True))
    else:  # as the figures drew them: every band (zorder 1), then every edge (2)
        for low, high, color in series:
            axes.fill_between(x, low, high, color=color, alpha=BAND_ALPHA, linewidth=0)
        for low, high, color in series:
            axes.plot(x, low, color=color, linewidth=EDGE_WIDTH_PT)
            axes.plot(x, high, color=color, linewidth=EDGE_WIDTH_PT)
    axes.set_xlim(x[0], x[-1])
    axes.set_ylim(-2.0, 2.0)
    return _pixels(figure), figure


_X = np.linspace(0.0, 100.0, 900)  # 900 columns over the axes' 480 pixels
_NOISE = np.random.default_rng(1).random((2, _X.size))
_CASES = {
    "faster than a column": [
        (np.sin(3.1 * _X) - 0.5, np.sin(3.1 * _X) + 0.5, "C0"),
        (np.cos(2.3 * _X) - 0.3, np.cos(2.3 * _X) + 0.2, "C1"),
    ],
    "slow, and steady": [
        (np.sin(_X / 10.0) - 0.2, np.sin(_X / 10.0) + 0.2, "C0"),
        (np.full(_X.size, 0.5), np.full(_X.size, 0.5), "C2"),
    ],
    "noisy": [(-1.0 + 0.3 * _NOISE[0], 1.0 - 0.3 * _NOISE[1], "C1")],
    "with a gap (NaN)": [
        (np.where(np.abs(_X - 50.0) < 10.0, np.nan, np.sin(_X) - 0.5), np.sin(_X) + 0.5, "C0")
    ],
}


@pytest.mark.parametrize("case", list(_CASES))
def test_the_bands_are_the_picture_of_fill_between_and_plot(case):
    series = _CASES[case]
    theirs, _ = _bands(False, _X, series)
    ours, figure = _bands(True, _X, series)
    assert np.mean(np.abs(ours - theirs)) < 4.0  # of 255: measured 0.5 to 2.8
    # Each column's ink (its mean over the rows) within a tenth of the most a column
    # has, or one level of 255, but the two on the axes' sides, under a figure's spines
    # (where a line's end reaches half its width beyond them).
    axes_box = figure.axes[0].bbox
    inner = slice(int(np.floor(axes_box.x0)) + 1, int(np.ceil(axes_box.x1)) - 1)
    ink_theirs = 255.0 - theirs.mean(axis=(0, 2))[inner]
    ink_ours = 255.0 - ours.mean(axis=(0, 2))[inner]
    assert np.max(np.abs(ink_ours - ink_theirs)) < max(0.1 * np.max(ink_theirs), 1.0)
    # No extreme lost: in every pixel column of the axes, every row between the least
    # and the largest value of the vertices in it is painted.
    axes = figure.axes[0]
    columns = range(int(np.floor(axes_box.x0)), int(np.ceil(axes_box.x1)))
    painted = np.any(ours < 255, axis=2)  # rows from the top
    height = painted.shape[0]
    for low, high, _ in series:
        x = axes.transData.transform(np.column_stack([_X, np.zeros(_X.size)]))[:, 0]
        _, y_low = axes.transData.transform(np.column_stack([_X, low])).T
        _, y_high = axes.transData.transform(np.column_stack([_X, high])).T
        finite = np.isfinite(y_low) & np.isfinite(y_high)
        for column in np.intersect1d(np.floor(x[finite]).astype(int), columns):
            inside = finite & (np.floor(x).astype(int) == column)
            top = height - 1 - int(np.floor(np.max(y_high[inside])))
            bottom = height - 1 - int(np.floor(np.min(y_low[inside])))
            assert np.all(painted[top : bottom + 1, column]), (case, column)


def test_the_png_reads_back_as_the_canvas_with_its_resolution():
    figure = Figure(figsize=(3.0, 2.0), dpi=100)
    axes = figure.add_subplot()
    axes.plot([0, 1, 2], [2, 0, 1], color="C3")
    axes.fill_between([0, 1, 2], [0, 0.5, 0], [1, 1.5, 2], alpha=0.35)
    axes.set_title("read back")
    canvas = FigureCanvasAgg(figure)
    canvas.draw()
    rgb = np.asarray(canvas.buffer_rgba())[:, :, :3]
    image = Image.open(io.BytesIO(_png(rgb, 100)))
    image.load()  # every chunk's checksum and the deflate stream checked
    assert image.mode == "RGB" and image.size == (300, 200)
    assert np.array_equal(np.asarray(image), rgb)
    assert image.info["dpi"] == pytest.approx((100.0, 100.0), abs=0.01)


def test_an_axes_set_off_has_no_ticks():
    """The polhode of a body at rest sets its panel off: nothing of its axes is drawn."""
    pixels = []
    for ours in (False, True):
        figure = Figure(figsize=(3.0, 2.0), dpi=100)
        axes = figure.add_subplot()
        if ours:
            Ticks(axes, grid_alpha=0.3)
        axes.text(0.5, 0.5, "at rest", ha="center", va="center")
        axes.set_axis_off()
        pixels.append(_pixels(figure))
    assert np.array_equal(pixels[0], pixels[1])
