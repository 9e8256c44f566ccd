"""AEM 2.0 export, checked against hand derivations and the independent parser ccsds-ndm-py.

The authority is CCSDS 504.0-B-2 (Attitude Data Messages).  Annex F2.1 defines the
quaternion "from A to B" by ``X_B = M_BA X_A``, with M_BA given from Q1..QC.  §4.2.4.6
puts ANGVEL in deg/s, §4.2.4.7.3 writes a leap second as ``23:59:60``, and §6.8.4 sets the
number formats.  The quaternion fields are checked against values derived by hand from
those definitions, and against the annex's matrix for random rotations.

ccsds-ndm-py (import name ``ccsds_ndm``, a Rust parser independent of this project) reads
every file we write.  It checks the structure, the keywords, the column count and that
INTERPOLATION_DEGREE goes with INTERPOLATION_METHOD.  It reports the numbers and epoch
strings it finds, which we compare with the expected values.  It does not check unit
norms, increasing epochs, START/STOP_TIME against the data, TIME_SYSTEM or frame names
(any value passes).  ``aem_read_back.read_back`` checks the first three in numpy on
every file read here; the names are compared below, and the kinematics test checks that
the rates agree with the quaternions.  (The package has no AEM reader of its own.)
"""

import os
import re

import numpy as np
import pytest
from aem_read_back import parse, read_back
from astropy.time import Time
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.environment.timescales import offline_time, time_from_tt_seconds, tt_seconds
from attitude.outputs.aem_writer import QUATERNION_COMMENT, AemSegment, write_aem

CREATED = "2026-11-22T12:00:00"
# A quaternion component |x| < 1 written with 16 significant digits comes back within
# half a unit of its 16th digit (5e-17), plus half an ulp from parsing: < 1.2e-16.
QUATERNION_FORMAT_ERROR = 1.2e-16


def _write(path, segments, **options):
    options = {
        "object_name": "TESTSAT",
        "object_id": "2027-001A",
        "time_scale": "utc",
        "creation_date": CREATED,
        **options,
    }
    return write_aem(path, segments, **options)


def _data_fields(path):
    """The data lines of our file, split into fields, one list per segment."""
    segments, current = [], None
    for line in path.read_text().splitlines():
        if line == "DATA_START":
            current = []
        elif line == "DATA_STOP":
            segments.append(current)
            current = None
        elif current is not None:
            current.append(line.split())
    return segments


def _m_ba(q1, q2, q3, qc):
    """The frame transformation X_B = M_BA X_A of CCSDS 504.0-B-2 annex F2.1, verbatim."""
    return np.array(
        [
            [
                q1 * q1 - q2 * q2 - q3 * q3 + qc * qc,
                2 * (q1 * q2 + q3 * qc),
                2 * (q1 * q3 - q2 * qc),
            ],
            [
                2 * (q1 * q2 - q3 * qc),
                -q1 * q1 + q2 * q2 - q3 * q3 + qc * qc,
                2 * (q2 * q3 + q1 * qc),
            ],
            [
                2 * (q1 * q3 + q2 * qc),
                2 * (q2 * q3 - q1 * qc),
                -q1 * q1 - q2 * q2 + q3 * q3 + qc * qc,
            ],
        ]
    )


def _utc(*isot):
    return Time(list(isot), scale="utc", precision=9)


def _hamilton_scalar_last(p, q):
    """Row-wise Hamilton product of (x, y, z, w) quaternions."""
    pv, pw, qv, qw = p[..., :3], p[..., 3:], q[..., :3], q[..., 3:]
    vector = pw * qv + qw * pv + np.cross(pv, qv)
    scalar = pw * qw - np.sum(pv * qv, axis=-1, keepdims=True)
    return np.concatenate([vector, scalar], axis=-1)


