import imageio.v3 as iio
import numpy as np
import pytest

from fluidymation.errors import InputError, StageError
from fluidymation.stages import exemplar_user as eu

PAPER = np.array([0.93, 0.9, 0.84])
INK = np.array([0.2, 0.3, 0.6])


def _disk(shape, radius):
    yy, xx = np.mgrid[: shape[0], : shape[1]]
    return np.hypot(yy - shape[0] / 2 + 0.5, xx - shape[1] / 2 + 0.5) <= radius


def _frames(count=6, shape=(40, 48), seed=0):
    """Ink disks growing on noisy paper, float in [0, 1], and their true masks."""
    rng = np.random.default_rng(seed)
    frames, masks = [], []
    for k in range(count):
        mask = _disk(shape, 6 + 2 * k)
        frame = np.where(mask[..., None], INK, PAPER) + rng.normal(0, 0.015, shape + (3,))
        frames.append(np.clip(frame, 0, 1))
        masks.append(mask)
    return frames, masks


def _write_sequence(folder, images, name="{:04d}.png"):
    folder.mkdir(parents=True, exist_ok=True)
    for k, image in enumerate(images):
        data = image if image.dtype == np.uint8 else np.round(np.clip(image, 0, 1) * 255).astype(np.uint8)
        iio.imwrite(folder / name.format(k), data)


def _iou(a, b):
    return (a & b).sum() / (a | b).sum()


def test_auto_mask_finds_the_ink_and_the_paper_colour(tmp_path):
    frames, masks = _frames()
    _write_sequence(tmp_path / "frames", frames)
    exemplar = eu.load_user_exemplar(eu.Params(source=str(tmp_path / "frames" / "%04d.png")))
    assert exemplar.rgb.shape == (6, 40, 48, 3) and exemplar.rgb.dtype == np.float32
    assert np.allclose(exemplar.paper, PAPER, atol=0.02)
    for found, truth in zip(exemplar.mask, masks):
        assert _iou(found, truth) > 0.85


def test_given_masks_with_range_step_reverse_and_scale(tmp_path):
    frames, masks = _frames(count=8)
    _write_sequence(tmp_path / "frames", frames, "f_{}.png")
    _write_sequence(tmp_path / "masks", [m.astype(np.uint8) * 255 for m in masks])
    params = eu.Params(source=str(tmp_path / "frames"), mask=str(tmp_path / "masks" / "*.png"), start=1, end=7,
                       step=2, reverse=True, scale=0.5)
    exemplar = eu.load_user_exemplar(params)
    assert exemplar.source_frames.tolist() == [5, 3, 1]
    assert exemplar.rgb.shape == (3, 20, 24, 3) and exemplar.mask.shape == (3, 20, 24)
    areas = exemplar.mask.sum(axis=(1, 2))
    assert areas[0] > areas[1] > areas[2]  # reversed: the disk shrinks
    expected = masks[5].reshape(20, 2, 24, 2).mean(axis=(1, 3)) > 0.5
    assert _iou(exemplar.mask[0], expected) > 0.9


def test_natural_order_of_unpadded_numbers(tmp_path):
    frames, _ = _frames(count=11)
    _write_sequence(tmp_path / "frames", frames, "{}.png")
    paths = eu.image_sequence(str(tmp_path / "frames"))
    assert [p.stem for p in paths] == [str(k) for k in range(11)]


def test_video_source(tmp_path):
    import imageio_ffmpeg

    frames, masks = _frames(count=5, shape=(48, 64))
    path = tmp_path / "ink.mp4"
    writer = imageio_ffmpeg.write_frames(str(path), (64, 48), fps=10, quality=9, macro_block_size=16,
                                         ffmpeg_log_level="error")
    writer.send(None)
    for frame in frames:
        writer.send(np.ascontiguousarray(np.round(frame * 255).astype(np.uint8)))
    writer.close()
    exemplar = eu.load_user_exemplar(eu.Params(source=str(path), step=2))
    assert exemplar.rgb.shape == (3, 48, 64, 3)
    for found, truth in zip(exemplar.mask, masks[::2]):
        assert _iou(found, truth) > 0.8


def test_mask_count_and_size_mismatches_are_clear_errors(tmp_path):
    frames, masks = _frames(count=4)
    _write_sequence(tmp_path / "frames", frames)
    _write_sequence(tmp_path / "three", [m.astype(np.uint8) * 255 for m in masks[:3]])
    with pytest.raises(InputError, match="3 mask images but 4 frames"):
        eu.load_user_exemplar(eu.Params(source=str(tmp_path / "frames"), mask=str(tmp_path / "three")))
    _write_sequence(tmp_path / "small", [np.zeros((20, 24), np.uint8)] * 4)
    with pytest.raises(InputError, match="24x20 but the frames"):
        eu.load_user_exemplar(eu.Params(source=str(tmp_path / "frames"), mask=str(tmp_path / "small")))


def test_empty_masks_are_an_error(tmp_path):
    frames, masks = _frames(count=3)
    _write_sequence(tmp_path / "frames", frames)
    _write_sequence(tmp_path / "empty", [np.zeros(masks[0].shape, np.uint8)] * 3)
    with pytest.raises(InputError, match="empty in every"):
        eu.load_user_exemplar(eu.Params(source=str(tmp_path / "frames"), mask=str(tmp_path / "empty")))
    blank = [np.clip(np.broadcast_to(PAPER, f.shape) + 0 * f, 0, 1) for f in frames]
    _write_sequence(tmp_path / "blank", blank)
    with pytest.raises(InputError, match="empty in every"):
        eu.load_user_exemplar(eu.Params(source=str(tmp_path / "blank")))


def test_missing_source_and_bad_parameters(tmp_path):
    with pytest.raises(InputError, match="no such video"):
        eu.load_user_exemplar(eu.Params(source=str(tmp_path / "nothing" / "%04d.png")))
    frames, _ = _frames(count=3)
    _write_sequence(tmp_path / "frames", frames)
    with pytest.raises(InputError, match="past"):
        eu.load_user_exemplar(eu.Params(source=str(tmp_path / "frames"), start=5))
    with pytest.raises(StageError, match="step"):
        eu.Params(source="x", step=0)
    with pytest.raises(StageError, match="scale"):
        eu.Params(source="x", scale=0)


def test_motion_flow_follows_a_translated_recording():
    from scipy.ndimage import gaussian_filter, shift

    from fluidymation.stages.exemplar_user import motion_flow

    rng = np.random.default_rng(4)
    base = gaussian_filter(rng.random((48, 64, 3)), sigma=(1.5, 1.5, 0)).astype(np.float32)
    rgb = np.stack([shift(base, (0, 2 * k, 0), order=3, mode="reflect") for k in range(3)]).astype(np.float32)
    flow = motion_flow(rgb, seed=1)
    assert flow.shape == (3, 48, 64, 2)
    assert np.abs(flow[1:, 10:-10, 10:-10, 0] - 2).max() < 0.5 and np.abs(flow[1:, 10:-10, 10:-10, 1]).max() < 0.5
    assert np.array_equal(flow[0], flow[1])
