"""The full report of a scenario with pointing, through the command line.

The spinner scenario (TLE orbit, three body vectors, a thruster pulse) run with the
network refused and warnings as errors.  Checked: every file is there and the page
links them; the time series, the intervals and the summary agree with one another;
the CCSDS AEM, read by an independent parser (ccsds-ndm-py, through
``aem_read_back``), holds the CSV's attitude in the standard's order (scalar last) and
its rates in deg/s.
"""

import json
import socket
import warnings
from pathlib import Path

import numpy as np
import pytest
from aem_read_back import interpolate_as_declared, read_back, rotation_angle
from csv_read_back import read_csv

from attitude.cli.main import main
from attitude.environment.timescales import tt_seconds
from attitude.files.scenario_reader import load_scenario
from attitude.trajectory.trajectory import propagate

SCENARIO = Path(__file__).parents[1] / "scenarios" / "spinner_thruster_pulse.toml"


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    out = tmp_path_factory.mktemp("report") / "spinner"
    with pytest.MonkeyPatch.context() as patch:

        def refuse(*args, **kwargs):
            raise AssertionError(f"network access attempted: {args}")

        for target, name in (
            (socket.socket, "connect"),
            (socket.socket, "connect_ex"),
            (socket, "create_connection"),
            (socket, "getaddrinfo"),
        ):
            patch.setattr(target, name, refuse)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            assert main(["run", str(SCENARIO), "--out", str(out), "--quiet"]) == 0
    return out


def test_every_file_is_written_and_linked(report):
    names = {p.name for p in report.iterdir()} - {"attitude-manifest.json"}
    manifest = json.loads((report / "attitude-manifest.json").read_text())
    assert set(manifest["files"]) == names  # the folder is marked as attitude's
    assert names == {
        "timeseries.csv",
        "intervals.csv",
        "summary.json",
        "attitude.aem",
        "report.html",
        "angular_velocity.png",
        "polhode.png",
        "sun_angles.png",
        "eclipse.png",
    }
    page = (report / "report.html").read_text()
    for name in names - {"report.html"}:
        assert f"'{name}'" in page
    for png in report.glob("*.png"):
        data = png.read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 20_000


def test_incidence_flags_and_intervals_agree(report):
    data = read_csv(report / "timeseries.csv")
    fraction = data["sunlit_fraction"]
    for name in ("top_panel", "side_panel", "star_tracker"):
        angle = np.radians(data[f"{name}_sun_angle_deg"])
        np.testing.assert_allclose(
            data[f"{name}_cos_incidence"], np.maximum(np.cos(angle), 0.0) * fraction, atol=1e-12
        )
    intervals = read_csv(report / "intervals.csv")
    t = data["t_s"]
    violation = intervals[(intervals["kind"] == "sun_exclusion")]
    inside = np.zeros(t.size, dtype=bool)
    near_an_end = np.zeros(t.size, dtype=bool)  # within the ends' precision (1 ms): either
    for row in violation:
        inside |= (t >= row["start_s"]) & (t <= row["end_s"])
        for end in (row["start_s"], row["end_s"]):
            near_an_end |= np.abs(t - end) <= 1e-3
    flags = data["star_tracker_sun_exclusion_violated"].astype(bool)
    assert np.array_equal(inside[~near_an_end], flags[~near_an_end])
    summary = json.loads((report / "summary.json").read_text())
    tracker = summary["pointing"]["body_vectors"]["star_tracker"]
    assert tracker["sun_exclusion"]["count"] == len(violation) > 100
    assert tracker["sun_exclusion"]["total_s"] == pytest.approx(
        np.sum(violation["duration_s"]), rel=1e-9
    )
    eclipses = intervals[intervals["kind"] == "eclipse"]
    assert summary["pointing"]["eclipses"]["shadow"]["count"] == len(eclipses) == 1
    # In the umbra the panels get no light; in the penumbra (27 s here), part of it.
    umbra = intervals[intervals["kind"] == "umbra"]
    assert eclipses["start_s"][0] < umbra["start_s"][0] < umbra["end_s"][0] < eclipses["end_s"][0]
    dark = (t >= umbra["start_s"][0]) & (t <= umbra["end_s"][0])
    assert np.all(data["top_panel_cos_incidence"][dark] == 0.0)
    penumbra = (t > eclipses["start_s"][0]) & (t < umbra["start_s"][0])
    assert np.all((data["sunlit_fraction"][penumbra] > 0) & (data["sunlit_fraction"][penumbra] < 1))
    # The extremum times are real: the minimum Sun angle of the tracker is below its limit.
    assert (
        tracker["sun_angle_min_deg"]
        < tracker["sun_exclusion_half_angle_deg"]
        == pytest.approx(35.0)
    )


def test_aem_holds_the_attitude_for_an_independent_parser(report):
    """The AEM has its own records (sampled for 1e-6 rad, not on the CSV's grid): read by
    ccsds-ndm-py and interpolated as it declares, it gives the CSV's attitude at every
    CSV epoch to within that tolerance, and its rates in deg/s."""
    # ccsds-ndm-py is a declared dependency: without it this fails, it does not skip.
    # read_back also checks the norms, the epoch order and START/STOP_TIME.
    segments, message = read_back(report / "attitude.aem")
    data = read_csv(report / "timeseries.csv")
    scenario = load_scenario(SCENARIO).scenario
    epoch, trajectory = scenario.epoch, propagate(scenario)
    assert len(message.segments) == 2  # a new segment at the thruster pulse
    t = data["t_s"]
    q_csv = np.column_stack([data[f"q_body_to_icrf_{c}"] for c in "wxyz"])
    ω_csv = np.column_stack([data[f"omega_body_{c}_rad_s"] for c in "xyz"])
    covered = 0
    for segment, parsed in zip(segments, message.segments, strict=True):
        assert parsed.metadata.ref_frame_a == "ICRF"
        assert parsed.metadata.ref_frame_b == "SC_BODY_1"
        assert parsed.metadata.attitude_type == "QUATERNION/ANGVEL"
        x = tt_seconds(segment.times, epoch)
        inside = (t > x[0]) & (t < x[-1])
        error = rotation_angle(interpolate_as_declared(segment, t[inside], epoch), q_csv[inside])
        assert np.max(error) <= 1e-6
        covered += int(np.sum(inside))
        # The rates (written in deg/s) against the exact ones at the records' epochs; the
        # segment's ends are skipped: an event's epoch is both sides of it.
        exact = trajectory.angular_velocity(x[1:-1])
        np.testing.assert_allclose(segment.angular_velocity_body_rad_s[1:-1], exact, atol=1e-12)
    assert covered >= len(data) - 3
    # The CSV's rates are the exact ones on its grid.
    np.testing.assert_allclose(ω_csv, trajectory.angular_velocity(t), rtol=0, atol=0)
