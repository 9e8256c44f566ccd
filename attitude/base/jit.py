"""How the package compiles its kernels: ``jit``, numba's ``njit`` with one policy, and
``inline``, which makes plain functions callable from the kernels.

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

Importing this module imports numba (~0.25 s): only compiled code imports it, so that
a process that compiles nothing does not pay for it.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Any

import numba
from numba.extending import register_jitable

__all__ = ["inline", "jit"]

_OPTIONS: dict[str, Any] = {"error_model": "numpy", "nogil": True}
_INLINED: set[Callable[..., Any]] = set()


def jit(function: Callable[..., Any]) -> Any:
    """``function`` compiled by numba with the policy of this module."""
    try:
        return numba.njit(cache=True, **_OPTIONS)(function)
    except RuntimeError:  # "cannot cache function ...: no locator available"
        return numba.njit(cache=False, **_OPTIONS)(function)


def inline(functions: Iterable[Callable[..., Any]]) -> None:
    """Let compiled kernels call these plain Python functions (arithmetic on floats).

    Each stays an ordinary function for Python callers (floats, numpy arrays) and is
    compiled, with this module's error model, into every kernel that calls it
    (numba's ``register_jitable``).  Registered once, whichever module asks first.
    """
    for function in functions:
        if function not in _INLINED:
            register_jitable(error_model=_OPTIONS["error_model"])(function)
            _INLINED.add(function)
