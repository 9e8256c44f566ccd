"""The first guess, without any search: Euler's equations are linear in the moments.

Torque-free, I ω̇ + ω × (I ω) = 0 at every instant.  For principal moments along known
axes each sample gives three equations, linear and homogeneous in (I1, I2, I3):

    I1 ω̇1 + (I3 − I2) ω2 ω3 = 0,   I2 ω̇2 + (I1 − I3) ω3 ω1 = 0,   I3 ω̇3 + (I2 − I1) ω1 ω2 = 0,

and for a full tensor in the sensor axes (the principal axes unknown) three equations
linear in its six components.  Stacked over the samples they form a matrix A with
A I = 0: the moments are the right singular vector of the smallest singular value
(``numpy.linalg.svd``), up to the scale that a torque-free motion cannot show.  The rates
come from the gyro or from the differences of dense attitude quaternions; ω̇ from a
Savitzky–Golay filter (``scipy.signal.savgol_filter``, cubic) over each evenly sampled run.

The noise in ω̇ biases this estimate (the errors are in the matrix, not in a right-hand
side), so it is only a start: the fit on the exact solver takes over.  What the guess
cannot decide becomes several starts (``candidates``): a second small singular value
(a null space of two dimensions: a nearly symmetric body, a nearly steady spin) gives
starts across it, and a guess within 20 % of the separatrix gets its mirror image on
the other side, where the motion circulates about the other axis.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.signal import savgol_filter
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.environment.timescales import SAME_INSTANT_S
from attitude.estimation.telemetry import Telemetry, _uniform_runs

__all__ = ["GUESS_SAMPLES", "Guess", "Rates", "candidates", "measured_rates"]

# The guess is solved on at most this many readings of each sensor (the first ones).
GUESS_SAMPLES = 50_000


@dataclass(frozen=True)
class Rates:
    """Smoothed body rates and their derivatives at the times where both are known."""

    t: NDArray[np.float64]
    ω: NDArray[np.float64]
    ω_dot: NDArray[np.float64]
    source: str  # "gyro" or "quaternions"
    W: float  # the typical rate, rad/s
    ω_dot_scaled: NDArray[np.float64]  # ω̇ / W², computed without underflow


@dataclass(frozen=True)
class Guess:
    """A start for the fit: principal moments (arbitrary scale), the rotation taking
    principal axes to body axes, the body rate at t = 0, and what made it."""

    moments: NDArray[np.float64]
    axes: Rotation
    ω0: NDArray[np.float64]
    label: str


def _window(dt: float, speed: float, length: int) -> int:
    """Savitzky–Golay window: about 0.3 rad of rotation, 7 to 101 samples, odd, and no
    longer than the run."""
    samples = 0.3 / max(speed * dt, 1e-300)
    w = int(min(max(samples, 7.0), 101.0, float(length)))
    return w if w % 2 else w - 1


def measured_rates(
    telemetry: Telemetry,
    breaks: tuple[float, ...] = (),
    excluded: tuple[tuple[float, float], ...] = (),
) -> Rates | None:
    """Body rates and ω̇ from the gyro (or, without one, from dense quaternions), over
    each evenly sampled run long enough for the filter, the runs cut at ``breaks``
    (the times of impulses, where the rates jump) and with the intervals ``excluded``
    (known burns: not torque-free) left out; None if no run is."""
    t_parts, ω_parts, dω_parts, scaled_parts = [], [], [], []
    if telemetry.gyro is not None and len(telemetry.gyro) >= 7:
        # The first GUESS_SAMPLES readings: a guess needs the motion's shape (tens of
        # periods), not every reading of a long arc.
        t, ω, source = (
            telemetry.gyro.t[:GUESS_SAMPLES],
            telemetry.gyro.values[:GUESS_SAMPLES],
            "gyro",
        )
    elif telemetry.attitude is not None and len(telemetry.attitude) >= 8:
        q = telemetry.attitude.values[:GUESS_SAMPLES]
        R = Rotation.from_quat(q, scalar_first=True)
        fixes = telemetry.attitude.t[:GUESS_SAMPLES]
        steps = np.diff(fixes)
        increments = (R[:-1].inv() * R[1:]).as_rotvec()  # body axes, ≈ ω dt
        t = fixes[:-1] + 0.5 * steps
        ω, source = increments / steps[:, None], "quaternions"
    else:
        return None
    # |ω| within a factor √3, and no square to underflow (a norm of 1e-200 rad/s is 0).
    speed = float(np.median(np.max(np.abs(ω), axis=1)))
    W = speed or 1.0
    runs = []
    for run in _uniform_runs(t):
        edges = [e for interval in excluded for e in interval]
        cuts = [
            run.start,
            *(int(np.searchsorted(t, b - SAME_INSTANT_S)) for b in breaks),
            *(int(np.searchsorted(t, e)) for e in edges),
            run.stop,
        ]
        cuts = sorted(c for c in set(cuts) if run.start <= c <= run.stop)
        runs += [
            slice(a, b)
            for a, b in itertools.pairwise(cuts)
            if b > a and not any(lo <= t[a] < hi for lo, hi in excluded)
        ]
    for run in runs:
        n = run.stop - run.start
        if n < 7:
            continue
        dt = float(t[run][1] - t[run][0])
        w = _window(dt, speed, n)
        if w < 7:
            continue
        t_parts.append(t[run])
        ω_parts.append(savgol_filter(ω[run], w, 3, axis=0))
        dω_parts.append(savgol_filter(ω[run], w, 3, deriv=1, delta=dt, axis=0))
        # d(ω/W)/d(t W) = ω̇/W²: of order one whatever the units.
        scaled_parts.append(savgol_filter(ω[run] / W, w, 3, deriv=1, delta=dt * W, axis=0))
    if not t_parts:
        return None
    return Rates(
        np.concatenate(t_parts),
        np.concatenate(ω_parts),
        np.concatenate(dω_parts),
        source,
        W,
        np.concatenate(scaled_parts),
    )


def _principal_rows(ω: NDArray[np.float64], dω: NDArray[np.float64]) -> NDArray[np.float64]:
    """Rows of A for (I1, I2, I3) along the sensor axes."""
    w1, w2, w3 = ω.T
    d1, d2, d3 = dω.T
    rows = np.stack(
        [
            np.stack([d1, -w2 * w3, w2 * w3], axis=1),
            np.stack([w3 * w1, d2, -w3 * w1], axis=1),
            np.stack([-w1 * w2, w1 * w2, d3], axis=1),
        ],
        axis=1,
    )
    return rows.reshape(-1, 3)


def _tensor_rows(ω: NDArray[np.float64], dω: NDArray[np.float64]) -> NDArray[np.float64]:
    """Rows of A for the tensor's (Ixx, Iyy, Izz, Ixy, Ixz, Iyz): I ω̇ + ω × (I ω) = 0."""
    basis = []
    for a, b in ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)):
        E = np.zeros((3, 3))
        E[a, b] = E[b, a] = 1.0
        basis.append(E)
    columns = [dω @ E.T + np.cross(ω, ω @ E.T) for E in basis]  # each (N, 3)
    return np.stack(columns, axis=2).reshape(-1, 6)


