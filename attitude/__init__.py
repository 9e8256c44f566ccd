"""attitude: exact spacecraft attitude.

The layers, each importing only the ones above it in this list:

- ``attitude.elliptic``: Jacobi functions and elliptic integrals in mc = 1 − m
- ``attitude.euler_solver``: ``EulerSolver``, the closed-form torque-free rigid body

Conventions: SI units (s, kg m², N m s, rad/s; astropy Quantities accepted at the
public edge); an attitude is the ``scipy.spatial.transform.Rotation`` taking body
coordinates to inertial (ICRF/GCRS) coordinates; quaternions shown to a user are
scalar first and say so.
"""

from attitude.errors import AttitudeError, InputError
from attitude.euler_solver import EulerSolver
from attitude.version import __version__

__all__ = ["AttitudeError", "EulerSolver", "InputError", "__version__"]
