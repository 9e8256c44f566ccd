"""The exact hand-off: from a law's state at a control loss to the free motion after it.

When control is lost at τ, the law stops holding the attitude.  The body then moves
from the law's attitude R_law(τ), with its rigid momentum I·ω_law(τ) (ω_law the law's
analytic rate, :mod:`attitude.laws.align_constrain`), plus the momentum h the reaction
wheels hold (body axes, N m s).  The spacecraft's total angular momentum in body axes
is therefore

    M(τ) = I ω_law(τ) + h,

and what follows depends on the wheels (:class:`attitude.scenario.modes.Wheels`):

- ``locked`` (or no wheels): the wheels stop relative to the body and their momentum
  passes to it; the body is a torque-free rigid body of momentum M, moving exactly
  (:class:`~attitude.solver.euler_solver.EulerSolver`, the closed form);
- ``spinning``: the wheels keep their speed relative to the body; the body is a
  gyrostat with internal momentum h, its rate ω = I⁻¹(M − h) equal to ω_law(τ) at τ (no
  jump of the rate), propagated by the splitting with the exact gyroscopic flow
  (:mod:`attitude.torques.gyrostat`, :class:`~attitude.torques.solver.TorquedSolver`);
- under external torques (gravity gradient, burns), either case goes through
  :class:`~attitude.torques.solver.TorquedSolver`.

:func:`hand_off` makes that motion from one state; :func:`hand_off_states` gives the
initial states for many failure instants at once (one law evaluation for all), for a
batch (``propagate_batch`` with ``wheel_momentum``, or an exact solver per state).
``tests/test_handoff_against_dop853.py`` checks both wheel cases against DOP853 of
Euler's and the gyrostat's equations started from the law's state.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from attitude.base.errors import InputError
from attitude.base.quantities import as_vector3
from attitude.laws.align_constrain import BoundLaw, LawState
from attitude.scenario.modes import Wheels
from attitude.solver.euler_solver import EulerSolver
from attitude.solver.inertia import PrincipalAxes, principal_axes
from attitude.torques.solver import TorquedSolver

__all__ = ["hand_off", "hand_off_at", "hand_off_states"]


def _tensor(inertia: Any) -> NDArray[np.float64]:
    if isinstance(inertia, PrincipalAxes):
        return inertia.tensor
    return principal_axes(inertia).tensor


def hand_off(
    attitude: Rotation,
    angular_velocity: ArrayLike,
    inertia: Any,
    t0: float = 0.0,
    wheels: Wheels | None = None,
    torques: Sequence[Any] = (),
    *,
    step: float | None = None,
    accuracy: float | None = None,
    span: float | None = None,
    order: int | None = None,
) -> EulerSolver | TorquedSolver:
    """The motion from a control loss at ``t0`` (s): ``attitude`` (body → ICRF) and
    ``angular_velocity`` (body axes, rad/s) are the law's state there; ``inertia``: 3
    principal moments, a 3×3 tensor (body axes, kg m²) or a ``PrincipalAxes``;
    ``wheels``: :class:`~attitude.scenario.modes.Wheels` (None: no stored momentum;
    a momentum no wheel holds, |I⁻¹h| > 100 rad/s, is refused as in a scenario).

    Returns the exact :class:`EulerSolver` for locked wheels without torques, else a
    :class:`TorquedSolver` (spinning wheels: a gyrostat; ``torques``: torque models of
    :mod:`attitude.torques.models`), with ``step`` or ``accuracy`` and ``span``
    (default: ``TorquedSolver``'s step) and ``order``.  Both give ``attitude(t)``,
    ``angular_velocity(t)`` (body, rad/s) and ``angular_momentum(t)`` (the total M, body
    axes) for t ≥ t0.
    """
    tensor = _tensor(inertia)
    ω = as_vector3(angular_velocity, "angular_velocity", "angular_velocity")
    if wheels is not None:  # the refusal a scenario's control_loss gets
        wheels.check_against(tensor)
    h = np.zeros(3) if wheels is None else wheels.momentum_vector
    M = tensor @ ω + h
    spinning = wheels is not None and wheels.case == "spinning"
    if not spinning and not torques:
        return EulerSolver(tensor, M, attitude, t0=t0)
    options: dict[str, Any] = {"order": order}
    if accuracy is not None:
        options.update(accuracy=accuracy, span=span)
    elif step is not None:
        options["step"] = step
    return TorquedSolver(
        tensor,
        M,
        attitude,
        t0,
        list(torques),
        wheel_momentum=h if spinning else None,
        **options,
    )


def hand_off_at(
    bound: BoundLaw,
    t0: float,
    inertia: Any,
    wheels: Wheels | None = None,
    torques: Sequence[Any] = (),
    **options: Any,
) -> EulerSolver | TorquedSolver:
    """:func:`hand_off` from the bound law's state at ``t0`` (TT seconds after the
    law's epoch), for one failure instant."""
    state = bound.state([float(t0)])
    return hand_off(
        state.attitude[0], state.angular_velocity[0], inertia, t0, wheels, torques, **options
    )


def hand_off_states(
    state: LawState, inertia: Any, wheels: Wheels | None = None
) -> tuple[Rotation, NDArray[np.float64]]:
    """The initial states of the free motion after a control loss at each epoch of
    ``state`` (a law's :class:`LawState`, any number of epochs): the attitudes (a stack,
    body → ICRF) and the total momenta M = I ω_law + h (n, 3), body axes.  With spinning
    wheels, ω = I⁻¹(M − h) equals ω_law: pass ``wheel_momentum=h`` to the propagation."""
    tensor = _tensor(inertia)
    ω = np.asarray(state.angular_velocity, dtype=np.float64)
    if ω.ndim != 2 or ω.shape[1] != 3:
        raise InputError(f"state.angular_velocity must be (n, 3), got {ω.shape}")
    if wheels is not None:
        wheels.check_against(tensor)
    h = np.zeros(3) if wheels is None else wheels.momentum_vector
    return state.attitude, ω @ tensor.T + h
