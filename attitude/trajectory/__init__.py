"""The propagated motion of a scenario: its segments (exact, torqued, or guided by an
attitude law), the hand-off at a control loss, the validity horizon, and what each
segment's motion is.

Modules:

- ``averaged_kicks``: Gravity gradient as averaged kicks along the exact free flow: the
  validity horizon's long steps.
- ``guided``: A stretch of a scenario's motion under an attitude law or a slew, seen
  as the layers above see a segment.
- ``handoff``: The exact hand-off: from a law's state at a control loss to the free
  motion after it.
- ``horizon``: How long a scenario that neglects gravity gradient holds: its validity
  horizon.
- ``modes``: The segments of a scenario with attitude laws: guided, slewing, free,
  torqued.
- ``motion``: Flips, spin, precession and nutation of a trajectory, per segment, from
  the closed form.
- ``rates``: The largest body rate of a segment, found on its motion (not on an output
  grid).
- ``segments``: The segments of a scenario's motion, built one after another through
  its events, and where their motion is not smooth (breakpoints).
- ``steps``: The step of a scenario's torqued segments, and the run's error estimate.
- ``torqued``: A stretch of a scenario's motion under torques, seen as the layers above
  see a segment.
- ``trajectory``: The propagated motion of a scenario: exact solver segments between
  events.
"""
