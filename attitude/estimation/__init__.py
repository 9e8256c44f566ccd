"""Estimation: the spin state and inertia ratios fitted to telemetry on the exact motion.

Modules:

- ``fit``: ``fit_spin_state``: the inertia ratios and spin state that best explain
  telemetry.
- ``linear_guess``: The first guess, without any search: Euler's equations are linear
  in the moments.
- ``model``: The motion the fit adjusts: its parameters, and the predicted rates and
  attitudes with their Jacobian.
- ``solve``: Least squares on the exact motion: robust, over a growing arc, from
  several starts, and never stopping in a local minimum.
- ``statistics``: What a converged fit says about itself: the covariance, the goodness
  of fit, and whether the residuals look like the noise they should be.
- ``telemetry``: Telemetry as the fit takes it: gyro rates and attitude quaternions at
  their times, checked, sorted and cleaned, with a model-free estimate of each sensor's
  noise.
"""
