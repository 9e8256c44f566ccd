"""``attitude fit`` as a user runs it, against the scenario that made the telemetry:
the outputs of ``attitude run`` (CSV, Parquet, AEM) fitted back to the moments and the
rate they were made with; a noisy CSV whose fitted scenario ``attitude run`` then
predicts within the stated uncertainty; a known impulse from ``--scenario`` giving the
absolute moments; and hostile files and options refused with one line naming the
file, the column, the row or the option."""

import json
import os
from pathlib import Path

import numpy as np
import pytest
from cli_lines import said
from scipy.spatial.transform import Rotation
from signal_dispositions import defaults

from attitude import EulerSolver, fit_spin_state
from attitude.cli.main import main
from attitude.environment.timescales import tt_seconds
from attitude.estimation.telemetry_files import read_telemetry

MOMENTS = np.array([100.0, 200.0, 260.0])
ω0 = np.array([0.05, 0.02, 0.03])
Q_INIT = np.array(
    [0.9515485246437885, 0.2392983377447303, 0.18930785741199993, 0.03813457647485015]
)

SCENARIO = f"""
[scenario]
name = "truth"
epoch = "2027-03-01T00:00:00"

[spacecraft]
name = "tumbler"
principal_moments = {MOMENTS.tolist()}

[initial_state]
quaternion = {Q_INIT.tolist()}
angular_velocity = {ω0.tolist()}

[[events]]
type = "angular_impulse"
offset = 401.0
impulse = [3.0, -2.0, 1.5]

[output]
duration = 900.0
step = 2.0
"""


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("truth")
    (folder / "truth.toml").write_text(SCENARIO)
    assert (
        main(
            [
                "run",
                str(folder / "truth.toml"),
                "--out",
                str(folder / "out"),
                "--quiet",
                "--formats",
                "csv,parquet,aem",
            ]
        )
        == 0
    )
    return folder


def _fit_json(out: Path) -> dict:
    return json.loads((out / "fit.json").read_text())


@pytest.mark.parametrize("name", ["timeseries.csv", "timeseries.parquet", "attitude.aem"])
def test_the_outputs_of_attitude_run_fit_back_to_their_scenario(run, tmp_path, name):
    """With the impulse of the scenario (--scenario), the absolute moments come back."""
    out = tmp_path / "fit"
    code = main(
        [
            "fit",
            str(run / "out" / name),
            "--out",
            str(out),
            "--scenario",
            str(run / "truth.toml"),
            "--gyro-sigma",
            "1e-7 rad/s",
            "--attitude-sigma",
            "1e-6 rad",
            "--quiet",
        ]
    )
    assert code == 0
    summary = _fit_json(out)
    np.testing.assert_allclose(summary["principal_moments_kg_m2"], MOMENTS, rtol=1e-5)
    np.testing.assert_allclose(summary["angular_velocity_rad_s"], ω0, rtol=1e-6, atol=1e-9)
    assert sorted(os.listdir(out)) == sorted(
        [
            "attitude-manifest.json",
            "correlations.csv",
            "fit.json",
            "fitted_scenario.toml",
            "parameters.csv",
            "report.html",
            "residuals.csv",
            "residuals.png",
            "uncertainty.png",
        ]
    )
    text = (out / "fitted_scenario.toml").read_text()
    assert "absolute moments observable" in text
    assert 'type = "angular_impulse"' in text  # the impulse after the epoch is kept