def _positive(v: NDArray[np.float64]) -> NDArray[np.float64] | None:
    """The singular vector with the sign that makes the moments positive, or None."""
    v = v if v.sum() > 0 else -v
    return v if np.all(v > 0) else None


def candidates(
    telemetry: Telemetry,
    principal_axes: bool,
    breaks: tuple[float, ...] = (),
    excluded: tuple[tuple[float, float], ...] = (),
) -> tuple[list[Guess], str]:
    """The starts of the fit, best first, and a line describing the linear guess.

    Raises :class:`InputError` if the telemetry gives no rates to solve for (sparse
    attitude fixes alone: give the fit a guess) or the rates fit no rigid body.
    """
    rates = measured_rates(telemetry, breaks, excluded)
    if rates is None:
        raise InputError(
            "the samples are too sparse for the linear first guess (it needs runs of 7 or "
            "more evenly spaced gyro readings or 8 quaternions close enough to differentiate)",
            file=telemetry.source,
        )
    # Euler's equations are homogeneous of degree 2 in (ω, ω̇/W): scaled by the typical
    # rate W, the rows are of order one whatever the units (no underflow or overflow).
    ω, dω = rates.ω / rates.W, rates.ω_dot_scaled
    rows = _tensor_rows(ω, dω) if principal_axes else _principal_rows(ω, dω)
    if not np.all(np.isfinite(rows)):
        raise InputError("the rates' products overflow: rates too large", file=telemetry.source)
    scale = np.linalg.norm(rows, axis=0)
    scale[scale == 0.0] = 1.0
    _, s, Vt = np.linalg.svd(rows / scale, full_matrices=False)
    null = Vt / scale  # rows: singular vectors in the original units
    ω0 = rates.ω[0]
    guesses: list[tuple[NDArray[np.float64], Rotation, str]] = []

    def add(vector: NDArray[np.float64], label: str) -> None:
        if principal_axes:
            xx, yy, zz, xy, xz, yz = vector
            tensor = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
            tensor = tensor if np.trace(tensor) > 0 else -tensor
            moments, axes = np.linalg.eigh(tensor)
            if np.linalg.det(axes) < 0:
                axes[:, 2] *= -1.0
            if np.all(moments > 0):
                guesses.append((moments, Rotation.from_matrix(axes), label))
        else:
            positive = _positive(vector)
            if positive is not None:
                guesses.append((positive, Rotation.identity(), label))

    add(null[-1], "linear guess (SVD)")
    ratio = s[-1] / s[-2] if s[-2] > 0 else 1.0
    if ratio > 0.3:  # a second direction nearly as null: starts across that plane
        for angle in np.linspace(0.0, math.pi, 7)[1:-1]:
            add(
                math.cos(angle) * null[-1] + math.sin(angle) * null[-2],
                "linear guess, 2-D null space",
            )
    if not guesses:
        raise InputError(
            f"the measured rates follow Euler's equations of no rigid body (the linear guess "
            f"gives moments of both signs; smallest singular values {s[-1]:.3g}, "
            f"{s[-2]:.3g}): torques, a biased or mislabelled gyro, or noise alone?",
            file=telemetry.source,
        )
    out = []
    for moments, axes, label in guesses:
        moments = moments / moments.min()
        out.append(Guess(moments, axes, ω0.copy(), label))
        mirrored = _mirror(moments, axes.inv().apply(ω0))
        if mirrored is not None:
            out.append(Guess(mirrored, axes, ω0.copy(), label + ", mirrored across the separatrix"))
    singular = ", ".join(f"{x:.3g}" for x in s[-3:])
    text = f"linear guess from {rates.source} rates at {rates.t.size} times"
    return out, f"{text} (smallest singular values {singular})"


