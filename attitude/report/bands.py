"""The figures' bands (``attitude.report.plots``), rasterised per pixel column.

A band shows a series' range in each pixel column of the time axis: the area between
the polyline of the columns' minima and that of their maxima, with the two polylines
drawn as its edges.  Agg fills such an area as a polygon whose edges cross every pixel
row between one column's value and the next, and strokes the edges the same way: for
a motion faster than a column (a nutation, a spin over an hour) that is thousands of
rows a column, and the Sun-angle figure spent three quarters of its drawing there.

Cut along a vertical line, the area and each edge are an interval: the area between
its two polylines, an edge (a stroke of width w) the extent of its polyline within
w/2 of the line, widened by w/2.  :class:`Bands` cuts each pixel column at
:data:`SAMPLES` such lines, counts the fraction of each pixel inside those intervals
(exact in y, sampled in x: what Agg's antialiasing computes exactly), and composites
the layers into one image of the panel's pixels when the figure is drawn, once its
limits are known: a histogram and a cumulative sum per layer, whatever the motion.

Imported only by a figure's drawing: it imports matplotlib.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from matplotlib.artist import Artist
from matplotlib.colors import to_rgb
from numpy.typing import NDArray

__all__ = ["BAND_ALPHA", "EDGE_WIDTH_PT", "SAMPLES", "Bands", "extent_near"]

# A band's opacity, and its edges' width (points).
BAND_ALPHA = 0.35
EDGE_WIDTH_PT = 0.6
# Vertical cuts per pixel column: the antialiasing's steps in x (a quarter pixel).
SAMPLES = 4
# Below this share of a layer's (or the image's) pixels, they are painted one by one.
_FEW = 0.2


def extent_near(
    x: NDArray[np.float64], y: NDArray[np.float64], at: NDArray[np.float64], reach: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The least and the largest y of the polyline through (x, y) (x increasing) over
    [at - reach, at + reach] for each of ``at`` (increasing): its height at the two
    ends and its vertices between them; NaN where the window misses the polyline."""
    ends = (np.clip(at - reach, x[0], x[-1]), np.clip(at + reach, x[0], x[-1]))
    low = np.minimum(np.interp(ends[0], x, y), np.interp(ends[1], x, y))
    high = np.maximum(np.interp(ends[0], x, y), np.interp(ends[1], x, y))
    first = np.searchsorted(x, at - reach, side="left")
    stop = np.searchsorted(x, at + reach, side="right")
    for k in range(int(np.max(stop - first, initial=0))):  # a vertex or two a window
        inside = first + k < stop
        index = np.minimum(first + k, x.size - 1)
        low = np.where(inside, np.minimum(low, y[index]), low)
        high = np.where(inside, np.maximum(high, y[index]), high)
    missed = (at + reach < x[0]) | (at - reach > x[-1])
    low[missed] = np.nan
    high[missed] = np.nan
    return low, high


def _pixels_along(to_pixels, values: NDArray[np.float64], axis: int) -> NDArray[np.float64]:
    """Display pixels of ``values`` along one axis of a rectilinear axes' transform: the
    other coordinate held at 0, so that a NaN value (a gap in a series) stays its own,
    and does not make its time NaN as well (0 × NaN, in the affine transform)."""
    points = np.zeros((np.size(values), 2))
    points[:, axis] = values
    return to_pixels.transform(points)[:, axis]


