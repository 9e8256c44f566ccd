"""Everything a run checks before it samples: one path for ``attitude check`` and ``run``.

``plan_run(scenario, pointing)`` propagates the scenario (the exact solver segments,
refused where the motion is faster than TT seconds can follow), analyses each
segment (flips counted, not listed), checks the pointing (the orbit source over the
span, the Sun and Moon ephemeris with the interpolation's margins), counts the output
samples and estimates the outputs' size against the memory available.  It notes an
output step that undersamples the motion (more than a tenth of its shortest period).
What it refuses, a run would have refused later, after computing; what it returns is
what the run uses.
Errors are ``attitude.errors.InputError`` whose message starts with the scenario key.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from attitude.motion_analysis import SegmentMotion, analyze
from attitude.output_budget import OutputBudget, check_fits, estimate
from attitude.pointing import (
    CHUNK_POINTS,
    PointingSpec,
    check_pointing,
    undersampling_note,
)
from attitude.scenario import Scenario
from attitude.trajectory import Trajectory, propagate

__all__ = ["RunPlan", "plan_run"]


@dataclass
class RunPlan:
    """A scenario checked for a run: its trajectory, motion, output size and notes."""

    scenario: Scenario
    pointing: PointingSpec
    trajectory: Trajectory
    motion: list[SegmentMotion]
    budget: OutputBudget
    notes: list[str] = field(default_factory=list)


def plan_run(scenario: Scenario, pointing: PointingSpec | None = None) -> RunPlan:
    """Check ``scenario`` (and ``pointing``) as a run would, up to the sampling."""
    pointing = pointing or PointingSpec()
    samples = scenario.output_count()
    trajectory = propagate(scenario)
    # The memory check comes before the analysis and the pointing checks, which do
    # not depend on the output grid but can take a while on a long span.  The
    # pointing's search runs in chunks: its memory is one chunk's, whatever the span.
    grid = 0 if pointing.is_empty else CHUNK_POINTS
    budget = estimate(samples, grid, len(pointing.body_vectors), pointing.orbit is not None)
    check_fits(budget)
    motion = analyze(trajectory)
    notes = check_pointing(trajectory, pointing)
    undersampled = undersampling_note(trajectory, motion)
    if undersampled:
        notes.append(undersampled)
    return RunPlan(scenario, pointing, trajectory, motion, budget, notes)