def test_a_noisy_csv_its_fitted_scenario_predicts_within_its_uncertainty(tmp_path):
    rng = np.random.default_rng(41)
    solver = EulerSolver(MOMENTS, MOMENTS * ω0, Rotation.from_quat(Q_INIT, scalar_first=True))
    t = np.arange(0.0, 1200.0, 2.0)
    σ_ω, σ_q = 1e-3, 1e-3
    ω = solver.angular_velocity(t) + σ_ω * rng.standard_normal((t.size, 3))
    q = solver.attitude(t) * Rotation.from_rotvec(σ_q * rng.standard_normal((t.size, 3)))
    q = q.as_quat(scalar_first=True)
    q[1::3] *= -1.0  # sign flips, as some star trackers give
    lines = [
        "# epoch: 2027-03-01T00:00:00.000000000 UTC; t_s = TT seconds since the epoch",
        "t_s,omega_body_x_rad_s,omega_body_y_rad_s,omega_body_z_rad_s,"
        "q_body_to_icrf_w,q_body_to_icrf_x,q_body_to_icrf_y,q_body_to_icrf_z",
    ]
    for k in range(t.size):
        att = ",".join(repr(float(x)) for x in q[k]) if k % 4 == 0 else ",,,"
        rates = ",".join(repr(float(x)) for x in ω[k])
        lines.append(f"{float(t[k])!r},{rates},{att}")
    (tmp_path / "telemetry.csv").write_text("\n".join(lines) + "\n")
    out = tmp_path / "fit"
    assert (
        main(
            [
                "fit",
                str(tmp_path / "telemetry.csv"),
                "--out",
                str(out),
                "--quiet",
                "--attitude-sigma",
                f"{σ_q} rad",
            ]
        )
        == 0
    )
    summary = _fit_json(out)
    horizon = summary["prediction_horizon_s"]
    assert 1200.0 < horizon < 30 * 86400.0
    # Its span is the horizon, or 20 000 steps if shorter: set to the horizon here, as
    # its comment tells a user who wants to predict that far.
    import tomllib

    text = (out / "fitted_scenario.toml").read_text()
    output = tomllib.loads(text)["output"]
    assert output["duration"] == pytest.approx(min(horizon, 20_000 * output["step"]), rel=1e-9)
    text = text.replace(f"duration = {output['duration']!r}", f"duration = {horizon!r}")
    (out / "fitted_scenario.toml").write_text(text)
    predicted = tmp_path / "predicted"
    assert (
        main(
            [
                "run",
                str(out / "fitted_scenario.toml"),
                "--out",
                str(predicted),
                "--quiet",
                "--formats",
                "csv",
            ]
        )
        == 0
    )
    run = read_telemetry(predicted / "timeseries.csv")
    times = tt_seconds(run.times, run.times[0])  # the fitted scenario's epoch: t = 0
    assert abs(times[-1] - horizon) < 1e-6 * horizon  # its span is the horizon
    pick = np.flatnonzero(times > 1200.0)[::50]
    later, q_run = times[pick], run.quaternions[pick]
    error = (
        Rotation.from_quat(q_run, scalar_first=True).inv() * solver.attitude(later)
    ).magnitude()
    # The same fit in Python gives the stated uncertainty there: the truth lies within it.
    telemetry = read_telemetry(tmp_path / "telemetry.csv")
    fit = fit_spin_state(
        telemetry.times,
        angular_velocity=telemetry.angular_velocity,
        quaternions=telemetry.quaternions,
        attitude_sigma=σ_q,
    )
    σ, _ = fit.uncertainty(later)
    assert np.all(error < 4.0 * σ + 1e-6)
    assert np.max(σ) > 0.05  # the comparison reaches well into the growth


