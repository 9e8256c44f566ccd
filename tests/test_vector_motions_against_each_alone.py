"""The motion bounds of many torque-free segments found together
(``free_search.vector_motions``: their samples put end to end, each with its own
solver's constants, each maximum over its own samples) against each found alone
(``vector_motion``): the same bounds and the same tilt samples, bit for bit.

The segments mix a slow tumbler over a window shorter than its period, a fast spinner
whose period the window holds (periodic samples), a body with an inertia tensor that
is not diagonal, and a body at rest (no momentum): each takes its own branch.
"""

import numpy as np
from scipy.spatial.transform import Rotation

from attitude.pointing.free_search import vector_motion, vector_motions
from attitude.solver.euler_solver import EulerSolver

VECTORS = [
    ("camera", np.array([0.0, 0.0, 1.0])),
    ("tracker", np.array([0.0, -0.6427876096865393, -0.766044443118978])),
    ("panel", np.array([0.0, 0.0, -1.0])),
]


def _solvers():
    tilted = Rotation.from_euler("xyz", [0.3, -0.2, 0.7])
    tensor = tilted.as_matrix() @ np.diag([820.0, 1040.0, 610.0]) @ tilted.as_matrix().T
    return [
        (EulerSolver([820.0, 1040.0, 610.0], [0.3, 2.1, -0.4], tilted, 100.0), (100.0, 3700.0)),
        (EulerSolver([820.0, 1040.0, 610.0], [80.0, 5.0, 30.0], None, 0.0), (50.0, 650.0)),
        (EulerSolver(tensor, [1.0, -3.0, 0.5], None, 10.0), (10.0, 1810.0)),
        (EulerSolver([820.0, 1040.0, 610.0], [0.0, 0.0, 0.0], None, 0.0), (0.0, 3600.0)),
    ]


def test_vector_motions_against_vector_motion_alone():
    cases = _solvers()
    together = vector_motions([s for s, _ in cases], VECTORS, [span for _, span in cases])
    periodic = []
    for (solver, (a, b)), found in zip(cases, together, strict=True):
        alone = vector_motion(solver, VECTORS, a, b)
        assert list(found) == list(alone)
        for name in alone:
            x, y = found[name], alone[name]
            assert (x.rate, x.bend, x.tilt_start_s, x.tilt_spacing_s) == (
                y.rate,
                y.bend,
                y.tilt_start_s,
                y.tilt_spacing_s,
            )
            assert (x.tilt_periodic, x.tilt_slack) == (y.tilt_periodic, y.tilt_slack)
            if y.tilt_values is None:
                assert x.tilt_values is None
            else:
                assert np.array_equal(x.tilt_values, y.tilt_values)
            periodic.append(y.tilt_periodic)
    # Both branches of the samples (a period, the window) are exercised.
    assert any(periodic) and not all(periodic)
