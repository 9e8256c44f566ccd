"""The AEM ends a segment wherever the motion is not smooth, whoever says so.

A segment's solver declares where its motion changes law with a method
``breakpoints(start_s, end_s)`` (``attitude.trajectory.segments``): the torqued
segments for their torques' switches, and any future kind of segment (a guidance
mode) for its own.  Here an exact segment declares a mode change that its motion does
not have: the AEM is cut there all the same, both sides sampled for the tolerance, and
the file, parsed by ccsds-ndm-py, starts a segment at that epoch with the comment
that says why.
"""

from pathlib import Path

from aem_read_back import read_back

from attitude.environment.epoch_texts import EpochTexts
from attitude.environment.timescales import tt_seconds
from attitude.files.scenario_reader import load_scenario
from attitude.outputs.aem_sampling import plan_aem, write_planned_aem
from attitude.solver.euler_solver import EulerSolver
from attitude.trajectory.motion import analyze
from attitude.trajectory.segments import Segment
from attitude.trajectory.trajectory import Trajectory, propagate

ROOT = Path(__file__).parents[1]
MODE_S = 150.0


class _Guided(EulerSolver):
    """The exact motion, with a mode change declared at MODE_S."""

    def breakpoints(self, start_s, end_s):
        return [(MODE_S, "a guidance mode starts")]


def test_a_declared_breakpoint_ends_an_aem_segment(tmp_path):
    scenario = load_scenario(ROOT / "scenarios" / "boom_deployment.toml").scenario
    plain = propagate(scenario)
    first = plain.segments[0]
    assert first.start_s < MODE_S < first.end_s
    state = first.state
    guided = _Guided(state.inertia.tensor, state.angular_momentum, state.attitude, t0=0.0)
    segments = [Segment(first.start_s, first.end_s, guided, state), *plain.segments[1:]]
    trajectory = Trajectory(scenario, segments)
    assert [b.time_s for b in trajectory.breakpoints()] == [MODE_S]

    plan = plan_aem(trajectory, analyze(trajectory), scenario.start_s, scenario.stop_s)
    starts = [item.start_s for item in plan.segments]
    assert MODE_S in starts and len(plan.segments) == len(plain.segments) + 1
    path = tmp_path / "attitude.aem"
    with open(path, "wb") as stream:
        written = write_planned_aem(
            stream, trajectory, plan, EpochTexts(scenario.epoch), object_name="X", object_id="Y"
        )
    assert 0.0 < written.measured_error_rad <= plan.tolerance_rad
    parsed, _ = read_back(path)
    first_epochs = [float(tt_seconds(s.times[:1], scenario.epoch)[0]) for s in parsed]
    index = min(range(len(parsed)), key=lambda k: abs(first_epochs[k] - MODE_S))
    assert abs(first_epochs[index] - MODE_S) < 1e-9
    assert "a guidance mode starts" in path.read_text()
