"""``fit_spin_state``: the inertia ratios and spin state that best explain telemetry.

The pipeline (docs/estimation.md): the telemetry is checked and cleaned
(attitude.estimation.telemetry), each sensor's noise taken as given or estimated from
the data's high differences, a body without motion in its own axes refused (a steady
spin shows no inertia ratio, noise alone no motion at all); the linear first guess
(attitude.estimation.linear_guess) gives the starts (for fixes too sparse for it, the
global start of attitude.estimation.global_start, which reports every family of
solutions the fixes allow); least squares on the exact motion
over a growing arc (attitude.estimation.solve) keeps the first start that fits down to
the noise; its covariance and goodness of fit (attitude.estimation.statistics) are then
checked against what the data can show (``_observability``), and what they cannot
show is refused, not reported.

What is observable (checked, and stated in ``SpinStateFit.observability``):

- from a torque-free arc, the ratios of the principal moments, never their scale: the
  motion of a body with moments c I is that of I at the same rates;
- the body rate at t0 from either sensor; the attitude only from attitude fixes
  (gyro rates alone leave the inertial frame free);
- the absolute moments with a known angular impulse (or a known burn) in the arc: the
  rates jump by I⁻¹ ΔH.  Not with gravity gradient, whose torque is proportional to the
  inertia: a body with moments c I feels c times the torque and moves the same;
- the principal axes in the sensor frame when asked, except about the symmetry axis of
  a symmetric body;
- nothing from an arc shorter than one period of the body's motion: the ratios are
  then refused, whatever the covariance says.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.base.quantities import as_si_array, as_si_scalar
from attitude.estimation.burns import known_burns
from attitude.estimation.linear_guess import Guess, candidates, impulse_scale, measured_rates
from attitude.estimation.model import ExactModel, Impulse, Layout
from attitude.estimation.solve import Data, FitRefused, Solution, fit_from_starts, residuals
from attitude.estimation.statistics import Goodness, covariance, goodness
from attitude.estimation.telemetry import Telemetry, difference_noise, prepare_telemetry
from attitude.solver.euler_solver import EulerSolver

__all__ = ["FitRefused", "SpinStateFit", "fit_spin_state"]

# Refused beyond these 1σ: a ratio known to worse than 10 %, axes to worse than 10°.
RATIO_LIMIT = 0.10
SCALE_LIMIT = 0.10
AXES_LIMIT_RAD = math.radians(10.0)
DEFAULT_HORIZON_DEG = 10.0
# Rates beyond this are refused: their squares (Euler's equations) leave the float range.
MAX_RATE = 1e100


@dataclass
class SpinStateFit:
    """A fit of the spin state and inertia ratios to telemetry (``fit_spin_state``).

    Times are seconds from ``epoch`` (the first sample; an astropy ``Time``, or None for
    telemetry in relative seconds), which is t = 0 of ``solver``.  Vectors are in the
    telemetry's body axes; attitudes are body → ICRF.

    ``solver`` is the fitted motion as an ``EulerSolver`` at t = 0: torque-free, and up
    to the first known impulse; ``predict``, ``uncertainty`` and ``horizon`` follow the
    whole fitted model (impulses, and the torques of a fit under torques).

    The parameters, their 1σ and ``covariance`` are listed by ``parameter_names`` (with
    ``parameter_units``): the ratios I2/I1 and I3/I1 of the principal moments sorted
    ascending; I1 (kg m²) when the absolute moments are observable; the body rate at
    t = 0; with attitude fixes, the attitude error at t = 0 (a body-axes rotation
    vector about ``attitude``); with the principal axes estimated, their error (a
    body-axes rotation vector about ``principal_axes``); with a gyro bias, the bias.

    ``families``: every family of solutions that fits the data within the noise, best
    χ² first, this fit the first; several (``ambiguous``) when sparse fixes do not
    decide the number of turns between them: each is a ``SpinStateFit`` with its own
    covariance, and none is more the answer than the others.
    """

    inertia_ratios: NDArray[np.float64]  # (1, I2/I1, I3/I1)
    inertia_ratios_sigma: NDArray[np.float64]  # (0, σ, σ)
    principal_moments: NDArray[np.float64] | None  # kg m², ascending, when observable
    principal_moments_sigma: NDArray[np.float64] | None
    principal_axes: NDArray[np.float64]  # (3, 3): row k, the unit axis of moment k, body
    principal_axes_sigma: NDArray[np.float64] | None  # rad, body axes, when estimated
    angular_velocity: NDArray[np.float64]  # body, rad/s at t = 0
    angular_velocity_sigma: NDArray[np.float64]
    gyro_bias: NDArray[np.float64] | None  # rad/s, body axes, when estimated
    gyro_bias_sigma: NDArray[np.float64] | None
    attitude: Rotation | None  # body → ICRF at t = 0, when observable
    attitude_sigma: NDArray[np.float64] | None  # rad, body axes
    parameter_names: list[str]
    parameter_units: list[str]
    parameter_values: NDArray[np.float64]
    covariance: NDArray[np.float64]
    reduced_chi2: float
    goodness: Goodness
    noise: dict[str, Any]
    residuals: dict[str, Any]
    solver: EulerSolver
    epoch: Any
    span: tuple[float, float]
    period: float
    formula: str
    observability: list[str]
    notes: list[str]
    _model: Any = field(repr=False)
    _x: NDArray[np.float64] = field(repr=False)
    _cov_x: NDArray[np.float64] = field(repr=False)
    # Every family of solutions that fits within the noise, best first, this fit the
    # first: several for sparse fixes whose turns between them the data do not decide.
    families: list[SpinStateFit] = field(default_factory=list, repr=False)

    @property
    def ambiguous(self) -> bool:
        """True when several families of solutions fit the data within the noise."""
        return len(self.families) > 1

    @property
    def parameter_sigma(self) -> NDArray[np.float64]:
        """1σ of each parameter (the square roots of the covariance's diagonal)."""
        return np.sqrt(np.diag(self.covariance))

    @property
    def correlations(self) -> NDArray[np.float64]:
        """The correlation matrix of the parameters."""
        σ = self.parameter_sigma
        with np.errstate(invalid="ignore", divide="ignore"):
            return self.covariance / np.outer(σ, σ)

    @property
    def chi2(self) -> float:
        return self.goodness.chi2

    @property
    def absolute_moments(self) -> bool:
        """True when the fit determined the moments in kg m² (a known impulse or burn)."""
        return self.principal_moments is not None

    # -------------------------------------------------------------- prediction

    def predict(self, t: Any) -> tuple[NDArray[np.float64], Rotation]:
        """Body rates (N, 3) and attitudes (body → ICRF; relative to the unknown initial
        attitude for a fit without attitude fixes) at ``t``, seconds from ``epoch``."""
        times = np.atleast_1d(as_si_array(t, "time", "t"))
        rates, attitude = self._model.predict(self._x, times, times, jacobian=False)
        return rates.ω, attitude.attitude

    def uncertainty(self, t: Any) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The 1σ of the predicted attitude (rad, the largest axis of its covariance)
        and of the rates (rad/s, likewise) at ``t``, seconds from ``epoch``, by linear
        propagation of the fit's covariance through the motion's sensitivities.

        Without attitude fixes the attitude is relative to the one at t = 0, taken as
        exact: its uncertainty is then the growth of the phase alone."""
        times = np.atleast_1d(as_si_array(t, "time", "t"))
        rates, attitude = self._model.predict(self._x, times, times, jacobian=True)
        return _largest_sigma(attitude.dθ, self._cov_x), _largest_sigma(rates.dω, self._cov_x)

    def prediction_covariance(self, t: Any) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The covariance of the predicted attitude ((N, 3, 3), rad², of the body-axes
        rotation vector δθ with Q_true = Q_predicted exp([δθ]×)) and of the predicted
        body rates ((N, 3, 3), (rad/s)²) at ``t``, seconds from ``epoch``."""
        times = np.atleast_1d(as_si_array(t, "time", "t"))
        rates, attitude = self._model.predict(self._x, times, times, jacobian=True)
        return (
            np.einsum("nip,pq,njq->nij", attitude.dθ, self._cov_x, attitude.dθ),
            np.einsum("nip,pq,njq->nij", rates.dω, self._cov_x, rates.dω),
        )

    def envelope(self, t: Any, points: int = 24) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``uncertainty`` at its largest over one cycle of the motion about each of
        ``t`` (the longer of the body period and one turn, 2π/|ω|, sampled at
        ``points`` times): the uncertainty oscillates within each cycle, and a curve
        sampled once per many cycles would alias."""
        times = np.atleast_1d(as_si_array(t, "time", "t"))
        turn = 2.0 * math.pi / max(float(np.linalg.norm(self.angular_velocity)), 1e-300)
        cycle = max(turn, self.period if math.isfinite(self.period) else 0.0)
        offsets = cycle * (np.arange(points) / points - 0.5)
        grid = (times[:, None] + offsets[None, :]).ravel()
        grid = np.maximum(grid, self.span[0])
        σ_attitude, σ_rate = self.uncertainty(grid)
        return σ_attitude.reshape(times.size, points).max(axis=1), σ_rate.reshape(
            times.size, points
        ).max(axis=1)

    def horizon(self, threshold: Any = None, limit: float | None = None) -> float:
        """The first time after the arc (s from ``epoch``) at which the predicted 1σ
        attitude uncertainty, at its largest over a cycle (``envelope``), reaches
        ``threshold`` (an angle: a Quantity, or radians; 10° by default); ``inf`` if it
        stays below until ``limit`` (default: the arc's end plus 10⁶ times its length,
        or 30 times it under torques, whose propagation costs per second of span).
        Linear propagation of the covariance: near 10° the first-order phase error is
        still the whole story for a tumbler, whose error is mostly along its turn."""
        threshold_rad = (
            math.radians(DEFAULT_HORIZON_DEG)
            if threshold is None
            else as_si_scalar(threshold, "angle", "threshold")
        )
        start, end = self.span
        length = max(end - start, 1e-9)
        if limit is None:
            limit = end + (30.0 if getattr(self._model, "torques", None) else 1e6) * length
        limit = float(limit)

        def σ(t: float) -> float:
            return float(self.envelope(t)[0][0])

        previous = end
        if σ(end) >= threshold_rad:
            return end
        k = 0
        while True:
            t = min(end + length * 2.0 ** (k / 2.0 - 2.0), limit)
            if σ(t) >= threshold_rad:
                break
            if t >= limit:
                return math.inf
            previous, k = t, k + 1
        low, high = previous, t
        for _ in range(40):
            middle = 0.5 * (low + high)
            if σ(middle) >= threshold_rad:
                high = middle
            else:
                low = middle
            if high - low <= 1e-4 * (high - end):
                break
        return high

    def summary(self) -> str:
        """A few lines: the ratios, the rate, the attitude, χ², what is observable."""
        r, s = self.inertia_ratios, self.inertia_ratios_sigma
        lines = [
            f"inertia ratios 1 : {r[1]:.6g} ± {s[1]:.2g} : {r[2]:.6g} ± {s[2]:.2g}"
            f" (formula {self.formula}, body period {self.period:.6g} s)",
            "angular velocity at t0 (body, rad/s): "
            + ", ".join(
                f"{v:.6g} ± {e:.2g}"
                for v, e in zip(self.angular_velocity, self.angular_velocity_sigma, strict=True)
            ),
        ]
        if self.gyro_bias is not None and self.gyro_bias_sigma is not None:
            lines.append(
                "gyro bias (body, rad/s): "
                + ", ".join(
                    f"{v:.6g} ± {e:.2g}"
                    for v, e in zip(self.gyro_bias, self.gyro_bias_sigma, strict=True)
                )
            )
        if self.principal_moments is not None and self.principal_moments_sigma is not None:
            lines.append(
                "principal moments (kg m²): "
                + ", ".join(
                    f"{v:.6g} ± {e:.2g}"
                    for v, e in zip(
                        self.principal_moments, self.principal_moments_sigma, strict=True
                    )
                )
            )
        if self.attitude is not None and self.attitude_sigma is not None:
            q = self.attitude.as_quat(scalar_first=True)
            lines.append(
                f"attitude at t0 (body -> ICRF, scalar first): {np.array2string(q, precision=9)}"
                f", 1σ {np.degrees(self.attitude_sigma).max():.3g} deg"
            )
        lines.append(f"reduced chi2 {self.reduced_chi2:.4g}")
        if self.ambiguous:
            lines.append(
                f"{len(self.families)} families of solutions fit within the noise (the data do "
                "not decide between them):"
            )
            for k, family in enumerate(self.families):
                r, s = family.inertia_ratios, family.inertia_ratios_sigma
                ω = ", ".join(f"{v:.6g}" for v in family.angular_velocity)
                lines.append(
                    f"  family {k + 1}: 1 : {r[1]:.7g} ± {s[1]:.2g} : {r[2]:.7g} ± {s[2]:.2g}, "
                    f"rate at t0 {ω} rad/s, reduced chi2 {family.reduced_chi2:.4g}"
                )
        return "\n".join(lines + self.observability)


def _largest_sigma(d: NDArray[np.float64], cov: NDArray[np.float64]) -> NDArray[np.float64]:
    """√ of the largest eigenvalue of d Σ dᵀ at each time (d: (N, 3, n))."""
    P = np.einsum("nip,pq,njq->nij", d, cov, d)
    return np.sqrt(np.maximum(np.linalg.eigvalsh(P)[:, -1], 0.0))


# ----------------------------------------------------------------- the entry point


def fit_spin_state(
    times: Any,
    *,
    angular_velocity: Any = None,
    quaternions: Any = None,
    gyro_sigma: Any = None,
    attitude_sigma: Any = None,
    principal_axes: bool = False,
    gyro_bias: bool = False,
    impulses: Any = (),
    guess: Any = None,
    torques: Any = None,
    orbit: Any = None,
    source: str = "telemetry",
    progress: Callable[[str], None] | None = None,
) -> SpinStateFit:
    """Fit the exact torque-free motion to gyro rates and/or attitude quaternions.

    Parameters
    ----------
    times
        The sample times: an astropy ``Time`` array, or seconds (then relative, with no
        epoch).  Any order; gaps allowed.
    angular_velocity
        (N, 3) body rates, rad/s (or a ``Quantity``); rows of NaN where missing.
    quaternions
        (N, 4) attitude, body → ICRF, scalar first (w, x, y, z); rows of NaN where
        missing.  q and −q are the same attitude.  Or a ``Rotation`` of N attitudes
        (body → ICRF), one per time (a star tracker that reads at every time).
    gyro_sigma, attitude_sigma
        The white noise of each sensor: rad/s (one value or one per axis) and rad per
        axis (or ``Quantity``).  Estimated from the data when not given.
    principal_axes
        Also estimate the principal axes in the telemetry's body axes (a misaligned
        gyro or star tracker); otherwise the body axes are taken as principal.
    gyro_bias
        Also estimate a constant gyro bias (rad/s, body axes), which the rates then
        have subtracted; otherwise the gyro is taken as unbiased (a bias then shows as
        residuals above the noise, and the fit is refused).
    impulses
        Known angular impulses in the arc: ``attitude.AngularImpulse`` events (epoch a
        ``Time``, or seconds from the first sample), body or inertial.  They make the
        absolute moments observable.
    guess
        A start instead of the linear guess (an ``EulerSolver`` at the first sample, in
        body axes, or an earlier ``SpinStateFit``).  Without one, fixes too sparse to
        differentiate (radar passes a day apart, with the rates at each) are started by
        a global search from the fixes themselves (attitude.estimation.global_start),
        and every family of solutions that fits is reported (``families``).
    torques
        A ``ScenarioTorques`` (gravity gradient, burns) fitted through the splitting
        (``TorquedSolver``); None for the torque-free motion.
    orbit
        The orbit the gravity gradient acts on (``gravity_gradient=True``), as
        ``Scenario(orbit=...)`` takes it.
    source
        The name used in messages (the file the telemetry came from).
    progress
        Told each stage as it starts or ends, with an estimate of the time left (one
        line each; the command line writes them to stderr); None: silent.

    Returns a ``SpinStateFit``.  Raises ``FitRefused`` (an ``InputError``) when the
    telemetry cannot determine the fit, saying why: too short an arc, no motion, only
    local minima, a parameter the data leave undetermined.
    """
    telemetry = prepare_telemetry(times, angular_velocity, quaternions, source)
    if telemetry.gyro_reads_zero:
        _refuse_at_rest(telemetry)
    if telemetry.gyro is not None:
        fastest = float(np.max(np.abs(telemetry.gyro.values)))
        if fastest > MAX_RATE:
            raise InputError(
                f"angular_velocity reaches {fastest:.3g} rad/s: beyond what a fit "
                f"can handle (up to {MAX_RATE:g} rad/s: Euler's equations square the rates)",
                file=source,
            )
    notes = list(telemetry.notes)
    say = progress or (lambda text: None)
    data, noise = _data(telemetry, gyro_sigma, attitude_sigma)
    say(_described(telemetry, noise))
    _refuse_without_motion(telemetry, data)
    impulse_list = _impulses(impulses, telemetry)
    burns = known_burns(getattr(torques, "burns", ()), telemetry.epoch) if torques else ()
    start, end = telemetry.span
    has_burns = any(b.stop > start and b.start < end for b in burns)  # in the arc
    if gyro_bias and telemetry.gyro is None:
        raise InputError("needs gyro rates, and there are none", key="gyro_bias", file=source)
    layout = Layout(
        attitude=telemetry.attitude is not None,
        scale=bool(impulse_list) or has_burns,
        axes=bool(principal_axes),
        bias=bool(gyro_bias),
    )
    if any(i.frame != "body" for i in impulse_list) and not layout.attitude:
        raise InputError(
            "an impulse in inertial axes needs the attitude: give quaternions, or "
            "the impulse in body axes",
            file=source,
        )
    if torques is not None and not layout.attitude:
        inertial_burns = any(b.frame != "body" for b in getattr(torques, "burns", ()))
        if getattr(torques, "gravity_gradient", None) is not None or inertial_burns:
            raise InputError(
                "a fit under gravity gradient (or an inertial burn) needs attitude "
                "fixes: the torque depends on the attitude, which rates alone barely show",
                file=source,
            )
    model = _model(layout, impulse_list, torques, telemetry, orbit, burns)
    if guess is None and _too_sparse(telemetry, model):
        say("fit: too sparse for the linear guess: the global start from the fixes")
        return _global_fit(model, telemetry, data, noise, notes, say)
    starts, guess_text = _starts(model, telemetry, guess, principal_axes, data)
    notes.append(guess_text)
    say(f"fit: {len(starts)} start(s): {guess_text}")
    solution = fit_from_starts(starts, data, say)
    notes += solution.notes
    if solution.tried:
        notes.append(
            f"{len(solution.tried)} start(s) rejected before the one kept ({solution.start}): "
            + "; ".join(solution.tried)
        )
    fit = _result(solution, telemetry, noise, notes)
    fit.families = [fit]
    return fit


# ----------------------------------------------------------------- pieces


def _data(telemetry: Telemetry, gyro_sigma: Any, attitude_sigma: Any) -> tuple[Data, dict]:
    """The measurements with their noise, given or estimated (and where from)."""
    noise: dict[str, Any] = {}
    g, a = telemetry.gyro, telemetry.attitude
    σ_g = σ_a = None
    if g is not None:
        if gyro_sigma is not None:
            σ_g = np.broadcast_to(
                as_si_array(gyro_sigma, "angular_velocity", "gyro_sigma"), (3,)
            ).astype(float)
            noise["gyro"] = {"sigma_rad_s": σ_g.tolist(), "source": "given"}
        else:
            σ_g = difference_noise(g.t, g.values)
            if σ_g is None:
                raise InputError(
                    "the gyro samples are too few or too sparse (20 or more sixth differences "
                    "of evenly spaced readings are needed) to estimate their noise: give it",
                    key="gyro_sigma",
                    file=telemetry.source,
                )
            σ_g = np.maximum(σ_g, 1e-300)
            noise["gyro"] = {
                "sigma_rad_s": σ_g.tolist(),
                "source": "estimated from 6th differences",
            }
        if np.any(σ_g <= 0.0):
            raise InputError(
                f"must be positive, got {σ_g.tolist()}", key="gyro_sigma", file=telemetry.source
            )
    if a is not None:
        if attitude_sigma is not None:
            σ_a = as_si_scalar(attitude_sigma, "angle", "attitude_sigma")
            noise["attitude"] = {"sigma_rad": σ_a, "source": "given"}
        else:
            σ_a = _attitude_noise(a.t, a.values)
            if σ_a is None:
                raise InputError(
                    "the attitude fixes are too few or too sparse (30 or more evenly spaced "
                    "ones are needed) to estimate their noise: give it",
                    key="attitude_sigma",
                    file=telemetry.source,
                )
            noise["attitude"] = {"sigma_rad": σ_a, "source": "estimated from 6th differences"}
        if not σ_a > 0.0:
            raise InputError(
                f"must be positive, got {σ_a!r}", key="attitude_sigma", file=telemetry.source
            )
    data = Data(
        None if g is None else g.t,
        None if g is None else g.values,
        σ_g,
        None if a is None else a.t,
        None if a is None else Rotation.from_quat(a.values, scalar_first=True),
        σ_a,
    )
    return data, noise


def _attitude_noise(t: NDArray[np.float64], q: NDArray[np.float64]) -> float | None:
    """Per-axis noise of attitude fixes, from the differences of their increments: the
    increment of white rotation noise n is n(i+1) − n(i), so its 5th differences are
    the 6th of n, of variance C(12, 6) σ² (as ``difference_noise`` with order 6)."""
    if t.size < 30:
        return None
    R = Rotation.from_quat(q, scalar_first=True)
    increments = (R[:-1].inv() * R[1:]).as_rotvec()
    σ5 = difference_noise(t[:-1], increments, order=5)
    if σ5 is None:
        return None
    # difference_noise divided by √C(10, 5); the 6th differences of n need √C(12, 6).
    σ = σ5 * math.sqrt(math.comb(10, 5) / math.comb(12, 6))
    return float(np.sqrt(np.mean(σ * σ))) or None


def _refuse_at_rest(telemetry: Telemetry) -> None:
    """A gyro that reads exactly zero: no rotation measured.  What that leaves to fit."""
    turned = 0.0
    a = telemetry.attitude
    if a is not None and len(a) >= 2:
        R = Rotation.from_quat(a.values, scalar_first=True)
        turned = math.degrees(float(np.max((R[0].inv() * R).magnitude())))
    said = "the gyro reads exactly 0 rad/s on every axis at every reading: no rotation is measured"
    if turned > 1.0:
        raise FitRefused(
            f"{said}, while the attitude fixes turn by up to {turned:.3g} deg: a gyro that is "
            "off or not connected; fit the attitude fixes alone (without the gyro's readings)",
            file=telemetry.source,
        )
    attitude = (
        f"its attitude is the star tracker's fixed reading (within {turned:.2g} deg)"
        if a is not None
        else "and without attitude fixes not even its attitude is known"
    )
    raise FitRefused(
        f"{said} (a body at rest, or a gyro that is off): a body at rest shows no inertia "
        f"ratio, no spin state and nothing to predict (the moments show only in a motion); "
        f"{attitude}",
        file=telemetry.source,
    )


def _refuse_without_motion(telemetry: Telemetry, data: Data) -> None:
    """A body whose rates do not vary beyond the gyro noise shows no inertia ratio."""
    if data.rates is None or data.σ_rates is None or data.rates.shape[0] < 10:
        return
    ω, σ = data.rates, data.σ_rates
    z = (ω - np.median(ω, axis=0)) / σ
    dof = z.size - 3
    # A χ² test of constant rates, with the outliers' weight capped as the fit does.
    chi2 = float(np.sum(np.minimum(z * z, 25.0)))
    if chi2 / dof < 1.0 + 5.0 * math.sqrt(2.0 / dof):
        mean = np.median(ω, axis=0)
        if np.all(np.abs(mean) < 5.0 * σ):
            raise FitRefused(
                f"noise only: the gyro reads no rotation beyond its noise "
                f"({np.linalg.norm(σ):.3g} rad/s); there is no motion to fit",
                file=telemetry.source,
            )
        raise FitRefused(
            f"a steady spin at {np.linalg.norm(mean):.6g} rad/s: the rates do not vary beyond "
            "the gyro noise over the arc, and a spin about a principal axis shows no inertia "
            "ratio (a longer arc, or a nutation, would)",
            file=telemetry.source,
        )


def _impulses(impulses: Any, telemetry: Telemetry) -> tuple[Impulse, ...]:
    """Known impulses as ``Impulse`` (seconds from the telemetry's t = 0)."""
    from attitude.environment.timescales import tt_seconds

    out = []
    for k, item in enumerate(impulses or ()):
        epoch = getattr(item, "epoch", None)
        vector = getattr(item, "impulse", None)
        if epoch is None or vector is None:
            raise InputError(f"impulses[{k}]: expected an AngularImpulse, got {item!r}")
        if hasattr(epoch, "jd1"):
            if telemetry.epoch is None:
                raise InputError(
                    f"impulses[{k}]: an epoch ({epoch}) needs telemetry times as epochs too"
                )
            t = float(tt_seconds(epoch, telemetry.epoch))
        else:
            t = as_si_scalar(epoch, "time", f"impulses[{k}].epoch")
        start, end = telemetry.span
        if not start < t <= end:
            raise InputError(
                f"impulses[{k}]: at t = {t:.6g} s, outside the telemetry's arc ({start:.6g} to "
                f"{end:.6g} s)"
            )
        out.append(Impulse(t, np.asarray(vector, dtype=float), item.frame))
    return tuple(out)


def _model(layout: Layout, impulses, torques, telemetry: Telemetry, orbit=None, burns=()):
    """The exact motion, across known impulses and burns (attitude.estimation.burns);
    under gravity gradient, the propagated scenario (attitude.estimation.scenario_model)."""
    if torques is None or not getattr(torques, "any", True):
        return ExactModel(layout, impulses)
    if getattr(torques, "gravity_gradient", None) is None:
        return ExactModel(layout, impulses, burns)
    from attitude.estimation.scenario_model import ScenarioModel

    return ScenarioModel(
        layout,
        impulses,
        torques=torques,
        epoch=telemetry.epoch,
        end=telemetry.span[1],
        orbit=orbit,
    )


def _first_attitude(telemetry: Telemetry, moments, axes: Rotation, ω0) -> Rotation | None:
    """The attitude at t = 0: the first fix, carried back along the guessed motion."""
    if telemetry.attitude is None:
        return None
    a = telemetry.attitude
    q_first = Rotation.from_quat(a.values[0], scalar_first=True)
    if a.t[0] == 0.0:
        return q_first
    R = axes.as_matrix()
    tensor = R @ np.diag(moments) @ R.T
    solver = EulerSolver(0.5 * (tensor + tensor.T), tensor @ ω0)
    relative = solver.attitude(float(a.t[0]))  # Q(0) = identity
    return q_first * relative.inv()


def _starts(model, telemetry: Telemetry, guess: Any, principal_axes: bool, data: Data):
    """(model, x, label, first arc end) for each start, and the guess's description."""
    impulses = getattr(model, "impulses", ())
    # Burns in the exact model, or in the torques of a propagated one.
    burns = model.burns or known_burns(
        getattr(getattr(model, "torques", None), "burns", ()), telemetry.epoch
    )
    if guess is not None:
        guesses = [_from_guess(guess)]
        text = "started from the guess given"
    else:
        guesses, text = candidates(
            telemetry,
            principal_axes,
            tuple(i.t for i in impulses),
            tuple((b.start, b.stop) for b in burns),
        )
    starts = []
    t_first = float(data.times[0])
    for g in guesses:
        Q0 = _first_attitude(telemetry, g.moments, g.axes, g.ω0)
        if model.layout.scale:
            scale = impulse_scale(
                telemetry,
                g.moments,
                g.axes,
                impulses,
                _rough_attitude(telemetry),
                burns,
            )
            if scale is not None:
                g = Guess(
                    g.moments * scale, g.axes, g.ω0, g.label + ", scale from the impulses or burns"
                )
        m, x = model.start(g.moments, g.axes, g.ω0, Q0)
        try:
            period = EulerSolver(g.moments, g.moments * g.axes.inv().apply(g.ω0)).period
        except InputError:
            period = math.inf
        # Half a period of the guessed motion, and at most one turn: short enough that
        # the guess's phase errors stay small (the arc then grows as the covariance
        # allows, attitude.estimation.solve).
        speed = float(np.max(np.abs(g.ω0)))
        turn = 2.0 * math.pi / speed if speed > 0.0 else math.inf
        first_end = t_first + min(0.5 * period if math.isfinite(period) else math.inf, turn)
        starts.append((m, x, g.label, first_end))
    return starts, text


def _too_sparse(telemetry: Telemetry, model) -> bool:
    """No run of samples is dense enough to differentiate: the linear first guess has
    nothing to solve, and the global start (attitude.estimation.global_start) is used."""
    impulses = getattr(model, "impulses", ())
    burns = getattr(model, "burns", ())
    breaks = tuple(i.t for i in impulses)
    return measured_rates(telemetry, breaks, tuple((b.start, b.stop) for b in burns)) is None


def _described(telemetry: Telemetry, noise: dict) -> str:
    """One line on what is fitted: the samples of each sensor and their noise."""
    parts = []
    for sensor, name in ((telemetry.gyro, "gyro"), (telemetry.attitude, "attitude")):
        if sensor is not None:
            σ = noise[name].get("sigma_rad_s", noise[name].get("sigma_rad"))
            σ_text = ", ".join(f"{v:.3g}" for v in σ) if isinstance(σ, list) else f"{float(σ):.3g}"
            unit = "rad/s" if name == "gyro" else "rad"
            parts.append(
                f"{len(sensor)} {name} samples (σ {σ_text} {unit}, {noise[name]['source']})"
            )
    start, end = telemetry.span
    return f"fit: {' and '.join(parts)} over {end - start:.6g} s"


def _global_fit(model, telemetry: Telemetry, data: Data, noise: dict, notes: list[str], say=None):
    """Every family of solutions of sparse fixes (attitude.estimation.global_start): the
    best as the fit, all of them in its ``families``; the fit says when there are
    several."""
    from attitude.estimation.global_start import families

    solutions, text = families(model, data, telemetry.source, say)
    fits = [_result(s, telemetry, noise, [*notes, text]) for s in solutions]
    if len(fits) > 1:
        ranges = [
            f"{name} {min(f.inertia_ratios[k] for f in fits):.6g} to "
            f"{max(f.inertia_ratios[k] for f in fits):.6g}"
            for k, name in ((1, "I2/I1"), (2, "I3/I1"))
        ]
        line = (
            f"the fixes do not decide between {len(fits)} families of solutions (numbers "
            f"of turns between the fixes) that fit within the noise: {', '.join(ranges)}; "
            "each is in fit.families with its covariance (more fixes, or closer ones, "
            "would decide)"
        )
        for k, f in enumerate(fits):
            f.observability.insert(0, line)
            f.notes.append(f"family {k + 1} of {len(fits)}, reduced chi2 {f.reduced_chi2:.4g}")
    for f in fits:
        f.families = fits
    return fits[0]


def _rough_attitude(telemetry: Telemetry):
    """The attitude fix nearest to a time (None without fixes): to turn an impulse
    given in inertial axes into body axes for the first guess."""
    a = telemetry.attitude
    if a is None:
        return None

    def at(t: float) -> Rotation:
        return Rotation.from_quat(a.values[int(np.argmin(np.abs(a.t - t)))], scalar_first=True)

    return at


def _from_guess(guess: Any) -> Guess:
    solver = guess.solver if isinstance(guess, SpinStateFit) else guess
    if not isinstance(solver, EulerSolver):
        raise InputError(
            f"guess must be an EulerSolver or a SpinStateFit, got {type(guess).__name__}"
        )
    tensor = solver.inertia_tensor
    moments, vectors = np.linalg.eigh(tensor)
    if np.linalg.det(vectors) < 0:
        vectors[:, 2] *= -1.0
    ω0 = solver.angular_velocity(solver.t0)
    return Guess(moments / moments.min(), Rotation.from_matrix(vectors), ω0, "the guess given")


# ----------------------------------------------------------------- the result


def _result(
    solution: Solution, telemetry: Telemetry, noise: dict, notes: list[str]
) -> SpinStateFit:
    model, x, data = solution.model, solution.x, solution.data
    L = model.layout
    r_all = residuals(model, x, data, False)
    per_sensor: dict[str, NDArray[np.float64]] = {}
    raw: dict[str, Any] = {}
    offset = 0
    rates_pred, _ = model.predict(x, data.t_rates, None, jacobian=False)
    if data.t_rates is not None:
        n = data.t_rates.size
        block = r_all[: 3 * n].reshape(-1, 3)
        per_sensor["gyro"] = block[data.rate_inliers]
        raw["gyro"] = {
            "t": data.t_rates,
            "residual": data.rates - rates_pred.ω,
            "normalized": block,
            "inlier": data.rate_inliers,
        }
        offset = 3 * n
    if data.t_attitude is not None:
        block = r_all[offset:].reshape(-1, 3)
        per_sensor["attitude"] = block[data.attitude_inliers]
        raw["attitude"] = {
            "t": data.t_attitude,
            "residual": block * data.σ_attitude,
            "normalized": block,
            "inlier": data.attitude_inliers,
        }
    fit_quality = goodness(per_sensor, x.size)
    cov_x, _ = covariance(solution.jac)
    estimated = any(v["source"] != "given" for v in noise.values())
    if estimated:
        cov_x = cov_x * fit_quality.reduced_chi2
    solver = model.solver(x)
    # The parameters as reported, and their covariance by the delta method.
    J = model.moments(x)
    order = np.argsort(J, kind="stable")
    lnJ_d = np.zeros((3, x.size))
    ρ = L.block("ρ")
    lnJ_d[1, ρ.start] = lnJ_d[2, ρ.start + 1] = 1.0
    if L.scale:
        lnJ_d[:, L.block("σ").start] = 1.0
    names, units, values, rows = [], [], [], []
    ratios = J[order] / J[order[0]]
    for k in (1, 2):
        names.append(f"I{k + 1}/I1")
        units.append("1")
        values.append(ratios[k])
        rows.append(ratios[k] * (lnJ_d[order[k]] - lnJ_d[order[0]]))
    if L.scale:
        names.append("I1")
        units.append("kg m2")
        values.append(J[order[0]])
        rows.append(J[order[0]] * lnJ_d[order[0]])
    w = L.block("w")
    ω0 = model.rate(x)
    for k, axis in enumerate("xyz"):
        names.append(f"omega_{axis}")
        units.append("rad/s")
        values.append(ω0[k])
        row = np.zeros(x.size)
        row[w.start + k] = model.rate_unit
        rows.append(row)
    A = model.axes(x).as_matrix()
    blocks = (("θ", "attitude", np.eye(3)), ("α", "axes", A))
    for block, label, transform in blocks:
        part = L.block(block)
        if part.stop == part.start:
            continue
        for k, axis in enumerate("xyz"):
            names.append(f"{label}_{axis}")
            units.append("rad")
            values.append(0.0)
            row = np.zeros(x.size)
            row[part] = transform[k]
            rows.append(row)
    if L.bias:
        bias = x[L.block("b")] * model.rate_unit
        for k, axis in enumerate("xyz"):
            names.append(f"gyro_bias_{axis}")
            units.append("rad/s")
            values.append(bias[k])
            row = np.zeros(x.size)
            row[L.block("b").start + k] = model.rate_unit
            rows.append(row)
    G = np.array(rows)
    cov_y = G @ cov_x @ G.T
    σ_y = np.sqrt(np.maximum(np.diag(cov_y), 0.0))
    index = {name: k for k, name in enumerate(names)}
    observability, absolute = _observability(
        model, solver, telemetry, σ_y, index, ratios, J[order[0]]
    )
    ratio_sigma = np.array([0.0, σ_y[index["I2/I1"]], σ_y[index["I3/I1"]]])
    moments = moments_sigma = None
    if absolute:
        moments = J[order]
        lnJ_sorted = lnJ_d[order]
        moments_sigma = (
            np.sqrt(np.maximum(np.einsum("ip,pq,iq->i", lnJ_sorted, cov_x, lnJ_sorted), 0.0))
            * moments
        )
    axes_rows = A[:, order].T
    attitude = attitude_sigma = None
    if L.attitude:
        attitude = model.initial_attitude(x)
        attitude_sigma = np.array([σ_y[index[f"attitude_{a}"]] for a in "xyz"])
    axes_sigma = np.array([σ_y[index[f"axes_{a}"]] for a in "xyz"]) if L.axes else None
    values_y = np.array(values)
    return SpinStateFit(
        inertia_ratios=ratios,
        inertia_ratios_sigma=ratio_sigma,
        principal_moments=moments,
        principal_moments_sigma=moments_sigma,
        principal_axes=axes_rows,
        principal_axes_sigma=axes_sigma,
        angular_velocity=ω0,
        angular_velocity_sigma=np.array([σ_y[index[f"omega_{a}"]] for a in "xyz"]),
        gyro_bias=bias if L.bias else None,
        gyro_bias_sigma=np.array([σ_y[index[f"gyro_bias_{a}"]] for a in "xyz"]) if L.bias else None,
        attitude=attitude,
        attitude_sigma=attitude_sigma,
        parameter_names=names,
        parameter_units=units,
        parameter_values=values_y,
        covariance=cov_y,
        reduced_chi2=fit_quality.reduced_chi2,
        goodness=fit_quality,
        noise=noise,
        residuals=raw,
        solver=solver,
        epoch=telemetry.epoch,
        span=telemetry.span,
        period=solver.period,
        formula=solver.formula,
        observability=observability,
        notes=notes,
        _model=model,
        _x=x,
        _cov_x=cov_x,
    )


def _observability(model, solver, telemetry, σ_y, index, ratios, I1) -> tuple[list[str], bool]:
    """What the fit determines, as lines, and whether the absolute moments are among it;
    ``FitRefused`` for what it was asked to determine and cannot (module docstring)."""
    L = model.layout
    source = telemetry.source
    start, end = telemetry.span
    arc = end - start
    period = solver.period
    if not math.isfinite(period) or arc < period:
        shown = "infinite (the separatrix)" if not math.isfinite(period) else f"{period:.6g} s"
        raise FitRefused(
            f"the telemetry spans {arc:.6g} s, less than one period of the body's motion "
            f"({shown} by the best fit): the inertia ratios are not determined by it (no fit "
            "is better than a wrong one); fit a longer arc",
            file=source,
        )
    for name, ratio in (("I2/I1", ratios[1]), ("I3/I1", ratios[2])):
        σ = σ_y[index[name]]
        if not σ <= RATIO_LIMIT * ratio:
            raise FitRefused(
                f"{name} = {ratio:.6g} ± {σ:.3g}: the telemetry does not determine the inertia "
                f"ratios (1σ beyond {RATIO_LIMIT:.0%}); a longer arc, or one with more motion "
                "in the body axes, would",
                file=source,
            )
    lines = []
    absolute = False
    if L.scale:
        σ = σ_y[index["I1"]]
        absolute = bool(σ <= SCALE_LIMIT * I1)
        if absolute:
            lines.append(
                f"absolute moments observable: the known impulse(s) or burn(s) show I1 = "
                f"{I1:.6g} ± {σ:.3g} kg m²"
            )
        else:
            lines.append(
                f"only the inertia ratios are observable: the known impulse(s) or burn(s) "
                f"determine I1 only to {σ / I1:.0%} (refused beyond {SCALE_LIMIT:.0%}); the "
                "moments are in units of I1"
            )
    else:
        torques = getattr(model, "torques", None)
        why = (
            "gravity gradient scales with the inertia, so it shows no scale either"
            if torques is not None and getattr(torques, "gravity_gradient", None) is not None
            else "a torque-free arc shows no scale"
        )
        lines.append(
            f"only the inertia ratios are observable ({why}): the moments are in units of I1, "
            "and the angular momentum in units of I1 rad/s"
        )
    if L.attitude:
        lines.append("the attitude at t0 is observable (attitude fixes)")
    else:
        lines.append(
            "the attitude is not observable from rates alone: the solver's attitude at t0 is "
            "the identity, and predictions are relative to it"
        )
    if L.axes:
        σ = [σ_y[index[f"axes_{a}"]] for a in "xyz"]
        if max(σ) > AXES_LIMIT_RAD:
            raise FitRefused(
                f"the principal axes are not determined (1σ up to {math.degrees(max(σ)):.3g} "
                f"deg, refused beyond {math.degrees(AXES_LIMIT_RAD):.0f} deg): a nearly "
                "symmetric body leaves them free about its symmetry axis; fit without them",
                key="principal_axes",
                file=source,
            )
        lines.append(
            f"principal axes observable in the sensor frame to {math.degrees(max(σ)):.3g} deg"
        )
    return lines, absolute
