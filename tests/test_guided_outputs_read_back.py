"""A run that mixes guided, slewing, free and captured segments, its outputs read back
by readers written apart from ours.

The scenario (built in Python, no TOML): nadir with zero-Doppler steering, a slew to
Sun pointing, a control loss with locked wheels (the exact solver), a capture back
to nadir through a slew from the tumble (control_resume), on a sun-synchronous orbit,
with a star tracker and a panel.

1. ``attitude.aem`` read by ccsds-ndm-py (``aem_read_back``) and interpolated as it
   declares at every mid-step of its records: within the tolerance it states; and its
   segments end at every non-smooth instant (each mode change, slew switch, control
   loss and resume).
2. ``timeseries.csv`` read by numpy: on guided segments the quaternions and rates are
   the law's own (evaluated apart, from the law bound here), on slews the slew's.
3. The pointing's extrema in summary.json (the exact search on guided segments, with
   their rate bound) against the same quantities sampled every 0.1 s: never less
   extreme than a sample, and within 1e-4 deg of the refined sampled extremum.
4. summary.json states each slew's angle and duration, the law of each segment and
   the control loss.
5. The search of the mixed run (the free segment after the loss on the motion's
   structure, the guided and slewing ones on the grid with their rate bounds) against
   the grid search of every segment: the same intervals and extrema.
"""

from __future__ import annotations

import dataclasses
import json
import math

import astropy.units as u
import numpy as np
import pytest
from aem_read_back import interpolate_as_declared, read_back, rotation_angle
from csv_read_back import read_csv
from eo_orbit import EPOCH, ORBIT

from attitude import (
    BodyVector,
    InitialState,
    NadirLaw,
    PointingSpec,
    Scenario,
    Spacecraft,
    SunLaw,
    propagate,
    write_report,
)
from attitude.environment.timescales import tt_seconds
from attitude.laws.slews import SlewLimits
from attitude.outputs.formats import OutputChoice
from attitude.pointing.sampling import pointing_samples
from attitude.pointing.search import pointing_analysis, search_grid
from attitude.scenario.modes import ControlLoss, ControlResume, ModeChange, Wheels

LIMITS = SlewLimits(1.0 * u.deg / u.s, 0.05 * u.deg / u.s**2)
NADIR = NadirLaw("zero_doppler")
SUN = SunLaw("-z", "+x", "orbit_normal")


def _scenario() -> Scenario:
    return Scenario(
        "guided outputs",
        Spacecraft("eo", [820.0, 1040.0, 610.0]),
        EPOCH,
        InitialState(law=NADIR),
        [
            ModeChange(600.0, SUN, LIMITS, label="charging"),
            ControlLoss(1500.0, Wheels("locked", [0.0, 2.0, 0.0])),
            ControlResume(2100.0, NADIR, LIMITS),
        ],
        duration=3000.0,
        step=5.0,
        orbit=ORBIT,
    )


SPEC = PointingSpec(
    [
        BodyVector(
            "star_tracker",
            [0.0, -0.6427876096865393, -0.766044443118978],
            math.radians(30.0),
            kind="star_tracker",
        ),
        BodyVector("panel", [0.0, 0.0, -1.0], kind="panel"),
    ]
)


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    out = tmp_path_factory.mktemp("guided") / "out"
    scenario = _scenario()
    summary = write_report(scenario, out, SPEC, outputs=OutputChoice(("csv", "aem")))
    return scenario, propagate(scenario), out, summary


def test_aem_within_its_tolerance_and_cut_at_every_non_smooth_instant(run):
    scenario, trajectory, out, summary = run
    tolerance = summary["outputs"]["aem"]["tolerance_rad"]
    segments, _ = read_back(out / "attitude.aem")
    worst = 0.0
    starts = []
    for segment in segments:
        x = tt_seconds(segment.times, scenario.epoch)
        starts.append(float(x[0]))
        t_mid = 0.5 * (x[1:] + x[:-1])
        exact = trajectory.attitude_quaternion(t_mid)
        worst = max(
            worst,
            float(
                np.max(
                    rotation_angle(interpolate_as_declared(segment, t_mid, scenario.epoch), exact)
                )
            ),
        )
    assert worst <= tolerance, worst
    expected = {0.0, 600.0, 1500.0, 2100.0}
    for item in summary["guidance"]["slews"]:
        slew = trajectory.segments[item["segment"]].solver.slew
        expected |= {
            slew.end_s,
            slew.start_s + slew.accelerating_s,
            slew.end_s - slew.accelerating_s,
        }
        expected.add(slew.start_s + slew.correction_s)
    for t in expected:
        assert np.min(np.abs(np.array(starts) - t)) < 1e-6, (t, starts)


