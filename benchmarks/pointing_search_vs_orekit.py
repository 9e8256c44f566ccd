"""Benchmark: the pointing search against Orekit's FieldOfViewDetector, on one case.

The case of issue 20: a tumbler (I = 100, 200, 300 kg m², ω0 = (0.001, 1, 0.001) rad/s,
an attitude of identity, spinning near its intermediate axis: it flips every 27.5 s)
over one day from 2027-03-20T12:00 UTC, the Sun near +x, at the Earth's centre, with a
30° cone about body +z: when does the Sun enter it?

- **Ours**: ``pointing_analysis`` of the scenario (every interval and extremum it
  reports, the cone's included), with the shared surroundings already built for the
  span (their build is timed apart, as Orekit is handed the Sun's table).
- **Orekit** 13 (orekit-jpype): a ``FieldOfViewDetector`` (``CircularFieldOfView``
  about +z, 30°, margin 0) on a ``KeplerianPropagator`` whose attitude is Orekit's own
  ``TorqueFree`` from the same inertia and rate, with max-check 0.1 s (1/60 of a turn)
  and threshold 1 ms (our interval precision).  Its target is our Sun direction
  (sampled every 60 s from our surroundings, interpolated linearly: within 2e-11 rad),
  placed 1 au from the spacecraft, so that both searches look for the same Sun and the
  comparison is about the search (``FieldOfViewRun.java``, compiled by javac).

CPU time (``time.process_time``), each side in its own process (the JVM's threads,
its compiler and collector, count for Orekit, not for us), each warmed up, the pair
alternated three times; the machine's load beside the figures.  Every Orekit
interval must be among ours (ends within 2 ms); those we find that Orekit does not are
listed with their lengths (shorter than its max-check, they can fall between its
samples).  Run with the bench venv (orekit-jpype, a JDK):

    PYTHONPATH=. /work/venv-bench/bin/python -m benchmarks.pointing_search_vs_orekit

Results: stdout and benchmarks/results/pointing_search_vs_orekit.json.
"""

from __future__ import annotations

import json
import math
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent
RESULTS = HERE / "results"
EPOCH = "2027-03-20T12:00:00"
SPAN_S = 86_400.0
INERTIA = (100.0, 200.0, 300.0)
RATE = (0.001, 1.0, 0.001)
HALF_ANGLE_DEG = 30.0
MAX_CHECK_S = 0.1
THRESHOLD_S = 1e-3
SUN_TABLE_STEP_S = 60.0
ROUNDS = 3


def case(span_s: float = SPAN_S):
    """The scenario's trajectory and pointing spec (ours)."""
    from scipy.spatial.transform import Rotation

    from attitude import BodyVector, InitialState, PointingSpec, Scenario, Spacecraft, propagate

    craft = Spacecraft("tumbler", list(INERTIA))
    state = InitialState(Rotation.identity(), angular_velocity=list(RATE))
    scenario = Scenario("tumbler", craft, EPOCH, state, duration=span_s, step=60.0)
    cone = BodyVector("cone", [0.0, 0.0, 1.0], math.radians(HALF_ANGLE_DEG), "star_tracker")
    return propagate(scenario), PointingSpec([cone])


def _uptime() -> str:
    return subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()


def start_jvm() -> None:
    """Compile FieldOfViewRun.java against Orekit's jars and start the JVM with it."""
    import orekit_jpype

    jars = os.path.join(os.path.dirname(orekit_jpype.__file__), "jars")
    build = tempfile.mkdtemp(prefix="attitude-bench-fov-")
    subprocess.run(
        [
            shutil.which("javac") or "javac",
            "-nowarn",
            "-cp",
            os.path.join(jars, "*"),
            "-d",
            build,
            str(HERE / "FieldOfViewRun.java"),
        ],
        check=True,
        capture_output=True,
    )
    orekit_jpype.initVM(additional_classpaths=[build])


