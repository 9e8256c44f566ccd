"""Pointing: where the Sun, the Moon and the Earth fall on the body vectors, sampled at any
times or searched over a span on the exact motion; intervals, extrema and eclipses.

Modules:

- ``eclipse``: Earth's shadow: the conical umbra/penumbra model, and eclipse intervals
  of an orbit.
- ``extrema``: The least (or greatest) value of a function over a span, found on the
  function itself.
- ``free_search``: The pointing search on a torque-free segment: values at nodes,
  rigorous bounds between them, and refinement only where something can happen.
- ``intervals``: Intervals where a condition holds, with their ends refined on the exact
  solution.
- ``sampling``: Pointing samples: everything the time series needs, at any times.
- ``search``: The pointing's search: every interval and extremum over a span, on the
  exact motion.
- ``shared_surroundings``: The surroundings of a span, computed once and shared: the
  orbit, the Sun, the Moon and the Earth's shadow, interpolated with a stated bound.
- ``spec``: What a scenario asks of the pointing: body vectors, their constraints, the
  orbit.
- ``surroundings``: The Sun, the Moon and the Earth seen from the spacecraft, at any
  times of a span.
"""