def _random_segments(seed, time_scale, counts=(5, 7, 4)):
    """Consecutive segments sharing their boundary epochs (an event) and attitudes there.

    Random rotations and rates; epochs with ns-irregular steps.
    """
    rng = np.random.default_rng(seed)
    total = sum(counts) - (len(counts) - 1)
    with offline_time():
        epoch = Time("2024-03-01T12:00:00", scale=time_scale, precision=9)
        steps_s = rng.uniform(0.2, 3.0, total - 1)
        times = time_from_tt_seconds(epoch, np.concatenate([[0.0], np.cumsum(steps_s)]))
        times = getattr(times, time_scale)
    quaternions = Rotation.random(total, random_state=seed).as_quat(scalar_first=True)
    segments, first = [], 0
    for count in counts:
        rates = rng.normal(scale=0.05, size=(count, 3))  # a new rate after each event
        chunk = slice(first, first + count)
        segments.append(AemSegment(times[chunk], quaternions[chunk], rates))
        first += count - 1
    return segments


def _aem_fields(segment):
    """What a segment should become: (Q1, Q2, Q3, QC) up to sign, and rates in deg/s."""
    quaternions = segment.quaternion_body_to_inertial_scalar_first
    return quaternions[:, [1, 2, 3, 0]], np.degrees(segment.angular_velocity_body_rad_s)


def _same_up_to_sign(actual, expected):
    signs = np.where(np.sum(actual * expected, axis=1) < 0.0, -1.0, 1.0)[:, np.newaxis]
    return expected * signs


def test_90_degree_rotation_about_z(tmp_path):
    """A body whose x axis points along inertial +y: the fields are annex F2.2's example.

    By hand.  Ours: the body→inertial rotation that sends the body x axis to inertial +y is
    +90° about z, so q = (w, x, y, z) = (cos 45°, 0, 0, sin 45°).

    CCSDS (annex F2.1).  With A = ICRF and B = SC_BODY_1, the quaternion "from A to B" is
    the rotation carrying A's basis vectors onto B's.  B's x axis is A's y axis, so that
    rotation is +90° about z: axis e = (0, 0, 1), angle φ = 90°.  Then
    Q1 = Q2 = 0, Q3 = e₃ sin(φ/2) = √½, and QC = cos(φ/2) = √½.  These are F2.2's numbers.

    Check with the annex's matrix.  M_BA(0, 0, √½, √½) has rows [Q1²−Q2²−Q3²+QC²,
    2(Q1Q2+Q3QC), 2(Q1Q3−Q2QC)] = [0, 1, 0], then [−1, 0, 0] and [0, 0, 1].  The inertial
    +y axis, X_A = (0, 1, 0), has body coordinates X_B = M_BA X_A = (1, 0, 0): it is the
    body's x axis, as required.

    With a body rate of 0.01 rad/s about body z, ANGVEL_Z = 0.01 × 180/π deg/s.
    """
    half = np.sqrt(0.5)
    q = np.array([[half, 0.0, 0.0, half]])
    assert np.allclose(Rotation.from_quat(q[0], scalar_first=True).apply([1, 0, 0]), [0, 1, 0])
    rate_rad_s = 0.01
    segment = AemSegment(_utc("2027-01-01T00:00:00"), q, [[0.0, 0.0, rate_rad_s]], ("90 deg",))
    path = _write(tmp_path / "ninety.aem", [segment], comments=["hand check"])

    # The text itself: Q1 Q2 Q3 QC = 0, 0, √½, √½ (16 significant digits), then deg/s.
    [[fields]] = _data_fields(path)
    assert fields == [
        "2027-01-01T00:00:00.000000000",
        "0.000000000000000E+00",
        "0.000000000000000E+00",
        "7.071067811865476E-01",
        "7.071067811865476E-01",
        "0.000000000000000E+00",
        "0.000000000000000E+00",
        "5.729577951308232E-01",
    ]
    q1, q2, q3, qc = (float(value) for value in fields[1:5])
    m_ba = _m_ba(q1, q2, q3, qc)
    np.testing.assert_allclose(m_ba, [[0, 1, 0], [-1, 0, 0], [0, 0, 1]], atol=1e-16)
    np.testing.assert_allclose(m_ba @ [0, 1, 0], [1, 0, 0], atol=1e-16)

    # The independent parser reads the same numbers and the right metadata.
    message = parse(path)
    assert message.version == "2.0"
    assert message.header.creation_date == CREATED
    assert message.header.originator == "attitude"
    assert message.header.comment == ["hand check", QUATERNION_COMMENT]  # ours, always
    [parsed] = message.segments
    np.testing.assert_array_equal(
        parsed.data.attitude_states_numpy,
        [[0.0, 0.0, half, half, 0.0, 0.0, np.degrees(rate_rad_s)]],
    )
    assert parsed.data.attitude_states_epochs == ["2027-01-01T00:00:00.000000000"]
    metadata = parsed.metadata
    assert metadata.comment == ["90 deg"]
    assert (metadata.object_name, metadata.object_id, metadata.center_name) == (
        "TESTSAT",
        "2027-001A",
        "EARTH",
    )
    assert (metadata.ref_frame_a, metadata.ref_frame_b) == ("ICRF", "SC_BODY_1")
    assert (metadata.attitude_type, metadata.angvel_frame) == ("QUATERNION/ANGVEL", "SC_BODY_1")
    assert metadata.time_system == "UTC"
    start = "2027-01-01T00:00:00.000000000"
    assert (metadata.start_time, metadata.useable_start_time) == (start, start)
    assert (metadata.useable_stop_time, metadata.stop_time) == (start, start)
    # One record: too few for any interpolation to be recommended.
    assert metadata.interpolation_method is None


