"""The shared base: errors, signals, progress messages, units, quaternions and vectors,
float helpers, the compile policy and double-double arithmetic. It imports no other
layer.

Modules:

- ``double_double``: Double-double arithmetic on floats, compiled (numba): a float plus
  its rounding error.
- ``errors``: Exception classes of the package.
- ``float_math``: numpy's elementwise functions, on Python floats: the namespace of a
  single state's path.
- ``hermite``: Cubic Hermite interpolation on equally spaced nodes, without
  scipy.interpolate.
- ``jets``: Taylor jets: a quantity with its first time derivatives, carried through
  arithmetic.
- ``jit``: How the package compiles its kernels: ``jit``, numba's ``njit`` with one
  policy.
- ``progress``: Stage messages for a user who waits: what is being done, and since
  when.
- ``quantities``: Numbers at the public edge: astropy Quantities to SI floats, and their
  checks.
- ``quaternions``: Hamilton quaternion algebra, scalar first, vectorized.
- ``signals``: How a run stops on a signal, and the dispositions a caller set, which
  the run keeps.
- ``vectors``: Two small vector helpers: the angle between vectors, and a basis across a
  unit vector.
- ``version``: The package version (read by pyproject.toml and written into every
  output).
"""