def test_hostile_files_and_options_are_refused_with_one_line(tmp_path, capsys):
    out = str(tmp_path / "out")

    def refused(args, pattern):
        code = main(["fit", *args])
        err = "\n".join(said(capsys.readouterr().err))  # without the progress lines
        assert code == 2, err
        assert len(err.strip().splitlines()) == 1, err
        assert pattern in err, err

    (tmp_path / "binary.csv").write_bytes(b"\x00\x01\x02" * 100)
    refused([str(tmp_path / "binary.csv"), "--out", out], "binary.csv: a binary file")
    (tmp_path / "columns.csv").write_text("a,b,c\n1,2,3\n")
    refused([str(tmp_path / "columns.csv"), "--out", out], "no time column")
    (tmp_path / "cell.csv").write_text(
        "t_s,omega_body_x_rad_s,omega_body_y_rad_s,omega_body_z_rad_s\n0,1,2,3\n1,x,2,3\n"
    )
    refused(
        [str(tmp_path / "cell.csv"), "--out", out, "--epoch", "2027-01-01T00:00:00"],
        "row 1, column omega_body_x_rad_s: 'x' is not a number",
    )
    (tmp_path / "relative.csv").write_text(
        "t_s,omega_body_x_rad_s,omega_body_y_rad_s,omega_body_z_rad_s\n0,1,2,3\n1,1,2,3\n"
    )
    refused([str(tmp_path / "relative.csv"), "--out", out], "give --epoch")
    refused([str(tmp_path / "missing.csv"), "--out", out], "no such file")
    refused(
        [str(tmp_path / "relative.csv"), "--out", out, "--gyro-sigma", "1e-4 Hz"], "--gyro-sigma"
    )
    refused(
        [str(tmp_path / "relative.csv"), "--out", out, "--gyro-sigma", "1e-4"],
        "needs a value with its unit",
    )
    (tmp_path / "empty.csv").write_text("")
    refused([str(tmp_path / "empty.csv"), "--out", out], "empty.csv")
    taken = tmp_path / "taken"
    taken.mkdir()
    (taken / "mine.txt").write_text("the user's")
    refused([str(tmp_path / "relative.csv"), "--out", str(taken)], "did not write")
    assert (taken / "mine.txt").read_text() == "the user's"
    partly = tmp_path / "partly.csv"
    partly.write_text("time_utc,omega_body_x_rad_s,omega_body_y_rad_s\n2027-01-01T00:00:00,1,2\n")
    refused([str(partly), "--out", out], "omega_body_z_rad_s is missing")
    assert not (tmp_path / "out").exists()  # nothing written by any refusal


def test_the_example_telemetry_fits_to_the_truth_that_made_it(tmp_path, monkeypatch):
    """scenarios/telemetry: its generator remakes the same bytes, and the fit of the
    file finds the moments it was made with (850, 1400, 1650 kg m²), outliers flagged."""
    import importlib.util
    import shutil

    folder = Path(__file__).parents[1] / "scenarios" / "telemetry"
    script = tmp_path / "make_tumbler_telemetry.py"
    shutil.copy(folder / "make_tumbler_telemetry.py", script)
    spec = importlib.util.spec_from_file_location("make_tumbler_telemetry", script)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    module.main()
    assert (tmp_path / "tumbler_telemetry.csv").read_bytes() == (
        folder / "tumbler_telemetry.csv"
    ).read_bytes()
    telemetry = read_telemetry(folder / "tumbler_telemetry.csv")
    fit = fit_spin_state(
        telemetry.times,
        angular_velocity=telemetry.angular_velocity,
        quaternions=telemetry.quaternions,
        attitude_sigma=np.radians(20.0 / 3600.0),
    )
    truth = np.array([1400.0, 1650.0]) / 850.0
    assert np.all(np.abs(fit.inertia_ratios[1:] - truth) < 4.0 * fit.inertia_ratios_sigma[1:])
    assert np.count_nonzero(~fit.residuals["gyro"]["inlier"]) == 3