def test_annex_f_matrix_of_the_written_fields_is_our_rotation_transposed(tmp_path):
    """For random attitudes, M_BA built from the parsed fields maps inertial to body coordinates.

    X_B = M_BA X_A (annex F2.1) must equal R(q)ᵀ X_A, with R(q) our body→inertial matrix.
    """
    quaternions = Rotation.random(50, random_state=7).as_quat(scalar_first=True)
    with offline_time():
        times = time_from_tt_seconds(Time("2030-01-01T00:00:00", scale="tt"), np.arange(50.0))
    segment = AemSegment(times, quaternions, np.zeros((50, 3)))
    path = _write(tmp_path / "random.aem", [segment], time_scale="tt")
    fields = parse(path).segments[0].data.attitude_states_numpy
    ours = Rotation.from_quat(quaternions, scalar_first=True).as_matrix()
    for row, matrix in zip(fields, ours, strict=True):
        np.testing.assert_allclose(_m_ba(*row[:4]), matrix.T, rtol=0, atol=1e-15)


@pytest.mark.parametrize("time_scale", ["utc", "tt", "tdb", "tai"])
def test_multi_segment_round_trip(tmp_path, time_scale):
    """Three segments sharing event epochs round-trip through ccsds-ndm-py."""
    segments = _random_segments(seed=11, time_scale=time_scale)
    path = _write(tmp_path / f"{time_scale}.aem", segments, time_scale=time_scale)
    text_fields = _data_fields(path)
    read, message = read_back(path)

    assert len(message.segments) == len(read) == len(segments) == 3
    assert message.header.originator == "attitude"
    assert message.header.creation_date == CREATED
    for original, ours, theirs, fields in zip(
        segments, read, message.segments, text_fields, strict=True
    ):
        expected_q, expected_deg_s = _aem_fields(original)
        # Epochs: written in the requested time system, to 1 ns.
        with offline_time():
            expected_epochs = Time(getattr(original.times, time_scale), precision=9).isot.tolist()
        assert theirs.data.attitude_states_epochs == expected_epochs
        assert [row[0] for row in fields] == expected_epochs
        assert theirs.metadata.time_system == time_scale.upper()
        assert theirs.metadata.start_time == expected_epochs[0]
        assert theirs.metadata.stop_time == expected_epochs[-1]
        assert ours.times.scale == time_scale
        assert np.abs(tt_seconds(ours.times, original.times)).max() <= 0.5e-9 + 1e-12

        # The parser reads exactly the numbers in the text ...
        numbers = theirs.data.attitude_states_numpy
        np.testing.assert_array_equal(numbers, [[float(v) for v in row[1:]] for row in fields])
        # ... which are the expected fields up to sign, to 16 significant digits.
        aligned = _same_up_to_sign(numbers[:, :4], expected_q)
        np.testing.assert_allclose(numbers[:, :4], aligned, rtol=0, atol=1e-15)
        np.testing.assert_allclose(numbers[:, :4], aligned, rtol=0, atol=QUATERNION_FORMAT_ERROR)
        np.testing.assert_allclose(numbers[:, 4:], expected_deg_s, rtol=1e-15, atol=0)

        # Read back into our convention, and rad/s.
        back = ours.quaternion_body_to_inertial_scalar_first
        original_q = original.quaternion_body_to_inertial_scalar_first
        np.testing.assert_allclose(back, _same_up_to_sign(back, original_q), rtol=0, atol=1e-15)
        np.testing.assert_allclose(
            ours.angular_velocity_body_rad_s,
            original.angular_velocity_body_rad_s,
            rtol=1e-15,
            atol=0,
        )

    # Events: each segment starts at the epoch where the previous one stops.
    for before, after in zip(message.segments, message.segments[1:], strict=False):
        assert after.metadata.start_time == before.metadata.stop_time
        assert after.metadata.useable_start_time >= before.metadata.useable_stop_time


