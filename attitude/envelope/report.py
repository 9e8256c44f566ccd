"""The envelope's outputs: the table per failure (``envelope.parquet``,
``envelope.csv``), the metrics plotted against the failure time (``envelope.png``),
``summary.json`` (the worst τ and its margins) and ``report.html``.

Times after the loss are seconds; ``inf`` in the table (``null`` in summary.json) means
"not within the window".  The folder is claimed as ``attitude run``'s is
(:func:`attitude.outputs.folder.claim`): a file this tool did not write is never
replaced, and a run stopped midway leaves the folder as it was.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from html import escape
from pathlib import Path
from typing import Any

import numpy as np

from attitude.base.version import __version__
from attitude.envelope.engine import EnvelopeResult
from attitude.envelope.plan import EnvelopePlan
from attitude.outputs.budget import (
    JobFolderSize,
    about_text,
    check_table_fits,
    table_size_text,
)
from attitude.outputs.folder import claim
from attitude.report.page import _STYLE, _figures_and_files, _table
from attitude.report.summaries import to_json, write_json

__all__ = ["FOLDER_SIZE", "OUTPUT_NAMES", "check_folder", "summary", "worst", "write_report"]

OUTPUT_NAMES = ("envelope.parquet", "envelope.csv", "summary.json", "envelope.png", "report.html")


# What the folder takes beside the table's cells (measured on these writers:
# tests/test_job_size_estimate_against_the_writers.py): a column's Parquet metadata
# and its entries in summary.json (700 bytes); the page, summary.json's frame, the
# manifest and the figure of a few failure times (120 kB), which grows with them
# (88 kB for 3, 150 kB for 56, 267 kB for 300, 359 to 369 kB for 1000 to 3000, then
# less as its lines fill it: 163 kB for 20 000).
FOLDER_SIZE = JobFolderSize(
    cell=16,
    per_column=700,
    fixed=120_000,
    checkpoint_cell=4,
    figure_per_row=1_000,
    figure_growth_at_most=300_000,
)


def check_folder(plan: EnvelopePlan, out_dir: str | Path) -> None:
    """Refuse, before anything runs, a folder that is not ours or a disk too small."""
    claim(out_dir, OUTPUT_NAMES, dry_run=True)
    check_table_fits(out_dir, plan.count, len(plan.columns), "failures", FOLDER_SIZE)


def worst(table) -> int | None:
    """The row of the worst failure: the soonest blinded (``first_violation_s``), then
    the soonest without power, then the fastest turning; None if every failure failed."""
    ok = table[table["status"] == "ok"]
    if ok.empty:
        return None
    keys = ["first_violation_s"]
    if "power_lost_s" in ok:
        keys.append("power_lost_s")
    ordered = ok.assign(_rate=-ok["rate_max_deg_s"]).sort_values([*keys, "_rate", "tau_s"])
    return int(ordered.index[0])


# Per metric, whether its worst value is its least (times, power) or its greatest
# (rates, flips, and a panel's least Sun angle: 0 is the panel square to the Sun, its
# best; the worst failure leaves the Sun furthest from it).
def _least_is_worst(name: str) -> bool:
    if name.endswith("_least_sun_angle_deg"):
        return False
    return not (name.startswith("rate_") or name == "flips" or name.endswith("_at_s"))


def _worst_of(name: str, tau: np.ndarray, values: np.ndarray) -> dict[str, float | None]:
    """The worst τ of one metric and its value, the earliest of ties; none (null) where
    the metric has a value at no τ (a time not within the window, ``inf``, at every τ:
    no failure time is worse than another)."""
    known = np.isfinite(values)
    if not known.any():
        return {"tau_s": None, "value": None}
    candidates = np.where(known, values, np.inf if _least_is_worst(name) else -np.inf)
    k = int(np.argmin(candidates) if _least_is_worst(name) else np.argmax(candidates))
    return {"tau_s": float(tau[k]), "value": float(values[k])}


def summary(result: EnvelopeResult) -> dict[str, Any]:
    """What summary.json says: the job, the worst τ and its margins, each metric's worst."""
    plan, table = result.plan, result.table
    ok = table[table["status"] == "ok"]
    row = worst(table)
    per_metric = {}
    tau = ok["tau_s"].to_numpy(dtype=float)
    for name in plan.metrics:
        if name in ("rate_max_at_s",) or ok.empty:
            continue
        per_metric[name] = _worst_of(name, tau, ok[name].to_numpy(dtype=float))
    settings = plan.settings
    return to_json(
        {
            "scenario": {"name": plan.name, "file": plan.file},
            "attitude_version": __version__,
            "failures": plan.count,
            "failed": int((table["status"] != "ok").sum()),
            "every_s": settings.every,
            "window_s": settings.window,
            "wheels": {"case": plan.wheels.case, "momentum_Nms": plan.wheels.momentum_vector},
            "power_threshold": settings.power_threshold,
            "units": "times in s after the loss (null: not within the window), angles deg, "
            "rates deg/s, power as a fraction of full (every panel square to the Sun, lit)",
            "worst": None
            if row is None
            else {
                "tau_s": float(table.loc[row, "tau_s"]),
                "epoch_utc": str(table.loc[row, "epoch_utc"]),
                "mode": str(table.loc[row, "mode"]),
                "margins": {name: _plain(table.loc[row, name]) for name in plan.metrics},
            },
            "worst_per_metric": per_metric,
            "execution": result.execution,
        }
    )