def test_ctrl_c_leaves_nothing_behind(tmp_path):
    """SIGINT in the middle of a fit: exit status 130, one line, and no output folder.
    The child starts with SIGINT at its default action whatever pytest started with (a
    ``pytest &`` ignores it, and the command rightly keeps an ignored SIGINT ignored:
    tests/signal_dispositions.py)."""
    import signal
    import subprocess
    import sys
    import time

    solver = EulerSolver(MOMENTS, MOMENTS * ω0)
    t = np.arange(0.0, 80000.0, 1.0)  # a fit of seconds
    ω = solver.angular_velocity(t) + 1e-4 * np.random.default_rng(61).standard_normal((t.size, 3))
    rows = "\n".join(f"{k:g},{a:.6e},{b:.6e},{c:.6e}" for k, (a, b, c) in zip(t, ω, strict=True))
    header = "t_s,omega_body_x_rad_s,omega_body_y_rad_s,omega_body_z_rad_s\n"
    (tmp_path / "long.csv").write_text(header + rows + "\n")
    out = tmp_path / "out"
    process = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "attitude",
            "fit",
            str(tmp_path / "long.csv"),
            "--out",
            str(out),
            "--epoch",
            "2027-03-01T00:00:00",
        ],
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=defaults,
    )
    for _ in range(20):  # until the fit has begun: "[   2.1 s] fit: 80000 gyro samples ..."
        first = process.stderr.readline()
        if "fit: " in first or not first:
            break
    assert "fit: " in first, first
    time.sleep(0.2)
    process.send_signal(signal.SIGINT)
    _, err = process.communicate(timeout=120)
    assert process.returncode == 130, err
    assert err.strip().splitlines()[-1] == (
        "attitude: error: interrupted; nothing of this run was left behind"
    )
    assert not out.exists()


GRAVITY_GRADIENT = """
[scenario]
name = "tumbler under gravity gradient"
epoch = "2027-03-01T00:00:00"

[spacecraft]
name = "tumbler"
principal_moments = [100.0, 200.0, 260.0]

[initial_state]
quaternion = [0.9515485246437885, 0.2392983377447303, 0.18930785741199993, 0.03813457647485015]
angular_velocity = [0.02, 0.01, 0.015]

[torques]
gravity_gradient = true
step = 5.0

[output]
duration = 1200.0
step = 4.0

[pointing.keplerian]
semi_major_axis = { value = 7000.0, unit = "km" }
eccentricity = 0.0
inclination = { value = 51.6, unit = "deg" }
raan = { value = 0.0, unit = "deg" }
argument_of_perigee = { value = 0.0, unit = "deg" }
mean_anomaly = { value = 0.0, unit = "deg" }
"""


@pytest.mark.slow  # 8 s of CPU: the API's fit under gravity gradient runs by default
def test_gravity_gradient_from_the_scenario_file(tmp_path):
    """The telemetry of a run under gravity gradient (5 s step), fitted with the orbit and
    the torques of the same file (--scenario, at 20 s): the moments' ratios come back,
    and the fitted scenario keeps the orbit and the torques."""
    (tmp_path / "truth.toml").write_text(GRAVITY_GRADIENT)
    run = tmp_path / "run"
    assert (
        main(
            [
                "run",
                str(tmp_path / "truth.toml"),
                "--out",
                str(run),
                "--quiet",
                "--formats",
                "parquet",
            ]
        )
        == 0
    )
    context = tmp_path / "context.toml"
    context.write_text(GRAVITY_GRADIENT.replace("step = 5.0", "step = 20.0"))
    out = tmp_path / "fit"
    code = main(
        [
            "fit",
            str(run / "timeseries.parquet"),
            "--out",
            str(out),
            "--scenario",
            str(context),
            "--gyro-sigma",
            "1e-6 rad/s",
            "--attitude-sigma",
            "1e-5 rad",
            "--quiet",
        ]
    )
    assert code == 0
    summary = _fit_json(out)
    np.testing.assert_allclose(summary["inertia_ratios"], [1.0, 2.0, 2.6], rtol=1e-4)
    assert summary["goodness"]["reduced_chi2"] < 2.0
    text = (out / "fitted_scenario.toml").read_text()
    assert "gravity_gradient = true" in text and "[pointing.keplerian]" in text


BURN = SCENARIO.replace(
    """[[events]]
type = "angular_impulse"
offset = 401.0
impulse = [3.0, -2.0, 1.5]
""",
    """[torques]
step = 0.5

[[torques.burns]]
offset = 200.0
duration = 60.0
torque = [0.3, -0.2, 0.25]
""",
).replace("step = 2.0", "step = 3.0")


