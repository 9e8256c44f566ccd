"""The outputs of ``attitude fit``: the fitted scenario, the parameter table, the
residuals, the uncertainty growth and a page, written through the output folder's
rules (attitude.outputs.folder: a new or empty folder, or one attitude wrote; nothing of
the user's is ever replaced, and nothing half-written is left).

- ``fitted_scenario.toml``: a scenario (docs/scenarios.md) at the first sample's epoch
  with the fitted moments (or tensor), attitude and rate, and ``output.duration`` set
  to the prediction horizon: ``attitude run`` predicts forward from it.  With a
  context scenario (``--scenario``), its orbit, torques and the impulses after the
  epoch are kept, so that ``attitude run`` also states the gravity gradient's validity
  horizon.  Its comments say what was fitted and what is not observable.
- ``parameters.csv`` (name, value, 1σ, unit) and ``correlations.csv``;
- ``fit.json``: everything above, the covariance, χ², the normality tests, the noise,
  the observability, the outliers, the notes;
- ``residuals.csv`` and ``residuals.png``: the residuals of each sensor over time,
  outliers marked, and their histogram against the unit normal;
- ``uncertainty.png``: the predicted 1σ attitude and rate uncertainty over time, and
  when the attitude's reaches 10°;
- ``report.html``: the page.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from html import escape
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from attitude.base.errors import InputError
from attitude.base.version import __version__
from attitude.environment.timescales import (
    iso_texts,
    offline_time,
    time_from_tt_seconds,
    tt_seconds,
)
from attitude.estimation.fit import DEFAULT_HORIZON_DEG, SpinStateFit
from attitude.estimation.global_start import MAX_FAMILIES
from attitude.outputs.folder import claim
from attitude.report.page import _STYLE, _figures_and_files, _table
from attitude.report.summaries import write_json

__all__ = ["OUTPUT_NAMES", "FitContext", "scenario_document", "write_fit_report"]

OUTPUT_NAMES = (
    "fitted_scenario.toml",
    *(f"fitted_scenario_family_{k}.toml" for k in range(2, MAX_FAMILIES + 1)),
    "parameters.csv",
    "correlations.csv",
    "fit.json",
    "residuals.csv",
    "residuals.png",
    "uncertainty.png",
    "report.html",
)
# The fitted scenario's span: the prediction horizon, within 30 days and this many
# output steps (about 15 MB of `attitude run`'s default outputs at 20 000).
MAX_DURATION_S = 30 * 86400.0
MAX_OUTPUT_STEPS = 20_000
# The residuals' figure draws at most this many samples a sensor (and every outlier).
PLOTTED_POINTS = 20_000


@dataclass
class FitContext:
    """What the fit took from a scenario file (``--scenario``): its document's
    ``[pointing]`` and ``[torques]`` tables (burns at absolute epochs), its angular
    impulses as ``[[events]]`` tables with absolute epochs, and its time scale."""

    source: str = ""
    time_scale: str = "utc"
    pointing: dict[str, Any] | None = None
    torques: dict[str, Any] | None = None
    events: list[tuple[Any, dict[str, Any]]] = field(default_factory=list)  # (Time, table)
    burns: list[tuple[Any, dict[str, Any]]] = field(default_factory=list)  # (Time, table)


def _epoch_text(epoch: Any, scale: str) -> str:
    with offline_time():
        return str(iso_texts(getattr(epoch, scale)))


def scenario_document(
    fit: SpinStateFit,
    name: str,
    horizon_s: float,
    context: FitContext | None = None,
    source: str = "telemetry",
) -> tuple[dict[str, Any], list[str]]:
    """The fitted scenario as a document (the TOML ``attitude run`` reads) and its
    comment lines."""
    if fit.epoch is None:
        raise InputError(
            "the telemetry's times are relative seconds: an epoch is needed to write the "
            "fitted scenario (--epoch)"
        )
    context = context or FitContext()
    scale = context.time_scale
    end = fit.span[1]
    solver = fit.solver
    tensor = solver.inertia_tensor
    document: dict[str, Any] = {
        "scenario": {
            "name": name,
            "epoch": _epoch_text(fit.epoch, scale),
            "time_scale": scale,
        }
    }
    if np.array_equal(tensor, np.diag(np.diag(tensor))):
        spacecraft = {"principal_moments": np.diag(tensor).tolist()}
    else:
        spacecraft = {"inertia_tensor": tensor.tolist()}
    document["spacecraft"] = {"name": name, **spacecraft}
    q = solver.initial_attitude.as_quat(scalar_first=True)
    document["initial_state"] = {
        "quaternion": q.tolist(),
        "angular_velocity": fit.angular_velocity.tolist(),
    }
    # Beyond the horizon search (30 arcs under torques, whose propagation costs per
    # second of span), the span stops where the search did.
    searched = (30.0 if getattr(fit._model, "torques", None) else 1e6) * (end - fit.span[0])
    reach = min(max(horizon_s if math.isfinite(horizon_s) else end + searched, end), MAX_DURATION_S)
    document["output"] = {"duration": float(reach), "step": float(reach)}
    shortest = _shortest_period(document, context)
    # The step `attitude check` accepts (a tenth of the motion's shortest period, to 3
    # digits, down), and at most MAX_OUTPUT_STEPS of it: a sensible size of outputs.
    step = _three_digits_down(0.1 * shortest) if math.isfinite(shortest) else reach / 1000.0
    duration = min(reach, MAX_OUTPUT_STEPS * step)
    document["output"] = {"duration": float(duration), "step": float(step)}
    if context.pointing:
        document["pointing"] = context.pointing
    dropped = 0
    if context.torques is not None:
        document["torques"] = dict(context.torques)
        burns = []
        for epoch, table in context.burns:
            if float(tt_seconds(epoch, fit.epoch)) >= 0.0:
                burns.append({**table, "epoch": _epoch_text(epoch, scale)})
            else:
                dropped += 1
        if burns:
            document["torques"]["burns"] = burns
    events = []
    for epoch, table in context.events:
        if float(tt_seconds(epoch, fit.epoch)) > 0.0:
            events.append({**table, "epoch": _epoch_text(epoch, scale)})
        else:
            dropped += 1
    if events:
        document["events"] = events
    r, s = fit.inertia_ratios, fit.inertia_ratios_sigma
    comments = [
        f"Fitted by attitude {__version__} (attitude fit) to {source}"
        + (f", with the orbit, torques and impulses of {context.source}" if context.source else "")
        + ".",
        f"Inertia ratios 1 : {r[1]:.9g} : {r[2]:.9g} (1σ {s[1]:.2g}, {s[2]:.2g}); reduced "
        f"chi2 {fit.reduced_chi2:.4g}.",
        *fit.observability,
    ]
    if len(fit.families) > 1:
        k = next((i for i, f in enumerate(fit.families) if f is fit), 0) + 1
        comments.append(
            f"Family {k} of {len(fit.families)}: the data do not decide between "
            f"{len(fit.families)} families of solutions that fit within the noise; each has "
            "its scenario (fitted_scenario.toml, fitted_scenario_family_2.toml, ...) and "
            "its parameters in fit.json."
        )
    if dropped:
        comments.append(
            f"{dropped} impulse(s) or burn(s) of {context.source} start before the epoch: "
            "their effect is in the fitted state, and they are left out."
        )
    if fit.principal_moments is None:
        comments.append(
            "The moments below are in units of the smallest (only their ratios are known): "
            "rates and attitudes predicted from them are right, momenta and energies scaled."
        )
    if fit.attitude is None:
        comments.append(
            "The attitude is not observable from rates alone: the quaternion below is the "
            "identity, and the attitudes `attitude run` predicts are relative to it."
        )
    if math.isfinite(horizon_s):
        when = _epoch_text(time_from_tt_seconds(fit.epoch, horizon_s), scale)
        comments.append(
            f"Prediction horizon: the 1σ attitude uncertainty reaches {DEFAULT_HORIZON_DEG:g} deg "
            f"{horizon_s:.6g} s after the epoch ({when} {scale.upper()})."
        )
    else:
        comments.append(
            f"The 1σ attitude uncertainty stays below {DEFAULT_HORIZON_DEG:g} deg as far as it was "
            "searched."
        )
    comments.append(
        f"output.step is a tenth of the motion's shortest period ({shortest:.6g} s), the step "
        "`attitude check` takes as sampling the motion; output.duration is the prediction "
        f"horizon, at most {MAX_DURATION_S / 86400:g} days and {MAX_OUTPUT_STEPS} steps "
        f"(about 15 MB of `attitude run`'s default outputs)"
        + (
            f": here {duration:.6g} s, short of the horizon (set a longer one to predict further)"
            if duration < min(horizon_s, MAX_DURATION_S)
            else ""
        )
        + "."
    )
    return document, comments


def _shortest_period(document: dict[str, Any], context: FitContext) -> float:
    """The shortest period `attitude check` reads in the fitted scenario's torque-free
    motion (body, spin, nutation, precession, flips: attitude.trajectory.motion's
    undersampling rule), over its span and across its impulses; inf if none."""
    from attitude.files.scenario_reader import scenario_from_document
    from attitude.trajectory.motion import analyze
    from attitude.trajectory.trajectory import propagate

    free = {k: v for k, v in document.items() if k not in ("torques", "pointing")}
    scenario = scenario_from_document(Path("fitted_scenario.toml"), free).scenario
    trajectory = propagate(scenario)
    periods = [math.inf]
    for item in analyze(trajectory, locate=False):
        for period in (
            item.period_s,
            item.spin_period_s,
            item.nutation_period_s,
            item.precession_period_s,
            item.flip_period_s,
        ):
            if period is not None and math.isfinite(period) and period > 0.0:
                periods.append(period)
    return min(periods)


def _three_digits_down(value: float) -> float:
    """``value`` rounded down to three significant digits (a step to read)."""
    if not value > 0.0:
        return value
    scale = 10.0 ** (math.floor(math.log10(value)) - 2)
    return math.floor(value / scale) * scale


def _summary(fit: SpinStateFit, horizon_s: float, source: str) -> dict[str, Any]:
    """fit.json."""
    σ = fit.parameter_sigma
    outliers = {}
    for sensor, block in fit.residuals.items():
        bad = ~block["inlier"]
        outliers[sensor] = {
            "count": int(bad.sum()),
            "t_s": block["t"][bad][:1000].tolist(),
        }
    return {
        "telemetry": source,
        "epoch": None if fit.epoch is None else f"{_epoch_text(fit.epoch, 'utc')} UTC",
        "arc_s": list(fit.span),
        "parameters": [
            {"name": n, "value": v, "sigma": s, "unit": u}
            for n, v, s, u in zip(
                fit.parameter_names, fit.parameter_values, σ, fit.parameter_units, strict=True
            )
        ],
        "covariance": fit.covariance,
        "correlations": fit.correlations,
        "inertia_ratios": fit.inertia_ratios,
        "inertia_ratios_sigma": fit.inertia_ratios_sigma,
        "principal_moments_kg_m2": fit.principal_moments,
        "principal_moments_sigma_kg_m2": fit.principal_moments_sigma,
        "principal_axes_body": fit.principal_axes,
        "angular_velocity_rad_s": fit.angular_velocity,
        "angular_velocity_sigma_rad_s": fit.angular_velocity_sigma,
        "gyro_bias_rad_s": fit.gyro_bias,
        "gyro_bias_sigma_rad_s": fit.gyro_bias_sigma,
        "attitude_q_body_to_icrf_wxyz": None
        if fit.attitude is None
        else fit.attitude.as_quat(scalar_first=True),
        "attitude_sigma_rad": fit.attitude_sigma,
        "formula": fit.formula,
        "body_period_s": fit.period,
        "goodness": {
            "chi2": fit.goodness.chi2,
            "degrees_of_freedom": fit.goodness.dof,
            "reduced_chi2": fit.reduced_chi2,
            "p_value": fit.goodness.p_value,
            "normality": {
                k: None if v is None else {"statistic": v[0], "p_value": v[1]}
                for k, v in fit.goodness.normality.items()
            },
            "lag1_autocorrelation": fit.goodness.autocorrelation,
        },
        "noise": fit.noise,
        "observability": fit.observability,
        "prediction_horizon_s": horizon_s,
        "prediction_horizon_threshold_deg": DEFAULT_HORIZON_DEG,
        "outliers": outliers,
        "notes": fit.notes,
        "families": [_family(k, family) for k, family in enumerate(fit.families or [fit])],
    }


def _family(k: int, family: SpinStateFit) -> dict[str, Any]:
    """A family of solutions in fit.json: its parameters, covariance and χ²."""
    return {
        "family": k + 1,
        "scenario": "fitted_scenario.toml" if k == 0 else f"fitted_scenario_family_{k + 1}.toml",
        "inertia_ratios": family.inertia_ratios,
        "inertia_ratios_sigma": family.inertia_ratios_sigma,
        "angular_velocity_rad_s": family.angular_velocity,
        "angular_velocity_sigma_rad_s": family.angular_velocity_sigma,
        "parameters": [
            {"name": n, "value": v, "sigma": s, "unit": u}
            for n, v, s, u in zip(
                family.parameter_names,
                family.parameter_values,
                family.parameter_sigma,
                family.parameter_units,
                strict=True,
            )
        ],
        "covariance": family.covariance,
        "reduced_chi2": family.reduced_chi2,
        "chi2": family.goodness.chi2,
        "degrees_of_freedom": family.goodness.dof,
    }


def write_fit_report(
    fit: SpinStateFit,
    out_dir: str | Path,
    source: str,
    name: str,
    context: FitContext | None = None,
    horizon_s: float | None = None,
    progress: Callable[[str], None] | None = None,
) -> list[str]:
    """Write the outputs (module docstring) into ``out_dir``; the names written.
    ``progress`` is told each stage (the horizon's search, the writing)."""
    say = progress or (lambda text: None)
    folder = claim(out_dir, OUTPUT_NAMES)
    if horizon_s is None:
        say("the prediction horizon: where the 1σ attitude uncertainty reaches 10 deg")
    horizon = fit.horizon() if horizon_s is None else horizon_s
    document, comments = scenario_document(fit, name, horizon, context, source)
    say(f"writing {', '.join(n for n in OUTPUT_NAMES if not n.startswith('fitted_scenario_'))}")

    def build(tmp: Path) -> list[str]:
        from attitude.files.scenario_reader import scenario_from_document
        from attitude.files.scenario_writer import scenario_text

        text = scenario_text(document, comments)
        path = tmp / "fitted_scenario.toml"
        path.write_text(text, encoding="utf-8")
        scenario_from_document(path, document)  # what we write, attitude run reads
        written = ["fitted_scenario.toml"]
        for k, family in enumerate(fit.families[1:], start=2):  # the others, as much
            other, lines = scenario_document(
                family, f"{name} (family {k})", family.horizon(), context, source
            )
            path = tmp / f"fitted_scenario_family_{k}.toml"
            path.write_text(scenario_text(other, lines), encoding="utf-8")
            scenario_from_document(path, other)
            written.append(path.name)
        summary = _summary(fit, horizon, source)
        write_json(tmp / "fit.json", summary)
        _parameters_csv(fit, tmp)
        _residuals_csv(fit, tmp / "residuals.csv")
        images = {
            "Residuals": _plot_residuals(fit, tmp / "residuals.png"),
            "Prediction uncertainty": _plot_uncertainty(fit, horizon, tmp / "uncertainty.png"),
        }
        files = [
            *written,
            "parameters.csv",
            "correlations.csv",
            "fit.json",
            "residuals.csv",
        ]
        (tmp / "report.html").write_text(
            _page(fit, summary, images, files, source), encoding="utf-8"
        )
        return [*files, *images.values(), "report.html"]

    return folder.write(build, source, __version__)


def _parameters_csv(fit: SpinStateFit, tmp: Path) -> None:
    σ = fit.parameter_sigma
    lines = ["name,value,sigma_1,unit"]
    for n, v, s, u in zip(
        fit.parameter_names, fit.parameter_values, σ, fit.parameter_units, strict=True
    ):
        lines.append(f"{n},{float(v)!r},{float(s)!r},{u}")
    (tmp / "parameters.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
    C = fit.correlations
    rows = [",".join(["name", *fit.parameter_names])]
    for n, row in zip(fit.parameter_names, C, strict=True):
        rows.append(",".join([n, *(f"{float(x):.6f}" for x in row)]))
    (tmp / "correlations.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")


def _residuals_csv(fit: SpinStateFit, path: Path) -> None:
    """residuals.csv, written by Arrow's CSV writer (its doubles read back to the bit;
    a million rows in a second, where Python's formatting took fourteen); the
    normalized residuals to six digits."""
    import pyarrow as pa
    from pyarrow import csv as pa_csv

    header = (
        "# residuals of attitude fit: measured minus fitted. gyro: rad/s, body axes; "
        "attitude: rad, the body-axes rotation vector of fitted^-1 * measured; "
        "normalized: divided by the noise sigma; inlier: 0 for an outlier\n"
        "sensor,t_s,residual_x,residual_y,residual_z,normalized_x,normalized_y,normalized_z,"
        "inlier\n"
    )
    with open(path, "wb") as stream:
        stream.write(header.encode("utf-8"))
        for sensor, block in fit.residuals.items():
            count = len(block["t"])
            columns = {
                "sensor": pa.array(np.full(count, sensor)),
                "t_s": pa.array(np.asarray(block["t"], dtype=np.float64)),
            }
            for k, axis in enumerate("xyz"):
                columns[f"residual_{axis}"] = pa.array(block["residual"][:, k])
            for k, axis in enumerate("xyz"):
                columns[f"normalized_{axis}"] = pa.array(_six_digits(block["normalized"][:, k]))
            columns["inlier"] = pa.array(block["inlier"].astype(np.int8))
            pa_csv.write_csv(
                pa.table(columns),
                stream,
                pa_csv.WriteOptions(include_header=False, quoting_style="none"),
            )


def _six_digits(values: NDArray[np.float64]) -> NDArray[np.float64]:
    """Each value rounded to six significant digits (written shortest, it reads so)."""
    values = np.asarray(values, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        exponent = np.floor(np.log10(np.abs(values)))
        scale = np.where(np.isfinite(exponent), 10.0 ** (5.0 - exponent), 1.0)
        rounded = np.round(values * scale) / scale
    return np.where(np.isfinite(rounded), rounded, values)


def _plot_residuals(fit: SpinStateFit, path: Path) -> str:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    sensors = list(fit.residuals)
    figure = Figure(figsize=(9.0, 2.6 * len(sensors) + 2.6))
    FigureCanvasAgg(figure)
    panels = figure.subplots(len(sensors) + 1, 1)
    everything = []
    for axes, sensor in zip(panels[:-1], sensors, strict=True):
        block = fit.residuals[sensor]
        t, z, ok = block["t"], block["normalized"], block["inlier"]
        # At most PLOTTED_POINTS dots an axis, evenly: a million dots on a 900-pixel
        # panel show the same band as these (the outliers are all drawn).
        shown = np.flatnonzero(ok)[:: max(1, math.ceil(np.count_nonzero(ok) / PLOTTED_POINTS))]
        for k, (axis, colour) in enumerate(zip("xyz", ("C0", "C1", "C2"), strict=True)):
            axes.plot(t[shown], z[shown, k], ".", markersize=2, color=colour, label=axis)
        if np.any(~ok):
            axes.plot(
                t[~ok],
                np.clip(np.max(np.abs(z[~ok]), axis=1), 0, 10),
                "x",
                color="red",
                label=f"outliers ({int((~ok).sum())}, clipped at 10)",
            )
        axes.set_ylabel(f"{sensor} residual / σ")
        axes.set_xlabel("time since the first sample (s)")
        axes.axhline(0.0, color="0.5", linewidth=0.5)
        axes.legend(loc="upper right", fontsize=7, ncol=4)
        everything.append(z[ok].ravel())
    axes = panels[-1]
    values = np.concatenate(everything)
    axes.hist(values, bins=60, range=(-5, 5), density=True, color="0.7", label="residuals / σ")
    x = np.linspace(-5, 5, 201)
    axes.plot(x, np.exp(-0.5 * x * x) / math.sqrt(2 * math.pi), color="C3", label="unit normal")
    axes.set_xlabel("normalized residual")
    axes.legend(fontsize=7)
    figure.tight_layout()
    figure.savefig(path, dpi=100)
    return path.name


def _plot_uncertainty(fit: SpinStateFit, horizon_s: float, path: Path) -> str:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from attitude.report.plots import time_unit

    start, end = fit.span
    far = horizon_s * 1.5 if math.isfinite(horizon_s) else 10.0 * max(end - start, 1.0)
    t = np.linspace(start, max(far, end), 200)
    σ_attitude, σ_rate = fit.envelope(t)
    unit_s, label = time_unit(float(t[-1] - start))
    x = t / unit_s
    figure = Figure(figsize=(9.0, 5.5))
    FigureCanvasAgg(figure)
    top, bottom = figure.subplots(2, 1, sharex=True)
    top.plot(x, np.degrees(σ_attitude), color="C0")
    top.axhline(
        DEFAULT_HORIZON_DEG, color="C3", linewidth=0.8, label=f"{DEFAULT_HORIZON_DEG:g} deg"
    )
    if math.isfinite(horizon_s):
        top.axvline(
            horizon_s / unit_s,
            color="C3",
            linestyle="--",
            linewidth=0.8,
            label=f"horizon {horizon_s:.4g} s",
        )
    top.axvspan(start / unit_s, end / unit_s, color="0.9", label="telemetry arc")
    relative = "" if fit.attitude is not None else ", relative to t0"
    top.set_ylabel(f"1σ attitude (deg{relative})")
    top.set_title("predicted 1σ, the largest over each cycle of the motion", fontsize=9)
    top.legend(fontsize=7)
    bottom.plot(x, σ_rate, color="C1")
    bottom.axvspan(start / unit_s, end / unit_s, color="0.9")
    bottom.set_ylabel("1σ body rate (rad/s)")
    bottom.set_xlabel(label.replace("the epoch", "the first sample"))
    figure.tight_layout()
    figure.savefig(path, dpi=100)
    return path.name


def _page(fit: SpinStateFit, summary: dict[str, Any], images, files, source: str) -> str:
    title = f"Spin state fitted to {source}"
    rows = [[p["name"], p["value"], p["sigma"], p["unit"]] for p in summary["parameters"]]
    names = fit.parameter_names
    C = fit.correlations
    correlations = [
        [n, *(round(float(x), 3) for x in row)] for n, row in zip(names, C, strict=True)
    ]
    g = fit.goodness
    horizon = summary["prediction_horizon_s"]
    parts = [
        "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>",
        f"<title>{escape(title)}</title><style>{_STYLE}</style></head><body>",
        f"<h1>{escape(title)}</h1>",
        f"<p>Epoch (first sample): {escape(str(summary['epoch']))}; arc {fit.span[0]:.6g} to "
        f"{fit.span[1]:.6g} s; motion formula {escape(fit.formula)}, body period "
        f"{fit.period:.6g} s.</p>",
        "<h2>Parameters (1σ)</h2>",
        _table(["parameter", "value", "1σ", "unit"], rows),
        "<h2>Correlations</h2>",
        _table(["", *names], correlations),
        "<h2>Goodness of fit</h2>",
        "<ul>" + "".join(f"<li>{escape(line)}</li>" for line in g.lines()) + "</ul>",
        "<h2>Noise</h2>",
        "<ul>"
        + "".join(f"<li>{escape(k)}: {escape(str(v))}</li>" for k, v in fit.noise.items())
        + "</ul>",
        "<h2>What the telemetry determines</h2>",
        "<ul>" + "".join(f"<li>{escape(line)}</li>" for line in fit.observability) + "</ul>",
        "<h2>Prediction</h2>",
        f"<p>The 1σ attitude uncertainty reaches {DEFAULT_HORIZON_DEG:g}° "
        + (
            f"{horizon:.6g} s after the first sample"
            if horizon is not None and math.isfinite(horizon)
            else "beyond the search"
        )
        + ": <code>fitted_scenario.toml</code> predicts forward to it (<code>attitude run "
        "fitted_scenario.toml --out DIR</code>).</p>",
        "<h2>Notes</h2>",
        "<ul>" + "".join(f"<li>{escape(line)}</li>" for line in fit.notes) + "</ul>",
        *_figures_and_files(images, files),
        "</body></html>\n",
    ]
    return "\n".join(parts)