class _Layers:
    """The premultiplied image that the layers are painted into, and the buffers each
    layer's coverage is counted in: allocated once per image (fresh pages cost more
    here than the arithmetic on them)."""

    def __init__(self, height: int, width: int) -> None:
        self.height, self.width = height, width
        # Red, green, blue and alpha, premultiplied, a plane each (whole rows: fast).
        self.planes = np.zeros((4, height, width), dtype=np.float32)
        self._steps = np.zeros((height + 1) * width, dtype=np.float32)
        self._parts = np.zeros((height + 1) * width, dtype=np.float32)
        self._below = np.empty((height + 1, width), dtype=np.float32)
        self._weight = np.empty((height, width), dtype=np.float32)
        self._change = np.empty((height, width), dtype=np.float32)
        self._column = np.tile(np.repeat(np.arange(width), SAMPLES), 2)  # cut i: i // SAMPLES

    def paint(self, a: NDArray[np.float64], b: NDArray[np.float64], opacity: float, rgba) -> None:
        """Paint ``rgba`` at ``opacity`` over the image, each pixel by the mean over its
        column's :data:`SAMPLES` cuts of the fraction of it ([r, r + 1) of its row r)
        inside the cut's [a, b); ``a``, ``b``: (width × SAMPLES,), in pixel rows from
        the bottom, NaN or a ≥ b for nothing.

        The fraction of [r, r + 1) below y is 1 under floor(y), frac(y) at floor(y), 0
        above; summed over the cuts it is the count of cuts with floor(y) above r, plus
        their fractions at r: one histogram of floor(b) less one of floor(a), summed
        down from the top, over the rows that some cut reaches only."""
        height, width = self.height, self.width
        full = a < b
        if not np.any(full):
            return
        ends = np.concatenate([np.where(full, np.clip(y, 0.0, height), 0.0) for y in (b, a)])
        row = np.floor(ends).astype(np.intp)
        first = int(np.min(row[a.size :][full]))
        stop = min(int(np.max(row[: a.size][full])) + 1, height)
        if stop <= first:
            return
        rows = stop - first
        if self._paint_few(a, b, full, opacity, rgba, rows):
            return
        row = np.where(np.concatenate([full, full]), row - first, rows)  # nothing: off the top
        where = row * width + self._column
        sign = np.repeat(np.array([1.0, -1.0], dtype=np.float32), a.size)
        size = (rows + 1) * width
        steps, parts = self._steps[:size], self._parts[:size]
        steps[:] = 0.0
        parts[:] = 0.0
        np.add.at(steps, where, sign)
        np.add.at(parts, where, sign * (ends - np.floor(ends)).astype(np.float32))
        below = self._below[: rows + 1]
        np.cumsum(steps.reshape(rows + 1, width), axis=0, out=below)  # floor(y) at r or lower
        weight = self._weight[:rows]
        np.subtract(below[rows], below[:rows], out=weight)  # ... above r
        weight += parts.reshape(rows + 1, width)[:rows]
        weight *= np.float32(opacity / SAMPLES)
        change = self._change[:rows]
        for plane, value in zip(self.planes[:, first:stop], rgba, strict=True):
            np.subtract(plane, np.float32(value), out=change)  # over: + weight (value - plane)
            change *= weight
            plane -= change

    def _paint_few(self, a, b, full, opacity: float, rgba, rows: int) -> bool:
        """:meth:`paint` pixel by pixel, when the cuts reach few of the rows' pixels (an
        edge of a slow series: two or three a column, not the whole panel); False,
        painting nothing, when they reach many."""
        height, width = self.height, self.width
        a = np.where(full, np.clip(a, 0.0, height), np.inf).reshape(width, SAMPLES)
        b = np.where(full, np.clip(b, 0.0, height), -np.inf).reshape(width, SAMPLES)
        reached = np.any(np.isfinite(a), axis=1)
        lowest = np.floor(np.min(a, axis=1, where=np.isfinite(a), initial=height))
        highest = np.floor(np.max(b, axis=1, where=np.isfinite(b), initial=0.0))
        counts = np.where(reached, np.minimum(highest, height - 1) - lowest + 1, 0)
        counts = np.maximum(counts, 0).astype(np.intp)
        total = int(counts.sum())
        if total > _FEW * rows * width:
            return False
        column = np.repeat(np.arange(width), counts)
        start = np.cumsum(counts) - counts
        row = lowest[column] + (np.arange(total) - start[column])
        weight = np.zeros(total)
        for k in range(SAMPLES):
            top, bottom = b[column, k], a[column, k]
            weight += np.clip(np.minimum(top, row + 1.0) - np.maximum(bottom, row), 0.0, 1.0)
        weight *= opacity / SAMPLES
        where = row.astype(np.intp) * width + column
        for plane, value in zip(self.planes.reshape(4, -1), rgba, strict=True):
            pixel = plane[where]
            pixel -= weight * (pixel - value)
            plane[where] = pixel
        return True

    def pixels(self) -> NDArray[np.uint8]:
        """The image as straight RGBA bytes, the first row the lowest."""
        pixels = np.zeros((self.height, self.width, 4), dtype=np.uint8)
        alpha = self.planes[3].ravel()
        painted = np.flatnonzero(alpha > 0.0)
        if painted.size < _FEW * alpha.size:  # a few edges: those pixels only
            flat = pixels.reshape(-1, 4)
            to_straight = 255.0 / alpha[painted]
            for k in range(3):
                flat[painted, k] = np.clip(
                    self.planes[k].ravel()[painted] * to_straight + 0.5, 0, 255
                )
            flat[painted, 3] = alpha[painted] * 255.0 + 0.5
            return pixels
        alpha = self.planes[3]
        to_straight = 255.0 / np.maximum(alpha, np.float32(1e-12))
        for k in range(3):
            value = self.planes[k] * to_straight
            value += 0.5
            np.clip(value, 0.0, 255.0, out=value)
            pixels[:, :, k] = value
        pixels[:, :, 3] = alpha * 255.0 + 0.5
        return pixels


