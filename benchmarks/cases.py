"""The benchmark problems, and the shape of a peer's answer.

Each case is a torque-free rigid body given the way every peer can take it: principal
moments along body x, y, z (kg m²), the body angular velocity ω0 (rad/s) and the
attitude q0 (scalar-first quaternion, body → inertial) at t = 0, a span and an output
step.  The independent reference is sampled every ``reference_step`` seconds (a
multiple of the output step): the worst error over the span is the largest over
those samples, and the final error is at the last sample, t = span.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from fractions import Fraction

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

DAY = 86400.0


@dataclass(frozen=True)
class Case:
    """One named problem: inertia, initial state and span."""

    name: str
    title: str
    inertia: tuple[float, float, float]
    omega0: tuple[float, float, float]
    q0: tuple[float, float, float, float]
    span: float
    step: float
    reference_step: float
    validation_span: float  # how far the reference is checked against mpmath odefun
    note: str = ""

    def times(self) -> NDArray[np.float64]:
        """The output times 0, step, ..., span (every peer produces all of them)."""
        n = round(self.span / self.step)
        return np.arange(n + 1) * self.step

    def reference_stride(self) -> int:
        """Every how many output samples the reference is sampled."""
        return round(self.reference_step / self.step)

    def reference_times(self) -> NDArray[np.float64]:
        return self.times()[:: self.reference_stride()]

    def momentum0(self) -> NDArray[np.float64]:
        return np.asarray(self.inertia) * np.asarray(self.omega0)

    def kinetic_energy0(self) -> float:
        return 0.5 * float(np.sum(np.asarray(self.inertia) * np.square(self.omega0)))

    def shortened(self, span: float, reference_step: float | None = None) -> Case:
        """The same body and initial state over a shorter span (quick runs, pilots)."""
        span = max(self.step, math.floor(span / self.step) * self.step)
        ref = reference_step if reference_step is not None else self.reference_step
        ref = max(self.step, min(ref, span))
        ref = round(ref / self.step) * self.step
        while round(span / self.step) % round(ref / self.step):
            ref -= self.step  # the last output sample must be a reference sample
        return replace(self, span=span, reference_step=ref)


def delta2_over_G2(case: Case) -> float:
    """Δ2/G² = (G² − 2T I2)/G² of the case, exact for its floats (I ω0 formed exactly)."""
    moments = [Fraction(x) for x in case.inertia]
    w = [Fraction(x) for x in case.omega0]
    m = [i * x for i, x in zip(moments, w, strict=True)]
    G2 = sum(x * x for x in m)
    two_T = sum(i * x * x for i, x in zip(moments, w, strict=True))
    return float((G2 - two_T * sorted(moments)[1]) / G2)


def _q(rotation: Rotation) -> tuple[float, float, float, float]:
    return tuple(float(x) for x in rotation.as_quat(scalar_first=True))  # type: ignore[return-value]


# A generic initial attitude (not the identity), so that a convention mistake in the
# initial attitude of a peer shows up as a large error, not as nothing.
_Q_GENERIC = _q(Rotation.from_euler("ZYX", [10.0, 20.0, 30.0], degrees=True))


def _near_separatrix_omega(delta: float) -> tuple[float, float, float]:
    """ω0 = (ε1, 1, 1e-5) on I = (100, 200, 300) with Δ2/G² = −delta (the m > 1 side).

    Δ2 = Σ Ij ωj² (Ij − I2) = −1e4 ε1² + 3e4 ε3² and G² = 4e4 + 1e4 ε1² + 9e4 ε3²;
    solved for ε1, then rounded to a double (the exact value is reported).
    """
    e3 = 1e-5
    e1 = math.sqrt((3e4 * e3**2 + delta * (4e4 + 9e4 * e3**2)) / (1e4 - delta * 1e4))
    return (e1, 1.0, e3)


_DZHANIBEKOV = dict(
    inertia=(100.0, 200.0, 300.0),
    omega0=(1e-3, 1.0, 1e-3),
    q0=_Q_GENERIC,
    note="intermediate-axis spin 1 - m = 2.0e-6 from the separatrix: a flip every 27 s",
)

CASES: dict[str, Case] = {
    c.name: c
    for c in [
        Case(
            name="dzhanibekov_1h",
            title="1. Dzhanibekov, 1 h",
            span=3600.0,
            step=1.0,
            reference_step=1.0,
            validation_span=60.0,
            **_DZHANIBEKOV,
        ),
        Case(
            name="dzhanibekov_1d",
            title="1. Dzhanibekov, 1 day",
            span=DAY,
            step=1.0,
            reference_step=10.0,
            validation_span=60.0,
            **_DZHANIBEKOV,
        ),
        Case(
            name="spinner_nutation_1d",
            title="2. Spinner with nutation, 1 day",
            inertia=(850.0, 900.0, 1200.0),
            omega0=(0.03, 0.02, math.pi / 6.0),  # 5 rpm about z, 2.8° of nutation
            q0=_Q_GENERIC,
            span=DAY,
            step=1.0,
            reference_step=60.0,
            validation_span=60.0,
            note="oblate spinner, 5 rpm about z; the momentum is 2.8° off z (nutation)",
        ),
        Case(
            name="near_separatrix_1h",
            title="3. Near the separatrix, 1 h",
            inertia=(100.0, 200.0, 300.0),
            omega0=_near_separatrix_omega(1e-10),
            q0=_Q_GENERIC,
            span=3600.0,
            step=1.0,
            reference_step=1.0,
            validation_span=120.0,
            note="|Δ2|/G² = 1e-10 on the side of the least axis (Jadczyk's m > 1)",
        ),
        Case(
            name="envisat_tumble_30d",
            title="4. Long span: tumbling Envisat-like body, 30 days",
            inertia=(17023.0, 124826.0, 129112.0),
            omega0=tuple(math.radians(x) for x in (0.05, 0.08, 2.67)),  # type: ignore[arg-type]
            q0=(math.sqrt(0.5), math.sqrt(0.5), 0.0, 0.0),
            span=30 * DAY,
            step=60.0,
            reference_step=600.0,
            validation_span=600.0,
            note="scenarios/tumbling_defunct_satellite.toml: 2.7 deg/s about z, small wobble",
        ),
    ]
}

# Not part of the benchmark: a few seconds of the Dzhanibekov body, for the smoke test.
SMOKE = Case(
    name="smoke",
    title="smoke test (20 s of case 1)",
    span=20.0,
    step=1.0,
    reference_step=5.0,
    validation_span=20.0,
    **_DZHANIBEKOV,
)

ALL_CASES: dict[str, Case] = {**CASES, SMOKE.name: SMOKE}


@dataclass
class PeerRun:
    """What a peer produced for one case and setting: its answer at every output time.

    ``q``: scalar-first quaternions body → inertial (N, 4), after the peer's own
    convention was converted (NaN where the peer returned NaN); ``omega``: body angular
    velocity (N, 3), rad/s; ``wall``: seconds spent producing them (building the
    propagator, propagating, converting to these arrays), excluding imports and JVM start.
    """

    q: NDArray[np.float64]
    omega: NDArray[np.float64]
    wall: float
    info: dict = field(default_factory=dict)


@dataclass(frozen=True)
class Setting:
    """One configuration of a peer (integrator, step, tolerance)."""

    peer: str
    label: str
    params: dict = field(default_factory=dict)