def test_signs_are_continuous_across_records_and_segments(tmp_path):
    """The first QC is ≥ 0 and each record is in the hemisphere of the one before it."""
    segments = _random_segments(seed=3, time_scale="tt")
    # Flip every other input quaternion: the file must not care.
    flipped = [
        AemSegment(
            s.times,
            s.quaternion_body_to_inertial_scalar_first * (-1.0) ** np.arange(len(s.times))[:, None],
            s.angular_velocity_body_rad_s,
        )
        for s in segments
    ]
    for chosen, name in ((segments, "a.aem"), (flipped, "b.aem")):
        numbers = np.vstack(
            [s.data.attitude_states_numpy for s in parse(_write(tmp_path / name, chosen)).segments]
        )
        assert numbers[0, 3] >= 0.0
        assert (np.sum(numbers[1:, :4] * numbers[:-1, :4], axis=1) >= 0.0).all()
    assert (tmp_path / "a.aem").read_text() == (tmp_path / "b.aem").read_text()


def test_leap_second_epoch(tmp_path):
    """2016-12-31T23:59:60 UTC is written as such (§4.2.4.7.3) and read back 1 s apart."""
    times = _utc(
        "2016-12-31T23:59:58",
        "2016-12-31T23:59:59",
        "2016-12-31T23:59:60",
        "2017-01-01T00:00:00",
        "2017-01-01T00:00:01",
    )
    quaternions = Rotation.random(5, random_state=5).as_quat(scalar_first=True)
    segment = AemSegment(times, quaternions, np.full((5, 3), 0.001))
    utc = _write(tmp_path / "utc.aem", [segment], time_scale="utc")
    epochs = parse(utc).segments[0].data.attitude_states_epochs
    assert epochs[2] == "2016-12-31T23:59:60.000000000"
    [read], _ = read_back(utc)
    np.testing.assert_allclose(tt_seconds(read.times[1:], read.times[:-1]), 1.0, rtol=0, atol=1e-9)

    # In TT the same instant has an ordinary reading: TT − UTC = 32.184 s + 36 s then.
    tt = _write(tmp_path / "tt.aem", [segment], time_scale="tt")
    assert parse(tt).segments[0].data.attitude_states_epochs[2] == "2017-01-01T00:01:08.184000000"


