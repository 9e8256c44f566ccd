"""Orekit's ``TorqueFree`` attitude provider as a peer, through ``orekit-jpype``.

``TorqueFree(Attitude initialAttitude, Inertia inertia)``: a closed form (Jacobi
elliptic functions from Hipparchus) for the momentum and two Euler angles, and a
DormandPrince853 quadrature over one period for the third, done in the constructor.
No orekit-data is needed: ``AbsoluteDate.J2000_EPOCH`` and ``FramesFactory.getGCRF()``
work with an empty data context.

The samples are evaluated inside the JVM by ``TorqueFreeBulk.java`` (beside this
file), compiled with ``javac`` into a temporary directory when the JVM starts: one
JPype call for all samples.  Without ``javac`` it falls back to one JPype round trip
per sample (about 3× slower), and says so.

Conventions, converted here and checked by ``check_conventions``:
- ``Attitude.getRotation()`` is the Hipparchus rotation from the reference frame to
  the body frame: ``applyTo(v_N) = v_B``, and ``getMatrix()`` is [BN].
- Hipparchus' ``applyTo(u)`` is q̄ u q in Hamilton's product (see
  ``hipparchus_apply_to``), the opposite of the active rotation q u q̄.  So its four
  numbers (q0, q1, q2, q3) are exactly our Hamilton scalar-first quaternion of
  body → inertial, and ``new Rotation(q0, q1, q2, q3, true)`` is built from ours.
- The ``Attitude`` spin vector is in body axes, as our ω.
- Exact spins about the axis of least or greatest inertia break ``TorqueFree`` (a 90°
  turn comes out as 180°, or NaN); none of the cases is one.
"""

from __future__ import annotations

import atexit
import os
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from benchmarks.cases import Case, PeerRun, Setting

NAME = "orekit"
_JAVA_SOURCE = Path(__file__).with_name("TorqueFreeBulk.java")
_state: dict = {"started": False, "bulk": False}


# ------------------------------------------------------------ conventions (numpy only)


def quaternion_to_hipparchus(q: np.ndarray) -> tuple[float, float, float, float]:
    """Our scalar-first body → inertial quaternion → Hipparchus (q0, q1, q2, q3) of frame → body."""
    return tuple(float(x) for x in np.asarray(q, dtype=float))  # type: ignore[return-value]


def hipparchus_to_quaternion(q_hipparchus: np.ndarray) -> np.ndarray:
    """Hipparchus (q0..q3) of ``Attitude.getRotation()`` (N, 4) → ours, body → inertial, w ≥ 0."""
    q = np.array(q_hipparchus, dtype=float, ndmin=2)
    q[q[:, 0] < 0] *= -1.0
    return q


