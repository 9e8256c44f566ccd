"""AEM and OEM interchange with Orekit's CCSDS readers and writers, from frozen data.

``tests/freeze_orekit_ccsds.py`` (run where orekit-jpype is installed) wrote
``tests/data/orekit/``; nothing here needs Java:

- **Our AEM files, read by Orekit.**  For every example of ``scenarios/``, the attitude
  Orekit's AEM parser and its segments' attitude providers gave at mid-steps of the
  records (where interpolation errs most), against our exact attitude at the same
  instants (``Trajectory.attitude``): within the tolerance the file declares.
- **An AEM written by Orekit, read by us.**  Orekit's ``TorqueFree`` tumbler written
  in EME2000 and UTC across the 2016-12-31 leap second: ``attitude_from_aem`` at the
  records and the mid-steps against Orekit's own attitude (in GCRF, so the EME2000
  frame bias is applied on both sides, ERFA's here and Orekit's there): at the
  records to the frame bias' agreement, between them within the error Orekit's own
  reader makes of the same file.
- **An OEM written by Orekit, read by us.**  A Keplerian orbit in EME2000 and UTC
  across the same leap second, every 60 s, LAGRANGE degree 7: ``OemOrbit`` against
  the orbit's own states in GCRF (at the records, to their digits), and between them
  against the declared interpolation computed here (scipy's Lagrange polynomial
  through the file's records).  Orekit's own reader interpolates by Hermite with the
  velocities whatever the file declares, so its error is not the declared one.
"""

from __future__ import annotations

import json
from pathlib import Path

import erfa
import numpy as np
import pytest
from aem_read_back import rotation_angle
from astropy.time import Time, TimeDelta
from orekit_frozen import read_frozen
from scipy.interpolate import BarycentricInterpolator

from attitude.environment.oem import OemOrbit
from attitude.environment.timescales import offline_time
from attitude.files.aem_reader import attitude_from_aem
from attitude.files.scenario_reader import load_scenario
from attitude.trajectory.trajectory import propagate

ROOT = Path(__file__).parents[1]
DATA = Path(__file__).parent / "data" / "orekit"
EXAMPLES = sorted((ROOT / "scenarios").glob("*.toml"))


def _quaternions(rows: np.ndarray, prefix: str) -> np.ndarray:
    return np.column_stack([rows[f"{prefix}{c}"] for c in "wxyz"])


def example_cases() -> list:
    return [pytest.param(path, id=path.stem) for path in EXAMPLES]


def test_every_example_has_frozen_orekit_readings():
    frozen = {p.stem for p in (DATA / "aem_read_by_orekit").glob("*.csv")}
    assert frozen == {p.stem for p in EXAMPLES}, "rerun tests/freeze_orekit_ccsds.py"


@pytest.mark.parametrize("example", example_cases())
def test_our_aem_read_by_orekit_is_within_its_declared_tolerance(example):
    header, rows = read_frozen(DATA / "aem_read_by_orekit" / f"{example.stem}.csv")
    loaded = load_scenario(example)
    scenario = loaded.scenario
    with offline_time():
        assert header["epoch_tt"] == str(scenario.times(0.0).tt.isot)
    trajectory = propagate(scenario)
    exact = trajectory.attitude_quaternion(rows["t_s"])
    error = rotation_angle(_quaternions(rows, "q_"), exact)
    tolerance = float(header["declared_tolerance_rad"])
    worst = int(np.argmax(error))
    assert error[worst] <= tolerance, (
        f"{example.name}: Orekit reads the AEM {error[worst]:.3g} rad off at "
        f"t = {rows['t_s'][worst]:.6f} s (segment {int(rows['segment'][worst])}), "
        f"{tolerance:g} declared"
    )
    # A segment per stretch of smooth motion: events (and, under laws, a slew's end),
    # and burns' starts and stops (and a slew's switches).
    pieces = len(trajectory.segments) + len(trajectory.breakpoints())
    assert len(json.loads(header["records_per_segment"])) == pieces


def _times(start_utc: str, offsets_s: np.ndarray) -> Time:
    with offline_time():
        start = Time(start_utc, scale="utc").tt
        return (start + TimeDelta(offsets_s, format="sec")).utc


