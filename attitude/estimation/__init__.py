"""Estimation: the spin state and inertia ratios fitted to telemetry on the exact motion.

Modules:

- ``burns``: Known burns in the fitted motion: constant torques over intervals, crossed
  by integrating the motion together with its sensitivities.
- ``fit``: ``fit_spin_state``: the inertia ratios and spin state that best explain
  telemetry.
- ``global_start``: A global start for sparse fixes: the inertia ratios and the phase
  searched from the fixes themselves, and every family of solutions that fits reported.
- ``linear_guess``: The first guess, without any search: Euler's equations are linear
  in the moments.
- ``model``: The motion the fit adjusts: its parameters, and the predicted rates and
  attitudes with their Jacobian.
- ``report``: The outputs of ``attitude fit``: the fitted scenario, the parameter table,
  the residuals, the uncertainty growth and a page, written through the output
  folder's rules.
- ``scenario_model``: The fitted motion under gravity gradient on a given orbit (with
  the scenario's burns and known impulses), through the splitting of ``TorquedSolver``.
- ``solve``: Least squares on the exact motion: robust, over a growing arc, from
  several starts, and never stopping in a local minimum.
- ``statistics``: What a converged fit says about itself: the covariance, the goodness
  of fit, and whether the residuals look like the noise they should be.
- ``telemetry``: Telemetry as the fit takes it: gyro rates and attitude quaternions at
  their times, checked, sorted and cleaned, with a model-free estimate of each sensor's
  noise.
- ``telemetry_files``: Telemetry files for ``attitude fit``: CSV, Parquet and CCSDS AEM,
  read into times, body rates and attitude quaternions, with every problem named by
  file, column, row and value.
"""
