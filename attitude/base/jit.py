"""How the package compiles its kernels: ``jit``, numba's ``njit`` with one policy.

- ``error_model="numpy"``: a division by zero gives an IEEE infinity or NaN, as in
  numpy, instead of raising (the kernels test their results for finiteness).
- No fast-math: every operation is the IEEE one written, none reordered or fused
  (the double-double arithmetic of attitude.base.double_double relies on each
  rounding).
- ``nogil=True``: threads (a Dask worker's, say) run kernels side by side.
- ``cache=True``: the machine code is kept beside the module (or in numba's user
  cache), so a process loads it instead of compiling (~0.3 s against ~3 s).  Where
  no cache location is writable (a read-only installation and home, for instance),
  numba refuses to cache at all; the kernel is then compiled in each process rather
  than failing the import.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numba

__all__ = ["jit"]

_OPTIONS: dict[str, Any] = {"error_model": "numpy", "nogil": True}


def jit(function: Callable[..., Any]) -> Any:
    """``function`` compiled by numba with the policy of this module."""
    try:
        return numba.njit(cache=True, **_OPTIONS)(function)
    except RuntimeError:  # "cannot cache function ...: no locator available"
        return numba.njit(cache=False, **_OPTIONS)(function)