def test_angular_velocity_is_written_in_degrees_per_second(tmp_path):
    """ANGVEL_X/Y/Z are deg/s (§4.2.4.6): 1 deg/s is written 1.0, and comes back in rad/s."""
    rates_rad_s = np.radians([[1.0, -2.5, 90.0], [0.0, 1e-9, -360.0]])
    quaternions = np.tile([1.0, 0.0, 0.0, 0.0], (2, 1))
    segment = AemSegment(
        _utc("2027-01-01T00:00:00", "2027-01-01T00:00:01"), quaternions, rates_rad_s
    )
    path = _write(tmp_path / "rates.aem", [segment])
    [fields] = _data_fields(path)
    assert fields[0][5:] == [
        "1.000000000000000E+00",
        "-2.500000000000000E+00",
        "9.000000000000000E+01",
    ]
    np.testing.assert_allclose(
        parse(path).segments[0].data.attitude_states_numpy[:, 4:],
        [[1.0, -2.5, 90.0], [0.0, 1e-9, -360.0]],
        rtol=1e-15,
    )
    [read], _ = read_back(path)
    np.testing.assert_allclose(read.angular_velocity_body_rad_s, rates_rad_s, rtol=1e-15, atol=0)


def test_hermite_with_the_written_rates_reproduces_a_uniform_spin(tmp_path):
    """The rates agree with the quaternions, so HERMITE interpolation from the file works.

    For a body spinning at a constant ω about body axis n, our q(t) = q₀ ⊗ (cos ωt/2,
    n sin ωt/2).  From the file alone, the annex F kinematics give Q̇ = ½ Q ⊗ (ω_B, 0),
    scalar last.  With that derivative, the cubic Hermite polynomial between two records h
    apart must hit the true midpoint within h⁴/384 · max|f⁗| = (ωh/2)⁴/384.  The
    components are sinusoids of frequency ω/2.  A rate with the wrong sign or in the wrong
    frame misses by O(ωh).
    """
    rate_rad_s, step_s = 0.05, 2.0
    axis = np.array([1.0, 2.0, 2.0]) / 3.0
    start = Rotation.from_quat([0.3, -0.1, 0.5, 0.8], scalar_first=True)

    def attitude(t_s):
        return start * Rotation.from_rotvec(np.outer(t_s, axis) * rate_rad_s)

    t_s = np.arange(6) * step_s
    with offline_time():
        times = time_from_tt_seconds(Time("2031-05-01T00:00:00", scale="tt"), t_s)
    segment = AemSegment(
        times,
        attitude(t_s).as_quat(scalar_first=True),
        np.tile(axis * rate_rad_s, (6, 1)),
    )
    path = _write(tmp_path / "spin.aem", [segment], time_scale="tt")
    parsed = parse(path).segments[0]
    assert (parsed.metadata.interpolation_method, parsed.metadata.interpolation_degree) == (
        "HERMITE",
        3,
    )

    numbers = parsed.data.attitude_states_numpy
    q, omega_body = numbers[:, :4], np.radians(numbers[:, 4:])

    def midpoint_error(omega):
        q_dot = 0.5 * _hamilton_scalar_last(q, np.hstack([omega, np.zeros((len(q), 1))]))
        hermite = (q[:-1] + q[1:]) / 2 + step_s * (q_dot[:-1] - q_dot[1:]) / 8
        exact = attitude(t_s[:-1] + step_s / 2).as_quat()  # scipy: scalar last, like the AEM
        return np.abs(hermite - _same_up_to_sign(hermite, exact)).max()

    bound = (rate_rad_s * step_s / 2) ** 4 / 384
    assert midpoint_error(omega_body) <= bound
    assert midpoint_error(-omega_body) > 100 * bound