def _plain(value: Any) -> Any:
    if isinstance(value, np.generic):
        value = value.item()
    return value


def write_report(
    result: EnvelopeResult, out_dir: str | Path, stage: Callable[[str], None] | None = None
) -> list[str]:
    """Write the outputs of ``result`` into ``out_dir`` (module notes); ``stage(text)``
    is told each step as it starts (a year of failure times is a table of hundreds of
    thousands of rows: its CSV and its figure take a while)."""
    folder = claim(out_dir, OUTPUT_NAMES)
    say = stage or (lambda text: None)
    return folder.write(
        lambda tmp: _build(result, tmp, say), result.plan.file or "python", __version__
    )


def _build(result: EnvelopeResult, tmp: Path, stage: Callable[[str], None]) -> list[str]:
    table = result.table
    stage(f"writing envelope.parquet and envelope.csv ({table_size_text(table)})")
    table.to_parquet(tmp / "envelope.parquet", index=False)
    table.to_csv(tmp / "envelope.csv", index=False)
    stage("the worst failure times (summary.json)")
    stats = summary(result)
    write_json(tmp / "summary.json", stats)
    files = ["envelope.parquet", "envelope.csv", "summary.json"]
    images = {}
    if (table["status"] == "ok").any():
        drawing = _FIGURE_S + _FIGURE_S_PER_FAILURE * len(table)
        stage(
            "drawing the metrics against the failure time "
            f"({len(table):,} failure times{about_text(drawing)})"
        )
        images["The metrics against the failure time"] = _plot(result, tmp / "envelope.png")
    stage("writing report.html")
    (tmp / "report.html").write_text(_page(result, stats, images, files), encoding="utf-8")
    return [*files, *images.values(), "report.html"]


# The figure's CPU time: 1 s, and 24 µs a failure time (5.7 s for 200 000 on the
# development machine, idle).
_FIGURE_S = 1.0
_FIGURE_S_PER_FAILURE = 24e-6


def _groups(plan: EnvelopePlan) -> list[tuple[str, list[str]]]:
    """The panels of the figure: metrics of one unit together."""
    metrics = plan.metrics
    times = [m for m in metrics if m.endswith("_s") and not m.startswith("rate_")]
    pairs: list[tuple[str, list[str]]] = [
        ("time to first violation, power loss, flip (s after the loss)", times),
        ("least Sun angle of each panel (deg)", [m for m in metrics if m.endswith("_deg")]),
        (
            "panels' power fraction",
            [m for m in ("power_at_loss", "power_mean") if m in metrics],
        ),
        ("body rate (deg/s)", ["rate_at_loss_deg_s", "rate_max_deg_s"]),
        ("flips within the window", ["flips"]),
    ]
    return [(name, chosen) for name, chosen in pairs if chosen]


