"""The figures' ticks, tick labels, grid lines and axis labels, drawn as a few artists.

matplotlib's own axis makes a tick object of five artists (two tick marks, a grid line,
two labels) for every tick of every new axes, each from the rcParams, and draws them
one by one: over half of the report's figures' drawing time.  :class:`Ticks` draws the
same things from the same sources when the figure is drawn (the axis' own locator and
formatter, at its final limits; matplotlib's sizes, pads and colours from the
rcParams): the grid lines of each axis as one line, its tick marks as one line of
markers, a text for each tick label, and the axis' own label and offset text placed
as matplotlib places them (beyond the tick labels' extent by the label pad).

Only what the figures use: linear axes, major ticks at the bottom and on the left,
pointing out.  Imported only by a figure's drawing: it imports matplotlib.
"""

from __future__ import annotations

from typing import Any, cast

import matplotlib as mpl
import numpy as np
from matplotlib import transforms
from matplotlib.artist import Artist
from matplotlib.lines import Line2D
from matplotlib.markers import TICKDOWN, TICKLEFT, MarkerStyle
from matplotlib.text import Text

__all__ = ["Ticks"]

# An axis' offset text, this far (points) beyond its tick labels: matplotlib's
# Axis.OFFSETTEXTPAD.
_OFFSET_PAD_PT = 3.0


class Ticks(Artist):
    """The ticks, tick labels, grid lines (at ``grid_alpha``), axis labels and offset
    texts of ``axes``, whose own x and y axes it hides (their labels' texts, fonts and
    positions along the axis stay theirs: ``set_xlabel`` works as ever).  Drawn where
    matplotlib draws an axis: above filled areas, below lines (zorder 1.5)."""

    def __init__(self, axes, grid_alpha: float) -> None:
        super().__init__()
        self.set_zorder(1.5)
        self._grid_alpha = grid_alpha
        axes.xaxis.set_visible(False)
        axes.yaxis.set_visible(False)
        axes.add_artist(self)

    def draw(self, renderer) -> None:
        axes: Any = self.axes
        if not self.get_visible() or axes is None or not axes.axison:  # set_axis_off
            return
        dpi = axes.get_figure(root=True).dpi
        for axis, name in ((axes.xaxis, "x"), (axes.yaxis, "y")):
            labels = self._draw_axis(renderer, axis, name)
            extents = [text.get_window_extent(renderer) for text in labels]
            spine = axes.spines["bottom" if name == "x" else "left"].get_window_extent(renderer)
            around = transforms.Bbox.union([*extents, spine])
            pad = axis.labelpad * dpi / 72.0
            label, offset = axis.label, axis.offsetText
            if name == "x":
                label.set_position((label.get_position()[0], around.y0 - pad))
                below = transforms.Bbox.union(extents).y0 if extents else axes.bbox.ymin
                offset.set_position((offset.get_position()[0], below - _OFFSET_PAD_PT * dpi / 72))
            else:
                label.set_position((around.x0 - pad, label.get_position()[1]))
                offset.set_position(
                    (offset.get_position()[0], axes.bbox.ymax + _OFFSET_PAD_PT * dpi / 72)
                )
            offset.set_text(axis.get_major_formatter().get_offset())
            label.draw(renderer)
            offset.draw(renderer)

    def _draw_axis(self, renderer, axis, name: str) -> list[Text]:
        """The grid lines, tick marks and tick labels of one axis; its labels."""
        axes: Any = self.axes
        rc = cast(dict[str, Any], mpl.rcParams)
        locations = np.asarray(axis.get_major_locator()(), dtype=np.float64)
        texts = axis.get_major_formatter().format_ticks(locations)  # sets its offset
        low, high = sorted(axis.get_view_interval())
        slack = 1e-10 * (high - low)  # matplotlib's: a tick on a limit is drawn
        shown = (locations >= low - slack) & (locations <= high + slack)
        locations = locations[shown]
        texts = [text for text, keep in zip(texts, shown, strict=True) if keep]
        if locations.size == 0:
            return []
        along = np.repeat(locations, 3)
        along[2::3] = np.nan  # one line, broken between the grid lines
        across = np.tile([0.0, 1.0, np.nan], locations.size)
        size, width = rc[f"{name}tick.major.size"], rc[f"{name}tick.major.width"]
        color = rc[f"{name}tick.color"]
        label_color = rc[f"{name}tick.labelcolor"]
        label_color = color if label_color == "inherit" else label_color
        pad = rc[f"{name}tick.major.pad"] + size  # pointing out: the label beyond it
        if name == "x":
            grid = Line2D(along, across, transform=axes.get_xaxis_transform("grid"))
            marks = Line2D(locations, np.zeros_like(locations), marker=MarkerStyle(TICKDOWN))
            marks.set_transform(axes.get_xaxis_transform("tick1"))
            place, va, ha = axes.get_xaxis_text1_transform(pad)
            at = [(x, 0.0) for x in locations]
        else:
            grid = Line2D(across, along, transform=axes.get_yaxis_transform("grid"))
            marks = Line2D(np.zeros_like(locations), locations, marker=MarkerStyle(TICKLEFT))
            marks.set_transform(axes.get_yaxis_transform("tick1"))
            place, va, ha = axes.get_yaxis_text1_transform(pad)
            at = [(0.0, y) for y in locations]
        grid.set(
            color=rc["grid.color"],
            linestyle=rc["grid.linestyle"],
            linewidth=rc["grid.linewidth"],
            alpha=self._grid_alpha,
        )
        marks.set(
            linestyle="none",
            color=color,
            markeredgecolor=color,
            markersize=size,
            markeredgewidth=width,
            clip_on=False,
        )
        labels = [
            Text(
                x,
                y,
                text,
                transform=place,
                verticalalignment=va,
                horizontalalignment=ha,
                fontsize=rc[f"{name}tick.labelsize"],
                color=label_color,
                clip_on=False,
            )
            for (x, y), text in zip(at, texts, strict=True)
        ]
        figure = axes.get_figure(root=False)
        grid.set_clip_path(axes.patch)
        for artist in (grid, marks, *labels):
            artist.set_figure(figure)
            artist.draw(renderer)
        return labels