def test_interpolation_is_recommended_only_with_four_records_or_more(tmp_path):
    """HERMITE/3 is written where a segment has the records it needs (§4.2.4.8.4)."""
    segments = _random_segments(seed=2, time_scale="utc", counts=(4, 3, 2))
    message = parse(_write(tmp_path / "interp.aem", segments))
    methods = [
        (s.metadata.interpolation_method, s.metadata.interpolation_degree) for s in message.segments
    ]
    assert methods == [("HERMITE", 3), (None, None), (None, None)]


def test_creation_date_defaults_to_now_in_utc(tmp_path):
    segment = AemSegment(_utc("2027-01-01T00:00:00"), [[1.0, 0.0, 0.0, 0.0]], [[0.0, 0.0, 0.0]])
    before = Time.now()
    path = write_aem(
        tmp_path / "now.aem",
        [segment],
        object_name="TESTSAT",
        object_id="UNKNOWN",
        time_scale="utc",
    )
    written = Time(parse(path).header.creation_date, scale="utc")
    assert -1.0 <= (written - before).sec <= 60.0


# --- bad input -------------------------------------------------------------------------

T3 = ("2027-01-01T00:00:00", "2027-01-01T00:00:01", "2027-01-01T00:00:02")
Q3 = Rotation.random(3, random_state=1).as_quat(scalar_first=True)
W3 = np.zeros((3, 3))


def _good():
    return AemSegment(_utc(*T3), Q3, W3)


def _bad_quaternion(row, column, value):
    q = Q3.copy()
    q[row, column] = value
    return q


BAD_INPUTS = {
    "non-unit quaternion": (
        lambda: [AemSegment(_utc(*T3), Q3 * [[1.0], [1.0], [1.1]], W3)],
        {},
        r"quaternion_body_to_inertial_scalar_first\[2\] = .* has norm 1\.1",
    ),
    "nan quaternion": (
        lambda: [AemSegment(_utc(*T3), _bad_quaternion(1, 2, np.nan), W3)],
        {},
        r"quaternion_body_to_inertial_scalar_first must be finite, got nan at \[1, 2\]",
    ),
    "infinite rate": (
        lambda: [AemSegment(_utc(*T3), Q3, [[0, 0, 0], [0, 0, 0], [0, np.inf, 0]])],
        {},
        r"angular_velocity_body_rad_s must be finite, got inf at \[2, 1\]",
    ),
    "repeated epoch": (
        lambda: [AemSegment(_utc(T3[0], T3[1], T3[1]), Q3, W3)],
        {},
        r"times must increase strictly .*times\[2\] = 2027-01-01T00:00:01\.000000000 UTC",
    ),
    "decreasing epochs": (
        lambda: [AemSegment(_utc(T3[1], T3[0], T3[2]), Q3, W3)],
        {},
        r"times\[1\] = 2027-01-01T00:00:00\.000000000 UTC is not after",
    ),
    "quaternion shape": (
        lambda: [AemSegment(_utc(*T3), Q3[:, :3], W3)],
        {},
        r"quaternion_body_to_inertial_scalar_first must have shape \(3, 4\) .*got \(3, 3\)",
    ),
    "rate rows": (
        lambda: [AemSegment(_utc(*T3), Q3, np.zeros((2, 3)))],
        {},
        r"angular_velocity_body_rad_s must have shape \(3, 3\) .*got \(2, 3\)",
    ),
    "text quaternion": (
        lambda: [AemSegment(_utc(*T3), [["a"] * 4] * 3, W3)],
        {},
        r"quaternion_body_to_inertial_scalar_first must be numeric",
    ),
    "empty segment": (
        lambda: [AemSegment(Time([], format="jd", scale="tt"), np.zeros((0, 4)), np.zeros((0, 3)))],
        {},
        r"empty segment",
    ),
    "times not a Time": (
        lambda: [AemSegment(list(T3), Q3, W3)],
        {},
        r"times must be an astropy\.time\.Time, got list",
    ),
    "scalar time": (
        lambda: [AemSegment(Time(T3[0], scale="utc"), Q3[:1], W3[:1])],
        {},
        r"times must be 1-D, got shape \(\)",
    ),
    "no segments": (lambda: [], {}, r"at least one segment"),
    "not a segment": (lambda: [Q3], {}, r"segments\[0\] must be an AemSegment, got ndarray"),
    "overlapping segments": (
        lambda: [
            _good(),
            AemSegment(_utc("2027-01-01T00:00:01.5", "2027-01-01T00:00:03"), Q3[:2], W3[:2]),
        ],
        {},
        r"segments\[1\] starts at 2027-01-01T00:00:01\.500000000 UTC, before segments\[0\] stops",
    ),
    "epochs closer than 1 ns": (
        lambda: [
            AemSegment(
                _utc("2027-01-01T00:00:00", "2027-01-01T00:00:00.0000000001"), Q3[:2], W3[:2]
            )
        ],
        {},
        r"times\[0\] and \[1\] are both written 2027-01-01T00:00:00\.000000000 UTC",
    ),
    "year 10000": (
        lambda: [
            AemSegment(
                time_from_tt_seconds(Time("9999-12-31T23:59:59", scale="tt"), [0.0, 2.0]),
                Q3[:2],
                W3[:2],
            )
        ],
        {"time_scale": "tt"},
        r"segments\[0\]\.times: 10000-01-01T00:00:01\.000000000 TT is outside the years 0000-9999",
    ),
    "time scale": (
        lambda: [_good()],
        {"time_scale": "ut1"},
        r"time_scale must be one of .*got 'ut1'",
    ),
    "frame": (
        lambda: [_good()],
        {"reference_frame": "EME2000"},
        r"reference_frame must be one of ICRF, GCRF",
    ),
    "mixed-case name": (
        lambda: [_good()],
        {"object_name": "TestSat"},
        r"object_name: 'TestSat' cannot be written: .*all upper case or all lower case",
    ),
    "empty id": (
        lambda: [_good()],
        {"object_id": ""},
        r"object_id: '' cannot be written: it is empty",
    ),
    "two-line comment": (
        lambda: [_good()],
        {"comments": ["one\ntwo"]},
        r"comments\[0\]: 'one\\ntwo' must be one line",
    ),
    "creation date": (
        lambda: [_good()],
        {"creation_date": "yesterday"},
        r"creation_date: not an ISO 8601 epoch",
    ),
}