def _mirror(moments: NDArray[np.float64], ω: NDArray[np.float64]) -> NDArray[np.float64] | None:
    """The intermediate moment reflected through its separatrix value for this ω, if the
    guess lies within 20 % of it: I2* = (I1² ω1² + I3² ω3²)/(I1 ω1² + I3 ω3²) makes
    Δ2 = I1 ω1² (I1 − I2) + I3 ω3² (I3 − I2) vanish (docs/derivation.md §1)."""
    order = np.argsort(moments)
    I1, I2, I3 = moments[order]
    w1, _, w3 = ω[order]
    denominator = I1 * w1 * w1 + I3 * w3 * w3
    if denominator <= 0.0 or not I1 < I2 < I3:
        return None
    star = (I1 * I1 * w1 * w1 + I3 * I3 * w3 * w3) / denominator
    mirrored = 2.0 * star - I2
    if abs(mirrored - I2) > 0.2 * I2 or not I1 < mirrored < I3:
        return None
    out = moments.copy()
    out[order[1]] = mirrored
    return out


def _side_rate(gyro, at: float, before: bool) -> NDArray[np.float64] | None:
    """The gyro rate at ``at`` from a quadratic through the five nearest readings on
    one side (before it, or at or after it); None with fewer than three there."""
    index = np.flatnonzero(gyro.t < at if before else gyro.t >= at)
    nearest = index[np.argsort(np.abs(gyro.t[index] - at))[:5]]
    if nearest.size < 3:
        return None
    τ = gyro.t[nearest] - at
    design = np.stack([np.ones_like(τ), τ, τ * τ], axis=1)
    coefficients, *_ = np.linalg.lstsq(design, gyro.values[nearest], rcond=None)
    return np.asarray(coefficients[0])  # the quadratic's value at ``at``


