"""The closed-form 3x3 and affine 4x4 inverses the draw path uses instead
of np.linalg (core/view.py): the same matrices as LAPACK's, to rounding."""

import numpy as np
import pytest

from solidwire_addon.core.draw import normal_to_view
from solidwire_addon.core.view import affine_inverse, determinant3, inverse_transpose3


def _random_linear(rng, count):
    """Rotations times non-uniform scales (some negative: mirrored) times
    a shear: the object matrices a scene has."""
    q, _ = np.linalg.qr(rng.normal(size=(count, 3, 3)))
    scale = rng.uniform(0.01, 100.0, (count, 1, 3)) * rng.choice([-1.0, 1.0], (count, 1, 3))
    shear = np.eye(3) + np.triu(rng.normal(scale=0.5, size=(count, 3, 3)), 1)
    return q * scale @ shear


def test_inverse_transposes_and_determinants_are_lapacks():
    linear = _random_linear(np.random.default_rng(3), 500)
    inverse_t, det = inverse_transpose3(linear)
    assert np.allclose(det, np.linalg.det(linear), rtol=1e-12, atol=0.0)
    expected = np.swapaxes(np.linalg.inv(linear), -1, -2)
    assert np.allclose(inverse_t, expected, rtol=1e-9, atol=1e-12 * np.abs(expected).max())
    assert np.array_equal(determinant3(linear), det)
    # One matrix, not a batch: the same values.
    single_t, single_det = inverse_transpose3(linear[7])
    assert np.array_equal(single_t, inverse_t[7]) and single_det == det[7]
    # The signs say which matrices mirror.
    assert np.array_equal(det < 0.0, np.linalg.det(linear) < 0.0)


def test_a_singular_matrix_has_no_normal_matrix():
    linear = _random_linear(np.random.default_rng(4), 4)
    linear[1, :, 2] = 0.0  # flattened along one axis
    linear[2] = 0.0
    matrices = np.zeros((4, 4, 4))
    matrices[:, :3, :3], matrices[:, 3, 3] = linear, 1.0
    normals = normal_to_view(matrices)
    assert np.isfinite(normals).all()
    assert not normals[1].any() and not normals[2].any()
    assert np.allclose(normals[0, :3, :3], np.linalg.inv(linear[0]).T)


def test_affine_inverse_is_lapacks_and_refuses_what_lapack_refuses():
    rng = np.random.default_rng(5)
    for linear in _random_linear(rng, 50):
        matrix = np.eye(4)
        matrix[:3, :3], matrix[:3, 3] = linear, rng.uniform(-1e3, 1e3, 3)
        assert np.allclose(affine_inverse(matrix) @ matrix, np.eye(4), atol=1e-9)
        assert np.allclose(affine_inverse(matrix), np.linalg.inv(matrix), rtol=1e-9, atol=1e-12)
    projective = np.eye(4)
    projective[3] = (0.0, 0.0, -1.0, 0.0)
    projective[2, 3] = -0.2
    assert np.allclose(affine_inverse(projective), np.linalg.inv(projective))
    singular = np.eye(4)
    singular[2, 2] = 0.0
    with pytest.raises(np.linalg.LinAlgError):
        affine_inverse(singular)
