"""The exact torque-free solver: inertia, the exact case test, the closed-form motion of
each case, ``EulerSolver``, and the free-flow map (numpy and compiled).

Modules:

- ``closed_form``: The closed-form motion of a torque-free rigid body, one formula per
  case.
- ``compiled_flow``: The exact free flow of one state in compiled code (numba): the
  elliptic cases.
- ``euler_solver``: The exact motion of a torque-free rigid body from one state:
  ``EulerSolver``.
- ``free_flow``: The exact torque-free flow map: many states, each advanced by its own
  step.
- ``inertia``: Inertia of a rigid body: principal moments and axes from moments or a
  full tensor.
- ``invariants``: Δ1, Δ2, Δ3 and mc of float inputs: the exact case test, for one state
  or a batch.
- ``sensitivities``: Sensitivities of the exact torque-free motion: its Jacobian with
  respect to the initial attitude, the initial body momentum and the principal moments.
"""
