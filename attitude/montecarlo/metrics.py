"""The metrics of one Monte Carlo sample: the numbers ``summary.json`` reports, and
each body vector's Sun-angle extremes per time bin (a few kB a sample instead of the
whole series).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from attitude.outputs.formats import OutputChoice
from attitude.pointing.sampling import pointing_samples
from attitude.pointing.search import pointing_analysis
from attitude.pointing.spec import PointingSpec
from attitude.report.plan import RunPlan
from attitude.report.summaries import motion_summary, pointing_summary
from attitude.scenario.scenario import Scenario
from attitude.trajectory.motion import largest_rate_of

__all__ = [
    "ANGLE_STEPS",
    "ANGLE_STEP_DEG",
    "METRICS_ONLY",
    "TIME_BINS",
    "angle_extremes",
    "metric_names",
    "pointing_outcome",
    "sample_metrics",
    "sun_angles_deg",
    "time_bin_edges",
]

# The Sun-angle series of each sample is reduced to its extremes in this many time
# bins, quantized to this step (uint16: 0 to 3600 steps of 0.05 deg).
TIME_BINS = 200

ANGLE_STEP_DEG = 0.05

ANGLE_STEPS = round(180.0 / ANGLE_STEP_DEG)
# A sample writes no files: its plan checks the scenario, the motion and the pointing
# as `attitude run` does, and no output's own limits (no AEM records are chosen, no
# Parquet span is checked; the CSV's estimated size goes unused).
METRICS_ONLY = OutputChoice(formats=("csv",))


def _segment_metric_names(k: int) -> list[str]:
    return [
        f"segment{k}_{name}"
        for name in (
            "motion",
            "body_period_s",
            "flip_count",
            "flip_period_s",
            "nutation_min_deg",
            "nutation_max_deg",
            "nutation_period_s",
            "spin_period_s",
            "precession_period_s",
            "kinetic_energy_J",
            "angular_momentum_norm_N_m_s",
        )
    ]


# Each body vector's extrema, as summary.json names them (attitude.report.summaries): the
# quantity, and whether it is an angle (reported in degrees).
_VECTOR_EXTREMA = (
    ("sun_angle", True, False),
    ("moon_angle", True, False),
    ("nadir_angle", True, True),
    ("earth_limb_angle", True, True),
    ("cos_incidence", False, False),
)  # (quantity, in degrees, needs an orbit)


_CONSTRAINTS = (
    ("sun_exclusion", "sun_exclusion_half_angle_rad"),
    ("moon_exclusion", "moon_exclusion_half_angle_rad"),
    ("earth_limb_exclusion", "earth_limb_exclusion_angle_rad"),
)
# The totals of a vector's "blinded" (the union of its exclusions) and "sun_in_view"
# (its Sun inclusion cone holding the Sun), as summary.json names them.
_UNION_TOTALS = ("count", "total_s", "longest_s", "fraction_of_span")


def _vector_metric_names(vector, on_orbit: bool) -> list[str]:
    v = vector.name
    names = []
    for quantity, degrees, needs_orbit in _VECTOR_EXTREMA:
        if needs_orbit and not on_orbit:
            continue
        unit = "_deg" if degrees else ""
        names += [
            f"{v}_{quantity}_min{unit}",
            f"{v}_{quantity}_min_at_s",
            f"{v}_{quantity}_max{unit}",
            f"{v}_{quantity}_max_at_s",
        ]
    names += [f"{v}_mean_cos_incidence", f"{v}_sun_visible_s"]
    for constraint, angle in _CONSTRAINTS:
        if getattr(vector, angle) is not None:
            names += [f"{v}_{constraint}_{total}" for total in ("count", "total_s", "longest_s")]
    # Blinded by any of its exclusions (their union), and the Sun in a Sun sensor's view.
    for union, present in (
        ("blinded", bool(vector.exclusions)),
        ("sun_in_view", vector.sun_inclusion_half_angle_rad is not None),
    ):
        if present:
            names += [f"{v}_{union}_{total}" for total in _UNION_TOTALS]
    return names


def metric_names(scenario: Scenario, pointing: PointingSpec) -> list[str]:
    """The outcome columns of a scenario's samples (the same for every sample: the
    dispersions change numbers, not the number of segments or body vectors)."""
    names = ["flip_count", "max_rate_deg_s"]
    for k in range(len(scenario.events) + 1):
        names += _segment_metric_names(k)
    for vector in pointing.body_vectors:
        names += _vector_metric_names(vector, pointing.on_orbit)
    if pointing.on_orbit:
        names += [
            "eclipse_count",
            "eclipse_total_s",
            "umbra_total_s",
            "sunlit_fraction",
            "moon_behind_earth_total_s",
        ]
    return names


def _number(value: Any) -> float:
    return math.nan if value is None else float(value)


def _count(value: int | None) -> int | float:
    """A count as an integer, NaN where it was not computed (never a 0 for it)."""
    return math.nan if value is None else int(value)


def pointing_outcome(plan: RunPlan) -> dict[str, float]:
    """The pointing metrics of one checked scenario, as ``summary.json`` reports them:
    each body vector's extrema (with their times, TT seconds) and constraint totals, and
    the eclipses, all found on the exact motion over the span by
    :func:`attitude.pointing.search.pointing_analysis` on the plan's search grid, as
    ``attitude run`` finds them (none from the output grid)."""
    analysis = pointing_analysis(plan.trajectory, plan.pointing, grid=plan.search)
    summary = pointing_summary(analysis, float)  # times as TT seconds, not ISO text
    metrics: dict[str, float] = {}
    for name, entry in summary["body_vectors"].items():
        for quantity, degrees, _ in _VECTOR_EXTREMA:
            unit = "_deg" if degrees else ""
            if f"{quantity}_min{unit}" not in entry:  # an orbit's quantity, without one
                continue
            for end in ("min", "max"):
                metrics[f"{name}_{quantity}_{end}{unit}"] = entry[f"{quantity}_{end}{unit}"]
                metrics[f"{name}_{quantity}_{end}_at_s"] = entry[f"{quantity}_{end}_at"]
        metrics[f"{name}_mean_cos_incidence"] = entry["mean_cos_incidence"]
        metrics[f"{name}_sun_visible_s"] = entry["sun_visible"]["total_s"]
        for constraint, _ in _CONSTRAINTS:
            if constraint in entry:
                for total in ("count", "total_s", "longest_s"):
                    metrics[f"{name}_{constraint}_{total}"] = entry[constraint][total]
        for union in ("blinded", "sun_in_view"):
            if union in entry:
                for total in _UNION_TOTALS:
                    metrics[f"{name}_{union}_{total}"] = entry[union][total]
    if "eclipses" in summary:
        eclipses = summary["eclipses"]
        metrics["eclipse_count"] = eclipses["shadow"]["count"]
        metrics["eclipse_total_s"] = eclipses["shadow"]["total_s"]
        metrics["umbra_total_s"] = eclipses["umbra"]["total_s"]
        metrics["sunlit_fraction"] = eclipses["sunlit_fraction_of_span"]
        metrics["moon_behind_earth_total_s"] = summary["moon_behind_earth"]["total_s"]
    return metrics


def sun_angles_deg(plan: RunPlan, seconds: NDArray[np.float64]) -> NDArray[np.float64]:
    """Each body vector's Sun angle at ``seconds`` (deg, one row per vector): the series
    the envelopes reduce (:func:`attitude.pointing.sampling.pointing_samples`, as the time
    series of ``attitude run`` samples it)."""
    samples = pointing_samples(plan.trajectory, plan.pointing, seconds)
    angles = [np.degrees(item.sun_angle_rad) for item in samples.vectors]
    return np.array(angles).reshape(len(samples.vectors), seconds.size)


def sample_metrics(plan: RunPlan) -> tuple[dict[str, Any], NDArray[np.float64]]:
    """The metrics of one checked scenario: the numbers its ``summary.json`` holds
    (flips, each segment's motion, the largest rate, the pointing extrema, violation
    and eclipse totals), and its Sun-angle series (one row per body vector, deg).

    The largest rate is the summary's, found on the motion
    (``attitude.trajectory.rates``), not on the output grid; a count that was not
    computed (flips not located) is NaN, never 0.
    """
    scenario = plan.scenario
    seconds = scenario.output_seconds()
    motion = motion_summary(plan.trajectory, plan.motion, epochs=False)
    largest = largest_rate_of(plan.motion)
    metrics: dict[str, Any] = {
        "flip_count": _count(motion["flips"]["count"]),
        "max_rate_deg_s": math.nan if largest is None else math.degrees(largest[0]),
    }
    for k, segment in enumerate(motion["segments"]):
        names = _segment_metric_names(k)
        values = [
            segment["motion"],
            segment["body_period_s"],
            segment["flip_count"],
            segment["flip_period_s"],
            segment["nutation_angle_min_deg"],
            segment["nutation_angle_max_deg"],
            segment["nutation_period_s"],
            segment["spin_period_s"],
            segment["precession_period_s"],
            segment["kinetic_energy_J"],
            segment["angular_momentum_norm_N_m_s"],
        ]
        metrics[names[0]] = values[0]
        metrics.update({n: _number(v) for n, v in zip(names[1:], values[1:], strict=True)})
        metrics[names[2]] = _count(segment["flip_count"])
    angles = np.empty((0, seconds.size))
    if not plan.pointing.is_empty:
        metrics.update(pointing_outcome(plan))
        if plan.pointing.body_vectors:
            angles = sun_angles_deg(plan, seconds)
    return metrics, angles


def time_bin_edges(count: int) -> NDArray[np.intp]:
    """Edges (output indices) of min(TIME_BINS, count) bins of nearly equal size."""
    bins = min(TIME_BINS, count)
    return (np.arange(bins + 1) * count) // bins


def angle_extremes(angles_deg: NDArray[np.float64]) -> NDArray[np.uint16]:
    """Each series' minimum and maximum in each time bin, in steps of ANGLE_STEP_DEG:
    shape (vectors, 2, bins)."""
    edges = time_bin_edges(angles_deg.shape[1])[:-1]
    low = np.minimum.reduceat(angles_deg, edges, axis=1)
    high = np.maximum.reduceat(angles_deg, edges, axis=1)
    steps = np.rint(np.stack([low, high], axis=1) / ANGLE_STEP_DEG)
    return np.clip(steps, 0, ANGLE_STEPS).astype(np.uint16)