def impulse_scale(
    telemetry: Telemetry,
    moments: NDArray[np.float64],
    axes: Rotation,
    impulses,
    attitude,
    burns=(),
) -> float | None:
    """The factor c that makes the moments c · ``moments`` change the measured rates
    across the known impulses and burns as they did: a linear least squares in 1/c, in
    the rates (where the errors of the measured changes are), over

    - each impulse: ω⁺ − ω⁻ = (1/c) ΔH / r (principal axes, r the guessed moments),
      each side's rate at the impulse from a quadratic through its five nearest readings;
    - each body burn, Euler's equations integrated over [a, b]:
      ω(b) − ω(a) + [∫ ω × (r ω) dt] / r = (1/c) Aᵀ Γ (b − a) / r, the integral by the
      trapezoidal rule over the readings within it;
    - each inertial burn, the inertial momentum's change seen in the body at b:
      ω(b) − [R (r ω(a))] / r = (1/c) (Q(b) A)ᵀ Γ (b − a) / r, with R = (Q(b) A)ᵀ Q(a) A
      and Q from the nearest attitude fix.

    None without gyro readings on both sides.  ``attitude``: a rough Q(t) (for inertial
    axes), or None; ``burns``: ``KnownBurn`` s (attitude.estimation.burns)."""
    gyro = telemetry.gyro
    if gyro is None:
        return None
    A = axes.inv()
    a_rows, changes = [], []  # changes = (1/c) a_rows, stacked
    for impulse in impulses:
        at = impulse.t - SAME_INSTANT_S  # a reading a nanosecond before is after it
        before, after = _side_rate(gyro, at, True), _side_rate(gyro, at, False)
        if before is None or after is None:
            continue
        ΔH = impulse.vector
        if impulse.frame != "body":
            if attitude is None:
                continue
            ΔH = attitude(impulse.t).inv().apply(ΔH)
        a_rows.append(A.apply(ΔH) / moments)
        changes.append(A.apply(after - before))
    for burn in burns:
        a, b = max(burn.start, float(gyro.t[0])), min(burn.stop, float(gyro.t[-1]))
        ω_a, ω_b = _side_rate(gyro, a, True), _side_rate(gyro, b, False)
        if not b > a or ω_a is None or ω_b is None:
            continue
        if burn.frame == "body":
            within = (gyro.t > a) & (gyro.t < b)
            t = np.concatenate([[a], gyro.t[within], [b]])
            ω = A.apply(np.concatenate([[ω_a], gyro.values[within], [ω_b]]))
            turning = np.cross(ω, moments * ω)
            integral = 0.5 * np.sum((turning[1:] + turning[:-1]) * np.diff(t)[:, None], axis=0)
            a_rows.append(A.apply(burn.torque) * (b - a) / moments)
            changes.append(ω[-1] - ω[0] + integral / moments)
        elif attitude is not None:
            P_a, P_b = attitude(a) * axes, attitude(b) * axes  # principal -> ICRF
            carried = (P_b.inv() * P_a).apply(moments * A.apply(ω_a)) / moments
            a_rows.append(P_b.inv().apply(burn.torque) * (b - a) / moments)
            changes.append(A.apply(ω_b) - carried)
    if not a_rows:
        return None
    rows, measured = np.concatenate(a_rows), np.concatenate(changes)
    u = float(rows @ measured) / float(rows @ rows) if float(rows @ rows) > 0 else 0.0
    return 1.0 / u if u > 0.0 and math.isfinite(1.0 / u) else None
