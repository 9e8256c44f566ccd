"""Everything a run checks before it samples: one path for ``attitude check`` and ``run``.

``plan_run(scenario, pointing, outputs)`` propagates the scenario (the exact solver
segments, refused where the motion is faster than TT seconds can follow), analyses
each segment (flips counted, not listed), checks the pointing (the orbit source over
the span, the Sun and Moon ephemeris with the interpolation's margins, the size of
the exact search), chooses the AEM's records for its tolerance, counts the output
samples and estimates the outputs' sizes and the (constant) memory of the streamed
run.  It notes an output step that undersamples the motion (more than a tenth of its
shortest period).  Segments under torques are propagated at the step given or chosen
for the accuracy, and the run's error is estimated (``attitude.trajectory.steps``);
a scenario with an orbit that leaves the gravity gradient out (torque-free, or burns
alone) gets its validity horizon (``attitude.trajectory.horizon.validity_horizon``).
What it refuses, a run would have refused later, after computing; what it returns is
what the run uses.  ``attitude check`` plans with ``check=True``: the same path
within a budget of steps, with what lies beyond it predicted (a run that measures
more can still refuse an accuracy that its measurement says is missed).  Errors are
``attitude.base.errors.InputError`` whose ``key`` is the scenario key that holds the
bad value.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field

from attitude.base.errors import InputError, LawRateWarning
from attitude.outputs.aem_sampling import AemPlan, check_time_tags, plan_aem
from attitude.outputs.budget import OutputBudget, check_fits, estimate
from attitude.outputs.csv import pointing_column_count
from attitude.outputs.formats import OutputChoice
from attitude.outputs.parquet import check_span
from attitude.pointing.search import SearchGrid, check_pointing
from attitude.pointing.spec import PointingSpec, for_scenario
from attitude.report.beside import Beside
from attitude.scenario.scenario import Scenario
from attitude.trajectory.guided import GUIDED, GuidedMotion
from attitude.trajectory.horizon import (
    ValidityHorizon,
    screened_horizon,
    splitting_horizon,
    validity_horizon,
)
from attitude.trajectory.modes import uses_laws
from attitude.trajectory.motion import SegmentMotion, analyze, undersampling_note
from attitude.trajectory.steps import CHECK_BUDGET_S
from attitude.trajectory.trajectory import Trajectory, propagate

__all__ = ["LAW_RATE_WARNING_DEG_S", "RunPlan", "horizon_beside", "plan_run"]

# With no slew limits given, a law that demands more than this body rate (deg/s) is
# warned of: agile spacecraft turn at about a degree a second.
LAW_RATE_WARNING_DEG_S = 1.0


@dataclass
class RunPlan:
    """A scenario checked for a run: its trajectory, motion, outputs, sizes and notes."""

    scenario: Scenario
    pointing: PointingSpec
    trajectory: Trajectory
    motion: list[SegmentMotion]
    budget: OutputBudget
    notes: list[str] = field(default_factory=list)
    outputs: OutputChoice = field(default_factory=OutputChoice)
    aem: AemPlan | None = None
    search: SearchGrid | None = None  # the pointing's exact search (None without pointing)
    horizon: ValidityHorizon | None = None  # on an orbit, no gravity gradient: how long it holds
    # The horizon is wanted but left for the run to compute (plan_run(horizon=False)).
    horizon_deferred: bool = False
    # Planned for `attitude check` (plan_run(check=True)): predictions where the run computes.
    check: bool = False


def plan_run(
    scenario: Scenario,
    pointing: PointingSpec | None = None,
    outputs: OutputChoice | None = None,
    horizon: bool = True,
    progress: Callable[[str], None] | None = None,
    check: bool = False,
    free_memory: bool = True,
) -> RunPlan:
    """Check ``scenario`` (``pointing``, ``outputs``) as a run would, up to the sampling.

    ``horizon=False``: the validity horizon, when there is one, is not computed here
    (``horizon_deferred`` says it is wanted): a run computes it beside its outputs
    (``attitude.report.run``), since it checks nothing and takes as long as a day's outputs.
    ``progress(text)`` is told each stage as it starts (the command line's stderr).

    ``check``: for ``attitude check``, which answers in seconds: under torques, the
    step search within its budget (``attitude.trajectory.steps``: what it refuses, the
    run refuses too), the run's error measured as far as the budget goes and predicted
    beyond, a run longer than the budget propagated at a longer step for the checks
    that read the motion (``Trajectory.approximate``), and the flips under torques
    left to the run.

    ``free_memory=False``: the run's memory is not checked against the memory free
    now (a job's sample, whose row must not depend on the machine's free memory: the
    job checks its nominal's once, before it starts).
    """
    say = progress or (lambda text: None)
    # The scenario's orbit, when the pointing gives none (the orbit is given once).
    pointing = for_scenario(pointing or PointingSpec(), scenario)
    outputs = outputs or OutputChoice()
    samples = scenario.output_count()
    if "parquet" in outputs:
        check_span(scenario.start_s, scenario.stop_s, "--formats parquet")
    _check_gravity_gradient_orbit(scenario)
    say(_propagating(scenario, check))
    trajectory = _propagated(scenario, outputs, check)
    # The size and memory checks come before the analysis and the pointing checks,
    # which do not depend on the output grid but can take a while on a long span.
    vectors, on_orbit = len(pointing.body_vectors), pointing.on_orbit
    columns = pointing_column_count(pointing) if not pointing.is_empty else 0
    budget = estimate(
        samples, 0, vectors, on_orbit, outputs.formats, aem_records=0, pointing_columns=columns
    )
    if free_memory:
        check_fits(budget)
    # The run's estimated error (a given step: measured now; check: within its budget).
    if not check and trajectory.steps is not None and trajectory.steps.measurement is None:
        say("estimating the propagation's error: the run again at twice the step")
    steps = trajectory.steps if check else trajectory.measured()
    if steps is not None and steps.measurement is not None:
        if not math.isfinite(steps.measurement.estimate_rad):
            raise InputError(
                f"at {steps.step_s:g} s the propagation has no finite error estimate (the "
                "run at twice the step runs away): give a smaller step or an accuracy",
                key="torques.step",
                value=steps.step_s,
            )
    if "aem" in outputs:  # from the rate bounds: the analysis of a runaway motion is long
        check_time_tags(
            trajectory,
            scenario.start_s,
            scenario.stop_s,
            outputs.aem_tolerance_rad,
            outputs.tolerance_key,
        )
    say("analysing the motion (flips, nutation, spin, precession)")
    motion = analyze(trajectory, locate=not check)
    if not pointing.is_empty:
        say("checking the pointing: the orbit, the Sun and the Moon over the span")
    notes, search = check_pointing(trajectory, pointing)
    # Attitude laws: ground sites never seen, the Earth orientation table's coverage.
    guided = [n for s in trajectory.segments for n in getattr(s.solver, "notes", ())]
    notes = [*dict.fromkeys(guided), *notes]
    _warn_of_fast_laws(scenario, trajectory)
    undersampled = undersampling_note(trajectory, motion)
    if undersampled:
        notes.append(undersampled)
    found = None
    # On an orbit, unless the gravity gradient is modelled: a torque-free run, or burns
    # alone, neglects it.
    wanted = pointing.orbit is not None and scenario.torques.gravity_gradient is None
    # Under a law the controller holds the attitude: only free segments neglect anything.
    wanted = wanted and any(s.solver.formula not in GUIDED for s in trajectory.segments)
    if wanted and horizon:
        say("the validity horizon: the run again under the gravity gradient it leaves out")
        found = validity_horizon(trajectory, pointing.orbit)
    aem = None
    if "aem" in outputs:
        say(f"choosing the AEM's records for {outputs.aem_tolerance_rad:g} rad")
        aem = plan_aem(
            trajectory,
            motion,
            scenario.start_s,
            scenario.stop_s,
            outputs.aem_tolerance_rad,
            outputs.tolerance_key,
            budget_s=CHECK_BUDGET_S if check else None,
        )
    budget = estimate(
        samples,
        0 if search is None else search.turn_points,
        vectors,
        on_orbit,
        outputs.formats,
        0 if aem is None else aem.records,
        pointing_columns=columns,
    )
    return RunPlan(
        scenario,
        pointing,
        trajectory,
        motion,
        budget,
        notes,
        outputs,
        aem,
        search,
        found,
        horizon_deferred=wanted and not horizon,
        check=check,
    )


def _warn_of_fast_laws(scenario: Scenario, trajectory: Trajectory) -> None:
    """A :class:`LawRateWarning` for each law whose demanded body rate peaks beyond the
    scenario's slew limits (the largest ``max_rate`` given), or, with none given,
    beyond :data:`LAW_RATE_WARNING_DEG_S`: Sun yaw steering near β = 0 turns the yaw by
    180° in minutes (2.4 deg/s at β = 1.6°), a ground site passed overhead at low
    altitude needs its v/h.  The peak is the law's largest |ω| over its segment
    (``GuidedMotion.largest_rate``: sampled, refined by Brent's search)."""
    slews = [getattr(event, "slew", None) for _, event in scenario.events]
    limits = [slew.max_rate for slew in slews if slew is not None]
    limit = max(limits, default=math.radians(LAW_RATE_WARNING_DEG_S))
    for segment in trajectory.segments:
        solver = segment.solver
        # A slew keeps its own limits; the exact and the torqued motion follow no law.
        if not isinstance(solver, GuidedMotion) or solver.formula != "guided":
            continue
        rate, at = solver.largest_rate(segment.start_s, segment.end_s)
        if not rate > limit:
            continue
        beyond = (
            f"beyond the slews' max_rate of {math.degrees(limit):.4g} deg/s"
            if limits
            else f"more than {LAW_RATE_WARNING_DEG_S:g} deg/s (no slew limits are given to "
            "compare it with)"
        )
        warnings.warn(
            LawRateWarning(
                f"the {solver.law.name} law ({solver.law.describe()}) demands a body rate "
                f"of up to {math.degrees(rate):.3g} deg/s, at {scenario.format_epoch(at)} "
                f"(t = {at:.6g} s), {beyond}: the run follows the law as it is",
                key=solver.key,
            ),
            stacklevel=2,
        )


def _propagated(scenario: Scenario, outputs: OutputChoice, check: bool) -> Trajectory:
    """The scenario propagated for the plan.  A run under torques first takes check's
    path (:func:`propagate` with ``check``: the step search, or the estimate at a given
    step, within check's CPU budget; its tries are the run's own): within the budget
    that is the run itself, bit for bit, and is kept; past it, check's motion at a
    longer step says what check refuses from it (the AEM's 1 ns time tags of a runaway
    burn) before the run propagates for minutes, so that run refuses it at once with
    check's line.  The full propagation follows."""
    if check or not scenario.torques.any:
        return propagate(scenario, check=check)
    preview = propagate(scenario, check=True)
    steps = preview.steps
    found = None if steps is None else steps.measurement
    if not preview.approximate and steps is not None and steps.settled:
        if found is not None and found.complete:
            return preview
    if "aem" in outputs:
        check_time_tags(
            preview,
            scenario.start_s,
            scenario.stop_s,
            outputs.aem_tolerance_rad,
            outputs.tolerance_key,
        )
    return propagate(scenario)


def _propagating(scenario: Scenario, check: bool) -> str:
    """The propagation stage in words: the segments, how many are under torques, and
    how their step is set (chosen for the accuracy, the run's error estimated on the
    way: ``attitude.trajectory.steps``)."""
    segments = len(scenario.events) + 1
    text = f"propagating {segments} segment{'s' if segments > 1 else ''}"
    if uses_laws(scenario):  # a slew adds a segment of its own, known once it is made
        count = len(scenario.events)
        text = f"propagating the modes through {count} event{'s' if count != 1 else ''}"
    what = []
    if scenario.torques.gravity_gradient is not None:
        what.append("gravity gradient")
    if scenario.burns:
        what.append(f"{len(scenario.burns)} burn{'s' if len(scenario.burns) > 1 else ''}")
    if not what:
        return text
    text += f" under {' and '.join(what)} (splitting)"
    torques = scenario.torques
    within = f" within {CHECK_BUDGET_S:g} s of CPU" if check else ""
    if torques.step is not None:
        return text + (
            f" at {torques.step:g} s, and at twice it for the error estimate{within}"
            if check
            else f" at {torques.step:g} s"
        )
    return text + (
        f", at the step whose error estimate (the run at h and 2h) meets "
        f"{torques.accuracy_rad:g} rad{within}"
    )


def _check_gravity_gradient_orbit(scenario: Scenario) -> None:
    """The orbit the gravity gradient is computed on covers the span (an OEM file that
    ends early is refused here, naming its key, before the torqued propagation would
    stop at the first step outside it); its notes are the pointing's to give."""
    orbit = scenario.torques.gravity_gradient
    if orbit is not None and hasattr(orbit, "check_span"):
        orbit.check_span(scenario.times(scenario.start_s), scenario.times(scenario.stop_s))


def horizon_beside(plan: RunPlan) -> Beside[ValidityHorizon] | None:
    """The validity horizon ``plan`` left to the run, or None when the plan has none to
    compute.  A torque-free span the averaged kicks find clear is answered here, in
    this process (:func:`attitude.trajectory.horizon.screened_horizon`: a tenth of a
    second for a day, less than forking would cost); otherwise the splitting is
    started now in a process beside this one (:class:`attitude.report.beside.Beside`;
    use it as a context manager).  The command line calls this before it imports the
    writers and the plots, so that the splitting, the longest single job of a report
    that needs it, starts as early as it can."""
    if not plan.horizon_deferred:
        return None
    screened = screened_horizon(plan.trajectory, plan.pointing.orbit)
    if screened is not None:
        return Beside.known(screened)
    return Beside(splitting_horizon, plan.trajectory, plan.pointing.orbit)
