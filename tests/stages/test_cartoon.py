"""Cartoon synthesis (seed 004): the clip's geometry samples, global motion and refusals, the motion-propagated
start, and a textured sprite re-synthesized to twice its length keeping its motion and its look."""

import numba
import numpy as np
import pytest

from fluidymation.engine.nnf import NNF
from fluidymation.errors import InputError, ParameterError
from fluidymation.stages import cartoon
from fluidymation.stages.cartoon_clip import analyse_clip, fit_affine, geometry_samples, subject_box

from tests.naive import naive_patch_distance, naive_shift
from tests.scenes import disk

QUICK = dict(patch_size=5, pyramid_levels=1, motion_iterations=20, block_size=9)


def sprite_clip(frames=8, step=1, shape=(36, 52), side=12, y=12):
    """A blocky random texture of ``side`` px moving right by ``step`` px a frame on white paper."""
    texture = np.kron(np.random.default_rng(3).random((side // 2, side // 2, 3)), np.ones((2, 2, 1)))
    rgb = np.ones((frames,) + shape + (3,), np.float32)
    mask = np.zeros((frames,) + shape, bool)
    for index in range(frames):
        x = 4 + index * step
        rgb[index, y:y + side, x:x + side] = texture
        mask[index, y:y + side, x:x + side] = True
    return rgb, mask


def test_geometry_samples_of_a_disk_are_its_centre_and_rim():
    alpha = disk(41, 12.0, 20.5)  # centred on pixel (20, 20)
    samples = geometry_samples(alpha, subject_box(alpha))
    assert np.allclose(samples[0], [20, 20], atol=0.01)
    assert np.allclose(np.hypot(*(samples[1:] - samples[0]).T), 12.0, atol=0.75)
    assert np.allclose(np.degrees(np.arctan2(*(samples[1:] - samples[0])[:, ::-1].T)) % 360, np.arange(0, 360, 45),
                       atol=0.01)


def test_geometry_samples_of_an_empty_ray_stop_at_the_rectangle():
    alpha = np.zeros((20, 30), np.float32)
    alpha[5:15, 5:8] = alpha[5:15, 20:23] = 1.0  # two bars: nothing on the horizontal rays' middle
    samples = geometry_samples(alpha, subject_box(alpha))
    assert np.allclose(samples[0], [13.5, 9.5])
    assert np.isclose(samples[1, 0], 22.0, atol=0.51) and np.isclose(samples[5, 0], 5.0, atol=0.51)
    assert subject_box(np.zeros((4, 4), np.float32)) is None


def test_fit_affine_recovers_a_map_and_falls_back_to_a_translation_on_a_line():
    points = np.random.default_rng(0).random((9, 2)) * 20
    affine = np.array([[1.1, 0.2, 3.0], [-0.1, 0.9, -2.0]])
    moved = points @ affine[:, :2].T + affine[:, 2]
    assert np.allclose(fit_affine(points, moved), affine)
    line = np.stack([np.arange(9.0), np.arange(9.0)], axis=1)
    assert np.allclose(fit_affine(line, line + [2, -1]), [[1, 0, 2], [0, 1, -1]])


def test_the_global_motion_pattern_is_the_samples_velocity():
    rgb, mask = sprite_clip(step=2)
    clip = analyse_clip(rgb, mask, name="sprite", motion=cartoon.Params(**QUICK).motion)
    assert np.allclose(clip.velocities[1:, :, 0], 2.0) and np.allclose(clip.velocities[1:, :, 1], 0.0)
    assert np.allclose(clip.velocities[0], 0.0)
    inside = mask[3]
    assert np.allclose(np.median(clip.motion[3][inside], axis=0), [2.0, 0.0], atol=0.1)


@pytest.mark.parametrize("case, message", [
    ("one frame", "a clip needs at least 2 frames"),
    ("empty", "frame 2: no subject found"),
    ("everything", "frame 0: the subject covers 100%"),
    ("moving background", "frame 1: the background moves"),
])
def test_clips_the_method_cannot_take_are_refused_naming_the_frame(case, message):
    rgb, mask = sprite_clip(frames=4)
    if case == "one frame":
        rgb, mask = rgb[:1], mask[:1]
    elif case == "empty":
        mask[2] = False
    elif case == "everything":
        mask[:] = True
    else:
        rgb[1, 30:, :20] = 0.3  # a shadow crossing the background
    with pytest.raises(InputError, match=f"^clip.avi: {message}"):
        analyse_clip(rgb, mask, name="clip.avi", motion=cartoon.Params(**QUICK).motion)


def test_clip_time_plays_the_clip_then_loops_past_its_first_frame():
    assert [cartoon.clip_time(t, 4) for t in range(9)] == [0, 1, 2, 3, 1, 2, 3, 1, 2]


def test_advancing_a_match_follows_the_clip_motion_and_loops_through_the_geometry():
    rgb, mask = sprite_clip(frames=4, step=2)
    clip = analyse_clip(rgb, mask, name="sprite", motion=cartoon.Params(**QUICK).motion)
    frame = np.array([[1, 3, -1]], np.int32)
    coords = np.array([[[9.0, 17.0, 0.0], [13.0, 17.0, 0.0], [0.0, 0.0, 0.0]]], np.float32)
    advanced = cartoon.advance_in_clip(NNF(frame, coords), clip)
    assert advanced.frame.tolist() == [[2, 1, -1]]
    assert np.allclose(advanced.coords[0, 0, :2], [11.0, 17.0], atol=0.1)  # 2 px on with the sprite
    assert np.allclose(advanced.coords[0, 1, :2], [9.0, 17.0], atol=0.1)  # frame 3 → 0 by the samples, then on to 1


@pytest.fixture(scope="module")
def resynthesized():
    rgb, mask = sprite_clip()
    params = cartoon.Params(**QUICK)
    clip = analyse_clip(rgb, mask, name="sprite", motion=params.motion)
    path = cartoon.ResynthPath(clip, 16)
    frames = list(cartoon.synthesize_frames(cartoon.CartoonSynthesis(clip, params),
                                            ((index, path.target(index)) for index in range(16))))
    return rgb, mask, frames


def test_a_resynthesized_sprite_keeps_its_motion_at_twice_its_length(resynthesized):
    _, _, frames = resynthesized
    assert len(frames) == 16
    for before, after in zip(frames, frames[1:]):
        interior = after.rgba[..., 3] >= 0.99
        shift = naive_shift(before.rgba, after.rgba, interior.astype(np.float64))
        assert np.allclose(shift, [1.0, 0.0], atol=0.5), (after.index, shift)


def test_a_resynthesized_sprite_keeps_its_look(resynthesized):
    rgb, mask, frames = resynthesized
    sources = [np.concatenate([rgb[k], mask[k][..., None]], axis=-1) for k in range(len(rgb))]
    noise = np.random.default_rng(1).random(sources[0].shape)
    for frame in frames[::5]:
        output = cartoon.straight(frame.rgba)
        output[..., :3] = output[..., :3] * output[..., 3:] + (1 - output[..., 3:])
        ys, xs = np.nonzero(frame.rgba[2:-2, 2:-2, 3] >= 0.5)
        centres = list(zip(xs + 2, ys + 2))
        distance = naive_patch_distance(output, sources, centres, 5)
        assert distance < 0.01, (frame.index, distance)
        assert naive_patch_distance(noise, sources, centres, 5) > 3 * 0.01  # the bound tells noise apart


def test_cartoon_synthesis_is_deterministic_on_one_thread_too(resynthesized):
    rgb, mask, frames = resynthesized
    params = cartoon.Params(**QUICK)
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        clip = analyse_clip(rgb, mask, name="sprite", motion=params.motion)
        path = cartoon.ResynthPath(clip, 3)
        again = list(cartoon.synthesize_frames(cartoon.CartoonSynthesis(clip, params),
                                               ((index, path.target(index)) for index in range(3))))
    finally:
        numba.set_num_threads(threads)
    assert all(np.array_equal(a.rgba, b.rgba) for a, b in zip(again, frames))


def test_parameters_are_checked_by_name():
    with pytest.raises(ParameterError, match="block_size must be an odd number"):
        cartoon.Params(block_size=16)
