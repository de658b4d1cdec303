import numpy as np

from fluidymation.engine.nnf import NNF
from fluidymation.engine.uniformity import budget_scales, occurrence_map, uniformity_penalty
from tests.naive import naive_occurrence


def test_occurrence_counts_rotated_cuboids():
    rng = np.random.default_rng(4)
    frame = rng.integers(0, 5, (6, 7)).astype(np.int32)
    frame[2, 3] = -1
    coords = np.stack([rng.uniform(0, 11, (6, 7)), rng.uniform(0, 9, (6, 7)), rng.uniform(-3, 3, (6, 7))], 2)
    coords = coords.astype(np.float32)
    # unturned patches (counted by box sums), some on the source's border, among turned ones
    coords[::2, :, 2] = 0.0
    coords[0, :4, :2] = [[0.0, 0.0], [11.0, 9.0], [0.4, 8.6], [10.5, 0.5]]
    field = NNF(frame, coords)
    for radius in (0, 2):
        got = occurrence_map(field, source_shape=(5, 10, 12), patch_size=5, frame_radius=radius)
        np.testing.assert_array_equal(got, naive_occurrence(frame, coords, (5, 10, 12), 5, radius))


def test_occurrence_of_unturned_patches_alone():
    frame = np.zeros((9, 8), np.int32)
    yy, xx = np.mgrid[:9, :8]
    coords = np.stack([xx * 1.5, yy * 1.0, np.zeros((9, 8))], 2).astype(np.float32)
    got = occurrence_map(NNF(frame, coords), source_shape=(1, 9, 12), patch_size=3)
    np.testing.assert_array_equal(got, naive_occurrence(frame, coords, (1, 9, 12), 3, 0))


def test_penalty_is_the_scaled_window_sum_per_segment():
    rng = np.random.default_rng(5)
    occurrence = rng.integers(0, 4, (2, 6, 7)).astype(np.int32)
    source_segment = np.zeros((2, 6, 7), np.int32)
    source_segment[:, :, 4:] = 1
    source_segment[1, 0, 0] = -1
    scales = np.array([0.5, 2.0], np.float32)
    penalty = uniformity_penalty(occurrence, source_segment=source_segment, scales=scales, patch_size=3)
    padded = np.pad(occurrence, ((0, 0), (1, 1), (1, 1)))
    for f, y, x in np.ndindex(occurrence.shape):
        label = source_segment[f, y, x]
        expected = 0.0 if label < 0 else padded[f, y:y + 3, x:x + 3].sum() * scales[label]
        assert penalty[f, y, x] == expected


def test_budget_follows_the_segment_sizes():
    source_segment = np.zeros((3, 10, 10), np.int32)
    source_segment[:, :, 5:] = 1  # 150 voxels per label
    target_segment = np.zeros((6, 10), np.int32)
    target_segment[:, 7:] = 1  # 42 and 18 pixels
    target_segment[0, 0] = -1  # 41 left
    scales = budget_scales(source_segment=source_segment, target_segment=target_segment, patch_size=5,
                           frame_radius=1, weight=2.0)
    budget = 25 * 3 * np.array([41, 18]) / 150
    np.testing.assert_allclose(scales, 2.0 / (25 * budget), rtol=1e-6)