class Bands(Artist):
    """Bands, or their edges: ``series`` of (low, high, colour) at the times ``x`` (data
    coordinates), each series' band (at :data:`BAND_ALPHA`) or, with ``edges``, its
    lower and its upper edge (:data:`EDGE_WIDTH_PT` wide), painted in that order.
    Where matplotlib draws the same things: the bands below the grid lines (zorder 1,
    a filled area's), the edges above them (zorder 2, a line's), so that every
    series' edges lie over every band."""

    def __init__(self, x: NDArray[np.float64], series: Sequence[tuple], edges: bool) -> None:
        super().__init__()
        self._x = np.asarray(x, dtype=np.float64)
        self._series = list(series)
        self._edges = edges
        self.set_zorder(2 if edges else 1)

    def draw(self, renderer) -> None:
        axes: Any = self.axes
        if not self.get_visible() or self._x.size == 0 or axes is None:
            return
        box = axes.bbox
        left, bottom = math.floor(box.x0), math.floor(box.y0)
        width, height = math.ceil(box.x1) - left, math.ceil(box.y1) - bottom
        if width <= 0 or height <= 0:
            return
        image = self._image(renderer, left, bottom, width, height)
        gc = renderer.new_gc()
        gc.set_clip_rectangle(box)  # the axes'
        renderer.draw_image(gc, left, bottom, image)  # its rows from the bottom up
        gc.restore()

    def _image(self, renderer, left: int, bottom: int, width: int, height: int):
        """The bands (or edges) as straight RGBA bytes, the first row the lowest."""
        half = 0.5 * renderer.points_to_pixels(EDGE_WIDTH_PT)
        cuts = left + (np.arange(width * SAMPLES) + 0.5) / SAMPLES  # display x
        layers = _Layers(height, width)
        axes: Any = self.axes
        to_pixels = axes.transData
        for low, high, color in self._series:
            x = _pixels_along(to_pixels, self._x, 0)
            y_low, y_high = (_pixels_along(to_pixels, y, 1) for y in (low, high))
            y_low, y_high = y_low - bottom, y_high - bottom
            rgba = (*to_rgb(color), 1.0)
            if not self._edges:
                on = (cuts >= x[0]) & (cuts <= x[-1])
                a = np.where(on, np.interp(cuts, x, y_low), np.nan)
                b = np.where(on, np.interp(cuts, x, y_high), np.nan)
                layers.paint(a, b, BAND_ALPHA, rgba)
                continue
            for y in (y_low, y_high):
                least, most = extent_near(x, y, cuts, half)
                layers.paint(least - half, most + half, 1.0, rgba)
        return layers.pixels()
