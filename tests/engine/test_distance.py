import numpy as np
import pytest
from scipy import ndimage

from fluidymation.engine import distance


def _ramp_coverage(signed, width=4.0):
    """Coverage that crosses 0.5 exactly where ``signed`` is 0, linearly over ``width`` px."""
    return np.clip(0.5 + signed / width, 0.0, 1.0).astype(np.float32)


@pytest.mark.parametrize("sigma", [1.5, 2.0])
def test_gaussian_blur_matches_scipy_nearest(sigma):
    rng = np.random.default_rng(1)
    image = rng.random((23, 31)).astype(np.float32)
    expected = ndimage.gaussian_filter(image.astype(np.float64), sigma, mode="nearest", truncate=3.0)
    np.testing.assert_allclose(distance.gaussian_blur(image, sigma=sigma), expected, atol=1e-5)


def test_gaussian_weights_sum_to_one_and_zero_sigma_is_identity():
    taps = distance.gaussian_weights(2.0)
    assert taps.shape == (13,)
    assert abs(taps.sum() - 1.0) < 1e-6
    assert np.all(np.diff(taps[:7]) > 0)
    np.testing.assert_array_equal(distance.gaussian_weights(0.0), [1.0])


@pytest.mark.parametrize("angle", [0.0, 0.3, np.pi / 4, 2.0])
def test_signed_distance_of_a_straight_edge_is_exact(angle):
    yy, xx = np.mgrid[:40, :40].astype(np.float64)
    normal = np.array([np.cos(angle), np.sin(angle)])
    signed = 19.3 - (xx * normal[0] + yy * normal[1]) + 20 * (normal[0] + normal[1] - 1) * 0.5
    result = distance.signed_distance(_ramp_coverage(signed), threshold=0.5)
    # away from the image edges, where the nearest boundary point is on the image
    core = (slice(8, 32), slice(8, 32))
    np.testing.assert_allclose(result[core], signed[core], atol=0.02)
    assert np.array_equal(result > 0, signed > 0)


def test_signed_distance_of_a_smooth_disk_is_sub_pixel_accurate():
    yy, xx = np.mgrid[:64, :64].astype(np.float64)
    signed = 17.35 - np.hypot(xx - 31.6, yy - 30.2)
    result = distance.signed_distance(_ramp_coverage(signed), threshold=0.5)
    near = np.abs(signed) < 10
    np.testing.assert_allclose(result[near], signed[near], atol=0.03)
    # deep inside, the tangent at the chosen foot deviates a little from the circle
    np.testing.assert_allclose(result[~near], signed[~near], atol=0.15)


def test_signed_distance_of_a_binary_rectangle_puts_the_edge_between_pixels():
    mask = np.zeros((20, 30), dtype=bool)
    mask[5:15, 8:25] = True
    result = distance.signed_distance(mask)
    assert result[5, 12] == pytest.approx(0.5)
    assert result[4, 12] == pytest.approx(-0.5)
    assert result[10, 12] == pytest.approx(4.5)  # 5 rows to the edge above row 5
    assert result[10, 2] == pytest.approx(-5.5)
    assert np.array_equal(result > 0, mask)


def test_signed_distance_without_a_boundary_uses_the_diagonal():
    empty = distance.signed_distance(np.zeros((3, 4), dtype=bool))
    full = distance.signed_distance(np.ones((3, 4), dtype=bool))
    np.testing.assert_allclose(empty, -5.0)
    np.testing.assert_allclose(full, 5.0)


def test_threshold_below_one_half_grows_the_mask():
    yy, xx = np.mgrid[:48, :48].astype(np.float64)
    coverage = (np.hypot(xx - 24, yy - 24) < 12).astype(np.float32)
    blurred = distance.gaussian_blur(coverage, sigma=3.0)
    at_half = (distance.signed_distance(blurred, threshold=0.5) > 0).sum()
    at_low = (distance.signed_distance(blurred, threshold=0.3) > 0).sum()
    assert at_low > at_half


def test_shape_channel_is_the_mask_blurred_with_a_third_of_the_radius():
    mask = np.zeros((30, 30), dtype=bool)
    mask[10:20, 5:25] = True
    shape = distance.shape_channel(mask, radius=6.0)
    np.testing.assert_allclose(shape, distance.gaussian_blur(mask.astype(np.float32), sigma=2.0))
    assert shape.min() >= 0.0 and shape.max() <= 1.0
    assert 0.4 < shape[10, 15] < 0.6


def test_edge_factor_and_segments():
    dist = np.array([[-2.0, 0.5, 3.0, 10.0, 25.0]], dtype=np.float32)
    np.testing.assert_allclose(distance.edge_factor(dist, border_width=10.0), [[-0.2, 0.05, 0.3, 1.0, 1.0]])
    labels = distance.segments(dist, border_width=10.0)
    assert labels.tolist() == [[distance.OUTSIDE, distance.BORDER, distance.BORDER, distance.INTERIOR, distance.INTERIOR]]
    with pytest.raises(ValueError):
        distance.segments(dist, border_width=0.0)


def test_gaussian_blur_of_a_small_shape_matches_scipy_everywhere():
    # the blur computes only the box around the nonzero pixels
    image = np.zeros((60, 70), dtype=np.float32)
    image[20:26, 30:41] = 1.0
    image[24, 5] = 0.5
    expected = ndimage.gaussian_filter(image.astype(np.float64), 2.0, mode="nearest", truncate=3.0)
    np.testing.assert_allclose(distance.gaussian_blur(image, sigma=2.0), expected, atol=1e-6)
    edge = np.zeros((30, 30), dtype=np.float32)
    edge[:4, 10:14] = 1.0
    expected = ndimage.gaussian_filter(edge.astype(np.float64), 1.5, mode="nearest", truncate=3.0)
    np.testing.assert_allclose(distance.gaussian_blur(edge, sigma=1.5), expected, atol=1e-6)
    assert not distance.gaussian_blur(np.zeros((5, 6), dtype=np.float32), sigma=1.0).any()