def test_csv_holds_the_laws_own_states(run):
    _, trajectory, out, _ = run
    table = read_csv(out / "timeseries.csv")
    t = table["t_s"]
    q = np.stack([table[f"q_body_to_icrf_{c}"] for c in "wxyz"], axis=1)
    ω = np.stack([table[f"omega_body_{c}_rad_s"] for c in "xyz"], axis=1)
    # Nadir from the epoch to the mode change, Sun pointing after the first slew.
    slew = trajectory.segments[1].solver.slew
    for law, a, b in ((NADIR, 0.0, 600.0 - 1e-6), (SUN, slew.end_s + 1e-6, 1500.0 - 1e-6)):
        inside = (t >= a) & (t <= b)
        state = law.bind(EPOCH, a, b, ORBIT).state(t[inside])
        assert np.max(rotation_angle(q[inside], state.attitude.as_quat(scalar_first=True))) < 1e-15
        assert np.max(np.abs(ω[inside] - state.angular_velocity)) < 1e-18
    inside = (t > 600.0) & (t < slew.end_s)
    state = slew.state(t[inside])
    assert np.max(rotation_angle(q[inside], state.attitude.as_quat(scalar_first=True))) < 1e-15
    assert np.max(np.linalg.norm(ω, axis=1)) <= LIMITS.max_rate * (1 + 1e-12)


def _refined(t, values, largest):
    """The extreme sample refined by the parabola through it and its neighbours."""
    k = int(np.argmax(values) if largest else np.argmin(values))
    if k == 0 or k == values.size - 1:
        return float(values[k])
    y0, y1, y2 = values[k - 1 : k + 2]
    denominator = y0 - 2 * y1 + y2
    if denominator == 0:
        return float(y1)
    return float(y1 - 0.125 * (y0 - y2) ** 2 / denominator)


@pytest.mark.parametrize("vector", ["star_tracker", "panel"])
def test_pointing_extrema_against_dense_sampling(run, vector):
    _, trajectory, _, summary = run
    entry = summary["pointing"]["body_vectors"][vector]
    t = np.arange(0.0, 3000.0, 0.1)
    samples = pointing_samples(trajectory, SPEC, t)
    angle = np.degrees(next(v for v in samples.vectors if v.vector.name == vector).sun_angle_rad)
    low, high = entry["sun_angle_min_deg"], entry["sun_angle_max_deg"]
    assert low <= np.min(angle) + 1e-9 and high >= np.max(angle) - 1e-9
    assert abs(low - _refined(t, angle, False)) < 1e-4
    assert abs(high - _refined(t, angle, True)) < 1e-4


def test_summary_states_the_slews_laws_and_control_loss(run):
    _, trajectory, out, _ = run
    on_disk = json.loads((out / "summary.json").read_text())
    guidance = on_disk["guidance"]
    kinds = [s["kind"] for s in guidance["segments"]]
    assert kinds == ["guided", "slew", "guided", "free", "slew", "guided"]
    assert [s["law"] for s in guidance["segments"] if "law" in s] == [
        "nadir",
        "sun",
        "sun",
        "nadir",
        "nadir",
    ]
    assert len(guidance["slews"]) == 2
    for item in guidance["slews"]:
        slew = trajectory.segments[item["segment"]].solver.slew
        assert item["angle_deg"] == pytest.approx(math.degrees(slew.angle_rad), rel=1e-15)
        assert item["duration_s"] == pytest.approx(slew.duration_s, rel=1e-15)
        assert 0.0 < item["duration_s"] < 600.0
    (loss,) = guidance["control_losses"]
    assert loss["wheels"] == "locked" and loss["wheel_momentum_body_N_m_s"] == [0.0, 2.0, 0.0]
    # Locked: the wheels' momentum has passed to the body (I ω jumps by h).
    jump = np.radians(np.array(loss["rate_after_deg_s"]) - np.array(loss["rate_before_deg_s"]))
    assert np.allclose(jump * [820.0, 1040.0, 610.0], [0.0, 2.0, 0.0], atol=1e-12)
    assert on_disk["motion"]["segments"][3]["motion"] in ("periodic", "steady spin")


def test_the_mixed_runs_search_against_the_grid_search(run):
    from test_search_against_grid_search import assert_same

    _, trajectory, _, _ = run
    grid = search_grid(trajectory, SPEC)
    # Only the segment after the loss (locked wheels: torque-free) has a structural plan.
    assert [plan is not None for plan in grid.plans] == [False, False, False, True, False, False]
    structural = pointing_analysis(trajectory, SPEC, grid=grid)
    gridded = pointing_analysis(trajectory, SPEC, grid=dataclasses.replace(grid, plans=()))
    assert_same(structural, gridded)
