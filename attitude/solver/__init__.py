"""The exact torque-free solver: the formula set, its backends, and the front ends that
use them (``EulerSolver``, ``EulerSolverBatch``, the free-flow map).

Modules:

- ``backends``: The backends of the formula set, and the one rule that picks them.
- ``batch``: Many states at many times: ``EulerSolverBatch``, N torque-free rigid
  bodies at once.
- ``closed_form``: The formula set: the closed-form motion of a torque-free rigid body,
  one formula per case, its frames, one state's attitude and a step of the flow.
- ``euler_solver``: The exact motion of a torque-free rigid body from one state:
  ``EulerSolver``.
- ``float_backend``: The formula set on Python floats: one state at one time.
- ``free_flow``: The exact torque-free flow map: many states, each advanced by its own
  step.
- ``inertia``: Inertia of a rigid body: principal moments and axes from moments or a
  full tensor.
- ``invariants``: Δ1, Δ2, Δ3 and mc of float inputs: the exact case test, for one state
  or a batch.
- ``numba_backend``: The free flow of the elliptic cases compiled (numba), one state at
  a time.
- ``numpy_backend``: The formula set on numpy arrays: one state at many times, many
  states.
- ``sensitivities``: Sensitivities of the exact torque-free motion: its Jacobian with
  respect to the initial attitude, the initial body momentum and the principal moments.
- ``table_backend``: The numpy backend with ψ's periodic part from a table built once.
"""
