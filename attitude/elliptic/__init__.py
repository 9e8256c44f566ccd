"""Elliptic kernels: Jacobi elliptic functions and elliptic integrals in mc = 1 − m, for the
solver's backends (numpy arrays and Python floats, compiled), and the phase table.

Modules:

- ``compiled``: Compiled (numba) elliptic kernels for one parameter and one argument at
  a time: the numba backend's.
- ``functions``: Jacobi elliptic functions and elliptic integrals, parametrized by mc =
  1 − m: the numpy and float backends'.
- ``phase_table``: A smooth function of the phase, tabulated once: piecewise Chebyshev
  interpolation (the table backend's).
"""
