"""The scenario layer: the spacecraft, its initial state at an epoch, events, and the
torques a scenario models.

Modules:

- ``events``: Events that change the spacecraft's motion at an epoch.
- ``modes``: Mode events: a controlled spacecraft changes law, loses control, regains
  it (with the wheels' momentum at a control loss).
- ``scenario``: A scenario: spacecraft, initial state at an epoch, events, and the
  output span.
- ``spacecraft``: The spacecraft: a name and an inertia in its own body axes.
- ``torques``: The torques of a scenario: gravity gradient, finite burns, and how they
  are propagated.
"""