def _plot(result: EnvelopeResult, path: Path) -> str:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    plan, table = result.plan, result.table
    ok = table[table["status"] == "ok"]
    hours = ok["tau_s"].to_numpy(dtype=float) / 3600.0
    groups = _groups(plan)
    figure = Figure(figsize=(10, 2.6 * len(groups)), layout="constrained")
    FigureCanvasAgg(figure)
    axes = figure.subplots(len(groups), 1, sharex=True, squeeze=False)[:, 0]
    window = plan.settings.window
    for ax, (title, names) in zip(axes, groups, strict=True):
        for name in names:
            values = ok[name].to_numpy(dtype=float)
            if name.endswith("_s"):  # none within the window: drawn at the window's end
                values = np.where(np.isfinite(values), values, window)
            ax.plot(hours, values, ".-", markersize=2, linewidth=0.8, label=name)
        ax.set_title(title, fontsize=9)
        # Beside the panel: never over the points, and no search for the emptiest
        # corner ("best" counts every point of every line: 9 s of a 200 000-point plot).
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel(f"failure time τ (h after {plan.scenario.format_epoch(0.0)})")
    figure.savefig(path, dpi=90)
    return path.name


def _cell(value: Any) -> str:
    if isinstance(value, float):
        return "—" if not math.isfinite(value) else f"{value:.6g}"
    return str(value) if value is not None else "— (none within the window)"


def _page(result: EnvelopeResult, stats: dict[str, Any], images, files) -> str:
    plan = result.plan
    title = f"Loss-of-control envelope: {plan.name}"
    parts = [
        "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>",
        f"<title>{escape(title)}</title><style>{_STYLE}</style></head><body>",
        f"<h1>{escape(title)}</h1>",
        f"<p class='note'>{escape(plan.file or 'a scenario built in Python')}, computed by "
        f"attitude {escape(__version__)}: the exact motion after each loss, searched exactly "
        "(docs/envelope.md).</p>",
        "<p>" + "<br>".join(escape(line) for line in plan.describe()) + "</p>",
    ]
    worst_row = stats["worst"]
    if worst_row is not None:
        parts.append(
            f"<h2>The worst failure time: {escape(worst_row['epoch_utc'])} "
            f"(τ = {worst_row['tau_s']:g} s, {escape(worst_row['mode'])})</h2>"
        )
        parts.append(
            _table(
                ["metric", "value"],
                [[name, _cell(value)] for name, value in worst_row["margins"].items()],
            )
        )
    parts.append("<h2>Each metric's worst failure time</h2>")
    parts.append(
        _table(
            ["metric", "τ (s)", "value"],
            [
                [
                    name,
                    "—" if entry["tau_s"] is None else f"{entry['tau_s']:g}",
                    _cell(entry["value"]),
                ]
                for name, entry in stats["worst_per_metric"].items()
            ],
        )
    )
    if stats["failed"]:
        first = result.table[result.table["status"] != "ok"].iloc[0]
        parts.append(
            f"<p class='note'>{stats['failed']} failures could not be computed; the first "
            f"(τ = {first['tau_s']:g} s): {escape(str(first['error']))}</p>"
        )
    parts += _figures_and_files(images, files)
    execution = result.execution
    parts.append(
        f"<p class='note'>{escape(str(execution['scheduler']))}: "
        f"{execution['compute_s']:.3g} s of CPU on the workers, {execution['wall_s']:.3g} s "
        "of wall time.</p>"
    )
    parts.append("</body></html>\n")
    return "\n".join(parts)