def orekit_setup(trajectory, sun_table: np.ndarray):
    """Orekit's propagator, target and field of view for the case."""
    import jpype
    from org.hipparchus.geometry.euclidean.threed import Rotation as HRotation
    from org.hipparchus.geometry.euclidean.threed import Vector3D
    from org.orekit.attitudes import Attitude, Inertia, InertiaAxis, TorqueFree
    from org.orekit.frames import FramesFactory
    from org.orekit.geometry.fov import CircularFieldOfView
    from org.orekit.orbits import KeplerianOrbit, PositionAngleType
    from org.orekit.time import AbsoluteDate
    from org.orekit.utils import Constants

    from attitude.environment.timescales import SECONDS_PER_DAY
    from attitude.pointing.surroundings import scenario_jd

    jd1, jd2 = scenario_jd(trajectory)
    since_j2000 = ((jd1 - 2451545.0) + jd2) * SECONDS_PER_DAY  # TT seconds
    date = AbsoluteDate.J2000_EPOCH.shiftedBy(since_j2000)
    frame = FramesFactory.getGCRF()
    # Where the spacecraft is does not matter: the target is placed from it.
    orbit = KeplerianOrbit(
        7.0e6,
        0.001,
        0.5,
        0.0,
        0.0,
        0.0,
        PositionAngleType.MEAN,
        frame,
        date,
        Constants.EIGEN5C_EARTH_MU,
    )
    inertia = Inertia(
        InertiaAxis(INERTIA[0], Vector3D.PLUS_I),
        InertiaAxis(INERTIA[1], Vector3D.PLUS_J),
        InertiaAxis(INERTIA[2], Vector3D.PLUS_K),
    )
    attitude = Attitude(date, frame, HRotation.IDENTITY, Vector3D(*RATE), Vector3D.ZERO)
    provider = TorqueFree(attitude, inertia)
    run = jpype.JClass("FieldOfViewRun")
    array = jpype.JArray(jpype.JDouble)
    target = run.SunFromTable(
        orbit,
        SUN_TABLE_STEP_S,
        array(sun_table[:, 0].tolist()),
        array(sun_table[:, 1].tolist()),
        array(sun_table[:, 2].tolist()),
    )
    fov = CircularFieldOfView(Vector3D.PLUS_K, math.radians(HALF_ANGLE_DEG), 0.0)
    return run, (orbit, provider), target, fov


def orekit_intervals(events: np.ndarray, span_s: float, inside_at_start: bool) -> list:
    """Intervals (start, end) from Orekit's (time, +1 enter / −1 leave) events."""
    out, start = [], 0.0 if inside_at_start else None
    for t, sign in events:
        if sign > 0:
            start = t
        elif start is not None:
            out.append((start, t))
            start = None
    if start is not None:
        out.append((start, span_s))
    return out


def compare(ours: list, theirs: list, tolerance_s: float = 2e-3) -> dict:
    """Orekit's intervals found among ours, and ours that Orekit does not have."""
    ours_a = np.array(ours).reshape(-1, 2)
    matched = np.zeros(len(ours), dtype=bool)
    worst = 0.0
    missing = []
    starts = ours_a[:, 0]
    for a, b in theirs:
        k = int(np.argmin(np.abs(starts - a))) if len(ours) else -1
        if k >= 0 and abs(ours_a[k, 0] - a) <= tolerance_s and abs(ours_a[k, 1] - b) <= tolerance_s:
            matched[k] = True
            worst = max(worst, abs(ours_a[k, 0] - a), abs(ours_a[k, 1] - b))
        else:
            missing.append((a, b))
    extra = [
        (float(a), float(b), float(b - a))
        for (a, b), m in zip(ours_a, matched, strict=True)
        if not m
    ]
    return {
        "orekit_intervals": len(theirs),
        "our_intervals": len(ours),
        "orekit_found_by_us": len(theirs) - len(missing),
        "orekit_not_found_by_us": missing,
        "worst_end_difference_s": worst,
        "ours_not_in_orekit": extra,
        "ours_not_in_orekit_longest_s": max((e[2] for e in extra), default=0.0),
    }


