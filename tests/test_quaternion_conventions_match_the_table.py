"""Every output's quaternion order and direction, against the table in docs/conventions.md.

The attitude is a hand-known rotation: the body's x axis along ICRF +y, a +90° turn
about z, q = (√½, 0, 0, √½) scalar first, reset after 10 s to +90° about x,
q = (√½, √½, 0, 0).  Each output is read as a user would (the CSV header and first
row, the Parquet schema and first row, the AEM's header lines and first record,
summary.json, the Python calls) and its four numbers, taken in the order the table
states, must be that rotation's (w, x, y, z), up to the sign of the whole quaternion.
Inputs (a scenario file, InitialState.from_quaternion, AemSegment, the free-flow map)
are given the numbers in the table's order and must come out as that rotation.
"""

import json
import math
import re
from pathlib import Path

import astropy.units as u
import numpy as np
import pyarrow.parquet as pq
import pytest
from astropy.time import Time
from scipy.spatial.transform import Rotation

from attitude import (
    AttitudeReset,
    InitialState,
    Scenario,
    Spacecraft,
    load_scenario,
    propagate,
    propagate_batch,
    write_report,
)
from attitude.outputs.aem_writer import QUATERNION_COMMENT, AemSegment, write_aem
from attitude.outputs.formats import OutputChoice
from attitude.solver.free_flow import advance

TABLE = Path(__file__).resolve().parents[1] / "docs" / "conventions.md"
HALF = math.sqrt(0.5)
TURN_Z = {"w": HALF, "x": 0.0, "y": 0.0, "z": HALF}  # +90° about z: body x along ICRF +y
TURN_X = {"w": HALF, "x": HALF, "y": 0.0, "z": 0.0}  # +90° about x


def _table() -> dict[str, tuple[tuple[str, ...], str]]:
    """Row name (the first cell's first `code`) -> (order letters, direction)."""
    rows = {}
    for line in TABLE.read_text(encoding="utf-8").splitlines():
        cells = [cell.strip() for cell in line.strip().strip("|").split("|")]
        if len(cells) < 4 or not cells[1].startswith("("):
            continue
        name = re.search(r"`([^`]+)`", cells[0]).group(1)
        order = tuple(letter.strip() for letter in cells[1].strip("()").split(","))
        rows[name] = (order, cells[2])
    return rows


ROWS = _table()


def _as_rotation(values, name: str) -> Rotation:
    """The four numbers of ``name``'s output, in the table's order, as a Rotation."""
    order, direction = ROWS[name]
    assert sorted(order) == ["w", "x", "y", "z"], (name, order)
    assert direction.startswith("body →"), (name, direction)
    by_letter = dict(zip(order, (float(v) for v in values), strict=True))
    return Rotation.from_quat([by_letter[k] for k in "wxyz"], scalar_first=True)


def _in_order(quaternion: dict[str, float], name: str) -> list[float]:
    return [quaternion[letter] for letter in ROWS[name][0]]


def _assert_same(rotation: Rotation, quaternion: dict[str, float]) -> None:
    expected = Rotation.from_quat([quaternion[k] for k in "wxyz"], scalar_first=True)
    assert (rotation * expected.inv()).magnitude() < 1e-12
    # The direction: body x goes to ICRF +y under the +90° turn about z.
    if quaternion is TURN_Z:
        np.testing.assert_allclose(rotation.apply([1.0, 0.0, 0.0]), [0.0, 1.0, 0.0], atol=1e-12)


def test_the_table_lists_every_output():
    assert set(ROWS) == {
        "attitude_quaternion",
        "Rotation.as_quat",
        "propagate_batch",
        "free_flow.advance",
        "InitialState.from_quaternion",
        "AemSegment",
        "quaternion",
        "timeseries.csv",
        "timeseries.parquet",
        "summary.json",
        "attitude.aem",
    }


def _scenario() -> Scenario:
    epoch = Time("2027-03-01T12:00:00", scale="utc")
    initial = InitialState.from_quaternion(
        _in_order(TURN_Z, "InitialState.from_quaternion"), angular_velocity=[0.0, 0.0, 1e-3]
    )
    reset = AttitudeReset(epoch + 10.0 * u.s, Rotation.from_rotvec([math.pi / 2, 0.0, 0.0]))
    return Scenario(
        "conventions",
        Spacecraft("box", [100.0, 200.0, 300.0]),
        epoch,
        initial,
        [reset],
        duration=20.0,
        step=1.0,
    )


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    out = tmp_path_factory.mktemp("conventions") / "out"
    write_report(_scenario(), out, outputs=OutputChoice(formats=("csv", "parquet", "aem")))
    return out


def test_input_initial_state_from_quaternion():
    initial = InitialState.from_quaternion(
        _in_order(TURN_Z, "InitialState.from_quaternion"), angular_velocity=[0.0, 0.0, 1.0]
    )
    _assert_same(initial.attitude, TURN_Z)


