"""The backends of the formula set, and the one rule that picks them.

attitude.solver.closed_form defines what is computed (each case's constants and
formulas, the frames, one state's attitude and the step of the flow); four modules
evaluate it, the way scipy's ``Rotation`` keeps its formulas in backends and selects
one per call (``scipy.spatial.transform._rotation.select_backend``):

=================  ==========================================  ===============================
backend            runs                                        takes / leaves
=================  ==========================================  ===============================
``float_backend``  the formulas on Python floats               every case, one state at a time
``numpy_backend``  the formulas on numpy arrays                every case, any mix
``table_backend``  numpy, ψ's periodic part from a table       one elliptic state with n ≠ 0
                                                               and mc ≥ 2^-128; leaves the rest
                                                               to the numpy backend
``numba_backend``  a compiled copy of the elliptic formulas    the flow of elliptic states
                                                               whose double-double case test is
                                                               certain, mc ≥ 2^-128, magnitudes
                                                               within 2^±60; leaves the others
=================  ==========================================  ===============================

Each module's docstring says which states it takes and which it leaves, and why it
exists.  The front ends (``EulerSolver``: one state, many times; ``free_flow``: many
states, one step each; ``EulerSolverBatch``: many states, many times) ask ``select``
which backend evaluates what they were asked, except for the numba backend, which a
flow tries first on every state (it says which it leaves only after its exact case
test): ``select`` then picks the backend of the states it left.

All backends give the same numbers to rounding: the numba and numpy flows agree to a
few ε per radian turned (tests/test_compiled_flow_against_numpy_flow.py), the float and
numpy paths to an ulp of the angle turned, and the table to the formula's rounding
(tests/test_fast_paths_against_the_general_ones.py,
tests/test_phase_table_against_mpmath.py).
"""

from __future__ import annotations

from types import ModuleType

from attitude.solver import float_backend, numpy_backend, table_backend
from attitude.solver.closed_form import CaseFormula

__all__ = ["SMALL_BATCH", "TABLE_MIN_SAMPLES", "select"]

# From this many times in one call, one state's attitude takes ψ's periodic part from
# a table built once instead of one R_J a sample.  The table's 1000 to 6000 formula
# evaluations pay for themselves within the call from ~6000 to ~8000 samples
# (benchmarks.solver_speed, section 4; docs/solver.md, "Speed").
TABLE_MIN_SAMPLES = 8192
# Below this many states at one time each, the float backend takes them one at a time:
# numpy's fixed cost (~1 ms for the few hundred calls of a batch) exceeds that of this
# many states on floats (~40 µs each).
SMALL_BATCH = 36


def select(states: int, times: int | None, formula: CaseFormula | None = None) -> ModuleType | None:
    """The backend that evaluates ``states`` states at ``times`` times each.

    ``times`` is None for one time per state given as a number (a scalar t, or each
    state's own step of a flow), else the length of the array of times; ``formula``
    is the state's, for one state.

    1. Scalar times, fewer than ``SMALL_BATCH`` states: the float backend, a state
       at a time.
    2. One state at ``TABLE_MIN_SAMPLES`` times or more, whose formula a table takes:
       the table backend.
    3. Several states at ``TABLE_MIN_SAMPLES`` times or more each: None, meaning each
       state alone, by these rules with its own formula (its table then pays).
    4. Everything else: the numpy backend.
    """
    if times is None:
        return float_backend if states < SMALL_BATCH else numpy_backend
    if times >= TABLE_MIN_SAMPLES:
        if states > 1:
            return None
        if formula is not None and table_backend.takes(formula):
            return table_backend
    return numpy_backend
