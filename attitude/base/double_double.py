"""Double-double arithmetic: a float plus its rounding error, on floats, arrays or compiled.

The one implementation of the package's error-free transformations and double-word
operations, used by the exact case test of attitude.solver.invariants (numpy arrays of
a batch), by the numba backend's case test (attitude.solver.numba_backend) and by the
compiled K of attitude.elliptic.compiled.  Each function is arithmetic operators only,
so that it runs unchanged on Python floats, elementwise on numpy arrays, and inside a
compiled kernel: ``attitude.base.jit.inline`` registers these functions with numba
(``register_jitable``), where each is compiled into the kernel that calls it.  This
module itself imports nothing, so that numpy code and float code need no numba.

Knuth's and Dekker's error-free sums and products (T. J. Dekker, "A floating-point
technique for extending the available precision", Numer. Math. 18, 1971) and the
double-word operations of Joldes, Muller and Popescu, "Tight and rigorous error bounds
for basic building blocks of double-word arithmetic", ACM Trans. Math. Softw. 44(2),
2017, doi:10.1145/3121432 (Algorithms 6, 7 and 10; the relative error bounds that
attitude.solver.invariants uses are theirs).  A double-double is a pair (hi, lo) of
floats, passed as two arguments.  No operation may be reordered or fused into one
rounding (Dekker's product relies on each): numpy does neither, and the compile
policy of attitude.base.jit excludes fast-math.

The ``*_presplit`` forms take an operand with its Veltkamp halves computed beforehand
(``split``): the same operations in the same order, so the same bits, for an operand
that many products share (the moments of a batch).
"""

from __future__ import annotations

from typing import Any

__all__ = [
    "FUNCTIONS",
    "dd_over_dd",
    "dd_plus_dd",
    "dd_times_dd",
    "dd_times_dd_presplit",
    "dd_times_float",
    "dd_times_float_presplit",
    "fast_two_sum",
    "split",
    "two_prod",
    "two_prod_presplit",
    "two_sum",
]


def two_sum(a: Any, b: Any) -> tuple[Any, Any]:
    """s + e = a + b exactly (Knuth)."""
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


def fast_two_sum(a: Any, b: Any) -> tuple[Any, Any]:
    """s + e = a + b exactly, for |a| ≥ |b| (Dekker)."""
    s = a + b
    return s, b - (s - a)


def split(a: Any) -> tuple[Any, Any]:
    """a = hi + lo with 26-bit halves (Veltkamp; |a| < 2^995)."""
    c = 134217729.0 * a  # 2^27 + 1
    hi = c - (c - a)
    return hi, a - hi


def two_prod_presplit(a: Any, b: Any, b_hi: Any, b_lo: Any) -> tuple[Any, Any]:
    """p + e = a b exactly (Dekker), barring underflow, with b's halves given."""
    p = a * b
    a_hi, a_lo = split(a)
    return p, ((a_hi * b_hi - p) + a_hi * b_lo + a_lo * b_hi) + a_lo * b_lo


def two_prod(a: Any, b: Any) -> tuple[Any, Any]:
    """p + e = a b exactly (Dekker), barring underflow."""
    b_hi, b_lo = split(b)
    return two_prod_presplit(a, b, b_hi, b_lo)


def dd_times_float_presplit(x0: Any, x1: Any, b: Any, b_hi: Any, b_lo: Any) -> tuple[Any, Any]:
    """(x0 + x1) b, with b's halves given."""
    p, e = two_prod_presplit(x0, b, b_hi, b_lo)
    return fast_two_sum(p, e + x1 * b)


def dd_times_float(x0: Any, x1: Any, b: Any) -> tuple[Any, Any]:
    """(x0 + x1) b."""
    p, e = two_prod(x0, b)
    return fast_two_sum(p, e + x1 * b)


def dd_times_dd_presplit(
    x0: Any, x1: Any, y0: Any, y1: Any, y0_hi: Any, y0_lo: Any
) -> tuple[Any, Any]:
    """(x0 + x1)(y0 + y1), with y0's halves given."""
    p, e = two_prod_presplit(x0, y0, y0_hi, y0_lo)
    return fast_two_sum(p, e + (x0 * y1 + x1 * y0))


def dd_times_dd(x0: Any, x1: Any, y0: Any, y1: Any) -> tuple[Any, Any]:
    """(x0 + x1)(y0 + y1)."""
    p, e = two_prod(x0, y0)
    return fast_two_sum(p, e + (x0 * y1 + x1 * y0))


def dd_plus_dd(x0: Any, x1: Any, y0: Any, y1: Any) -> tuple[Any, Any]:
    """(x0 + x1) + (y0 + y1)."""
    s, e = two_sum(x0, y0)
    t, f = two_sum(x1, y1)
    s, e = fast_two_sum(s, e + t)
    return fast_two_sum(s, e + f)


def dd_over_dd(x0: Any, x1: Any, y0: Any, y1: Any) -> tuple[Any, Any]:
    """(x0 + x1)/(y0 + y1)."""
    q = x0 / y0
    p0, p1 = dd_times_float(y0, y1, q)
    r0, _ = dd_plus_dd(x0, x1, -p0, -p1)
    return fast_two_sum(q, r0 / y0)


# Every function of this module, for attitude.base.jit.inline (callees first).
FUNCTIONS = (
    two_sum,
    fast_two_sum,
    split,
    two_prod_presplit,
    two_prod,
    dd_times_float_presplit,
    dd_times_float,
    dd_times_dd_presplit,
    dd_times_dd,
    dd_plus_dd,
    dd_over_dd,
)