def _ours(connection) -> None:
    """Our side, in its own process: on each message, one timed search."""
    from attitude.pointing.search import pointing_analysis
    from attitude.pointing.shared_surroundings import shared_surroundings

    trajectory, spec = case()
    begin = time.process_time()
    shared_surroundings(trajectory, spec)
    built = time.process_time() - begin
    pointing_analysis(trajectory, spec)  # warm: imports, the solver's table
    connection.send({"surroundings_build_cpu_s": built})
    while connection.recv():
        begin = time.process_time()
        analysis = pointing_analysis(trajectory, spec)
        cpu = time.process_time() - begin
        cone = analysis.vectors[0]
        connection.send(
            {
                "cpu_s": cpu,
                "intervals": [(i.start_s, i.end_s) for i in cone.sun_exclusion],
                "inside_at_start": bool(cone.sun_exclusion and cone.sun_exclusion[0].starts_before),
            }
        )


def _theirs(connection, sun_table: np.ndarray) -> None:
    """Orekit's side, in its own process (the JVM): on each message, one timed search."""
    trajectory, _ = case()
    start_jvm()
    run, (orbit, provider), target, fov = orekit_setup(trajectory, sun_table)

    def once():
        return np.array(run.run(orbit, provider, target, fov, MAX_CHECK_S, THRESHOLD_S, SPAN_S))

    once()  # warm: the JIT
    connection.send({})
    while connection.recv():
        begin = time.process_time()
        out = once()
        cpu = time.process_time() - begin
        connection.send({"cpu_s": cpu, "events": out[:-1].reshape(-1, 2), "g": int(out[-1])})


def main() -> dict:
    import multiprocessing

    from attitude.pointing.shared_surroundings import shared_surroundings

    report: dict = {
        "machine": f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores",
        "case": f"tumbler I={INERTIA} kg m2, w0={RATE} rad/s, {SPAN_S:g} s from {EPOCH} UTC, "
        f"{HALF_ANGLE_DEG:g} deg cone on +z, Sun at the Earth's centre",
        "orekit_settings": {"max_check_s": MAX_CHECK_S, "threshold_s": THRESHOLD_S},
        "uptime_at_start": _uptime(),
    }
    trajectory, spec = case()
    times = np.arange(0.0, SPAN_S + 2 * SUN_TABLE_STEP_S, SUN_TABLE_STEP_S)
    sun = shared_surroundings(trajectory, spec).targets(times).sun
    sun = sun / np.linalg.norm(sun, axis=1)[:, None]
    context = multiprocessing.get_context("spawn")
    ours_end, ours_child = context.Pipe()
    theirs_end, theirs_child = context.Pipe()
    workers = [
        context.Process(target=_ours, args=(ours_child,)),
        context.Process(target=_theirs, args=(theirs_child, sun)),
    ]
    for worker in workers:
        worker.start()
    report["our_surroundings_build_cpu_s"] = ours_end.recv()["surroundings_build_cpu_s"]
    theirs_end.recv()
    our_cpu, their_cpu = [], []
    for _ in range(ROUNDS):
        ours_end.send(True)
        mine = ours_end.recv()
        our_cpu.append(mine["cpu_s"])
        theirs_end.send(True)
        other = theirs_end.recv()
        their_cpu.append(other["cpu_s"])
    for end in (ours_end, theirs_end):
        end.send(False)
    for worker in workers:
        worker.join()
    theirs_intervals = orekit_intervals(other["events"], SPAN_S, mine["inside_at_start"])
    report["comparison"] = compare(mine["intervals"], theirs_intervals)
    report["our_cpu_s"] = our_cpu
    report["orekit_cpu_s"] = their_cpu
    report["orekit_g_evaluations"] = other["g"]
    report["orekit_us_per_g"] = 1e6 * float(np.median(their_cpu)) / other["g"]
    report["ratio_orekit_over_ours_median"] = float(np.median(their_cpu) / np.median(our_cpu))
    report["ratio_orekit_over_ours_per_round"] = [
        t / o for o, t in zip(our_cpu, their_cpu, strict=True)
    ]
    report["uptime_at_end"] = _uptime()
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "pointing_search_vs_orekit.json").write_text(json.dumps(report, indent=2) + "\n")
    summary = {k: v for k, v in report.items() if k != "comparison"}
    summary["comparison"] = {
        k: v if not isinstance(v, list) or len(v) < 6 else f"{len(v)} items"
        for k, v in report["comparison"].items()
    }
    print(json.dumps(summary, indent=2))
    return report


if __name__ == "__main__":
    sys.exit(0 if main() else 1)
