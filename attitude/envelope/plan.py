"""An envelope's plan: the scenario and its ``[envelope]`` checked before anything runs
(:func:`plan_envelope`, also run by ``attitude check``), and the job every worker gets
(:func:`make_job`).

The **nominal timeline** is the scenario without its ``control_loss`` and
``control_resume`` events: the laws and slews as planned.  Its state at every failure
instant τ is read once (attitude, rate), and handed off to the free motion with the
wheels' momentum (:func:`attitude.trajectory.handoff.hand_off_states`).  The motion
after a loss runs under the scenario's torques, when it has any (gravity gradient,
burns): a law's controller absorbs them, a free body does not.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.envelope.failure import EnvelopeJob, evaluate_batch, metric_names, motion_after
from attitude.envelope.settings import EnvelopeSettings, failure_times, read_envelope
from attitude.files.scenario_reader import ScenarioFile
from attitude.laws.align_constrain import LawState
from attitude.outputs.formats import OutputChoice
from attitude.pointing.search import orbit_intervals
from attitude.pointing.spec import PointingSpec, for_scenario
from attitude.report.plan import RunPlan, plan_run
from attitude.scenario.events import State
from attitude.scenario.modes import ControlLoss, ControlResume, Wheels
from attitude.scenario.scenario import InitialState, Scenario
from attitude.trajectory.handoff import hand_off_states
from attitude.trajectory.modes import _gyrostat_step, uses_laws
from attitude.trajectory.torqued import scenario_torque_models
from attitude.trajectory.trajectory import propagate

__all__ = [
    "EnvelopePlan",
    "check_envelope_table",
    "failure_cost_s",
    "make_job",
    "nominal_scenario",
    "plan_envelope",
]

# The columns before the metrics, and after them.
LEADING = ("failure", "tau_s", "epoch_utc", "mode")
TRAILING = ("status", "error")


@dataclass
class EnvelopePlan:
    """An envelope checked: the scenario (``name`` for the reports), its pointing, the
    settings, the failure instants ``seconds`` and the wheels at each loss."""

    name: str
    file: str
    scenario: Scenario
    pointing: PointingSpec
    settings: EnvelopeSettings
    seconds: NDArray[np.float64]
    wheels: Wheels

    @property
    def count(self) -> int:
        return int(self.seconds.size)

    @property
    def metrics(self) -> list[str]:
        return metric_names(self.pointing)

    @property
    def columns(self) -> list[str]:
        return [*LEADING, *self.metrics, *TRAILING]

    def describe(self) -> list[str]:
        s = self.settings
        when = (
            f"every {s.every:g} s over the nominal timeline"
            if s.every is not None
            else "at the listed times"
        )
        return [
            f"envelope: {self.count:,} control losses {when}, {s.window:g} s of motion after each",
            f"  {self.wheels.describe()}",
            f"  panels' power lost below {s.power_threshold:g} of full; "
            f"{len(self.metrics)} metrics a failure",
        ]


def plan_envelope(
    scenario: Scenario | ScenarioFile,
    pointing: PointingSpec | None = None,
    settings: EnvelopeSettings | None = None,
    plan: RunPlan | None = None,
) -> EnvelopePlan:
    """Check an envelope as ``attitude check`` does: the scenario as a run checks it
    (``plan``, from :func:`attitude.report.plan.plan_run` if not given), the settings
    (``settings``, else the file's ``[envelope]`` table), against the scenario."""
    if isinstance(scenario, ScenarioFile):
        loaded = scenario
        pointing = loaded.pointing if pointing is None else pointing
        settings = read_envelope(loaded) if settings is None else settings
        name, file, scenario = loaded.scenario.name, loaded.path.name, loaded.scenario
    else:
        name, file = scenario.name, ""
        if settings is None:
            raise InputError("give the envelope's settings (an EnvelopeSettings)", key="settings")
    pointing = pointing or PointingSpec()
    # The table against the scenario first (a moment), then the scenario as a run
    # checks it (a propagation of the nominal timeline).
    seconds, wheels = _settings_against(settings, scenario)
    if plan is None:
        plan_run(scenario, pointing, OutputChoice(formats=("csv",)), horizon=False)
    return EnvelopePlan(name, file, scenario, pointing, settings, seconds, wheels)


def check_envelope_table(loaded: ScenarioFile) -> None:
    """The file's ``[envelope]`` table read and checked against its scenario, as
    :func:`plan_envelope` does first: ``attitude check`` says what is wrong with the
    table before checking the rest of the scenario at length."""
    _settings_against(read_envelope(loaded), loaded.scenario)


def _settings_against(
    settings: EnvelopeSettings, scenario: Scenario
) -> tuple[NDArray[np.float64], Wheels]:
    """The failure instants and the wheels of ``settings`` for ``scenario`` (raises
    :class:`InputError` naming the key)."""
    if not uses_laws(scenario):
        raise InputError(
            "an envelope of control losses needs a nominal timeline under attitude laws "
            "(initial_state.law, mode_change events): this scenario moves freely throughout",
            key="envelope",
        )
    seconds = failure_times(settings, scenario)
    wheels = settings.wheels_for(scenario)
    wheels.check_against(scenario.spacecraft.principal_axes.tensor, "envelope")
    return seconds, wheels


def nominal_scenario(scenario: Scenario, stop_s: float | None = None) -> Scenario:
    """``scenario`` without its control losses and resumes (the laws and slews as
    planned), to ``stop_s`` (its own stop by default)."""
    events = [e for _, e in scenario.events if not isinstance(e, ControlLoss | ControlResume)]
    return Scenario(
        scenario.name,
        scenario.spacecraft,
        scenario.epoch,
        scenario.initial_state,
        events,
        duration=scenario.stop_s if stop_s is None else stop_s,
        torques=scenario.torques,
        orbit=scenario.orbit,
    )


def _mode(segment: Any) -> str:
    """The nominal segment in words: its law's name, "slew to" it, or "free"."""
    solver = segment.solver
    law = getattr(solver, "law", None)
    if law is None:
        return "free"
    name = str(getattr(law, "name", type(law).__name__))
    return f"slew to {name}" if getattr(solver, "slew", None) is not None else name


def make_job(plan: EnvelopePlan) -> tuple[EnvelopeJob, list[str], list[str]]:
    """The job of ``plan``: the nominal states at every τ handed off, the span of the
    searches, the splitting's step when the free motion needs one; and, per failure,
    the epoch (UTC) and the nominal mode, for the table."""
    scenario, settings = plan.scenario, plan.settings
    nominal = propagate(nominal_scenario(scenario))
    seconds = plan.seconds
    attitudes = nominal.attitude(seconds)
    rates = nominal.angular_velocity(seconds)
    axes = scenario.spacecraft.principal_axes
    state = LawState(seconds, attitudes, rates, np.zeros_like(rates))
    handed, momenta = hand_off_states(state, axes, plan.wheels)
    stop = float(seconds[-1]) + settings.window
    span = Scenario(
        scenario.name,
        scenario.spacecraft,
        scenario.epoch,
        InitialState(Rotation.identity(), angular_velocity=np.zeros(3)),
        duration=max(stop, scenario.stop_s),
        orbit=scenario.orbit,
    )
    spec = for_scenario(plan.pointing, span)
    models = scenario_torque_models(scenario) if scenario.torques.any else []
    torques = tuple((a, b, model) for a, b, model, _ in models)
    spinning = plan.wheels.case == "spinning"
    step = None
    if spinning or torques:
        # One step for every failure, chosen where the body turns fastest after a loss
        # (the splitting's error grows with the rate): the same table on any workers.
        k = int(np.argmax(np.linalg.norm(momenta, axis=1)))
        worst = State(handed[k], momenta[k], axes)
        τ = float(seconds[k])
        step = _gyrostat_step(
            worst,
            τ,
            τ + settings.window,
            [m for a, b, m in torques if a < τ + settings.window and b > τ],
            scenario.torques,
            plan.wheels.momentum_vector if spinning else None,
        ).step
    job = EnvelopeJob(
        span,
        spec,
        seconds,
        handed.as_quat(),
        momenta,
        rates,
        plan.wheels,
        settings.window,
        settings.power_threshold,
        torques,
        step,
        int(scenario.torques.order),
        tuple(plan.metrics),
    )
    # The eclipses and the Moon behind the Earth depend on the orbit alone: found once
    # over the whole span, each window takes its part.
    orbit = orbit_intervals(motion_after(job, 0), spec, 0.0, span.stop_s)
    job = dataclasses.replace(job, orbit=orbit)
    index = nominal.segment_index(seconds)
    modes = [_mode(nominal.segments[i]) for i in index]
    epochs = [str(text) for text in np.atleast_1d(scenario.iso(seconds))]
    return job, epochs, modes


def failure_cost_s(plan: EnvelopePlan, timed: int = 2) -> float:
    """The CPU seconds of one failure, for ``attitude check``'s time estimate: the job
    of ``timed`` of the plan's failure times (spread over them) made and computed in
    this process, as the job times its first ones.  An upper bound of a long job's
    cost a failure: the surroundings a worker computes once for its failures count
    here whole."""
    few = dataclasses.replace(plan, seconds=plan.seconds[:: max(1, plan.count // timed)][:timed])
    job, _, _ = make_job(few)
    return evaluate_batch(job, 0, job.count).compute_s / job.count
