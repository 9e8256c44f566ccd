"""Epochs: the same instant in any time scale, leap seconds, and no network.

References: astropy's own conversions between scales (ERFA), and the IERS leap
second of 2016-12-31T23:59:60 UTC (TAI − UTC went from 36 s to 37 s).
"""

import socket
import warnings

import numpy as np
import pytest
from astropy import units as u
from astropy.time import Time
from scipy.spatial.transform import Rotation

from attitude.cli.main import main
from attitude.environment.timescales import as_time, offline_time, tt_seconds
from attitude.scenario.events import AngularImpulse
from attitude.scenario.scenario import InitialState, Scenario
from attitude.scenario.spacecraft import Spacecraft
from attitude.trajectory.trajectory import propagate

SPACECRAFT = Spacecraft("test", [100.0, 200.0, 300.0])
STATE = InitialState(Rotation.from_rotvec([0.2, 0.4, -0.1]), angular_velocity=[0.05, 0.3, 0.02])


def _trajectory(epoch, event_epoch):
    scenario = Scenario(
        "scales",
        SPACECRAFT,
        epoch,
        STATE,
        [AngularImpulse(event_epoch, [0.0, 0.0, 5.0])],
        duration=600.0,
        step=1.0,
    )
    return propagate(scenario)


def test_the_same_instant_in_utc_tt_and_tdb_gives_the_same_attitude():
    epoch_utc = Time("2027-03-01T12:00:00", scale="utc")
    event_utc = Time("2027-03-01T12:04:10.25", scale="utc")
    with offline_time():
        epochs = {"utc": epoch_utc, "tt": epoch_utc.tt, "tdb": epoch_utc.tdb}
        events = {"utc": event_utc, "tt": event_utc.tt, "tdb": event_utc.tdb}
        probe = epoch_utc + np.linspace(0.0, 600.0, 301) * u.s
        probes = {"utc": probe, "tt": probe.tt, "tdb": probe.tdb}
    reference = _trajectory(epochs["utc"], events["utc"]).attitude(probes["utc"])
    for scale in ("tt", "tdb"):
        for probe_scale in ("utc", "tt", "tdb"):
            attitude = _trajectory(epochs[scale], events[scale]).attitude(probes[probe_scale])
            # TDB − TT is computed by ERFA to about 1e-12 s here; the spin is 0.3 rad/s.
            assert np.max((attitude.inv() * reference).magnitude()) <= 1e-12, (scale, probe_scale)


def test_iso_strings_in_each_scale():
    """The same instant written as ISO text in each scale: to the nanosecond it is given."""
    scenarios = {
        "utc": ("2027-03-01T12:00:00.000000000", "2027-03-01T12:04:10.250000000"),
        "tt": ("2027-03-01T12:01:09.184000000", "2027-03-01T12:05:19.434000000"),
    }
    attitudes = []
    for scale, (epoch, event) in scenarios.items():
        trajectory = _trajectory(as_time(epoch, scale), as_time(event, scale))
        attitudes.append(trajectory.attitude(np.linspace(0.0, 600.0, 61)))
    assert np.max((attitudes[0].inv() * attitudes[1]).magnitude()) <= 1e-12


def test_leap_second_is_one_tt_second():
    epoch = Time("2016-12-31T23:59:58", scale="utc")
    times = Time(
        [
            "2016-12-31T23:59:59",
            "2016-12-31T23:59:60",
            "2016-12-31T23:59:60.5",
            "2017-01-01T00:00:00",
        ],
        scale="utc",
    )
    np.testing.assert_allclose(tt_seconds(times, epoch), [1.0, 2.0, 2.5, 3.0], rtol=0, atol=1e-9)
    # A scenario across it: an event at 23:59:60 lands 2 s after the epoch, and the
    # output grid, written in UTC, shows the leap second.
    scenario = Scenario(
        "leap",
        SPACECRAFT,
        epoch,
        STATE,
        [AngularImpulse(Time("2016-12-31T23:59:60", scale="utc"), [0.0, 0.0, 5.0])],
        duration=4.0,
        step=0.5,
    )
    assert scenario.events[0][0] == pytest.approx(2.0, abs=1e-9)
    iso = scenario.iso(scenario.output_seconds())
    assert list(iso[3:7]) == [
        "2016-12-31T23:59:59.500000000",
        "2016-12-31T23:59:60.000000000",
        "2016-12-31T23:59:60.500000000",
        "2017-01-01T00:00:00.000000000",
    ]
    trajectory = propagate(scenario)
    assert trajectory.segment_index(Time("2016-12-31T23:59:60", scale="utc")) == 1
    assert trajectory.segment_index(Time("2016-12-31T23:59:59.999", scale="utc")) == 0


@pytest.fixture
def no_network(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError(f"network access attempted: {args}")

    monkeypatch.setattr(socket.socket, "connect", refuse)
    monkeypatch.setattr(socket.socket, "connect_ex", refuse)
    monkeypatch.setattr(socket, "create_connection", refuse)
    monkeypatch.setattr(socket, "getaddrinfo", refuse)


@pytest.mark.parametrize("year", [2027, 2028, 2029, 2030])
def test_utc_epochs_2027_to_2030_need_no_network_and_raise_no_warning(no_network, tmp_path, year):
    scenario = tmp_path / "late.toml"
    scenario.write_text(
        f"""
[scenario]
name = "late"
epoch = "{year}-12-31T23:00:00"
[spacecraft]
name = "s"
principal_moments = [1.0, 2.0, 2.5]
[initial_state]
quaternion = [1.0, 0.0, 0.0, 0.0]
angular_velocity = [0.1, 0.2, 0.3]
[[events]]
type = "angular_impulse"
epoch = "{year + 1}-01-01T00:30:00"
impulse = [0.0, 0.0, 0.1]
[output]
duration = 7200.0
step = 60.0
"""
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert main(["run", str(scenario), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    lines = (tmp_path / "out" / "timeseries.csv").read_text().splitlines()
    assert lines[-1].startswith(f"{year + 1}-01-01T01:00:00")
