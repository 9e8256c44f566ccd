"""numpy's elementwise functions, on Python floats: the namespace of a single state's path.

The solver's formulas are written once, against the names of numpy's functions
(``xp.sqrt``, ``xp.arctan2``, ``xp.where``...), and run with ``xp = numpy`` on arrays (a
batch of states, or one state at many times) or with ``xp = FLOAT`` on Python floats (one
state, one time).  Why two: a numpy call costs 0.3 to 2 µs whatever the size of its
arrays, 10 to 100 times the arithmetic of one state, while ``math`` on a float costs
about 30 ns.  ``FLOAT`` gives IEEE results where ``math`` would raise: ``exp`` overflows
to inf, ``log(0)`` is −inf.  Division by zero still raises on floats, so the shared
formulas never divide by a quantity that can vanish.
"""

from __future__ import annotations

import math

__all__ = ["FLOAT"]


def _exp(x: float) -> float:
    try:
        return math.exp(x)
    except OverflowError:
        return math.inf


def _log(x: float) -> float:
    return math.log(x) if x > 0.0 else (-math.inf if x == 0.0 else math.nan)


def _where(condition: bool, a: float, b: float) -> float:
    return a if condition else b


def _rint(x: float) -> float:
    return float(round(x))  # half to even, as numpy.rint


class _FloatMath:
    """The subset of numpy's namespace that the solver's formulas use, on floats."""

    sqrt = staticmethod(math.sqrt)
    exp = staticmethod(_exp)
    log = staticmethod(_log)
    tan = staticmethod(math.tan)
    tanh = staticmethod(math.tanh)
    arctan = staticmethod(math.atan)
    arctan2 = staticmethod(math.atan2)
    arcsinh = staticmethod(math.asinh)
    hypot = staticmethod(math.hypot)
    copysign = staticmethod(math.copysign)
    abs = staticmethod(abs)
    rint = staticmethod(_rint)
    where = staticmethod(_where)
    minimum = staticmethod(min)
    pi = math.pi
    inf = math.inf


FLOAT = _FloatMath()
