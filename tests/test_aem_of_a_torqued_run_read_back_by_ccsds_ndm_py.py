"""The AEM of a run under torques, read back by an independent parser, holds what it states.

``scenarios/tumbler_gravity_gradient_burn.toml`` (gravity gradient, a 5-minute burn
across an inertia change) is run with ``--formats aem``; ``attitude.aem`` is parsed by
ccsds-ndm-py (``aem_read_back``) and every segment is interpolated the way its metadata
declares (LAGRANGE of its INTERPOLATION_DEGREE, Neville's recurrence written in the
test) at 16 points inside every interval.  The authority is the propagated attitude of
the same scenario (each segment's own solver, as the file's segments end at the event
with the pre-event state).

What is checked:

- the burn's start and stop are boundaries of AEM segments (the rate's derivative jumps
  there: a polynomial across was 8.5e-5 rad off, for a tolerance of 1e-6);
- the error read back stays within the file's tolerance, and within the largest error
  that ``summary.json`` states for each segment (a figure measured on the file, not an
  estimate), at the default tolerance and at 1e-8 rad.
"""

import json
from pathlib import Path

import numpy as np
import pytest
from aem_read_back import interpolate_as_declared, read_back, rotation_angle

from attitude.cli.main import main
from attitude.environment.timescales import tt_seconds
from attitude.files.scenario_reader import load_scenario
from attitude.trajectory.trajectory import propagate

EXAMPLE = Path(__file__).parents[1] / "scenarios" / "tumbler_gravity_gradient_burn.toml"
BURN_S = (1800.0, 2100.0)
EVENT_S = 1950.0


@pytest.fixture(scope="module")
def trajectory():
    loaded = load_scenario(EXAMPLE)
    return loaded.scenario, propagate(loaded.scenario)


@pytest.mark.parametrize("tolerance", [None, "1e-8 rad"])
def test_the_file_read_back_holds_its_stated_error(trajectory, tolerance, tmp_path):
    scenario, motion = trajectory
    out = tmp_path / "out"
    argv = ["run", str(EXAMPLE), "--out", str(out), "--formats", "aem", "--quiet"]
    if tolerance is not None:
        argv += ["--aem-tolerance", tolerance]
    assert main(argv) == 0
    summary = json.loads((out / "summary.json").read_text())
    aem = summary["outputs"]["aem"]
    stated = aem["segments"]
    segments, _ = read_back(out / "attitude.aem")
    assert len(segments) == len(stated)

    # Every breakpoint of the motion, and the event, is a boundary of AEM segments.
    starts = [float(tt_seconds(s.times[:1], scenario.epoch)[0]) for s in segments]
    ends = [float(tt_seconds(s.times[-1:], scenario.epoch)[0]) for s in segments]
    for boundary in (*BURN_S, EVENT_S):
        assert min(abs(np.array(starts) - boundary)) < 1e-6, (boundary, starts)
        assert min(abs(np.array(ends) - boundary)) < 1e-6, (boundary, ends)

    worst = 0.0
    fractions = np.linspace(0.0, 1.0, 18)[1:-1]
    for segment, entry in zip(segments, stated, strict=True):
        x = tt_seconds(segment.times, scenario.epoch)
        t = (x[:-1, None] + fractions[None, :] * np.diff(x)[:, None]).ravel()
        solver = motion.segments[entry["segment"]].solver
        error = rotation_angle(
            interpolate_as_declared(segment, t, scenario.epoch), solver.attitude_quaternion(t)
        )
        # The stated figure is a bound of what a reader gets, measured on the file.
        assert np.max(error) <= entry["largest_error_rad"], (entry, float(np.max(error)))
        worst = max(worst, float(np.max(error)))
    assert worst <= aem["largest_error_rad"] <= aem["tolerance_rad"]
    # Measured, not a loose bound: within a few percent of what the reader sees.
    assert aem["largest_error_rad"] <= 1.2 * worst
