"""The quality metrics (fluidymation.quality) on small cases with known answers."""

import numpy as np
import pytest
from scipy import ndimage

from fluidymation import quality


def _grey(lum):
    return np.repeat(np.asarray(lum, np.float64)[..., None], 3, axis=2)


def _smooth_texture(size=128, seed=0, sigma=3.0):
    rng = np.random.default_rng(seed)
    texture = ndimage.gaussian_filter(rng.standard_normal((size, size)), sigma, mode="wrap")
    return _grey(0.5 + 0.1 * texture / texture.std())


def _disk(size, radius):
    yy, xx = np.mgrid[:size, :size] + 0.5
    return np.hypot(yy - size / 2, xx - size / 2) < radius


def test_edge_distance_counts_rings_from_the_edge():
    mask = np.zeros((9, 9), bool)
    mask[1:8, 1:8] = True
    distance = quality.edge_distance(mask)
    assert distance[1, 4] == 1 and distance[2, 4] == 2 and distance[4, 4] == 4 and distance[0, 0] == 0


def test_a_light_line_at_8_px_from_the_edge_peaks_the_profile_there():
    size = 128
    mask = _disk(size, 50)
    distance = quality.edge_distance(mask)
    image = _smooth_texture(size)
    image[(distance >= 8) & (distance < 9)] += 0.2  # a light ring one pixel wide
    profile, counts = quality.gradient_profile([image], [mask])
    ratio, band = quality.profile_peak_ratio(profile, counts)
    assert band in (7, 8, 9) and ratio > 2.0
    flat, _ = quality.profile_peak_ratio(*quality.gradient_profile([_smooth_texture(size)], [mask]))
    assert flat < 1.5


def test_the_profile_stops_at_the_bands_that_do_not_fit():
    profile = np.arange(41, dtype=np.float64)
    counts = np.full(41, 1000)
    counts[12:] = 10  # the shape holds bands up to 11 only
    ratio, band = quality.profile_peak_ratio(profile, counts)
    assert band == 11 and ratio == pytest.approx(11 / 8)
    counts[7:] = 10
    assert np.isnan(quality.profile_peak_ratio(profile, counts)[0])


