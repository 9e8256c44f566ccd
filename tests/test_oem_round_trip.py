"""Orbits written to CCSDS OEM files and read back, against the orbits themselves.

- SGP4 states of the ISS every 60 s, written by ccsds-ndm-py's own writer (OEM 3.0 KVN,
  EME2000, Lagrange of degree 9): read back and interpolated at every second, against
  direct SGP4 (``TleOrbit``).  Measured: 7 µm, 0.01 µm/s.
- A Molniya orbit (Keplerian, e = 0.74) every 120 s, written by hand (OEM 2.0, TDB,
  day-of-year epochs, two segments, Hermite of degree 7): against the Keplerian orbit.
- Files a user could hand over by mistake: each is refused with one line naming the
  file, the segment and the keyword.
"""

import math
from pathlib import Path

import ccsds_ndm
import numpy as np
import pytest
from astropy.time import Time

from attitude.base.errors import InputError
from attitude.environment.frames import eme2000_to_icrf
from attitude.environment.keplerian import KeplerianOrbit
from attitude.environment.oem import OemOrbit
from attitude.environment.orbit import TleOrbit
from attitude.environment.timescales import offline_time, time_from_tt_seconds

LINE1 = "1 25544U 98067A   14020.93268519  .00009878  00000-0  18200-3 0  5082"
LINE2 = "2 25544  51.6498 109.4756 0003572  55.9686 274.8005 15.49815350868473"
START = Time("2014-01-21T00:00:00", scale="utc")


def _iso(times, scale="utc") -> list[str]:
    with offline_time():
        return list(np.atleast_1d(getattr(times, scale).isot))


def test_sgp4_states_written_by_ccsds_ndm_py(tmp_path):
    sgp4 = TleOrbit(LINE1, LINE2)
    nodes = time_from_tt_seconds(START, np.arange(0.0, 3 * 3600.0 + 1.0, 60.0))
    r, v = sgp4.position_velocity(nodes)
    to_eme = eme2000_to_icrf().inv()  # the file holds EME2000
    states = np.hstack([to_eme.apply(r), to_eme.apply(v)]) / 1e3
    epochs = _iso(nodes)
    metadata = ccsds_ndm.OemMetadata(
        object_name="ISS",
        object_id="1998-067A",
        start_time=epochs[0],
        stop_time=epochs[-1],
        center_name="EARTH",
        ref_frame="EME2000",
        time_system="UTC",
        interpolation="LAGRANGE",
        interpolation_degree=9,
    )
    data = ccsds_ndm.OemData.from_numpy(epochs, states)
    header = ccsds_ndm.OdmHeader(creation_date="2014-01-20T00:00:00", originator="TEST")
    path = tmp_path / "iss.oem"
    path.write_text(ccsds_ndm.Oem(header, [ccsds_ndm.OemSegment(metadata, data)]).to_str("kvn"))

    oem = OemOrbit(path)
    times = time_from_tt_seconds(START, np.arange(0.0, 3 * 3600.0, 1.0))
    r_oem, v_oem = oem.position_velocity(times)
    r_sgp4, v_sgp4 = sgp4.position_velocity(times)
    assert np.linalg.norm(r_oem - r_sgp4, axis=-1).max() < 1e-3  # m; measured 7 µm
    assert np.linalg.norm(v_oem - v_sgp4, axis=-1).max() < 1e-5  # m/s
    assert oem.check_span(times[0], times[-1]) == []


def _write_by_hand(path: Path, segments: list[tuple], header_extra: str = "") -> None:
    """An OEM 2.0 in KVN: each segment (epochs text, states km, metadata lines)."""
    lines = ["CCSDS_OEM_VERS = 2.0", "CREATION_DATE = 2027-06-20T00:00:00", "ORIGINATOR = ME"]
    lines += [header_extra] if header_extra else []
    for epochs, states, meta in segments:
        lines += ["", "META_START", "OBJECT_NAME = PROBE", "OBJECT_ID = 2027-001A"]
        lines += meta
        lines += [f"START_TIME = {epochs[0]}", f"STOP_TIME = {epochs[-1]}", "META_STOP", ""]
        lines += [
            f"{e} " + " ".join(f"{x:.15e}" for x in s) for e, s in zip(epochs, states, strict=True)
        ]
    path.write_text("\n".join(lines) + "\n")


@pytest.fixture
def molniya():
    return KeplerianOrbit(
        "2027-06-21T00:00:00",
        26_600_000.0,
        0.74,
        math.radians(63.4),
        0.3,
        math.radians(270.0),
        mean_anomaly=0.0,
    )


def _molniya_file(tmp_path, molniya, meta=None, step=120.0, edit=None) -> Path:
    meta = meta or [
        "CENTER_NAME = EARTH",
        "REF_FRAME = ICRF",
        "TIME_SYSTEM = TDB",
        "INTERPOLATION = HERMITE",
        "INTERPOLATION_DEGREE = 7",
    ]
    segments = []
    for first, last in ((0.0, 6 * 3600.0), (6 * 3600.0, 12 * 3600.0)):
        nodes = time_from_tt_seconds(molniya.epoch, np.arange(first, last + 1.0, step))
        r, v = molniya.position_velocity(nodes)
        with offline_time():
            epochs = [t.strftime("%Y-%jT%H:%M:%S.%f") for t in nodes.tdb]  # day of year
        segments.append((epochs, np.hstack([r, v]) / 1e3, meta))
    path = tmp_path / "molniya.oem"
    _write_by_hand(path, segments)
    if edit:
        path.write_text(edit(path.read_text()))
    return path


