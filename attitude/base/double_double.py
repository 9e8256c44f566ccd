"""Double-double arithmetic on floats, compiled (numba): a float plus its rounding error.

The building blocks of attitude.solver.invariants for one float at a time
(attitude.solver.compiled_flow's
case test, attitude.elliptic.compiled's K): Knuth's and Dekker's error-free sums and
products (Dekker, "A floating-point technique for extending the available precision",
Numer. Math. 18, 1971) and the double-word operations of Joldes, Muller and Popescu,
"Tight and rigorous error bounds for basic building blocks of double-word arithmetic",
ACM Trans. Math. Softw. 44(2), 2017, doi:10.1145/3121432 (Algorithms 6, 7 and 10; the
relative error bounds that attitude.solver.invariants uses are theirs).  A double-double is a
pair (hi, lo) of floats.  Compiled by ``attitude.base.jit.jit``, without fast-math, so
that no product and sum are fused into one rounding (Dekker's product relies on each).
"""

from __future__ import annotations

from attitude.base.jit import jit

__all__ = [
    "dd_over_dd",
    "dd_plus_dd",
    "dd_times_dd",
    "dd_times_float",
    "fast_two_sum",
    "split",
    "two_prod",
    "two_sum",
]


@jit
def two_sum(a: float, b: float) -> tuple[float, float]:
    """s + e = a + b exactly (Knuth)."""
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


@jit
def fast_two_sum(a: float, b: float) -> tuple[float, float]:
    """s + e = a + b exactly, for |a| ≥ |b| (Dekker)."""
    s = a + b
    return s, b - (s - a)


@jit
def split(a: float) -> tuple[float, float]:
    """a = hi + lo with 26-bit halves (Veltkamp; |a| < 2^995)."""
    c = 134217729.0 * a  # 2^27 + 1
    hi = c - (c - a)
    return hi, a - hi


@jit
def two_prod(a: float, b: float) -> tuple[float, float]:
    """p + e = a b exactly (Dekker), barring underflow."""
    p = a * b
    ah, al = split(a)
    bh, bl = split(b)
    return p, ((ah * bh - p) + ah * bl + al * bh) + al * bl


@jit
def dd_times_dd(x0: float, x1: float, y0: float, y1: float) -> tuple[float, float]:
    """(x0 + x1)(y0 + y1)."""
    p, e = two_prod(x0, y0)
    return fast_two_sum(p, e + (x0 * y1 + x1 * y0))


@jit
def dd_times_float(x0: float, x1: float, b: float) -> tuple[float, float]:
    """(x0 + x1) b."""
    p, e = two_prod(x0, b)
    return fast_two_sum(p, e + x1 * b)


@jit
def dd_plus_dd(x0: float, x1: float, y0: float, y1: float) -> tuple[float, float]:
    """(x0 + x1) + (y0 + y1)."""
    s, e = two_sum(x0, y0)
    t, f = two_sum(x1, y1)
    s, e = fast_two_sum(s, e + t)
    return fast_two_sum(s, e + f)


@jit
def dd_over_dd(x0: float, x1: float, y0: float, y1: float) -> tuple[float, float]:
    """(x0 + x1)/(y0 + y1)."""
    q = x0 / y0
    p0, p1 = dd_times_float(y0, y1, q)
    r0, _ = dd_plus_dd(x0, x1, -p0, -p1)
    return fast_two_sum(q, r0 / y0)