@pytest.mark.parametrize("case", list(BAD_INPUTS))
def test_bad_input_leaves_no_file_behind(tmp_path, case):
    """Every bad input raises InputError naming the field and value, and writes nothing."""
    make_segments, options, message = BAD_INPUTS[case]
    with pytest.raises(InputError, match=message):
        _write(tmp_path / "bad.aem", make_segments(), **options)
    assert list(tmp_path.iterdir()) == []


def test_a_failed_write_keeps_the_previous_file(tmp_path):
    path = _write(tmp_path / "keep.aem", [_good()])
    before = path.read_bytes()
    with pytest.raises(InputError):
        _write(path, [_good()], object_name="Mixed Case")
    assert path.read_bytes() == before
    assert list(tmp_path.iterdir()) == [path]


def test_an_interrupted_write_leaves_no_temporary_file(tmp_path, monkeypatch):
    def failing_replace(source, target):
        raise OSError("disk full")

    monkeypatch.setattr(os, "replace", failing_replace)
    with pytest.raises(OSError, match="disk full"):
        _write(tmp_path / "interrupted.aem", [_good()])
    assert list(tmp_path.iterdir()) == []


def test_the_file_keeps_the_umask_permissions(tmp_path):
    umask = os.umask(0o022)
    os.umask(umask)
    path = _write(tmp_path / "mode.aem", [_good()])
    assert path.stat().st_mode & 0o777 == 0o666 & ~umask


# --- the read-back checks can fail ---------------------------------------------------
# ccsds-ndm-py accepts every one of these files: the checks of aem_read_back catch them.