def hipparchus_apply_to(q_hipparchus: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Hipparchus ``Rotation.applyTo(Vector3D)``, transcribed from its source, in numpy.

    Used by the tests to check ``hipparchus_to_quaternion`` without a JVM:
    ``applyTo(v_N)`` must be our ``R.inv().apply(v_N)``.
    """
    q0, q1, q2, q3 = (float(x) for x in q_hipparchus)
    x, y, z = (float(c) for c in u)
    s = q1 * x + q2 * y + q3 * z
    return np.array(
        [
            2 * (q0 * (x * q0 - (q2 * z - q3 * y)) + s * q1) - x,
            2 * (q0 * (y * q0 - (q3 * x - q1 * z)) + s * q2) - y,
            2 * (q0 * (z * q0 - (q1 * y - q2 * x)) + s * q3) - z,
        ]
    )


# ------------------------------------------------------------------ the peer


def availability() -> str | None:
    """None if orekit-jpype imports and a JVM can be found, else why not."""
    try:
        import jpype
        import orekit_jpype  # noqa: F401
    except Exception as error:
        return (
            f"orekit-jpype not installed ({type(error).__name__}: {error}); "
            "pip install 'attitude[bench]'"
        )
    try:
        jpype.getDefaultJVMPath()
    except Exception as error:
        return f"no Java runtime found for orekit-jpype ({error}); install a JDK (17+)"
    return None


def _jars() -> str:
    import orekit_jpype

    return os.path.join(os.path.dirname(orekit_jpype.__file__), "jars")


def start() -> dict:
    """Compile the helper (if javac exists) and start the JVM, once per process."""
    if _state["started"]:
        return {}
    import orekit_jpype

    info: dict = {}
    extra = []
    javac = shutil.which("javac")
    if javac:
        build = tempfile.mkdtemp(prefix="attitude-bench-orekit-")
        # The classes are loaded by then; nothing built stays behind the run.
        atexit.register(shutil.rmtree, build, ignore_errors=True)
        begin = time.perf_counter()
        subprocess.run(
            [javac, "-nowarn", "-cp", os.path.join(_jars(), "*"), "-d", build, str(_JAVA_SOURCE)],
            check=True,
            capture_output=True,
        )
        info["javac_s"] = time.perf_counter() - begin
        extra.append(build)
        _state["bulk"] = True
    else:
        info["note"] = "javac not found: one JPype call per sample (about 3x slower)"
    begin = time.perf_counter()
    orekit_jpype.initVM(additional_classpaths=extra)
    info["jvm_start_s"] = time.perf_counter() - begin
    from org.orekit.utils import Constants  # noqa: F401  (forces the Orekit classes in)

    info["mode"] = "bulk (Java loop)" if _state["bulk"] else "python loop"
    _state["started"] = True
    return info


def settings() -> list[Setting]:
    return [Setting(NAME, "Orekit TorqueFree")]


def _provider(inertia, omega0, q0):
    from org.hipparchus.geometry.euclidean.threed import Rotation as HRotation
    from org.hipparchus.geometry.euclidean.threed import Vector3D
    from org.orekit.attitudes import Attitude, Inertia, InertiaAxis, TorqueFree
    from org.orekit.frames import FramesFactory
    from org.orekit.time import AbsoluteDate

    frame = FramesFactory.getGCRF()
    t0 = AbsoluteDate.J2000_EPOCH
    i1, i2, i3 = (float(x) for x in inertia)
    axes = Inertia(
        InertiaAxis(i1, Vector3D.PLUS_I),
        InertiaAxis(i2, Vector3D.PLUS_J),
        InertiaAxis(i3, Vector3D.PLUS_K),
    )
    w = [float(x) for x in omega0]
    attitude0 = Attitude(
        t0, frame, HRotation(*quaternion_to_hipparchus(q0), True), Vector3D(*w), Vector3D.ZERO
    )
    return TorqueFree(attitude0, axes), t0, frame


def _evaluate(inertia, omega0, q0, times: np.ndarray) -> np.ndarray:
    """(N, 7): Hipparchus q0..q3 and the body spin at ``times``."""
    import jpype

    provider, t0, frame = _provider(inertia, omega0, q0)
    if _state["bulk"]:
        bulk = jpype.JClass("TorqueFreeBulk")
        out = bulk.evaluate(provider, t0, frame, jpype.JArray(jpype.JDouble)(times))
        return np.array(out, dtype=float).reshape(-1, 7)
    out = np.empty((len(times), 7))
    for k, dt in enumerate(times.tolist()):
        attitude = provider.getAttitude(None, t0.shiftedBy(dt), frame)
        r, w = attitude.getRotation(), attitude.getSpin()
        out[k] = (r.getQ0(), r.getQ1(), r.getQ2(), r.getQ3(), w.getX(), w.getY(), w.getZ())
    return out


def run(case: Case, setting: Setting, times: np.ndarray) -> PeerRun:
    """Build TorqueFree (its one-period quadrature included) and evaluate every sample."""
    times = np.ascontiguousarray(times, dtype=float)
    begin = time.perf_counter()
    out = _evaluate(case.inertia, case.omega0, np.asarray(case.q0), times)
    q = hipparchus_to_quaternion(out[:, :4])
    wall = time.perf_counter() - begin
    return PeerRun(q, out[:, 4:], wall, {"mode": "bulk" if _state["bulk"] else "python loop"})


def check_conventions() -> dict:
    """Run Orekit on two known rotations and measure the converted attitude's error.

    1. A spin of 0.5 rad/s about body z (plus a 1e-9 rad/s wobble: an exact
       principal-axis spin breaks TorqueFree) for a quarter turn: [BN] N_x = −y_B and
       our quaternion the +90° turn.  2. An axisymmetric body with the cases' generic
       initial attitude against the exact regular precession
       q(t) = q0 ⊗ exp(H_B0 t / I_t) ⊗ exp(ẑ ν t), ν = ω3 (1 − I3/I_t).
    """
    from benchmarks.cases import CASES
    from benchmarks.reference import quaternion_angle

    w = 0.5
    quarter = (np.pi / 2) / w
    provider, t0, frame = _provider([100, 200, 300], [1e-9, 0, w], [1.0, 0.0, 0.0, 0.0])
    rotation = provider.getAttitude(None, t0.shiftedBy(quarter), frame).getRotation()
    bn = np.array([list(row) for row in rotation.getMatrix()])
    q_quarter = hipparchus_to_quaternion(
        [rotation.getQ0(), rotation.getQ1(), rotation.getQ2(), rotation.getQ3()]
    )
    expected = Rotation.from_rotvec([0, 0, np.pi / 2]).as_quat(scalar_first=True)
    quarter_error = float(quaternion_angle(q_quarter, expected)[0])

    it, i3 = 100.0, 300.0
    omega = np.array([0.1, 0.05, 0.2])
    q0 = np.asarray(next(iter(CASES.values())).q0)
    times = np.array([0.0, 17.3, 100.0])
    out = _evaluate([it, it, i3], omega, q0, times)
    h0 = np.array([it, it, i3]) * omega
    nu = omega[2] * (1 - i3 / it)
    r0 = Rotation.from_quat(q0, scalar_first=True)
    exact = np.array(
        [
            (r0 * Rotation.from_rotvec(h0 * t / it) * Rotation.from_rotvec([0, 0, nu * t])).as_quat(
                scalar_first=True
            )
            for t in times
        ]
    )
    precession_error = float(quaternion_angle(hipparchus_to_quaternion(out[:, :4]), exact).max())
    return {
        "quarter_turn_BN_times_Nx": (bn @ [1.0, 0.0, 0.0]).tolist(),
        "quarter_turn_error_rad": quarter_error,
        "axisymmetric_generic_q0_error_rad": precession_error,
        "passed": quarter_error < 1e-7 and precession_error < 1e-10,
    }
