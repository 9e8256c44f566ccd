"""Elliptic kernels: Jacobi elliptic functions and elliptic integrals in mc = 1 − m (numpy
and compiled), and the phase table.

Modules:

- ``compiled``: Compiled (numba) elliptic kernels for one parameter and one argument at
  a time.
- ``functions``: Jacobi elliptic functions and elliptic integrals, parametrized by mc =
  1 − m.
- ``phase_table``: A smooth function of the phase, tabulated once: piecewise Chebyshev
  interpolation.
"""
