"""An initial attitude read from an AEM file, against the motion that wrote the file.

The exact solver's attitude is written every 2 s (our writer, ``attitude.aem``: ICRF to
SC_BODY_1, scalar last, rates in body axes, Hermite of degree 3) and read back by
``attitude_from_aem`` at records and between them.  On a record it is the record; between
records, the declared Hermite cubic follows the motion (its error bound is (ωh/2)⁴/384
per component for a steady rotation; 1.3e-4 rad here, on a tumble).  The same file
declared LAGRANGE 7 is closer; in EME2000 the result turns by the frame bias; with A
and B swapped, by the inverse.
Bad files and epochs outside them are refused with one line.
"""

import math

import numpy as np
import pytest
from astropy.time import Time
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.environment.frames import eme2000_to_icrf
from attitude.environment.timescales import time_from_tt_seconds
from attitude.files.aem_reader import attitude_from_aem
from attitude.outputs.aem_writer import AemSegment, write_aem
from attitude.solver.euler_solver import EulerSolver

EPOCH = Time("2027-06-21T00:00:00", scale="utc")
SOLVER = EulerSolver.from_angular_velocity([10.0, 20.0, 30.0], [0.05, 0.3, 0.02])
STEP_S = 2.0


def _exact(seconds: float) -> Rotation:
    return Rotation.from_quat(SOLVER.attitude_quaternion(np.array([seconds]))[0], scalar_first=True)


@pytest.fixture(scope="module")
def aem_text(tmp_path_factory) -> str:
    path = tmp_path_factory.mktemp("aem") / "spin.aem"
    seconds = np.arange(0.0, 100.0 + STEP_S / 2, STEP_S)
    segment = AemSegment(
        time_from_tt_seconds(EPOCH, seconds).utc,
        SOLVER.attitude_quaternion(seconds),
        SOLVER.angular_velocity(seconds),
    )
    write_aem(path, [segment], object_name="SPIN", object_id="2027-001A", time_scale="utc")
    return path.read_text()


def _read(tmp_path, text: str, seconds: float) -> Rotation:
    path = tmp_path / "file.aem"
    path.write_text(text)
    rotation, _ = attitude_from_aem(path, time_from_tt_seconds(EPOCH, seconds).utc)
    return rotation


@pytest.mark.parametrize("seconds", [0.0, 10.0, 11.0, 13.37, 99.0, 100.0])
def test_records_and_mid_steps_against_the_exact_motion(tmp_path, aem_text, seconds):
    error = (_read(tmp_path, aem_text, seconds).inv() * _exact(seconds)).magnitude()
    on_record = seconds % STEP_S == 0.0
    # Between records: the Hermite cubic's error, 1.3e-4 rad at most here (an epoch
    # read 1 s off would be 0.3 rad off).
    assert error < (1e-15 if on_record else 3e-4), error


def test_lagrange_as_declared(tmp_path, aem_text):
    text = aem_text.replace("INTERPOLATION_METHOD = HERMITE", "INTERPOLATION_METHOD = LAGRANGE")
    text = text.replace("INTERPOLATION_DEGREE = 3", "INTERPOLATION_DEGREE = 7")
    error = (_read(tmp_path, text, 13.37).inv() * _exact(13.37)).magnitude()
    assert error < 1e-5


def test_eme2000_is_rotated_by_the_frame_bias(tmp_path, aem_text):
    icrf = _read(tmp_path, aem_text, 13.37)
    eme = _read(tmp_path, aem_text.replace("REF_FRAME_A = ICRF", "REF_FRAME_A = EME2000"), 13.37)
    np.testing.assert_allclose(
        (eme2000_to_icrf() * icrf).as_matrix(), eme.as_matrix(), rtol=0, atol=1e-15
    )
    assert math.degrees((eme.inv() * icrf).magnitude()) * 3.6e6 == pytest.approx(23.15, abs=0.01)