def test_a_burn_of_the_scenario_file_gives_the_absolute_moments(tmp_path):
    """A run with a body burn at 200–260 s (the splitting at 0.5 s), its time series
    with noise fitted through the burn of the same file (--scenario): the moments come
    back within their σ, in well under a second of fitting (the issue's case refused
    with an overflow, or took a minute)."""
    (tmp_path / "truth.toml").write_text(BURN)
    run = tmp_path / "run"
    assert main(["run", str(tmp_path / "truth.toml"), "--out", str(run), "--quiet"]) == 0
    telemetry = read_telemetry(run / "timeseries.csv")
    rng = np.random.default_rng(5)
    ω = telemetry.angular_velocity + 1e-4 * rng.standard_normal(telemetry.angular_velocity.shape)
    lines = ["time_utc,omega_body_x_rad_s,omega_body_y_rad_s,omega_body_z_rad_s"]
    for text, rate in zip(telemetry.times.utc.isot, ω, strict=True):
        lines.append(f"{text},{','.join(repr(float(v)) for v in rate)}")
    (tmp_path / "gyro.csv").write_text("\n".join(lines) + "\n")
    out = tmp_path / "fit"
    args = ["fit", str(tmp_path / "gyro.csv"), "--out", str(out), "--quiet"]
    assert (
        main([*args, "--scenario", str(tmp_path / "truth.toml"), "--gyro-sigma", "1e-4 rad/s"]) == 0
    )
    summary = _fit_json(out)
    moments = np.array(summary["principal_moments_kg_m2"])
    σ = np.array(summary["principal_moments_sigma_kg_m2"])
    assert np.all(np.abs(moments - MOMENTS) <= 3.0 * σ), (moments, σ)
    assert "[[torques.burns]]" in (out / "fitted_scenario.toml").read_text()


def _gyro_csv(path: Path, t: np.ndarray, ω: np.ndarray, bom: bool = False) -> Path:
    from attitude.environment.timescales import as_time, time_from_tt_seconds

    times = time_from_tt_seconds(as_time("2027-03-01T00:00:00"), t).utc.isot
    lines = ["time_utc,omega_body_x_rad_s,omega_body_y_rad_s,omega_body_z_rad_s"]
    lines += [f"{a},{','.join(repr(float(v)) for v in r)}" for a, r in zip(times, ω, strict=True)]
    path.write_bytes((b"\xef\xbb\xbf" if bom else b"") + ("\r\n".join(lines) + "\r\n").encode())
    return path


def test_the_fit_says_what_it_does_with_a_time_estimate(tmp_path, capsys):
    """Progress as `attitude run` gives it: each stage, the growing arc's stages with
    the time left, on the process's clock; the figures at the end."""
    from cli_lines import progress_lines

    solver = EulerSolver(MOMENTS, MOMENTS * ω0)
    t = np.arange(0.0, 1200.0, 2.0)
    ω = solver.angular_velocity(t) + 1e-4 * np.random.default_rng(3).standard_normal((t.size, 3))
    csv = _gyro_csv(tmp_path / "gyro.csv", t, ω)
    assert main(["fit", str(csv), "--out", str(tmp_path / "fit")]) == 0
    lines = progress_lines(capsys.readouterr().err)
    text = "\n".join(lines)
    assert "reading" in lines[0] and "600 rows read" in text
    stages = [line for line in lines if "fit: arc to t = " in line]
    assert stages and all(" more" in line for line in stages), text
    assert "100 %" in stages[-1]
    assert any("the last solve on all 600 samples" in line for line in lines)
    assert any("prediction horizon" in line for line in lines)
    assert "done:" in lines[-1]
    # residuals.csv (now written by Arrow) read back by Python's own csv module.
    import csv as python_csv

    with open(tmp_path / "fit" / "residuals.csv", newline="") as stream:
        rows = [row for row in python_csv.reader(stream) if not row[0].startswith("#")]
    assert rows[0][:3] == ["sensor", "t_s", "residual_x"]
    table = rows[1:]
    assert len(table) == t.size and {row[0] for row in table} == {"gyro"}
    np.testing.assert_allclose([float(row[1]) for row in table], t, rtol=0, atol=1e-9)
    fit = _fit_json(tmp_path / "fit")
    assert all(row[8] in ("0", "1") for row in table)
    σ = np.array(fit["noise"]["gyro"]["sigma_rad_s"])
    residual = np.array([[float(v) for v in row[2:5]] for row in table])
    normalized = np.array([[float(v) for v in row[5:8]] for row in table])
    np.testing.assert_allclose(normalized, residual / σ, rtol=1e-5, atol=1e-6)