def test_keplerian_states_written_by_hand(tmp_path, molniya):
    oem = OemOrbit(_molniya_file(tmp_path, molniya, step=60.0))
    times = time_from_tt_seconds(molniya.epoch, np.arange(0.0, 12 * 3600.0, 7.0))
    r_oem, v_oem = oem.position_velocity(times)
    r, v = molniya.position_velocity(times)
    # Perigee passes at 10 km/s, sampled every minute: Hermite 7 follows to a millimetre.
    assert np.linalg.norm(r_oem - r, axis=-1).max() < 5e-3
    assert np.linalg.norm(v_oem - v, axis=-1).max() < 1e-5
    assert "2 segments" in oem.describe()


def test_no_declared_interpolation_is_said(tmp_path, molniya):
    meta = ["CENTER_NAME = EARTH", "REF_FRAME = GCRF", "TIME_SYSTEM = TDB"]
    oem = OemOrbit(_molniya_file(tmp_path, molniya, meta=meta, step=60.0))
    notes = oem.check_span(molniya.epoch, time_from_tt_seconds(molniya.epoch, 3600.0))
    assert len(notes) == 2 and "declares no INTERPOLATION: Hermite of degree 5" in notes[0]


def _replace(old: str, new: str):
    def edit(text: str) -> str:
        assert old in text, old
        return text.replace(old, new)

    return edit


def _epoch_repeated(text: str) -> str:
    """The second state of the file given the first one's epoch."""
    lines = text.splitlines()
    data = [i for i, line in enumerate(lines) if line.startswith("2027-")]
    first, second = data[0], data[1]
    lines[second] = lines[first].split()[0] + " " + " ".join(lines[second].split()[1:])
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize(
    "edit, message",
    [
        (
            lambda text: "\x89PNG\r\n\x1a\n\x00\x00",
            r"molniya\.oem: not a CCSDS OEM in KVN: not ASCII",
        ),
        (lambda text: "hello\n", r"molniya\.oem: not a CCSDS OEM \(KVN\)"),
        (lambda text: "", r"molniya\.oem: not a CCSDS OEM \(KVN\)"),
        (
            _replace("REF_FRAME = ICRF", "REF_FRAME = ITRF2000"),
            r"molniya\.oem: segment 0: REF_FRAME = 'ITRF2000': expected one of ICRF, GCRF, EME2000",
        ),
        (
            _replace("CENTER_NAME = EARTH", "CENTER_NAME = MOON"),
            r"segment 0: CENTER_NAME = 'MOON': only EARTH",
        ),
        (_replace("TIME_SYSTEM = TDB", "TIME_SYSTEM = MET"), r"segment 0: TIME_SYSTEM = 'MET'"),
        (
            _replace("INTERPOLATION = HERMITE", "INTERPOLATION = SPLINE"),
            r"segment 0: INTERPOLATION = 'SPLINE': expected one of HERMITE, LAGRANGE, LINEAR",
        ),
        (
            _replace("INTERPOLATION_DEGREE = 7", "INTERPOLATION_DEGREE = 40"),
            r"INTERPOLATION_DEGREE = 40: expected 1 to 15",
        ),
        (
            lambda text: "\n".join(
                " ".join(line.split()[:-1]) if line[:4] == "2027" and i == 20 else line
                for i, line in enumerate(text.splitlines())
            ),
            r"molniya\.oem: .*line 21",
        ),
        (_epoch_repeated, r"segment 0: epochs must increase: state 1"),
    ],
    ids=[
        "binary",
        "garbage",
        "empty",
        "ITRF",
        "Moon-centred",
        "time system",
        "spline",
        "degree 40",
        "a velocity missing",
        "epochs back",
    ],
)
def test_bad_files_are_refused_in_one_line(tmp_path, molniya, edit, message):
    path = _molniya_file(tmp_path, molniya, edit=edit)
    with pytest.raises(InputError, match=message) as caught:
        OemOrbit(path)
    assert "\n" not in str(caught.value)


def test_epochs_outside_the_file_are_refused(tmp_path, molniya):
    oem = OemOrbit(_molniya_file(tmp_path, molniya))
    after = time_from_tt_seconds(molniya.epoch, 13 * 3600.0)
    with pytest.raises(
        InputError, match=r"pointing\.oem: molniya\.oem covers .* not the span's end"
    ):
        oem.check_span(molniya.epoch, after)
    with pytest.raises(InputError, match=r"molniya\.oem: 2027-06-21T1\d:.* outside the file's"):
        oem.position_velocity(after)


def test_not_a_file(tmp_path):
    with pytest.raises(InputError, match=r"nothing\.oem: cannot read"):
        OemOrbit(tmp_path / "nothing.oem")
    with pytest.raises(InputError, match=r": not a file"):
        OemOrbit(tmp_path)