def test_swapped_frames_mean_the_inverse(tmp_path, aem_text):
    # A = body, B = ICRF: the quaternion carries the body axes onto ICRF's.  Written
    # here from the inverse rotation, it must read back as the same attitude.
    q = SOLVER.attitude_quaternion(np.array([10.0]))[0]
    inverse = np.array([-q[1], -q[2], -q[3], q[0]])  # conjugate, scalar last
    text = (
        "CCSDS_AEM_VERS = 2.0\nCREATION_DATE = 2027-06-20T00:00:00\nORIGINATOR = ME\n\n"
        "META_START\nOBJECT_NAME = SPIN\nOBJECT_ID = 2027-001A\nCENTER_NAME = EARTH\n"
        "REF_FRAME_A = SC_BODY_1\nREF_FRAME_B = ICRF\nTIME_SYSTEM = UTC\n"
        "START_TIME = 2027-06-21T00:00:10\nSTOP_TIME = 2027-06-21T00:00:10\n"
        "ATTITUDE_TYPE = QUATERNION\nMETA_STOP\n\nDATA_START\n"
        "2027-06-21T00:00:10 " + " ".join(f"{x:.16e}" for x in inverse) + "\nDATA_STOP\n"
    )
    assert (_read(tmp_path, text, 10.0).inv() * _exact(10.0)).magnitude() < 1e-15


@pytest.mark.parametrize(
    "edit, message",
    [
        (lambda t: t.replace("CCSDS_AEM_VERS = 2.0", "CCSDS_AEM_VERS = 1.0"), r"only AEM 2\.0"),
        (lambda t: "\x89PNG\r\n\x1a\n", r"file\.aem: not a CCSDS AEM in KVN: not ASCII"),
        (lambda t: "not an AEM at all\n", r"file\.aem: not a CCSDS AEM \(KVN\)"),
        (
            lambda t: t.replace("REF_FRAME_A = ICRF", "REF_FRAME_A = ITRF"),
            r"segment 0: REF_FRAME_A = 'ITRF', REF_FRAME_B = 'SC_BODY_1': expected one of",
        ),
        (
            lambda t: t.replace("INTERPOLATION_METHOD = HERMITE", "INTERPOLATION_METHOD = CUBIC"),
            r"INTERPOLATION_METHOD = 'CUBIC'",
        ),
        (lambda t: t.replace("TIME_SYSTEM = UTC", "TIME_SYSTEM = SCLK"), r"TIME_SYSTEM = 'SCLK'"),
    ],
    ids=["version 1", "binary", "garbage", "ITRF", "cubic", "clock time"],
)
def test_bad_files_are_refused_in_one_line(tmp_path, aem_text, edit, message):
    with pytest.raises(InputError, match=message) as caught:
        _read(tmp_path, edit(aem_text), 13.37)
    assert "\n" not in str(caught.value)


def test_an_epoch_outside_the_file_is_refused(tmp_path, aem_text):
    with pytest.raises(InputError, match=r"file\.aem: the scenario epoch 2027-06-21T00:03:20"):
        _read(tmp_path, aem_text, 200.0)


def test_a_scenario_starts_from_the_aem(tmp_path, aem_text):
    # [initial_state] aem = "spin.aem": the scenario's first attitude is the file's at its
    # epoch (2027-06-21T00:00:13.37, between records), relative to the scenario file.
    from attitude.files.scenario_reader import load_scenario
    from attitude.trajectory.trajectory import propagate

    (tmp_path / "spin.aem").write_text(aem_text)
    (tmp_path / "start.toml").write_text(
        '[scenario]\nname = "from an AEM"\nepoch = "2027-06-21T00:00:13.37"\n'
        '[spacecraft]\nname = "spin"\nprincipal_moments = [10.0, 20.0, 30.0]\n'
        '[initial_state]\naem = "spin.aem"\nangular_velocity = [0.05, 0.3, 0.02]\n'
        "[output]\nduration = 10.0\n"
    )
    loaded = load_scenario(tmp_path / "start.toml")
    first = propagate(loaded.scenario).attitude(np.array([0.0]))[0]
    expected = _read(tmp_path, aem_text, 13.37)
    assert (first.inv() * expected).magnitude() < 1e-15
    assert (first.inv() * _exact(13.37)).magnitude() < 3e-4