def test_an_excel_csv_with_a_byte_order_mark_fits(tmp_path):
    """Excel's "CSV UTF-8": a byte-order mark and CRLF line ends, read as the same table."""
    solver = EulerSolver(MOMENTS, MOMENTS * ω0)
    t = np.arange(0.0, 1200.0, 2.0)
    ω = solver.angular_velocity(t) + 1e-4 * np.random.default_rng(4).standard_normal((t.size, 3))
    plain = read_telemetry(_gyro_csv(tmp_path / "plain.csv", t, ω))
    marked = read_telemetry(_gyro_csv(tmp_path / "excel.csv", t, ω, bom=True))
    np.testing.assert_array_equal(marked.angular_velocity, plain.angular_velocity)
    assert (marked.times == plain.times).all()
    out = tmp_path / "fit"
    assert main(["fit", str(tmp_path / "excel.csv"), "--out", str(out), "--quiet"]) == 0
    assert _fit_json(out)["goodness"]["reduced_chi2"] < 1.5


def test_refusals_name_the_option_and_the_file_once_in_our_words(tmp_path, capsys):
    out = str(tmp_path / "out")

    def refused(args, *patterns):
        code = main(["fit", *args, "--out", out, "--quiet"])
        err = capsys.readouterr().err
        assert code == 2, err
        assert len(err.strip().splitlines()) == 1, err
        for pattern in patterns:
            assert pattern in err, err
        name = Path(args[0]).name
        assert err.count(name) <= 1, err  # the file named once
        for python in ("invalid literal", "could not convert", "Traceback", "broadcast"):
            assert python not in err, err
        return err

    t = np.arange(0.0, 1200.0, 2.0)
    zero = _gyro_csv(tmp_path / "zero.csv", t, np.zeros((t.size, 3)))
    refused([str(zero)], "reads exactly 0 rad/s", "no rotation is measured", "at rest")
    sparse = _gyro_csv(tmp_path / "sparse.csv", t[::100], np.tile(ω0, (t[::100].size, 1)))
    refused([str(sparse)], "sparse.csv: --gyro-sigma:", "give it")
    good = _gyro_csv(tmp_path / "good.csv", t, np.tile(ω0, (t.size, 1)))
    refused([str(good), "--gyro-sigma", "1e-4,2e-4 rad/s"], "--gyro-sigma", "1 or 3")
    refused([str(good), "--gyro-sigma", "nan rad/s"], "--gyro-sigma", "finite")
    refused([str(good), "--time-scale", "bogus"], "--time-scale bogus")
    refused([str(good), "--epoch", "2027-13-45"], "--epoch")
    (tmp_path / "leap.csv").write_text(
        "time_utc,omega_body_x_rad_s,omega_body_y_rad_s,omega_body_z_rad_s\n"
        "2027-01-01T00:00:00,1,2,3\n2027-01-01T00:00:61,1,2,3\n"
    )
    refused([str(tmp_path / "leap.csv")], "row 1, column time_utc", "past the end of the minute")
    (tmp_path / "short.csv").write_text(
        "time_utc,omega_body_x_rad_s,omega_body_y_rad_s,omega_body_z_rad_s\n"
        "2027-01-01T00:00:00,1,2,3\n2027-01-01T00:00:01,1,2\n"
    )
    refused([str(tmp_path / "short.csv")], "row 1: 3 cells where the header has 4")
    (tmp_path / "epoch.csv").write_text(
        "# epoch: 2027-01-01T00:00:00 XYZ\n"
        "t_s,omega_body_x_rad_s,omega_body_y_rad_s,omega_body_z_rad_s\n0,1,2,3\n1,1,2,3\n"
    )
    refused([str(tmp_path / "epoch.csv")], "epoch.csv: # epoch:")
    (tmp_path / "hex.csv").write_text(
        "t_s,omega_body_x_rad_s,omega_body_y_rad_s,omega_body_z_rad_s\n0x10,1,2,3\n1,1_000,2,3\n"
    )
    epoch = ["--epoch", "2027-01-01T00:00:00"]
    refused([str(tmp_path / "hex.csv"), *epoch], "row 0, column t_s: '0x10' is not a number")
    (tmp_path / "cut.parquet").write_bytes(b"PAR1" + b"\x00" * 20)
    refused([str(tmp_path / "cut.parquet")], "no Parquet footer")