def _good_text(tmp_path, time_scale="utc", times=T3):
    times = Time(list(times), scale=time_scale)
    return _write(
        tmp_path / "good.aem", [AemSegment(times, Q3, W3)], time_scale=time_scale
    ).read_text()


def _replace_once(text, old, new):
    assert text.count(old) >= 1, old
    return text.replace(old, new, 1)


def _first_data_line(text):
    return text.split("DATA_START\n")[1].splitlines()[0]


def _two_segments_overlapping(tmp_path):
    first = AemSegment(_utc(*T3), Q3, W3)
    second = AemSegment(_utc("2027-01-01T00:00:02", "2027-01-01T00:00:03"), Q3[:2], W3[:2])
    text = _write(tmp_path / "two.aem", [first, second]).read_text()
    earlier = "2027-01-01T00:00:01.500000000"
    return text.replace(
        "USEABLE_START_TIME = 2027-01-01T00:00:02.000000000", f"USEABLE_START_TIME = {earlier}"
    ).replace("START_TIME = 2027-01-01T00:00:02.000000000", f"START_TIME = {earlier}")


def _non_unit_quaternion(tmp_path):
    text = _good_text(tmp_path)
    line = _first_data_line(text)
    return _replace_once(text, line, re.sub(r" \S+", " 9.0E-01", line, count=4))


def _epochs_swapped(tmp_path):
    """Records 1 and 2 swap their epochs: still inside START_TIME ... STOP_TIME."""
    one, two = "\n2027-01-01T00:00:01.000000000 ", "\n2027-01-01T00:00:02.000000000 "
    text = _good_text(tmp_path)
    return text.replace(one, "\nSWAP ").replace(two, one).replace("\nSWAP ", two)


CORRUPTED = {
    "non-unit quaternion": (_non_unit_quaternion, r"record 0: quaternion norm 1\.8"),
    "decreasing epochs": (_epochs_swapped, r"epochs do not increase strictly"),
    "data before START_TIME": (
        lambda tmp: _good_text(tmp).replace(
            "START_TIME = 2027-01-01T00:00:00.000000000",
            "START_TIME = 2027-01-01T00:00:00.500000000",
        ),
        r"data before START_TIME",
    ),
    "data after STOP_TIME": (
        lambda tmp: _good_text(tmp).replace(
            "STOP_TIME = 2027-01-01T00:00:02.000000000",
            "STOP_TIME = 2027-01-01T00:00:01.500000000",
        ),
        r"data after STOP_TIME",
    ),
    "leap second in TT": (
        lambda tmp: _replace_once(
            _good_text(
                tmp,
                "tt",
                ("2017-01-01T00:00:59", "2017-01-01T00:01:00", "2017-01-01T00:01:01"),
            ),
            "\n2017-01-01T00:01:00.000000000 ",
            "\n2017-01-01T00:00:60.000000000 ",
        ),
        r"astropy reads 2017-01-01T00:00:60\.000000000 tt as 2017-01-01T00:01:00",
    ),
    "invented leap second": (
        # No leap second ended 2017-06-30 (IERS Bulletin C).
        lambda tmp: _replace_once(
            _good_text(
                tmp,
                "utc",
                ("2017-06-30T23:59:59", "2017-07-01T00:00:00", "2017-07-01T00:00:01"),
            ),
            "\n2017-07-01T00:00:00.000000000 ",
            "\n2017-06-30T23:59:60.000000000 ",
        ),
        r"astropy reads 2017-06-30T23:59:60\.000000000 utc as",
    ),
    "overlapping segments": (
        _two_segments_overlapping,
        r"segment 1: useable span starts before the previous one ends",
    ),
}


@pytest.mark.parametrize("case", list(CORRUPTED))
def test_read_back_catches_what_the_parser_accepts(tmp_path, case):
    change, message = CORRUPTED[case]
    path = tmp_path / "changed.aem"
    path.write_text(change(tmp_path))
    parse(path)  # the independent parser takes it
    with pytest.raises(AssertionError, match=message):
        read_back(path)
