import numpy as np
import pytest

from fluidymation.engine.pyramid import downsample, downsample_angles, gaussian_pyramid, level_shape, levels_that_fit
from tests.naive import naive_downsample


@pytest.mark.parametrize("shape", [(7, 9, 2), (8, 6, 1), (1, 5, 3)])
def test_downsample_matches_naive(shape):
    image = np.random.default_rng(0).random(shape).astype(np.float32)
    np.testing.assert_allclose(downsample(image), naive_downsample(image), atol=1e-6)


def test_sequence_and_plain_images_agree():
    frames = np.random.default_rng(1).random((3, 10, 11, 2)).astype(np.float32)
    small = downsample(frames)
    assert small.shape == (3, 5, 6, 2)
    np.testing.assert_allclose(small[2], downsample(frames[2]), atol=0)
    np.testing.assert_allclose(downsample(frames[0, :, :, 0]), small[0, :, :, 0], atol=0)


def test_constant_image_stays_constant_and_shapes_halve():
    pyramid = gaussian_pyramid(np.full((21, 40, 3), 0.25, np.float32), 4)
    assert [p.shape[:2] for p in pyramid] == [(21, 40), (11, 20), (6, 10), (3, 5)]
    assert [level_shape(21, 40, k) for k in range(4)] == [p.shape[:2] for p in pyramid]
    np.testing.assert_allclose(pyramid[-1], 0.25, atol=1e-6)


def test_angles_average_as_directions():
    angles = np.full((4, 4), np.pi - 0.01, np.float32)
    angles[::2] = -np.pi + 0.01  # the same direction across the ±π seam
    small = downsample_angles(angles)
    assert np.all(np.abs(np.abs(small) - np.pi) < 0.02)


def test_levels_keep_the_coarsest_side_at_least_two_patches_wide():
    assert levels_that_fit([(912, 1200), (912, 1200)], patch_size=5) == 7  # 912 → … → 15 ≥ 11
    assert levels_that_fit([(10, 10)], patch_size=5) == 1
    assert levels_that_fit([(200, 300), (22, 500)], patch_size=5) == 2