def test_the_fitted_scenario_is_one_its_own_check_accepts(tmp_path, capsys):
    """Its step samples the motion as `attitude check` asks (a tenth of the shortest
    period), its span is the horizon within 20 000 steps, and check notes nothing."""
    import tomllib

    solver = EulerSolver(MOMENTS, MOMENTS * ω0)
    t = np.arange(0.0, 1200.0, 2.0)
    ω = solver.angular_velocity(t) + 1e-4 * np.random.default_rng(5).standard_normal((t.size, 3))
    out = tmp_path / "fit"
    assert (
        main(["fit", str(_gyro_csv(tmp_path / "g.csv", t, ω)), "--out", str(out), "--quiet"]) == 0
    )
    capsys.readouterr()
    scenario = out / "fitted_scenario.toml"
    assert main(["check", str(scenario), "--quiet"]) == 0
    report = capsys.readouterr()
    assert "undersamples" not in report.out + report.err
    output = tomllib.loads(scenario.read_text())["output"]
    assert output["duration"] / output["step"] <= 20_000
    assert "a tenth of the motion's shortest period" in scenario.read_text()


def test_sparse_fixes_through_the_command_write_every_family(tmp_path):
    """Three radar passes a day apart, at the same time of day: the command reports
    each family of solutions in fit.json and writes a scenario for each."""
    solver = EulerSolver(MOMENTS, MOMENTS * ω0, Rotation.from_quat(Q_INIT, scalar_first=True))
    rng = np.random.default_rng(1)
    t = np.array([0.0, 1.0, 2.0]) * 86400.0
    ω = solver.angular_velocity(t) + 1e-5 * rng.standard_normal((t.size, 3))
    q = solver.attitude(t) * Rotation.from_rotvec(1e-3 * rng.standard_normal((t.size, 3)))
    lines = [
        "# epoch: 2027-03-01T00:00:00.000000000 UTC",
        "t_s,omega_body_x_rad_s,omega_body_y_rad_s,omega_body_z_rad_s,"
        "q_body_to_icrf_w,q_body_to_icrf_x,q_body_to_icrf_y,q_body_to_icrf_z",
    ]
    for k in range(t.size):
        values = [*ω[k], *q[k].as_quat(scalar_first=True)]
        lines.append(f"{float(t[k])!r}," + ",".join(repr(float(v)) for v in values))
    (tmp_path / "passes.csv").write_text("\n".join(lines) + "\n")
    out = tmp_path / "fit"
    args = ["--gyro-sigma", "1e-5 rad/s", "--attitude-sigma", "1e-3 rad", "--quiet"]
    assert main(["fit", str(tmp_path / "passes.csv"), "--out", str(out), *args]) == 0
    families = _fit_json(out)["families"]
    assert len(families) >= 2
    for family in families:
        assert (out / family["scenario"]).exists()
        assert len(family["covariance"]) == len(family["parameters"])
    truth = MOMENTS[1:] / MOMENTS[0]
    assert any(
        np.all(
            np.abs(np.array(f["inertia_ratios"][1:]) - truth)
            <= 3 * np.array(f["inertia_ratios_sigma"][1:])
        )
        for f in families
    )
    assert "do not decide between" in (out / "fitted_scenario.toml").read_text()