def test_blocks_of_2_px_are_blocky_and_a_smooth_image_is_not():
    size = 96
    mask = np.ones((size, size), bool)
    rng = np.random.default_rng(1)
    blocks = np.kron(rng.uniform(0.2, 0.8, (size // 2, size // 2)), np.ones((2, 2)))
    value, period = quality.blockiness([_grey(blocks)], [mask])
    assert period == 2 and value > 10  # every step between blocks, none inside them
    smooth, _ = quality.blockiness([_smooth_texture(size)], [mask])
    assert smooth == pytest.approx(1.0, abs=0.03)


def test_blockiness_is_even_against_odd_boundaries():
    row = np.array([0.0, 0.5, 1.0, 1.5] * 8 + [0.0])
    image = _grey(np.tile(row, (32, 1)))
    value, period = quality.blockiness([image], [np.ones((32, 33), bool)], periods=(2,), margin=0)
    # boundaries i = 1, 2, 3, 4 (between pixels i − 1 and i) have steps 0.5, 0.5, 0.5 and 1.5 (back
    # from 1.5 to 0), up to i = 32: the 16 even ones average (0.5 + 1.5) / 2 = 1.0, the 16 odd ones 0.5; rows are flat
    assert period == 2 and value == pytest.approx(2.0)


def test_local_contrast_of_a_flat_and_a_checkered_region():
    region = np.ones((20, 20), bool)
    assert quality.local_contrast(_grey(np.full((20, 20), 0.3)), region) == pytest.approx(0.0, abs=1e-9)
    checker = np.indices((20, 20)).sum(axis=0) % 2
    # a 5×5 window holds 13 of one value and 12 of the other: std = sqrt(p (1 − p))
    assert quality.local_contrast(_grey(checker), region) == pytest.approx(np.sqrt(13 * 12) / 25)
    assert np.isnan(quality.local_contrast(_grey(checker), _disk(20, 3)))  # nothing left after the erosion


def test_still_region_is_where_nothing_moves():
    size = 64
    yy, xx = np.mgrid[:size, :size] + 0.5
    still_disk = np.hypot(yy - 32, xx - 16) < 10
    before = still_disk | (np.hypot(yy - 32, xx - 44) < 8)
    after = still_disk | (np.hypot(yy - 32, xx - 47) < 8)
    displacement = np.zeros((size, size, 2))
    displacement[:, 30:, 0] = 3.0
    region = quality.still_region(before, after, displacement)
    assert region[32, 16] and region[:, 30:].sum() == 0
    assert region.sum() == (quality.edge_distance(still_disk) >= 2).sum()
    band = quality.moving_band(before, after)
    assert band[:, :30].sum() == 0 and band[32, 50] and band[32, 41]  # the leading and the trailing edge


def test_still_region_leaves_out_where_the_edge_distance_changes():
    # a bar grows 4 px to the right with no displacement given: its right end is not still
    before = np.zeros((40, 60), bool)
    before[10:30, 5:30] = True
    after = before.copy()
    after[10:30, 30:34] = True
    region = quality.still_region(before, after, np.zeros((40, 60, 2)))
    assert region[20, 8] and region[12, 26] and region[20, 22:].sum() == 0  # near the top edge it stays


def test_pooled_mean_weighs_every_pixel_the_same():
    maps = [np.full((2, 2), 1.0), np.full((2, 2), 4.0)]
    regions = [np.array([[True, False], [False, False]]), np.ones((2, 2), bool)]
    assert quality.pooled_mean(maps, regions) == pytest.approx((1 + 4 * 4) / 5)
    assert np.isnan(quality.pooled_mean(maps, regions, min_pixels=6))


def test_exemplar_stationary_paint_is_slow_and_away_from_where_it_moves():
    mask = np.ones((20, 20), bool)
    flow = np.zeros((20, 20, 2))
    flow[:, 10:, 0] = 1.0
    stationary = quality.exemplar_stationary(mask, mask, flow)
    assert stationary[10, 5] and not stationary[10, 8] and not stationary[10, 12]


def test_iou_of_known_masks():
    a = np.zeros((10, 10))
    b = np.zeros((10, 10))
    a[:, :6] = 1.0
    b[:, 4:] = 0.7
    assert quality.iou(a, b) == pytest.approx(20 / 100)
    assert quality.iou(a, a) == 1.0


def test_texture_fidelity_is_zero_for_exemplar_patches_and_grows_with_noise():
    exemplar = _smooth_texture(48, seed=3, sigma=1.0)
    mask = np.ones((48, 48), bool)
    shuffled = np.roll(exemplar, (7, -11), axis=(0, 1))  # every whole patch away from the seam is an exemplar one
    inner = np.zeros((48, 48), bool)
    inner[14:40, 3:30] = True
    assert quality.texture_fidelity([shuffled], [inner], [exemplar], [mask]) == pytest.approx(0.0, abs=1e-6)
    noise = np.random.default_rng(4).normal(0, 0.05, shuffled.shape)
    noisy = quality.texture_fidelity([shuffled + noise], [inner], [exemplar], [mask])
    assert 0.02 < noisy < 0.051  # the nearest patch is at most the noise's RMS away
    again = quality.texture_fidelity([shuffled + noise], [inner], [exemplar], [mask])
    assert again == noisy
    assert np.isnan(quality.texture_fidelity([shuffled], [_disk(48, 2)], [exemplar], [mask]))  # no whole patch


def test_compensated_residual_is_zero_for_texture_moved_with_the_shape():
    rng = np.random.default_rng(3)
    before = rng.random((32, 40, 3))
    mask = np.zeros((32, 40))
    mask[6:26, 6:30] = 1
    after, mask_after = np.roll(before, 3, axis=1), np.roll(mask, 3, axis=1)
    moved = np.broadcast_to(np.array([3.0, 0.0]), (32, 40, 2))
    assert quality.compensated_residual(before, after, moved, mask, mask_after) == pytest.approx(0.0, abs=1e-12)
    still = np.zeros((32, 40, 2))
    assert quality.compensated_residual(before, after, still, mask, mask_after) > 0.2  # |U − U'| averages 1/3
    assert np.isnan(quality.compensated_residual(before, after, moved, np.zeros_like(mask), mask_after))


def test_frame_usage_counts_the_matches_inside_the_eroded_region():
    mask = np.zeros((12, 12), bool)
    mask[1:11, 1:11] = True  # eroded by 3 px: rows and columns 4..7, 16 pixels
    frames = np.full((12, 12), 2, np.int32)
    frames[4:6, 4:8] = 0  # 8 of the 16 from frame 0
    frames[7, 4:8] = -1  # 4 unmatched
    frames[0, :] = 1  # outside the mask: not counted
    usage = quality.frame_usage(frames, mask, 3)
    assert usage == pytest.approx([8 / 12, 0, 4 / 12])
    assert not quality.frame_usage(np.full((12, 12), -1, np.int32), mask, 3).any()


def test_used_contrast_weighs_each_exemplar_frame_by_its_share():
    assert quality.used_contrast(np.array([0.25, 0.0, 0.75]), [0.04, 0.5, 0.02]) == pytest.approx(0.025)
    assert np.isnan(quality.used_contrast(np.zeros(3), [0.04, 0.5, 0.02]))
