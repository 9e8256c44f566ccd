"""The report's HTML page: the summary as tables, the plots, links to the data files.

A single self-contained file (inline CSS, images by relative link), built from the
same summary dictionary as ``summary.json``, so the page and the file cannot
disagree.
"""

from __future__ import annotations

from html import escape
from typing import Any

from attitude.report.guidance import guidance_section

__all__ = ["render_page"]

_STYLE = """
body { font-family: system-ui, sans-serif; margin: 2em auto; max-width: 1100px; color: #222; }
h1 { font-size: 1.5em; } h2 { font-size: 1.2em; margin-top: 1.6em; border-bottom: 1px solid #ccc; }
table { border-collapse: collapse; margin: 0.6em 0; font-size: 0.9em; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; }
th { background: #f3f3f3; } td.n { text-align: right; font-variant-numeric: tabular-nums; }
img { max-width: 100%; border: 1px solid #eee; margin: 0.5em 0; }
.note { color: #555; font-size: 0.9em; }
"""


def _number(value: Any, digits: int = 6) -> str:
    if value is None:
        return "–"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return f"{value:.{digits}g}"
    return escape(str(value))


def _table(header: list[str], rows: list[list[Any]]) -> str:
    head = "".join(f"<th>{escape(h)}</th>" for h in header)
    body = "".join(
        "<tr>"
        + "".join(
            f'<td class="n">{_number(v)}</td>'
            if isinstance(v, int | float) and not isinstance(v, bool)
            else f"<td>{_number(v)}</td>"
            for v in row
        )
        + "</tr>"
        for row in rows
    )
    return f"<table><tr>{head}</tr>{body}</table>"


def _range(v: dict[str, Any], name: str) -> str | None:
    """'least – greatest' of an extremum pair of the pointing summary, in degrees."""
    if f"{name}_min_deg" not in v:
        return None
    return f"{v[f'{name}_min_deg']:.4f} – {v[f'{name}_max_deg']:.4f}"


def _exclusion(v: dict[str, Any], name: str) -> str | None:
    """'count, total s' of an exclusion of the pointing summary, or None."""
    found = v.get(name)
    return None if found is None else f"{found['count']}, {found['total_s']:.6g} s"


def _share(v: dict[str, Any], name: str) -> str | None:
    """'count, total s (percent of the span)' of a union or inclusion of the pointing
    summary (``blinded``, ``sun_in_view``), or None."""
    found = v.get(name)
    if found is None:
        return None
    return f"{found['count']}, {found['total_s']:.6g} s ({100.0 * found['fraction_of_span']:.4g} %)"


def _pointing_table(vectors: dict[str, Any]) -> str:
    rows = [
        [
            name,
            v["kind"],
            f"{v['sun_angle_min_deg']:.4f} at {v['sun_angle_min_at']}",
            _range(v, "sun_angle"),
            _range(v, "moon_angle"),
            _range(v, "nadir_angle"),
            _range(v, "earth_limb_angle"),
            _exclusion(v, "sun_exclusion"),
            _exclusion(v, "moon_exclusion"),
            _exclusion(v, "earth_limb_exclusion"),
            _share(v, "blinded"),
            _share(v, "sun_in_view"),
            v["sun_visible"]["total_s"],
            v["mean_cos_incidence"],
        ]
        for name, v in vectors.items()
    ]
    header = [
        "body vector",
        "kind",
        "least Sun angle (deg)",
        "Sun angle (deg)",
        "Moon angle (deg)",
        "nadir angle (deg)",
        "above the limb (deg)",
        "Sun exclusions (n, time)",
        "Moon exclusions",
        "limb exclusions",
        "blinded by any (n, time, % of span)",
        "Sun in its view (n, time, % of span)",
        "Sun visible (s)",
        "mean cos incidence",
    ]
    return _table(header, rows)


def _propagation(summary: dict[str, Any]) -> str:
    """What the run is (``torques.propagation``: guided, exact, a gyrostat or torques by
    splitting with its error, attitude.report.torques.propagation_text)."""
    torques = summary.get("torques") or {}
    return torques.get("propagation") or "exact torque-free motion (closed form, no integration)"


