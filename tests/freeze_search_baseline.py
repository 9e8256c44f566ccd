"""Freeze the pointing search's results before the structural search, for its tests.

Run in a checkout of the commit to freeze (``tests/data/search_baseline/README.md`` names
it), with that checkout first on the path and no bytecode written into it:

    PYTHONDONTWRITEBYTECODE=1 PYTHONPATH=/path/to/old/checkout \\
        python tests/freeze_search_baseline.py tests/data/search_baseline

For each case (the examples with a pointing, and the issue's tumbler over 20 minutes):
every interval of every body vector (start, end and its flags), the extrema (time and
value), the mean incidence, the eclipses and the search step, as JSON.
``tests/test_search_against_the_search_before_it.py`` reads them.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).parents[1]
EXAMPLES = (
    "spinner_thruster_pulse",
    "nadir_cubesat_star_tracker",
    "tumbling_defunct_satellite",
    "tumbler_gravity_gradient_burn",
)
KINDS = (
    "sun_visible",
    "sun_exclusion",
    "moon_exclusion",
    "earth_limb_exclusion",
    "blinded",
    "sun_in_view",
)


def cases():
    """(name, trajectory, spec) of every case, built by the checkout's own API."""
    from scipy.spatial.transform import Rotation

    from attitude import (
        BodyVector,
        InitialState,
        PointingSpec,
        Scenario,
        Spacecraft,
        load_scenario,
        propagate,
    )

    for name in EXAMPLES:
        loaded = load_scenario(ROOT / "scenarios" / f"{name}.toml")
        yield name, propagate(loaded.scenario), loaded.pointing
    craft = Spacecraft("tumbler", [100.0, 200.0, 300.0])
    state = InitialState(Rotation.identity(), angular_velocity=[0.001, 1.0, 0.001])
    scenario = Scenario("tumbler", craft, "2027-03-20T12:00:00", state, duration=1200.0, step=10.0)
    cone = BodyVector("cone", [0.0, 0.0, 1.0], math.radians(30.0), "star_tracker")
    yield "tumbler_20_min", propagate(scenario), PointingSpec([cone])


def dump(analysis) -> dict:
    def intervals(items):
        return [[i.start_s, i.end_s, i.starts_before, i.ends_after] for i in items]

    out = {
        "search_step_s": analysis.grid.step_s,
        "precision_s": analysis.precision_s,
        "shadow": intervals(analysis.shadow),
        "umbra": intervals(analysis.umbra),
        "moon_hidden": intervals(analysis.moon_hidden),
        "sunlit_fraction_mean": analysis.sunlit_fraction_mean,
        "vectors": {},
    }
    for item in analysis.vectors:
        out["vectors"][item.vector.name] = {
            **{kind: intervals(getattr(item, kind, [])) for kind in KINDS},
            "extrema": {
                q: [low.time_s, low.value, high.time_s, high.value]
                for q, (low, high) in item.extrema.items()
            },
            "mean_cos_incidence": item.mean_cos_incidence,
        }
    return out


def main(folder: str) -> None:
    from attitude import pointing_analysis

    target = Path(folder)
    target.mkdir(parents=True, exist_ok=True)
    commit = subprocess.run(
        ["git", "rev-parse", "HEAD"],
        capture_output=True,
        text=True,
        cwd=Path(sys.modules["attitude"].__file__).parents[1],
    ).stdout.strip()
    for name, trajectory, spec in cases():
        data = dump(pointing_analysis(trajectory, spec))
        data["commit"] = commit
        (target / f"{name}.json").write_text(json.dumps(data, indent=1) + "\n")
        print(name, "frozen at", commit)


if __name__ == "__main__":
    main(sys.argv[1])
