"""The size estimate of a run (attitude.outputs.budget) against what the writers write.

The disk check before a run counts the time series' columns from the pointing spec
(attitude.outputs.csv.pointing_column_count); it is compared here with the columns the
writer actually produces (pointing_columns of real samples) for every shape of spec,
and the CSV estimate with the size of a CSV written by a run.
"""

import copy
from pathlib import Path

import numpy as np
import pytest

from attitude.files.scenario_reader import load_scenario, scenario_from_document
from attitude.outputs.csv import pointing_column_count, pointing_columns
from attitude.outputs.formats import OutputChoice
from attitude.pointing.sampling import pointing_samples
from attitude.pointing.spec import BodyVector, PointingSpec
from attitude.report.plan import plan_run
from attitude.report.run import write_report
from attitude.trajectory.trajectory import propagate

ROOT = Path(__file__).parents[1]
SPINNER = ROOT / "scenarios" / "spinner_thruster_pulse.toml"


def _vectors(constraints: bool) -> list[BodyVector]:
    if not constraints:
        return [BodyVector("a", [1.0, 0.0, 0.0]), BodyVector("b", [0.0, 0.0, 1.0], kind="panel")]
    return [
        BodyVector("a", [1.0, 0.0, 0.0], np.radians(30.0)),
        BodyVector(
            "b",
            [0.0, 1.0, 0.0],
            moon_exclusion_half_angle_rad=np.radians(10.0),
            earth_limb_exclusion_angle_rad=np.radians(15.0),
        ),
        BodyVector("c", [0.0, 0.0, 1.0], kind="panel"),
    ]


@pytest.mark.parametrize("on_orbit", [False, True])
@pytest.mark.parametrize("constraints", [False, True])
@pytest.mark.parametrize("euler", [None, "ZYX"])
def test_column_count_is_what_the_writer_writes(on_orbit, constraints, euler):
    if not on_orbit and (euler or constraints):
        # An Earth-limb exclusion and LVLH angles need an orbit (refused without one).
        vectors = _vectors(False)
        euler = None
    else:
        vectors = _vectors(constraints)
    file = load_scenario(SPINNER)
    if not on_orbit:  # at the Earth's centre: no orbit for the scenario either
        document = copy.deepcopy(file.document)
        del document["pointing"]["tle"]
        file = scenario_from_document(SPINNER, document)
    spec = PointingSpec(vectors, file.pointing.orbit, lvlh_euler_sequence=euler)
    trajectory = propagate(file.scenario)
    samples = pointing_samples(trajectory, spec, np.array([0.0, 1.0, 2.0]))
    assert pointing_column_count(spec) == len(pointing_columns(samples))


def test_csv_estimate_covers_the_written_file(tmp_path):
    # Ten minutes of the spinner at 1 s with its three vectors on the TLE orbit.
    text = SPINNER.read_text().replace("duration = ", "duration = 600.0 # ", 1)
    path = tmp_path / "short.toml"
    path.write_text(text)
    file = load_scenario(path)
    outputs = OutputChoice(("csv",))
    plan = plan_run(file.scenario, file.pointing, outputs)
    write_report(file.scenario, tmp_path / "out", file.pointing, plan=plan, outputs=outputs)
    written = (tmp_path / "out" / "timeseries.csv").stat().st_size
    estimated = plan.budget.files["timeseries.csv"]
    # An estimate for a disk check: not below what is written, and not far above it.
    assert written <= estimated <= 1.6 * written