def _torques_section(torques: dict[str, Any] | None) -> list[str]:
    """The torques modelled, the step and the estimated error; or the validity horizon."""
    if not torques:
        return []
    parts = ["<h2>Torques</h2>"]
    if not torques["modelled"]:
        horizon = torques["validity_horizon"]
        text = horizon["description"] if horizon else torques["validity_horizon_note"]
        parts.append(
            f"<p>None modelled: {escape(torques['propagation'])}. Validity: {escape(text)}.</p>"
        )
        return parts
    how = "given" if torques["step"] == "given" else f"chosen for {torques['accuracy_rad']:g} rad"
    parts.append(
        f"<p>Modelled: {escape(', '.join(torques['modelled']))}. Order {torques['order']}, "
        f"step {escape(how)}; estimated attitude error "
        f"{torques['estimated_error_rad']:.2g} rad over the run (each segment's own below).</p>"
    )
    horizon = torques.get("validity_horizon")
    if horizon:  # burns alone, on an orbit: the gravity gradient they leave out
        parts.append(f"<p>Validity: {escape(horizon['description'])}.</p>")
    if torques["burns"]:
        parts.append(
            _table(
                ["burn start", "duration (s)", "torque (N m)", "frame", "label"],
                [
                    [b["start"], b["duration_s"], str(b["torque_N_m"]), b["frame"], b["label"]]
                    for b in torques["burns"]
                ],
            )
        )
    parts.append(
        _table(
            ["segment", "method", "step (s)", "estimated error from its start (rad)"],
            [
                [s["segment"], s["method"], s["step_s"], s["estimated_error_rad"]]
                for s in torques["segments"]
            ],
        )
    )
    return parts


def render_page(summary: dict[str, Any], images: dict[str, str], files: list[str]) -> str:
    """The HTML text of the report.

    ``summary``: the dictionary written to summary.json; ``images``: caption → PNG
    file name; ``files``: the data files of the folder, linked.
    """
    parts = [
        *_heading(summary),
        *_events_section(summary["scenario"]["events"]),
        *_motion_section(summary["motion"]),
        *guidance_section(summary.get("guidance"), _table),
        *_torques_section(summary.get("torques")),
        *_pointing_section(summary.get("pointing")),
        *_plots_section(images),
        *_files_section(files, summary.get("outputs", {}).get("aem")),
        "</body></html>\n",
    ]
    return "\n".join(parts)


def _heading(summary: dict[str, Any]) -> list[str]:
    """The page's head, its title, and the scenario in one table."""
    scenario = summary["scenario"]
    return [
        "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>",
        f"<title>{escape(scenario['name'])}</title><style>{_STYLE}</style></head><body>",
        f"<h1>{escape(scenario['name'])}</h1>",
        f"<p class='note'>{escape(scenario['file'])}, computed by attitude "
        f"{escape(summary['attitude_version'])} ({escape(_propagation(summary))}).</p>",
        _table(
            [
                "epoch",
                "stop",
                "output step (s)",
                "samples",
                "spacecraft",
                "principal moments (kg m²)",
            ],
            [
                [
                    scenario["epoch"],
                    scenario["stop"],
                    scenario["output"]["step_s"],
                    scenario["output"]["samples"],
                    scenario["spacecraft"]["name"],
                    ", ".join(
                        f"{m:.6g}" for m in scenario["spacecraft"]["principal_moments_kg_m2"]
                    ),
                ]
            ],
        ),
    ]


def _events_section(events: list[dict[str, Any]]) -> list[str]:
    if not events:
        return []
    return [
        "<h2>Events</h2>",
        _table(["epoch", "type", "label"], [[e["epoch"], e["type"], e["label"]] for e in events]),
    ]