def test_input_scenario_file(tmp_path):
    numbers = ", ".join(repr(v) for v in _in_order(TURN_Z, "quaternion"))
    path = tmp_path / "s.toml"
    path.write_text(
        '[scenario]\nname = "q"\nepoch = "2027-03-01T12:00:00"\ntime_scale = "utc"\n'
        '[spacecraft]\nname = "box"\nprincipal_moments = [100.0, 200.0, 300.0]\n'
        f"[initial_state]\nquaternion = [{numbers}]\nangular_velocity = [0.0, 0.0, 0.001]\n"
        "[output]\nduration = 10.0\nstep = 1.0\n",
        encoding="utf-8",
    )
    _assert_same(load_scenario(path).scenario.initial_state.attitude, TURN_Z)


def test_python_calls():
    scenario = _scenario()
    trajectory = propagate(scenario)
    t0 = scenario.times(0.0)
    _assert_same(_as_rotation(trajectory.attitude_quaternion(t0), "attitude_quaternion"), TURN_Z)
    _assert_same(_as_rotation(trajectory.attitude(t0).as_quat(), "Rotation.as_quat"), TURN_Z)
    # Scalar last by scipy's default: the table's (x, y, z, w) is not ours by accident.
    assert ROWS["Rotation.as_quat"][0] == ("x", "y", "z", "w")

    _, q = propagate_batch(
        [100.0, 200.0, 300.0],
        [[0.0, 0.0, 0.3]],
        attitude=Rotation.from_quat(_in_order(TURN_Z, "attitude_quaternion"), scalar_first=True),
        times=[0.0],
    )
    _assert_same(_as_rotation(q[0, 0], "propagate_batch"), TURN_Z)

    _, q_after = advance(
        [100.0, 200.0, 300.0], [0.0, 0.0, 0.3], _in_order(TURN_Z, "free_flow.advance"), 0.0
    )
    _assert_same(_as_rotation(q_after, "free_flow.advance"), TURN_Z)


def test_csv(report):
    lines = (report / "timeseries.csv").read_text(encoding="utf-8").splitlines()
    header = [line for line in lines if line.startswith("#")]
    names, first = (
        line.split(",") for line in [line for line in lines if not line.startswith("#")][:2]
    )
    columns = [name for name in names if name.startswith("q_body_to_icrf_")]
    assert (
        tuple(name.removeprefix("q_body_to_icrf_") for name in columns) == ROWS["timeseries.csv"][0]
    )
    [stated] = [line for line in header if line.startswith("# quaternion ")]
    assert "q_body_to_icrf_(w,x,y,z): scalar first" in stated
    values = [first[names.index(name)] for name in columns]
    _assert_same(_as_rotation(values, "timeseries.csv"), TURN_Z)


def test_parquet(report):
    table = pq.read_table(report / "timeseries.parquet")
    columns = [name for name in table.column_names if name.startswith("q_body_to_icrf_")]
    order = ROWS["timeseries.parquet"][0]
    assert tuple(name.removeprefix("q_body_to_icrf_") for name in columns) == order
    stated = table.schema.metadata[b"attitude.quaternion_convention"].decode()
    assert "q_body_to_icrf_(w,x,y,z): scalar first" in stated
    values = [table.column(name)[0].as_py() for name in columns]
    _assert_same(_as_rotation(values, "timeseries.parquet"), TURN_Z)


def test_summary_json(report):
    summary = json.loads((report / "summary.json").read_text(encoding="utf-8"))
    [event] = summary["scenario"]["events"]
    _assert_same(_as_rotation(event["q_body_to_icrf_wxyz"], "summary.json"), TURN_X)
    assert ROWS["summary.json"][0] == ("w", "x", "y", "z")  # as the key's name says


def _aem(path: Path) -> tuple[list[str], list[str]]:
    lines = path.read_text(encoding="ascii").splitlines()
    first = lines[lines.index("DATA_START") + 1].split()
    return lines, first


def test_aem(report):
    lines, first = _aem(report / "attitude.aem")
    assert lines[0] == "CCSDS_AEM_VERS = 2.0"  # v2: the order is fixed, scalar last
    assert not any(line.startswith("QUATERNION_TYPE") for line in lines)
    assert f"COMMENT {QUATERNION_COMMENT}" in lines
    assert "scalar last" in QUATERNION_COMMENT
    assert ROWS["attitude.aem"][0] == ("x", "y", "z", "w")
    assert "REF_FRAME_A = ICRF" in lines and "REF_FRAME_B = SC_BODY_1" in lines
    _assert_same(_as_rotation(first[1:5], "attitude.aem"), TURN_Z)


def test_aem_segment_input(tmp_path):
    epochs = Time(["2027-03-01T12:00:00", "2027-03-01T12:00:01"], scale="utc")
    q = [_in_order(TURN_Z, "AemSegment")] * 2
    path = write_aem(
        tmp_path / "a.aem",
        [AemSegment(epochs, np.array(q), np.zeros((2, 3)))],
        object_name="box",
        object_id="2027-001A",
        time_scale="utc",
    )
    _, first = _aem(path)
    _assert_same(_as_rotation(first[1:5], "attitude.aem"), TURN_Z)
