import math

import numpy as np
import pytest

from fluidymation.engine.nnf import ROTATION_FLOW, NNF, downscale_nnf, fill_random, merge_nnf, upscale_nnf


def random_field(rng, shape, source_shape, rotate=True):
    frames, height, width = source_shape
    frame = rng.integers(0, frames, shape).astype(np.int32)
    coords = np.stack(
        [rng.integers(3, width - 3, shape), rng.integers(3, height - 3, shape),
         rng.uniform(-np.pi, np.pi, shape) if rotate else np.zeros(shape)], axis=2,
    ).astype(np.float32)
    return NNF(frame, coords)


def test_upscale_follows_the_formula_with_rotation():
    rng = np.random.default_rng(0)
    coarse = random_field(rng, (4, 5), (2, 30, 30))
    coarse.frame[1, 1] = -1
    fine = upscale_nnf(coarse, target_shape=(8, 9), source_shape=(60, 60))
    for ty in range(8):
        for tx in range(9):
            cy, cx = min(ty // 2, 3), min(tx // 2, 4)
            assert fine.frame[ty, tx] == coarse.frame[cy, cx]
            if coarse.frame[cy, cx] < 0:
                continue
            x, y, theta = coarse.coords[cy, cx].astype(np.float64)
            ox, oy = tx - 2 * cx - 0.5, ty - 2 * cy - 0.5
            expected = (2 * x + 0.5 + math.cos(theta) * ox - math.sin(theta) * oy,
                        2 * y + 0.5 + math.sin(theta) * ox + math.cos(theta) * oy, theta)
            np.testing.assert_allclose(fine.coords[ty, tx], expected, atol=1e-4)


def test_unrotated_upscale_is_the_classic_doubling():
    coarse = random_field(np.random.default_rng(1), (3, 3), (1, 20, 20), rotate=False)
    fine = upscale_nnf(coarse, target_shape=(6, 6), source_shape=(40, 40))
    np.testing.assert_array_equal(fine.coords[1::2, 0::2, 0], 2 * coarse.coords[:, :, 0])
    np.testing.assert_array_equal(fine.coords[0::2, 1::2, 1], 2 * coarse.coords[:, :, 1])


@pytest.mark.parametrize("rotate", [False, True])
def test_downscale_inverts_upscale(rotate):
    coarse = random_field(np.random.default_rng(2), (5, 6), (3, 40, 40), rotate=rotate)
    for steps in (1, 2):
        fine = coarse
        for _ in range(steps):
            fine = upscale_nnf(fine, target_shape=(fine.shape[0] * 2, fine.shape[1] * 2), source_shape=(160, 160))
        back = downscale_nnf(fine, steps=steps, target_shape=(5, 6), source_shape=(40, 40))
        np.testing.assert_array_equal(back.frame, coarse.frame)
        np.testing.assert_array_equal(back.coords, coarse.coords)


def test_downscale_by_no_steps_keeps_sub_pixel_matches():
    # the previous frame's field is carried over at full resolution: rounding it there
    # re-traded about half of a still target's matches every frame
    field = random_field(np.random.default_rng(4), (5, 6), (3, 40, 40), rotate=True)
    field.coords[..., :2] += np.float32(0.37)
    same = downscale_nnf(field, steps=0, target_shape=(5, 6), source_shape=(40, 40))
    np.testing.assert_array_equal(same.frame, field.frame)
    np.testing.assert_array_equal(same.coords, field.coords)
    assert same.coords is not field.coords
    with pytest.raises(ValueError, match="keeps the size"):
        downscale_nnf(field, steps=0, target_shape=(4, 6), source_shape=(40, 40))


def test_downscale_takes_the_mode_and_skips_unmatched():
    fine = NNF.empty(2, 4)
    fine.frame[:] = [[0, 1, -1, -1], [0, 0, -1, -1]]
    # three children point back to (frame 0, x 3, y 4); one to frame 1
    for ty, tx in [(0, 0), (1, 0), (1, 1)]:
        fine.coords[ty, tx] = (6 + tx, 8 + ty, 0)
    fine.coords[0, 1] = (20, 20, 0)
    coarse = downscale_nnf(fine, steps=1, target_shape=(1, 2), source_shape=(20, 20))
    assert coarse.frame.tolist() == [[0, -1]]
    np.testing.assert_array_equal(coarse.coords[0, 0], (3, 4, 0))


def test_merge_keeps_the_lower_error():
    a = NNF(np.zeros((1, 3), np.int32), np.zeros((1, 3, 3), np.float32))
    b = NNF(np.array([[1, 1, -1]], np.int32), np.ones((1, 3, 3), np.float32))
    merged, took_second = merge_nnf(a, b, np.array([[1.0, 0.5, 9.0]], np.float32),
                                    np.array([[0.5, 0.5, 0.0]], np.float32))
    assert merged.frame.tolist() == [[1, 0, 0]]
    assert took_second.tolist() == [[True, False, False]]


def test_random_fill_respects_segments_and_is_deterministic():
    source_segment = np.zeros((2, 12, 12), np.int32)
    source_segment[:, :, 6:] = 1
    source_segment[1, :2] = -1
    target_segment = np.zeros((7, 8), np.int32)
    target_segment[:, 4:] = 1
    target_segment[0, 0] = -1
    fields = []
    for _ in range(2):
        field = NNF.empty(7, 8)
        fill_random(field, target_segment=target_segment, source_segment=source_segment, seed=5)
        fields.append(field)
    np.testing.assert_array_equal(fields[0].coords, fields[1].coords)
    field = fields[0]
    assert field.frame[0, 0] == -1
    for ty, tx in zip(*np.nonzero(target_segment >= 0)):
        x, y, _ = field.coords[ty, tx]
        assert source_segment[field.frame[ty, tx], int(y), int(x)] == target_segment[ty, tx]
    assert len({tuple(c) for c in field.coords.reshape(-1, 3)}) > 40


def test_random_fill_keeps_valid_matches_and_uses_flow_angles():
    source_segment = np.zeros((1, 10, 10), np.int32)
    field = NNF.empty(3, 3)
    field.frame[0, 0] = 0
    field.coords[0, 0] = (4, 4, 0.5)
    source_angle = np.full((1, 10, 10), 0.25, np.float32)
    target_angle = np.full((3, 3), 1.0, np.float32)
    fill_random(field, target_segment=np.zeros((3, 3), np.int32), source_segment=source_segment, seed=1,
                replace_all=False, rotation_mode=ROTATION_FLOW, target_angle=target_angle, source_angle=source_angle)
    np.testing.assert_array_equal(field.coords[0, 0], (4, 4, 0.5))
    thetas = field.coords[:, :, 2].ravel()[1:]
    assert np.all(np.isclose(thetas, -0.75) | np.isclose(thetas, -0.75 + np.pi))  # θ_S − θ_T (+ π)
