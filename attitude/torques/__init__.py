"""Torques and splitting: torque models, the splitting compositions and ``TorquedSolver``,
the torques applied between exact free flows.

Modules:

- ``compiled_steps``: The splitting loop compiled, for one spacecraft under gravity
  gradient alone.
- ``gyrostat``: Wheels spinning at constant speed relative to the body: the
  gyrostat's gyroscopic term as an exact flow of the splitting.
- ``models``: External torques on a rigid spacecraft: gravity gradient, constant
  torques, user torques.
- ``solver``: Attitude under external torques: splitting with the exact free flow
  (``TorquedSolver``).
- ``splitting``: Splitting compositions: the coefficients that join the free flow and
  the torque kick.
"""
