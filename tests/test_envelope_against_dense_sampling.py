"""The envelope's metrics at a few failure times against a separate run of the motion
after that instant, sampled densely.

The separate run is the scenario itself with a ``control_loss`` event at τ (the mode
walk's own hand-off, :mod:`attitude.trajectory.modes`), propagated by ``propagate`` and
sampled every 0.5 s by ``pointing_samples`` (exact surroundings, no search).  From the
samples: the first sample where each exclusion is violated, the least Sun angle of the
panel, the panels' power fraction (cosine-weighted, lit fraction), the largest rate,
the flips.  The envelope's times are refined to 1 ms, so they precede the first
violated sample by less than one sampling step; its extrema are at most the sampled
ones, and within the curvature between samples.  Both wheel cases: locked (the exact
solver on both sides) and spinning (the gyrostat, each run at its own step).
"""

import math

import numpy as np
import pytest

from attitude import (
    ControlLoss,
    EnvelopeSettings,
    Scenario,
    Wheels,
    load_scenario,
    pointing_samples,
    propagate,
)
from attitude.envelope.failure import evaluate_batch
from attitude.envelope.plan import make_job, plan_envelope

SCENARIO = "scenarios/eo_envelope.toml"
STEP_S = 0.5
WINDOW_S = 1500.0
TAUS = (600.0, 1920.0, 3300.0)  # imaging, a slew to the station pass's end, charging


def _separate_run(loaded, τ: float, wheels: Wheels):
    scenario = loaded.scenario
    events = [event for offset, event in scenario.events if offset < τ] + [ControlLoss(τ, wheels)]
    run = Scenario(
        scenario.name,
        scenario.spacecraft,
        scenario.epoch,
        scenario.initial_state,
        events,
        duration=τ + WINDOW_S,
        orbit=scenario.orbit,
    )
    trajectory = propagate(run)
    seconds = np.arange(τ, τ + WINDOW_S + STEP_S / 2, STEP_S)
    return trajectory, seconds, pointing_samples(trajectory, loaded.pointing, seconds)


def _first(seconds, violated, τ):
    hits = np.flatnonzero(violated)
    return math.inf if hits.size == 0 else seconds[hits[0]] - τ


@pytest.mark.parametrize("case", ["locked", "spinning"])
def test_envelope_metrics_against_a_dense_run_after_each_loss(case):
    loaded = load_scenario(SCENARIO)
    wheels = Wheels(case, [0.0, 2.0, 0.0])
    settings = EnvelopeSettings(window=WINDOW_S, times=TAUS, wheels=wheels, power_threshold=0.3)
    # Each failure as a worker computes it, in this process (the Dask engine's table
    # is compared with this in test_envelope_outputs_against_independent_readers).
    job, _, _ = make_job(plan_envelope(loaded, settings=settings))
    rows = evaluate_batch(job, 0, job.count).rows
    assert [row["status"] for row in rows] == ["ok"] * len(TAUS)
    for τ, row in zip(TAUS, rows, strict=True):
        trajectory, seconds, samples = _separate_run(loaded, τ, wheels)
        # The same hand-off state: the motions agree (the gyrostat's at its step).
        assert row["tau_s"] == τ
        for item in samples.vectors:
            name = item.vector.name
            for exclusion, violated in (
                ("sun_exclusion", item.sun_violated),
                ("earth_limb_exclusion", item.earth_limb_violated),
            ):
                column = f"{name}_{exclusion}_s"
                if column not in row:
                    continue
                dense = _first(seconds, violated, τ)
                found = row[column]
                if math.isinf(dense):
                    assert math.isinf(found), (τ, column, found)
                else:  # before the first violated sample, within one step
                    assert dense - STEP_S - 2e-3 <= found <= dense + 2e-3, (τ, column, found, dense)
            if item.vector.kind == "panel":
                least = math.degrees(float(item.sun_angle_rad.min()))
                found = row[f"{name}_least_sun_angle_deg"]
                assert found <= least + 1e-6
                assert found >= least - 0.05, (τ, found, least)
                # The sampled incidence is max(cos, 0) times the lit fraction already.
                power = item.cos_incidence
                assert row["power_at_loss"] == pytest.approx(power[0], abs=1e-6)
                mean = np.trapezoid(power, seconds) / WINDOW_S
                assert row["power_mean"] == pytest.approx(mean, abs=2e-4)
                dense = _first(seconds, power <= 0.3, τ)
                if math.isinf(dense):
                    assert math.isinf(row["power_lost_s"])
                else:
                    assert dense - STEP_S - 2e-3 <= row["power_lost_s"] <= dense + 2e-3
        rates = np.degrees(np.linalg.norm(trajectory.angular_velocity(seconds), axis=1))
        assert row["rate_at_loss_deg_s"] == pytest.approx(rates[0], rel=1e-9, abs=1e-12)
        # Spinning wheels: the envelope's splitting step (one for every failure) and the
        # separate run's differ, each within its 1e-7 rad accuracy.
        slack = 1e-9 if case == "locked" else 1e-5
        assert row["rate_max_deg_s"] >= rates.max() * (1 - slack)
        assert row["rate_max_deg_s"] <= rates.max() * (1 + 1e-4)
        flips = trajectory.flip_times()
        flips = flips[(flips >= τ) & (flips <= τ + WINDOW_S)]
        assert row["flips"] == len(flips)
