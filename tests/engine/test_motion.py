"""Grid-based PatchMatch motion estimation."""

import numba
import numpy as np
import pytest
from scipy.ndimage import gaussian_filter, shift

from fluidymation.engine.motion import estimate_motion, motion_sequence


def texture(height=64, width=80, seed=3):
    rng = np.random.default_rng(seed)
    image = gaussian_filter(rng.random((height, width, 3)), sigma=(1.5, 1.5, 0))
    return ((image - image.min()) / np.ptp(image)).astype(np.float32)


def translated(image, dx, dy):
    return shift(image, (dy, dx, 0), order=3, mode="reflect").astype(np.float32)


@pytest.mark.parametrize("dx,dy", [(3, -2), (0, 0), (-5, 4), (2.5, 1.25)])
def test_recovers_a_translation_within_half_a_pixel(dx, dy):
    previous = texture()
    current = translated(previous, dx, dy)
    flow = estimate_motion(previous, current, seed=1)
    inner = flow[12:-12, 12:-12]
    assert np.abs(inner[..., 0] - dx).max() < 0.5
    assert np.abs(inner[..., 1] - dy).max() < 0.5


def test_two_regions_moving_apart():
    previous = texture(64, 96)
    current = previous.copy()
    current[:, :48] = translated(previous, -3, 0)[:, :48]
    current[:, 48:] = translated(previous, 3, 0)[:, 48:]
    flow = estimate_motion(previous, current, seed=2)
    assert np.median(flow[10:-10, 8:36, 0]) == pytest.approx(-3, abs=0.5)
    assert np.median(flow[10:-10, 60:88, 0]) == pytest.approx(3, abs=0.5)


def test_deterministic_for_a_seed():
    previous = texture()
    current = translated(previous, 2, 1)
    assert np.array_equal(estimate_motion(previous, current, seed=5), estimate_motion(previous, current, seed=5))


def test_integer_roll_is_found_exactly():
    """A whole-pixel shift of a periodic texture is matched exactly everywhere inside."""
    previous = texture(24, 24, seed=9)
    current = np.roll(previous, (2, -1), axis=(0, 1))
    flow = estimate_motion(previous, current, spacing=4, patch_size=5, search_radius=3, iterations=30, seed=0)
    assert np.round(flow[8:16, 8:16]).tolist() == np.full((8, 8, 2), (-1.0, 2.0)).tolist()


def test_rejects_bad_arguments():
    with pytest.raises(ValueError):
        estimate_motion(np.zeros((4, 4, 3)), np.zeros((5, 4, 3)))
    with pytest.raises(ValueError):
        estimate_motion(np.zeros((4, 4, 3)), np.zeros((4, 4, 3)), patch_size=4)


def test_a_sequence_s_pairs_match_the_pairs_alone_on_any_thread_count():
    rng = np.random.default_rng(4)
    frames = np.stack([np.roll(rng.random((20, 24, 3)), shift, axis=1) for shift in (0, 1, 3, 4)]).astype(np.float32)
    options = dict(spacing=3, patch_size=5, search_radius=4, iterations=6, seed=2)
    alone = [estimate_motion(frames[k - 1], frames[k], frame=k, **options) for k in range(1, 4)]
    threads = numba.get_num_threads()
    try:
        for count in (1, threads):
            numba.set_num_threads(count)
            flow = motion_sequence(frames, **options)
            assert all(np.array_equal(flow[k], alone[k - 1]) for k in range(1, 4))
            assert np.array_equal(flow[0], flow[1])
    finally:
        numba.set_num_threads(threads)
