"""Synthetic telemetry for the fit's tests: the exact solver's motion, sampled, with
Gaussian noise from a seeded generator.  The bodies are those the issue names
(generic, near the separatrix, nearly symmetric, a slow tumbler with gaps), each with
its truth: the moments, the rate and the attitude that generated it."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from attitude import EulerSolver

Q0 = Rotation.from_rotvec([0.3, -0.2, 0.5])


@dataclass(frozen=True)
class Body:
    name: str
    moments: np.ndarray  # along body x, y, z
    ω0: np.ndarray  # rad/s, body, at t = 0
    times: np.ndarray  # s
    gyro_sigma: float  # rad/s
    attitude_sigma: float = 1e-4  # rad per axis

    @property
    def solver(self) -> EulerSolver:
        return EulerSolver(self.moments, self.moments * self.ω0, Q0)

    @property
    def ratios(self) -> np.ndarray:
        m = np.sort(self.moments)
        return m / m[0]

    def gyro(self, rng: np.random.Generator, times: np.ndarray | None = None) -> np.ndarray:
        t = self.times if times is None else times
        return self.solver.angular_velocity(t) + self.gyro_sigma * rng.standard_normal((t.size, 3))

    def quaternions(self, rng: np.random.Generator, times: np.ndarray | None = None) -> np.ndarray:
        t = self.times if times is None else times
        noise = Rotation.from_rotvec(self.attitude_sigma * rng.standard_normal((t.size, 3)))
        return (self.solver.attitude(t) * noise).as_quat(scalar_first=True)


def _separatrix_rate(moments: np.ndarray, w1: float, w2: float, offset: float) -> np.ndarray:
    """A rate whose Δ2/G² is about ``offset`` (Δ2 = 0 at w3 = w1 √(I1 I21/(I3 I32)))."""
    I1, I2, I3 = moments
    w3 = w1 * np.sqrt(I1 * (I2 - I1) / (I3 * (I3 - I2))) * (1.0 + offset)
    return np.array([w1, w2, w3])


_SLOW_TIMES = np.arange(0.0, 3000.0, 5.0)

BODIES = {
    "generic": Body(
        "generic",
        np.array([100.0, 200.0, 260.0]),
        np.array([0.05, 0.02, 0.03]),
        np.arange(0.0, 700.0, 2.0),
        1e-4,
    ),
    "separatrix": Body(
        "separatrix",
        np.array([100.0, 200.0, 260.0]),
        _separatrix_rate(np.array([100.0, 200.0, 260.0]), 0.02, 0.04, 2e-3),
        np.arange(0.0, 1400.0, 2.0),
        1e-4,
    ),
    "symmetric": Body(
        "symmetric",
        np.array([100.0, 103.0, 180.0]),
        np.array([0.03, 0.01, 0.04]),
        np.arange(0.0, 1500.0, 3.0),
        1e-4,
    ),
    "slow_gaps": Body(
        "slow_gaps",
        np.array([1.7e4, 1.25e5, 1.29e5]),
        np.radians([0.05, 0.08, 0.6]),
        _SLOW_TIMES[(_SLOW_TIMES % 1000.0) < 700.0],
        2e-5,
    ),
}
