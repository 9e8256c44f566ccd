"""The spacecraft's inertia: moments or a full tensor, and what is refused or warned.

References: a tensor built from known principal moments and a known rotation
(I = C diag(moments) Cᵀ) must give those moments back, and principal axes that
carry the tensor to that diagonal form.
"""

import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from attitude import InputError
from attitude.base.errors import InertiaWarning
from attitude.scenario.spacecraft import Spacecraft


def test_a_rotated_tensor_gives_back_its_principal_moments_and_axes():
    moments = np.array([120.0, 250.0, 310.0])
    C = Rotation.from_rotvec([0.4, -1.1, 0.7])
    tensor = C.as_matrix() @ np.diag(moments) @ C.as_matrix().T
    craft = Spacecraft("sat", tensor)
    np.testing.assert_allclose(craft.principal_moments, moments, rtol=1e-14)
    V = craft.body_to_principal.as_matrix()  # x_principal = V x_body
    np.testing.assert_allclose(V @ tensor @ V.T, np.diag(moments), atol=1e-12)
    assert np.linalg.det(V) == pytest.approx(1.0)
    np.testing.assert_allclose(craft.inertia_tensor, tensor, rtol=1e-15)


def test_principal_moments_keep_their_axes():
    craft = Spacecraft("sat", [3.0, 1.0, 2.0])
    np.testing.assert_array_equal(craft.principal_moments, [3.0, 1.0, 2.0])
    np.testing.assert_array_equal(craft.inertia_tensor, np.diag([3.0, 1.0, 2.0]))
    assert craft.body_to_principal.magnitude() == 0.0


def test_a_body_that_cannot_exist_is_warned_about_not_refused():
    with pytest.warns(InertiaWarning, match=r"break the triangle inequality \(1 \+ 1 < 3\)"):
        craft = Spacecraft("impossible", [1.0, 1.0, 3.0])
    assert craft.principal_moments.tolist() == [1.0, 1.0, 3.0]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        Spacecraft("flat plate", [1.0, 2.0, 3.0])  # I1 + I2 = I3: a plate, allowed


@pytest.mark.parametrize(
    "inertia, message",
    [
        ([[1, 0, 0], [0.5, 2, 0], [0, 0, 3]], "tensor is not symmetric"),
        ([[1, 0, 0], [0, -2, 0], [0, 0, 3]], "tensor is not positive definite"),
        ([[2, 3, 0], [3, 2, 0], [0, 0, 3]], r"not positive definite \(eigenvalues \[-0\.99"),
        ([[1, 0, np.nan], [0, 2, 0], [np.nan, 0, 3]], "inertia must be finite, got nan"),
        ([1.0, 2.0, 3.0, 4.0], r"3 principal moments or a 3x3 tensor, got shape \(4,\)"),
    ],
)
def test_invalid_tensors_are_refused(inertia, message):
    with pytest.raises(InputError, match=message):
        Spacecraft("sat", inertia)


def test_a_name_is_required():
    with pytest.raises(InputError, match="spacecraft name must be a non-empty string"):
        Spacecraft("  ", [1.0, 2.0, 3.0])