def test_an_aem_written_by_orekit_read_by_us():
    path = DATA / "orekit_written.aem"
    text = path.read_text()
    assert "REF_FRAME_A          = EME2000" in text and "2016-12-31T23:59:60.000" in text
    header, rows = read_frozen(DATA / "orekit_written_aem_truth.csv")
    truth, orekit = _quaternions(rows, "truth_"), _quaternions(rows, "orekit_read_")
    times = _times(header["start_utc"], rows["t_s"])
    ours = np.array([attitude_from_aem(path, t)[0].as_quat(scalar_first=True) for t in times])
    error, own = rotation_angle(ours, truth), rotation_angle(orekit, truth)
    on_record = np.isclose(rows["t_s"] % 1.0, 0.0)
    # On a record: the record itself, in EME2000, rotated to GCRF by ERFA's frame bias
    # here and Orekit's there (23 mas): they agree to 1e-11 rad.
    assert np.max(error[on_record]) <= 1e-11
    # Between records: within the error Orekit's own reader makes of its file.
    assert np.max(error[~on_record]) <= np.max(own) + 1e-11
    assert np.max(own) > 1e-12  # the comparison is not between identical readings


def test_an_oem_written_by_orekit_read_by_us():
    path = DATA / "orekit_written.oem"
    text = path.read_text()
    assert "REF_FRAME            = EME2000" in text and "LAGRANGE" in text
    header, rows = read_frozen(DATA / "orekit_written_oem_truth.csv")
    times = _times(header["start_utc"], rows["t_s"])
    assert any(text.startswith("2016-12-31T23:59:60") for text in times.isot) or (
        "23:59:60" in text
    )
    orbit = OemOrbit(path)
    position, velocity = orbit.position_velocity(times)
    columns = {
        who: (
            np.column_stack([rows[f"{who}_r_{a}"] for a in "xyz"]),
            np.column_stack([rows[f"{who}_v_{a}"] for a in "xyz"]),
        )
        for who in ("truth", "orekit_read")
    }
    r_truth, v_truth = columns["truth"]
    r_own, v_own = columns["orekit_read"]
    error_r = np.linalg.norm(position - r_truth, axis=1)
    error_v = np.linalg.norm(velocity - v_truth, axis=1)
    own_r = np.linalg.norm(r_own - r_truth, axis=1)
    own_v = np.linalg.norm(v_own - v_truth, axis=1)
    on_record = np.isclose(rows["t_s"] % 60.0, 0.0)
    # On a record: its printed digits (km to 1e-13 relative) and the frame bias'
    # agreement (1e-11 rad of 7000 km).
    assert np.max(error_r[on_record]) <= 2e-4 and np.max(error_v[on_record]) <= 2e-7
    # Between records, as the file declares (LAGRANGE of degree 7 on each coordinate),
    # interpolated here by scipy over the 8 records centred on the interval, in EME2000.
    epochs, states = _oem_records(text)
    offsets = _seconds_after(header["start_utc"], epochs)
    bias = erfa.bp06(2451545.0, 0.0)[0]  # GCRS -> mean J2000 (EME2000)
    declared = np.array([_lagrange(offsets, states[:, :3], t, 7) for t in rows["t_s"]])
    np.testing.assert_allclose(position @ bias.T, declared, rtol=0.0, atol=1e-6)
    # And against the orbit itself: degree 7 at 60 s on this orbit is 0.3 mm at worst
    # (at the ends, where the window is off-centre); Orekit's own reader, Hermite with
    # the velocities whatever the file declares, is closer (own_r).
    assert np.max(error_r) <= 1e-3 and np.max(own_r) <= 1e-6
    assert np.max(error_v) <= 2e-6 and np.max(own_v) <= 1e-7


def _oem_records(text: str) -> tuple[list[str], np.ndarray]:
    """The data lines of a one-segment OEM: epochs (texts) and states (km, km/s → m)."""
    lines = (
        text.split("DATA_START")[-1].split("DATA_STOP")[0].splitlines()
        if ("DATA_START" in text)
        else [line for line in text.split("META_STOP")[-1].splitlines()]
    )
    records = [line.split() for line in lines if line[:1].isdigit()]
    epochs = [fields[0] for fields in records]
    states = np.array([[float(x) for x in fields[1:7]] for fields in records]) * 1e3
    return epochs, states


def _seconds_after(start_utc: str, texts: list[str]) -> np.ndarray:
    with offline_time():
        start = Time(start_utc, scale="utc")
        return (Time(texts, scale="utc") - start).to_value("s")


def _lagrange(x: np.ndarray, y: np.ndarray, t: float, degree: int) -> np.ndarray:
    """The Lagrange polynomial of ``degree`` through the records centred on t's interval."""
    interval = int(np.clip(np.searchsorted(x, t, side="right") - 1, 0, x.size - 2))
    first = int(np.clip(interval - (degree - 1) // 2, 0, x.size - degree - 1))
    nodes = slice(first, first + degree + 1)
    return BarycentricInterpolator(x[nodes] - t, y[nodes])(0.0)