def _motion_section(motion: dict[str, Any]) -> list[str]:
    """Each segment of the motion in a table, and the flips."""
    parts = [
        "<h2>Motion</h2>",
        _table(
            [
                "segment",
                "from",
                "closed form",
                "body period (s)",
                "flips",
                "flip period (s)",
                "nutation (deg)",
                "nutation period (s)",
                "spin period (s)",
                "precession period (s)",
                "kinetic energy (J)",
                "|H| (N m s)",
            ],
            [
                [
                    s["index"],
                    s["start"],
                    s["formula"],
                    s["body_period_s"],
                    s["flip_count"],
                    s["flip_period_s"],
                    None
                    if s["nutation_angle_min_deg"] is None
                    else f"{s['nutation_angle_min_deg']:.4g} – {s['nutation_angle_max_deg']:.4g}",
                    s["nutation_period_s"],
                    s["spin_period_s"],
                    s["precession_period_s"],
                    s["kinetic_energy_J"],
                    s["angular_momentum_norm_N_m_s"],
                ]
                for s in motion["segments"]
            ],
        ),
    ]
    flips = motion["flips"]
    if flips["count"]:
        shown = ", ".join(escape(t) for t in flips["times"][:12])
        more = f" … ({flips['count']} in all)" if flips["count"] > 12 else ""
        parts.append(f"<p>Flips (the Джанибеков effect): {shown}{more}</p>")
    return parts


def _pointing_section(pointing: dict[str, Any] | None) -> list[str]:
    """The body vectors' extrema and exclusions, and the eclipses."""
    if not pointing:
        return []
    parts = [
        "<h2>Pointing</h2>",
        f"<p class='note'>Spacecraft at: {escape(pointing['position'])}. Extrema and "
        "interval ends found on the exact motion (search step "
        f"{pointing['search_step_s']:.3g} s), interval ends to "
        f"{pointing['interval_precision_s']:g} s. Angles are geometric: an extremum may "
        "fall in an eclipse; exclusions leave out a hidden Sun or Moon.</p>",
        _pointing_table(pointing["body_vectors"]),
    ]
    eclipses = pointing.get("eclipses")
    if eclipses:
        parts.append(
            _table(
                [
                    "eclipses (shadow)",
                    "in shadow (s)",
                    "umbra passes",
                    "in umbra (s)",
                    "sunlit fraction",
                ],
                [
                    [
                        eclipses["shadow"]["count"],
                        eclipses["shadow"]["total_s"],
                        eclipses["umbra"]["count"],
                        eclipses["umbra"]["total_s"],
                        eclipses["sunlit_fraction_of_span"],
                    ]
                ],
            )
        )
    return parts


def _plots_section(images: dict[str, str]) -> list[str]:
    if not images:
        return []
    return ["<h2>Plots</h2>"] + [
        f"<figure><img src='{escape(name)}' alt='{escape(caption)}'>"
        f"<figcaption class='note'>{escape(caption)}</figcaption></figure>"
        for caption, name in images.items()
    ]


def _file_links(files: list[str]) -> list[str]:
    parts = ["<h2>Files</h2><ul>"]
    parts += [f"<li><a href='{escape(f)}'>{escape(f)}</a></li>" for f in files]
    parts.append("</ul>")
    return parts


def _figures_and_files(images: dict[str, str], files: list[str]) -> list[str]:
    """The figures under "Plots", if any, and the files as links (the Monte Carlo
    page's too, attitude.montecarlo.report)."""
    return _plots_section(images) + _file_links(files)


def _files_section(files: list[str], aem: dict[str, Any] | None) -> list[str]:
    """Links to the data files, the AEM's stated accuracy, and the conventions."""
    parts = _file_links(files)
    if aem:
        parts.append(
            f"<p class='note'>attitude.aem: {aem['records']} records, sampled so that "
            "LAGRANGE interpolation as declared (degree 7, each quaternion component over the "
            "8 records centred on the interval, normalized) stays within "
            f"{aem['tolerance_rad']:g} rad of the exact attitude.</p>"
        )
    parts.append(
        "<p class='note'>Frames: body = spacecraft body axes; ICRF axes for inertial vectors. "
        "Quaternions are scalar first and rotate body coordinates into ICRF "
        "(attitude.aem: CCSDS AEM 2.0, ICRF → SC_BODY_1, scalar last, as the standard says).</p>"
    )
    return parts
