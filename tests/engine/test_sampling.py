import numpy as np
import pytest

from fluidymation.engine.sampling import sample_back, sample_patch
from tests.naive import naive_bilinear, naive_rotate


@pytest.mark.parametrize("theta", [0.0, 0.4, np.pi / 2, -2.5])
@pytest.mark.parametrize("centre", [(4.0, 5.0), (1.3, 0.2), (8.7, 7.9)])
def test_rotated_patch_matches_naive_bilinear(theta, centre):
    rng = np.random.default_rng(1)
    source = rng.random((2, 9, 10, 3)).astype(np.float32)
    patch = sample_patch(source, 1, *centre, theta, patch_size=5)
    assert patch.shape == (5, 5, 3) and patch.dtype == np.float32
    for dy in range(-2, 3):
        for dx in range(-2, 3):
            ox, oy = naive_rotate(theta, dx, dy)
            expected = naive_bilinear(source[1], centre[0] + ox, centre[1] + oy)
            np.testing.assert_allclose(patch[dy + 2, dx + 2], expected, atol=2e-5)


def test_unrotated_integer_patch_is_a_crop():
    source = np.arange(2 * 8 * 8, dtype=np.float32).reshape(1, 8, 16, 1)
    patch = sample_patch(source, 0, 6, 4, 0.0, patch_size=3)
    np.testing.assert_array_equal(patch[..., 0], source[0, 3:6, 5:8, 0])


def test_sample_back_reads_where_the_material_came_from():
    values = np.arange(30, dtype=np.float64).reshape(5, 6)
    flow = np.zeros((5, 6, 2))
    flow[..., 0] = 2.0  # everything moved two pixels right
    np.testing.assert_array_equal(sample_back(values, flow)[:, 2:], values[:, :-2])
    np.testing.assert_array_equal(sample_back(values, flow)[:, :2], values[:, :1].repeat(2, axis=1))  # edge repeated
    flow[..., 0] = 0.5
    np.testing.assert_allclose(sample_back(values[..., None], flow)[:, 1:, 0], values[:, :-1] + 0.5)
    np.testing.assert_array_equal(sample_back(values, flow + 0.1, order=0)[:, 1:], values[:, :-1])
