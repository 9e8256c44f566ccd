"""Attitude laws: the attitude as a function of time, from the orbit, the Sun, the Moon
and the Earth's rotation, with its angular velocity and acceleration.

Every named law is a case of align-and-constrain (a primary body vector on a primary
direction, a secondary body vector as close as possible to a secondary direction);
docs/laws.md defines each, with its conventions and accuracy.

Modules:

- ``align_constrain``: The general law (two vectors), its analytic rates, its
  degenerate cases; what every law is and gives (``AttitudeLaw``, ``BoundLaw``,
  ``LawState``).
- ``directions``: The directions a body vector can follow: the Sun, the Moon, nadir,
  the Earth's centre, the velocity, the orbit normal, the ground velocity, ground
  sites, celestial targets, fixed directions.
- ``inputs``: What a law reads at given epochs (the orbit, the apparent Sun and Moon,
  the Earth's rotation), with derivatives.
- ``named_laws``: The named laws as cases of align-and-constrain: inertial, orbit
  frame, nadir (with yaw steering), Sun, target.
- ``orbit_derivatives``: The orbit's position and velocity with their derivatives:
  analytic, or by finite differences of stated accuracy.
- ``slews``: Slews between a state and a law: eigen-axis, bang–coast–bang, within a
  maximum rate and acceleration, from the start rate to the law's.
- ``visibility``: When a ground site sees the spacecraft: elevation, and the intervals
  above a minimum elevation.
"""
