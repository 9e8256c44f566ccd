"""The report of a Monte Carlo job: the table, its statistics, plots and a page.

``write_montecarlo_report(result, out_dir)`` writes, through the output folder's rules
(``attitude.outputs.folder``: only files attitude wrote are ever replaced, nothing of a
failed or interrupted write is left):

- ``samples.parquet`` and ``samples.csv``: one row per sample, the drawn parameters and
  the metrics (``docs/montecarlo.md`` lists the columns);
- ``statistics.json``: per metric and parameter, the mean, standard deviation,
  percentiles and the one-sided 99 % bounds with their confidence
  (``attitude.montecarlo.statistics``); the nominal run's metrics; the failed samples
  with their parameters and errors; how the job ran;
- ``sun_angle_envelopes.csv`` and ``.png``: per time bin, percentiles over the samples
  of each body vector's smallest and largest Sun angle in the bin;
- ``histograms.png``, and ``report.html``, a page in the style of ``attitude run``'s.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from html import escape
from pathlib import Path
from typing import Any

import numpy as np

from attitude.base.version import __version__
from attitude.montecarlo.metrics import ANGLE_STEP_DEG, TIME_BINS
from attitude.montecarlo.plan import MonteCarloPlan
from attitude.montecarlo.simulation import MonteCarloResult
from attitude.montecarlo.statistics import (
    CONFIDENCE,
    COVERAGE,
    PERCENTILES,
    describe,
)
from attitude.outputs.budget import JobFolderSize, check_table_fits, table_size_text
from attitude.outputs.folder import claim
from attitude.pointing.spec import interval_precision
from attitude.report.page import (  # the page of attitude run, its look
    _STYLE,
    _figures_and_files,
    _table,
)
from attitude.report.summaries import write_json

__all__ = [
    "OUTPUT_NAMES",
    "check_folder",
    "drawn_spread",
    "folder_size",
    "stated_precision",
    "statistics",
    "write_montecarlo_report",
]

OUTPUT_NAMES = (
    "samples.parquet",
    "samples.csv",
    "statistics.json",
    "sun_angle_envelopes.csv",
    "sun_angle_envelopes.png",
    "histograms.png",
    "report.html",
)
_MAX_LISTED_FAILURES = 100
_MAX_HISTOGRAMS = 16


def folder_size(mc: MonteCarloPlan) -> JobFolderSize:
    """What the folder takes beside the table's cells (measured on these writers:
    tests/test_job_size_estimate_against_the_writers.py): a column's Parquet metadata
    (800 bytes), statistics.json entry (1 kB) and line of the page (250 bytes); the
    histograms (at most 200 kB), the Sun-angle envelopes (45 kB of figure a vector,
    and 110 bytes a vector in each time bin's row of the CSV), the page's frame and
    the manifest (25 kB); in the checkpoint, a sample's extremes (2 bytes for each
    vector's two extremes in each time bin)."""
    bins = min(TIME_BINS, mc.plan.scenario.output_count())
    vectors = len(mc.vectors)
    return JobFolderSize(
        cell=30,
        per_column=2_050,
        fixed=200_000 + vectors * (45_000 + 110 * bins) + 20 * bins + 25_000,
        checkpoint_cell=9,
        checkpoint_row=4 * vectors * bins,
    )


def check_folder(mc: MonteCarloPlan, out_dir: str | Path) -> None:
    """Refuse, before anything runs, a folder that is not ours or a disk too small for
    the table (CSV and Parquet), the plots and the job's checkpoint."""
    claim(out_dir, OUTPUT_NAMES, dry_run=True)
    check_table_fits(
        out_dir,
        mc.samples,
        len(mc.columns),
        "samples",
        folder_size(mc),
        ": run fewer samples or use another disk",
    )


def _numeric(table, names: list[str]) -> list[str]:
    return [n for n in names if table[n].dtype.kind in "fiu"]


def statistics(result: MonteCarloResult) -> dict[str, Any]:
    """The content of statistics.json."""
    mc, table = result.plan, result.table
    ok = table[table["status"] == "ok"]
    scenario = mc.plan.scenario
    return {
        "attitude_version": __version__,
        "scenario": {
            "name": scenario.name,
            "file": mc.loaded.path.name,
            "epoch": scenario.format_epoch(0.0),
            "duration_s": scenario.stop_s,
            "output_step_s": scenario.step_s,
        },
        "dispersions": {
            "seed": mc.dispersions.seed,
            "samples": mc.samples,
            "dispersed": mc.dispersions.describe(),
        },
        "samples": {"total": len(table), "ok": len(ok), "failed": len(table) - len(ok)},
        "method": _method(),
        "nominal": result.nominal,
        "metrics": {n: describe(ok[n].to_numpy(float)) for n in _numeric(table, mc.metrics)},
        "categories": _categories(mc, table, ok),
        "parameters": {
            n: describe(table[n].to_numpy(float)) for n in _numeric(table, mc.parameters)
        },
        "failures": _failures(result),
        "envelopes": _envelopes_method(mc),
        "execution": result.execution,
    }


def _method() -> dict[str, str]:
    """How the statistics are computed, in words (statistics.json's ``method``)."""
    return {
        "percentiles": f"{list(PERCENTILES)}: numpy.percentile, linear interpolation",
        "std": "sample standard deviation (ddof = 1)",
        "bounds": (
            f"one-sided, distribution-free: the r-th largest (smallest) of n samples bounds "
            f"the {COVERAGE:g} ({1 - COVERAGE:.2g}) quantile from above (below) with "
            f"confidence P(Binomial(n, {1 - COVERAGE:.2g}) >= r); r is the largest with "
            f"confidence >= {CONFIDENCE:g} (Wilks 1941, doi:10.1214/aoms/1177731788)"
        ),
        "over": "the samples that ran, and the finite values of each column (n)",
        "metrics": (
            "each sample's numbers as summary.json of attitude run reports them: the "
            "pointing's extrema and intervals found on the sample's exact motion "
            "(attitude.pointing.search.pointing_analysis), the largest rate on the output grid"
        ),
    }


def _categories(mc: MonteCarloPlan, table, ok) -> dict[str, dict[str, int]]:
    """Per non-numeric metric (the kind of motion), how many samples that ran had each value."""
    return {
        name: {str(k): int(v) for k, v in ok[name].value_counts().sort_index().items()}
        for name in mc.metrics
        if table[name].dtype.kind not in "fiu"
    }


def _failures(result: MonteCarloResult) -> list[dict[str, Any]]:
    """The first failed samples, each with its error and the parameters it drew."""
    failures = []
    for _, row in result.failed.head(_MAX_LISTED_FAILURES).iterrows():
        failures.append(
            {
                "sample": int(row["sample"]),
                "error": row["error"],
                "parameters": {n: row[n] for n in result.plan.parameters if not _missing(row[n])},
            }
        )
    return failures


def _envelopes_method(mc: MonteCarloPlan) -> dict[str, str] | None:
    """Where the Sun angle envelopes are and how they are made (None without body vectors)."""
    if not mc.vectors:
        return None
    return {
        "file": "sun_angle_envelopes.csv",
        "method": (
            "each sample's Sun angle on the output grid is reduced, on the workers, to "
            "its smallest and largest value in each time bin, rounded to "
            f"{ANGLE_STEP_DEG} deg; the percentiles over the samples come from the "
            "histograms of these values (numpy's inverted_cdf on the rounded values)"
        ),
    }


def _missing(value: Any) -> bool:
    return value is None or (isinstance(value, float) and math.isnan(value))


def _envelope_columns(result: MonteCarloResult) -> dict[str, np.ndarray]:
    envelope = result.envelope
    values = envelope.percentiles_deg(PERCENTILES)  # (p, vectors, 2, bins)
    columns = {"t_start_s": envelope.bin_start_s, "t_end_s": envelope.bin_end_s}
    for v, name in enumerate(envelope.vectors):
        for e, extreme in enumerate(("min", "max")):
            for i, p in enumerate(PERCENTILES):
                columns[f"{name}_{extreme}_p{p}_deg"] = values[i, v, e]
    return columns


def write_montecarlo_report(
    result: MonteCarloResult, out_dir: str | Path, stage: Callable[[str], None] | None = None
) -> list[str]:
    """Write the report of ``result`` into ``out_dir`` (see the module docstring);
    ``stage(text)`` is told each step as it starts."""
    folder = claim(out_dir, OUTPUT_NAMES)

    def build(tmp: Path) -> list[str]:
        return _build(result, tmp, stage or (lambda text: None))

    return folder.write(build, result.plan.loaded.path.name, __version__)


def _build(result: MonteCarloResult, tmp: Path, stage: Callable[[str], None]) -> list[str]:
    import pandas

    mc, table = result.plan, result.table
    stage(f"writing samples.parquet and samples.csv ({table_size_text(table)})")
    table.to_parquet(tmp / "samples.parquet", index=False)
    table.to_csv(tmp / "samples.csv", index=False)
    files = ["samples.parquet", "samples.csv"]
    stage("the statistics of every metric and parameter (statistics.json)")
    stats = statistics(result)
    write_json(tmp / "statistics.json", stats)
    files.append("statistics.json")
    images = {}
    if mc.vectors and (table["status"] == "ok").any():
        stage("drawing the Sun-angle envelopes")
        envelope = pandas.DataFrame(_envelope_columns(result))
        envelope.to_csv(tmp / "sun_angle_envelopes.csv", index_label="bin")
        files.append("sun_angle_envelopes.csv")
        images["Sun angle envelopes over the samples"] = _plot_envelopes(
            result, tmp / "sun_angle_envelopes.png"
        )
    chosen = _histogram_columns(mc, table)
    if chosen:
        stage(f"drawing the histograms of {len(chosen)} metrics")
        images["Distributions of the metrics"] = _plot_histograms(
            result, chosen, stats, tmp / "histograms.png"
        )
    stage("writing report.html")
    (tmp / "report.html").write_text(_page(result, stats, images, files), encoding="utf-8")
    return [*files, *images.values(), "report.html"]


# Interval totals and longest intervals: their ends are refined to the pointing's
# interval precision, each to within half of it (attitude.pointing.intervals).
_DURATIONS = ("_total_s", "_longest_s", "_sun_visible_s")


def stated_precision(name: str, mc: MonteCarloPlan, ok) -> float | None:
    """How precisely summary.json states the metric ``name`` (None: to the last bit, or
    not stated): the noise below it is root finding's, not the dispersions'.

    A duration summed over n intervals (``*_total_s``) is within n times the interval
    precision (half of it at each end), n the largest of the samples' matching count
    (``*_count``; the eclipses' for the umbra; one where no count is reported), a
    longest interval within one; a ``*_fraction_of_span`` is that over the span.
    """
    spec, scenario = mc.plan.pointing, mc.plan.scenario
    if spec.is_empty:
        return None
    precision = interval_precision(spec, scenario.stop_s)[0]
    fraction = name.endswith("_fraction_of_span")
    stem = name.removesuffix("_fraction_of_span") if fraction else name
    if not (fraction or stem.endswith(_DURATIONS)):
        return None
    if stem.endswith("_longest_s"):
        return precision
    counts = {"umbra_total_s": "eclipse_count"}
    count = counts.get(stem, stem.removesuffix("_total_s") + "_count")
    if fraction:
        count = stem + "_count"
    intervals = 1.0
    if count in ok and ok[count].dtype.kind in "fiu" and len(ok):
        intervals = max(1.0, float(np.nanmax(ok[count].to_numpy(float))))
    step = intervals * precision
    return step / (scenario.stop_s - scenario.start_s) if fraction else step


def drawn_spread(values: np.ndarray, precision: float | None) -> np.ndarray | None:
    """The finite ``values`` rounded to ``precision`` for drawing their spread, or None
    when they do not spread beyond it (differences within the stated precision are
    root finding's noise, not a metric that varies)."""
    values = values[np.isfinite(values)]
    if values.size == 0:
        return None
    if precision is not None and precision > 0.0:
        values = np.round(values / precision) * precision
        # Two values one step apart may come from the same true value.
        if np.ptp(values) <= precision * (1.0 + 1e-9):
            return None
    return values if np.ptp(values) > 0 else None


def _histogram_columns(mc: MonteCarloPlan, table) -> list[str]:
    """The metrics worth a histogram: numeric, finite somewhere, spread beyond their
    stated precision (:func:`drawn_spread`); the pointing first, then flips, rates,
    nutation and periods."""
    ok = table[table["status"] == "ok"]
    order = [n for n in mc.metrics if "sun_angle" in n and not n.endswith("_at_s")]
    order += [n for n in mc.metrics if n.endswith("_exclusion_total_s")]
    order += [n for n in mc.metrics if n.endswith(("_blinded_total_s", "_sun_in_view_total_s"))]
    order += [n for n in mc.metrics if n == "eclipse_total_s"]
    order += [n for n in mc.metrics if "_limb_angle_min" in n and not n.endswith("_at_s")]
    order += [n for n in mc.metrics if "_moon_angle_min" in n and not n.endswith("_at_s")]
    order += ["flip_count", "max_rate_deg_s"]
    order += [n for n in mc.metrics if n.endswith(("nutation_max_deg", "spin_period_s"))]
    order += [n for n in mc.metrics if n.endswith("precession_period_s")]
    chosen = []
    for name in order:
        values = ok[name].to_numpy(float) if ok[name].dtype.kind in "fiu" else np.empty(0)
        spread = drawn_spread(values, stated_precision(name, mc, ok))
        if spread is not None and name not in chosen:
            chosen.append(name)
    return chosen[:_MAX_HISTOGRAMS]


def _plot_histograms(result: MonteCarloResult, names, stats, path: Path) -> str:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from attitude.report.plots import PNG_OPTIONS

    ok = result.table[result.table["status"] == "ok"]
    columns = min(4, len(names))
    rows = math.ceil(len(names) / columns)
    figure = _grid_figure(Figure, columns, rows, 3.4, 2.7, left_in=0.55)
    panels = np.atleast_1d(figure.subplots(rows, columns, squeeze=False).ravel())
    for axes, name in zip(panels, names, strict=False):
        values = drawn_spread(ok[name].to_numpy(float), stated_precision(name, result.plan, ok))
        if values is None:  # not spread: _histogram_columns leaves such a metric out
            continue
        axes.hist(values, bins=int(np.clip(np.sqrt(values.size), 10, 60)), color="C0", alpha=0.8)
        entry = stats["metrics"][name]
        for p, style in (("1", ":"), ("50", "-"), ("99", ":")):
            axes.axvline(entry["percentiles"][p], color="k", linestyle=style, linewidth=1.0)
        nominal = result.nominal.get(name)
        if isinstance(nominal, float | int) and math.isfinite(nominal):
            axes.axvline(nominal, color="C3", linewidth=1.2)
        axes.set_title(name, fontsize="small")
        axes.tick_params(labelsize="x-small")
    for axes in panels[len(names) :]:
        axes.set_axis_off()
    figure.suptitle(
        f"{len(ok)} samples: percentiles 1, 50, 99 (black), nominal (red)", fontsize="medium"
    )
    FigureCanvasAgg(figure)
    figure.savefig(path, dpi=100, **PNG_OPTIONS)
    return path.name


def _grid_figure(
    figure_class,
    columns: int,
    rows: int,
    width_in: float,
    height_in: float,
    left_in: float,
    bottom_in: float = 0.35,
):
    """A figure for ``rows`` × ``columns`` panels of ``width_in`` × ``height_in`` each
    (with their labels), a title above, fixed margins in inches: a layout engine
    (constrained) measures every text and draws twice, most of a figure's time."""
    width, height = width_in * columns, height_in * rows + 0.6
    figure = figure_class(figsize=(width, height))
    gap_x, gap_y = 0.55, 0.5  # between panels: tick labels, the next panel's title
    axes_w = (width - left_in - 0.15 - gap_x * (columns - 1)) / columns
    axes_h = (height - bottom_in - 0.7 - gap_y * (rows - 1)) / rows
    figure.subplots_adjust(
        left=left_in / width,
        right=1.0 - 0.15 / width,
        bottom=bottom_in / height,
        top=1.0 - 0.7 / height,
        wspace=gap_x / axes_w,
        hspace=gap_y / axes_h,
    )
    return figure


def _plot_envelopes(result: MonteCarloResult, path: Path) -> str:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from attitude.report.plots import PNG_OPTIONS, time_axis

    envelope = result.envelope
    values = envelope.percentiles_deg(PERCENTILES)  # (p, vectors, 2, bins)
    centres = 0.5 * (envelope.bin_start_s + envelope.bin_end_s)
    t, label = time_axis(centres)
    limits = {
        v.name: v.sun_exclusion_half_angle_deg for v in result.plan.loaded.pointing.body_vectors
    }
    count = len(envelope.vectors)
    figure = _grid_figure(Figure, 1, count, 9.0, 2.8, left_in=0.7, bottom_in=0.5)
    panels = figure.subplots(count, 1, squeeze=False)[:, 0]
    ran = int((result.table["status"] == "ok").sum())
    for v, (axes, name) in enumerate(zip(panels, envelope.vectors, strict=True)):
        _envelope_panel(axes, t, label, name, values[:, v, 0], values[:, v, 1], limits.get(name))
    figure.suptitle(
        f"Sun angle over {ran} samples: percentiles of each sample's smallest and largest "
        "angle in each time bin",
        fontsize="medium",
    )
    FigureCanvasAgg(figure)
    figure.savefig(path, dpi=100, **PNG_OPTIONS)
    return path.name


def _envelope_panel(axes, t, label: str, name: str, low, high, limit_deg: float | None) -> None:
    """One body vector's panel: the bands between percentiles of the bins' smallest
    (``low``) and largest (``high``) Sun angles, their medians, its exclusion limit."""
    p = {q: i for i, q in enumerate(PERCENTILES)}
    for below, above, alpha in ((1, 99, 0.2), (5, 95, 0.35)):
        axes.fill_between(
            t,
            low[p[below]],
            high[p[above]],
            step="mid",
            color="C0",
            alpha=alpha,
            label=f"{below} % of min to {above} % of max",
        )
    axes.step(t, low[p[50]], where="mid", color="C0", linewidth=1.0, label="median min, max")
    axes.step(t, high[p[50]], where="mid", color="C0", linewidth=1.0)
    if limit_deg is not None:
        axes.axhline(
            limit_deg,
            color="C3",
            linestyle="--",
            linewidth=1.0,
            label=f"exclusion ({limit_deg:g}°)",
        )
    axes.set_ylim(0.0, 180.0)
    axes.set_yticks(np.arange(0, 181, 30))
    axes.set_ylabel(f"{name}: Sun angle (deg)")
    axes.set_xlabel(label)
    axes.grid(alpha=0.3)
    axes.legend(loc="upper right", fontsize="x-small", ncols=2)


def _bound(entry: dict[str, Any], key: str) -> str | None:
    bound = entry.get(key)
    if not bound or bound["value"] is None:
        return None
    return f"{bound['value']:.6g} ({100 * bound['confidence']:.1f} %)"


def _page(result: MonteCarloResult, stats, images: dict[str, str], files: list[str]) -> str:
    title = f"Monte Carlo: {stats['scenario']['name']}"
    parts = [
        "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>",
        f"<title>{escape(title)}</title><style>{_STYLE}</style></head><body>",
        f"<h1>{escape(title)}</h1>",
        *_overview(stats),
        *_metrics_section(result, stats),
        *_failures_section(stats),
        *_figures_and_files(images, files),
        _execution_note(stats["execution"]),
        "</body></html>\n",
    ]
    return "\n".join(parts)


def _overview(stats) -> list[str]:
    """What ran: the file, the samples and how they ran, and the dispersions."""
    scenario, execution = stats["scenario"], stats["execution"]
    return [
        f"<p class='note'>{escape(scenario['file'])}, computed by attitude "
        f"{escape(__version__)} (exact torque-free motion for every sample).</p>",
        _table(
            ["samples", "ran", "failed", "seed", "epoch", "span (s)", "workers", "wall (s)"],
            [
                [
                    stats["samples"]["total"],
                    stats["samples"]["ok"],
                    stats["samples"]["failed"],
                    stats["dispersions"]["seed"],
                    scenario["epoch"],
                    scenario["duration_s"],
                    execution["workers"],
                    execution["wall_s"],
                ]
            ],
        ),
        "<h2>Dispersions</h2><ul>",
        *[f"<li>{escape(line)}</li>" for line in stats["dispersions"]["dispersed"]],
        "</ul>",
    ]


def _metrics_section(result: MonteCarloResult, stats) -> list[str]:
    """Per metric: the nominal, mean, std, percentiles and 99 % bounds; the kinds of motion."""
    parts = [
        "<h2>Metrics</h2>",
        f"<p class='note'>Over the samples that ran. Bounds: one-sided, {100 * COVERAGE:g} % "
        f"of cases, from order statistics (Wilks 1941), with their confidence; "
        "none below 299 samples.</p>",
    ]
    rows = []
    for name, entry in stats["metrics"].items():
        if entry["n"] == 0:
            continue
        percentiles = entry["percentiles"]
        rows.append(
            [
                name,
                entry["n"],
                result.nominal.get(name),
                entry["mean"],
                entry["std"],
                *[percentiles[str(p)] for p in PERCENTILES],
                _bound(entry, "lower_bound_99"),
                _bound(entry, "upper_bound_99"),
            ]
        )
    parts.append(
        _table(
            [
                "metric",
                "n",
                "nominal",
                "mean",
                "std",
                *[f"p{p}" for p in PERCENTILES],
                "99 % lower bound",
                "99 % upper bound",
            ],
            rows,
        )
    )
    if stats["categories"]:
        parts.append(
            _table(
                ["motion", "samples"],
                [
                    [f"{name}: {kind}", count]
                    for name, kinds in stats["categories"].items()
                    for kind, count in kinds.items()
                ],
            )
        )
    return parts


def _failures_section(stats) -> list[str]:
    """The first 20 failed samples with their errors, and how to re-run one alone."""
    if not stats["failures"]:
        return []
    return [
        "<h2>Failed samples</h2>",
        _table(
            ["sample", "error"],
            [[f["sample"], f["error"]] for f in stats["failures"][:20]],
        ),
        "<p class='note'>Their drawn parameters are in samples.csv; "
        "<code>attitude montecarlo FILE --sample K --emit-scenario DIR</code> writes "
        "sample K as a scenario to run alone.</p>",
    ]


def _execution_note(execution: dict[str, Any]) -> str:
    """How the job ran: its tasks, the scheduler, a sample's and a task's cost."""
    return (
        f"<p class='note'>{execution['tasks']} tasks of {execution['batch_size']} samples on "
        f"{escape(str(execution['scheduler']))}; one sample of the nominal took "
        f"{execution['nominal_sample_s']:.3g} s here, Dask {1e3 * execution['task_overhead_s']:.2g}"
        f" ms a task.</p>"
    )
