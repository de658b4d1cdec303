"""The keyframe morph (seed 003) on a textured disk translating 2 px a frame, keyframes at its ends."""

import functools

import imageio.v3 as iio
import numpy as np
import pytest
from scipy import ndimage

from fluidymation.errors import InputError
from fluidymation.pipeline.executors import run_jobs
from fluidymation.stages import keyframe_morph as km
from fluidymation.stages import keyframe_params
from fluidymation.stages.keyframes import keyframe_weights, read_keyframe

SIZE, FRAMES, RADIUS, STEP = 40, 7, 10.0, 2.0
TEXTURE = ndimage.gaussian_filter(np.random.default_rng(1).random((2 * SIZE, 2 * SIZE, 3)), (1.2, 1.2, 0))
TEXTURE = ((TEXTURE - TEXTURE.min()) / np.ptp(TEXTURE)).astype(np.float32)


def mask(frame):
    ys, xs = np.mgrid[:SIZE, :SIZE]
    return np.clip(RADIUS + 0.5 - np.hypot(xs - 12 - STEP * frame, ys - 20), 0, 1).astype(np.float32)


def painted(frame, shift=0):
    """The disk's texture carried along with it (``shift``: px of misregistration), premultiplied RGBA."""
    ys, xs = np.mgrid[:SIZE, :SIZE]
    texture = TEXTURE[(ys + 30) % (2 * SIZE), (xs - int(STEP * frame) + shift + 30) % (2 * SIZE)]
    alpha = mask(frame)
    return np.dstack([texture * alpha[..., None], alpha]).astype(np.float32)


def translation(frame):
    return np.dstack([np.full((SIZE, SIZE), STEP), np.zeros((SIZE, SIZE))]).astype(np.float32)


def still_flow(frame):
    return np.zeros((SIZE, SIZE, 2), np.float32)


def morph(tmp_path, keys, flow=translation, map_tasks=km.serial_map, **settings):
    km.prepare(tmp_path, mask, flow, FRAMES, keys)
    params = km.Params(**settings)
    contexts = km.morph(tmp_path, params, list(keys), FRAMES, (SIZE, SIZE), map_tasks=map_tasks)
    return dict(km.frames_out(contexts)), contexts


def residual(frames):
    """Mean |output − the keyframe carried along the motion| inside the disk, per in-between."""
    return [float(np.abs(frames[m] - painted(m))[mask(m) > 0.99].mean()) for m in range(1, FRAMES - 1)]


def test_in_betweens_reproduce_the_keyframes_carried_along_the_motion(tmp_path):
    frames, _ = morph(tmp_path, {0: painted(0), FRAMES - 1: painted(FRAMES - 1)})
    assert max(residual(frames)) < 0.01


def test_the_motion_follows_the_flow(tmp_path):
    following, _ = morph(tmp_path / "flow", {0: painted(0), FRAMES - 1: painted(FRAMES - 1)})
    ignoring, _ = morph(tmp_path / "still", {0: painted(0), FRAMES - 1: painted(FRAMES - 1)}, flow=still_flow)
    assert max(residual(following)) < 0.01 < 0.05 < np.mean(residual(ignoring))


def test_blend_without_neighbour_terms_reproduces_the_keyframes_exactly(tmp_path):
    keys = {0: painted(0), FRAMES - 1: painted(FRAMES - 1, shift=7)}  # keyframes that disagree
    frames, _ = morph(tmp_path, keys, weighting="blend", beta=0.0, two_pass=False)
    for key, rgba in keys.items():  # to float rounding: the same 8-bit frame
        assert np.abs(frames[key] - rgba).max() < 1e-5


def test_parallel_sweeps_reach_the_sequential_energy(tmp_path):
    keys = {0: painted(0), FRAMES - 1: painted(FRAMES - 1, shift=3)}
    energies = {}
    for schedule in keyframe_params.SCHEDULES:
        _, contexts = morph(tmp_path / schedule, keys, schedule=schedule, two_pass=False, sweeps=16)
        energies[schedule] = km.pass_energy(contexts[-1])
    assert energies["jacobi"] == pytest.approx(energies["sequential"], rel=1e-3)


def test_the_frames_are_the_same_bytes_for_any_number_of_workers(tmp_path):
    keys = {0: painted(0), FRAMES - 1: painted(FRAMES - 1, shift=3)}
    here, _ = morph(tmp_path / "here", keys, sweeps=1)
    two, _ = morph(tmp_path / "two", keys, sweeps=1, map_tasks=functools.partial(run_jobs, jobs=2))
    assert all(np.array_equal(here[m], two[m]) for m in range(FRAMES))


def test_a_killed_morph_continues_from_the_tasks_it_finished(tmp_path):
    keys = {0: painted(0), FRAMES - 1: painted(FRAMES - 1, shift=3)}
    whole, _ = morph(tmp_path / "whole", keys, sweeps=1)
    calls = []

    def dies_after_five(function, arguments):
        results = []
        for args in arguments:
            if len(calls) == 5:
                raise KeyboardInterrupt
            calls.append(args[1].frame)
            results.append(function(*args))
        return results

    with pytest.raises(KeyboardInterrupt):
        morph(tmp_path / "killed", keys, sweeps=1, map_tasks=dies_after_five)
    counted = []
    resumed, _ = morph(tmp_path / "killed", keys, sweeps=1, map_tasks=lambda f, arguments: [
        counted.append(args[1].frame) or f(*args) for args in arguments])
    assert all(np.array_equal(whole[m], resumed[m]) for m in range(FRAMES))
    assert len(list((tmp_path / "killed").rglob("sweep0/*.npz"))) >= 5


def test_keyframe_weights():
    keys = [0, 10, 20, 30]
    assert keyframe_weights(4, keys, "blend", 2) == pytest.approx({0: 0.6, 10: 0.4})
    assert keyframe_weights(10, keys, "blend", 2) == {10: 1.0}
    assert keyframe_weights(-3, keys, "blend", 2) == {0: 1.0} and keyframe_weights(35, keys, "blend", 2) == {30: 1.0}
    assert keyframe_weights(15, keys, "radius", 1) == pytest.approx({10: 0.5, 20: 0.5})
    assert keyframe_weights(10, keys, "radius", 1) == pytest.approx({0: 1 / 3, 10: 1 / 3, 20: 1 / 3})
    smooth = keyframe_weights(12, keys, "smooth", 1)
    assert smooth[10] > smooth[20] > smooth[0] > smooth[30] > 0 and sum(smooth.values()) == pytest.approx(1)


def test_a_keyframe_is_read_at_the_output_size_and_refused_when_its_paint_strays(tmp_path):
    big = np.zeros((2 * SIZE, 2 * SIZE, 4), np.uint8)
    big[..., 0] = 200
    big[..., 3] = np.kron(mask(0) > 0.5, np.ones((2, 2))).astype(np.uint8) * 255
    iio.imwrite(tmp_path / "key.png", big)
    rgba = read_keyframe(tmp_path / "key.png", 0, mask(0))
    assert rgba.shape == (SIZE, SIZE, 4) and abs(rgba[..., 3].sum() - mask(0).sum()) < 0.05 * mask(0).sum()
    iio.imwrite(tmp_path / "rgb.png", big[..., :3])
    assert np.array_equal(read_keyframe(tmp_path / "rgb.png", 0, mask(0))[..., 3], mask(0))
    with pytest.raises(InputError, match="stray.png.*outside the layer's mask at frame 3"):
        iio.imwrite(tmp_path / "stray.png", big)
        read_keyframe(tmp_path / "stray.png", 3, mask(3) * (np.arange(SIZE) < 25))
