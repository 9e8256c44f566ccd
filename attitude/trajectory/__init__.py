"""The propagated motion of a scenario: its segments (exact or torqued), the validity
horizon, and what each segment's motion is.

Modules:

- ``horizon``: How long a scenario that neglects gravity gradient holds: its validity
  horizon.
- ``motion``: Flips, spin, precession and nutation of a trajectory, per segment, from
  the closed form.
- ``torqued``: A stretch of a scenario's motion under torques, seen as the layers above
  see a segment.
- ``trajectory``: The propagated motion of a scenario: exact solver segments between
  events.
"""
