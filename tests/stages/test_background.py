import itertools

import numpy as np
import pytest
from scipy import ndimage

from fluidymation.errors import InputError, StageError
from fluidymation.stages import background as bg
from fluidymation.stages.files import write_png

PAPER = np.array([0.94, 0.91, 0.84], np.float32)


def test_solid_is_exact():
    out = bg.solid((0.2, 0.4, 0.6), (5, 3))
    assert out.shape == (3, 5, 3) and out.dtype == np.float32
    assert np.array_equal(out, np.broadcast_to(np.array([0.2, 0.4, 0.6], np.float32), (3, 5, 3)))
    assert np.array_equal(bg.solid("#ff0000", (2, 2))[1, 1], [1.0, 0.0, 0.0])
    with pytest.raises(StageError, match="#rrggbb"):
        bg.solid("#ff00", (2, 2))
    with pytest.raises(StageError, match="size must be positive"):
        bg.solid(PAPER, (0, 4))


def test_image_wider_than_the_frame_is_cropped_at_the_sides(tmp_path):
    source = np.zeros((20, 40, 3), np.float32)  # h = 20, w = 40
    source[:, 10:30, 0] = 1.0  # the middle half of the width
    source[:10, :, 1] = 1.0  # the top half
    write_png(tmp_path / "wide.png", source)
    out = bg.image(tmp_path / "wide.png", (20, 20))  # scale 1: keep columns 10..29
    assert out.shape == (20, 20, 3) and out.dtype == np.float32
    np.testing.assert_allclose(out[:, :, 0], 1.0, atol=1e-6)
    np.testing.assert_allclose(out[:10, :, 1], 1.0, atol=1e-6)
    np.testing.assert_allclose(out[10:, :, 1], 0.0, atol=1e-6)


def test_image_taller_than_the_frame_is_scaled_up_and_cropped_at_top_and_bottom(tmp_path):
    source = np.zeros((20, 10, 3), np.float32)  # h = 20, w = 10
    source[4:16, :, 1] = 1.0  # rows 5..14 (the middle half) are what the frame shows
    source[:, :5, 0] = 1.0  # the left half
    write_png(tmp_path / "tall.png", source)
    out = bg.image(tmp_path / "tall.png", (40, 40))  # scale 4 → 40x80, rows 20..59 kept
    assert out.shape == (40, 40, 3)
    np.testing.assert_allclose(out[:, :, 1], 1.0, atol=1e-6)
    assert np.all(out[:, :18, 0] > 0.999) and np.all(out[:, 22:, 0] < 1e-6)


def test_image_shrinks_smoothly_and_composites_alpha_over_white(tmp_path):
    rgba = np.zeros((60, 80, 4), np.float32)
    rgba[..., :3] = PAPER
    rgba[..., 3] = 1.0
    rgba[:, :40, 3] = 0.0  # transparent left half
    write_png(tmp_path / "alpha.png", rgba)
    out = bg.image(tmp_path / "alpha.png", (16, 12))
    assert out.shape == (12, 16, 3)
    np.testing.assert_allclose(out[:, 0], 1.0, atol=1e-6)
    np.testing.assert_allclose(out[:, -1], np.broadcast_to(np.round(PAPER * 255) / 255, (12, 3)), atol=1e-5)


def test_image_missing_file_names_the_path(tmp_path):
    with pytest.raises(InputError, match="nothing.png"):
        bg.image(tmp_path / "nothing.png", (8, 8))
    (tmp_path / "bad.png").write_text("not a png")
    with pytest.raises(InputError, match="bad.png"):
        bg.image(tmp_path / "bad.png", (8, 8))


def _exemplar_with_free_corner():
    """3 frames of 40x48; paint covers the top rows (frame 0), the right columns (frame 1)
    and a small bottom-left blob (frame 2); a shadow crosses the paper in frame 0 only."""
    frames, height, width = 3, 40, 48
    segment = np.full((frames, height, width), -1, np.int32)
    segment[0, :16] = 1
    segment[1, :, 34:] = 0
    segment[2, 36:, :4] = 1
    offsets = np.array([-0.02, 0.0, 0.02], np.float32)[:, None, None, None]
    rgb = np.broadcast_to(PAPER + offsets, (frames, height, width, 3)).copy()
    rgb[0, 20:24, 10:20] = 0.3  # transient: the per-pixel median over frames removes it
    return rgb, segment


def test_paper_sample_is_the_largest_rectangle_unpainted_in_every_frame():
    rgb, segment = _exemplar_with_free_corner()
    # margin 0: rows 16..39 × columns 4..33 (24×30) beats rows 16..35 × columns 0..33 (20×34)
    sample = bg.paper_sample(rgb, segment, margin=0)
    assert sample.shape == (24, 30, 3) and sample.dtype == np.float32
    np.testing.assert_allclose(sample, np.broadcast_to(PAPER, sample.shape), atol=1e-6)
    # margin 2: paper starts 2 px away from paint: rows 18..39 × columns 6..31 (22×26)
    assert bg.paper_sample(rgb, segment).shape == (22, 26, 3)
    assert bg.largest_rectangle(segment.max(axis=0) < 0, min_side=16) == (16, 4, 24, 30)


def test_paper_sample_too_small_asks_for_a_paper_image():
    rgb, segment = _exemplar_with_free_corner()
    segment[:, 16:28] = 0
    with pytest.raises(StageError, match="background.path"):
        bg.paper_sample(rgb, segment)


def test_largest_rectangle_matches_brute_force():
    rng = np.random.default_rng(0)
    for _ in range(20):
        mask = rng.random((7, 9)) > rng.uniform(0.05, 0.4)
        min_side = int(rng.integers(1, 4))
        best = 0
        for top, left in itertools.product(range(7), range(9)):
            for bottom, right in itertools.product(range(top + min_side, 8), range(left + min_side, 10)):
                if mask[top:bottom, left:right].all():
                    best = max(best, (bottom - top) * (right - left))
        found = bg.largest_rectangle(mask, min_side=min_side)
        if best == 0:
            assert found is None
        else:
            top, left, height, width = found
            assert height * width == best and min(height, width) >= min_side
            assert mask[top : top + height, left : left + width].all()


def _paper_texture(height=64, width=64, seed=3):
    """Grain (σ 1 px) plus blotches (σ 4 px) around ``PAPER``."""
    rng = np.random.default_rng(seed)
    grain = ndimage.gaussian_filter(rng.standard_normal((height, width)), 1.0, mode="wrap")
    blotch = ndimage.gaussian_filter(rng.standard_normal((height, width)), 4.0, mode="wrap")
    shade = 0.03 * grain / grain.std() + 0.03 * blotch / blotch.std()
    return np.clip(PAPER + shade[:, :, None], 0, 1).astype(np.float32)


def _period_correlation(image, rows, columns):
    """Correlation of the image's luminance with itself shifted by (rows, columns)."""
    grey = image.mean(axis=2)
    a, b = grey[: grey.shape[0] - rows, : grey.shape[1] - columns], grey[rows:, columns:]
    return float(np.corrcoef(a.ravel(), b.ravel())[0, 1])


def test_synthesized_paper_is_deterministic_alike_and_not_tiled():
    sample = _paper_texture()
    out = bg.synthesized(sample, (120, 96), seed=1)
    assert out.shape == (96, 120, 3) and out.dtype == np.float32
    assert np.array_equal(out, bg.synthesized(sample, (120, 96), seed=1))
    assert not np.array_equal(out, bg.synthesized(sample, (120, 96), seed=2))
    # voting blurs where neighbouring patches disagree: ~0.6–0.7 of the contrast remains
    np.testing.assert_allclose(out.mean(axis=(0, 1)), sample.mean(axis=(0, 1)), atol=0.01)
    ratio = out.std(axis=(0, 1)) / sample.std(axis=(0, 1))
    assert np.all((ratio > 0.45) & (ratio < 1.2)), ratio
    tiled = np.tile(sample, (2, 2, 1))[:96, :120]
    for shift in ((64, 0), (0, 64)):
        assert _period_correlation(tiled, *shift) > 0.99  # what a tiling would show
        assert abs(_period_correlation(out, *shift)) < 0.3


def test_synthesized_rejects_bad_samples_and_options():
    with pytest.raises(StageError, match="at least 16x16"):
        bg.synthesized(np.full((12, 40, 3), 0.9, np.float32), (32, 32))
    with pytest.raises(StageError, match="patch_size"):
        bg.synthesized(_paper_texture(), (32, 32), patch_size=4)
    with pytest.raises(StageError, match="seed"):
        bg.synthesized(_paper_texture(), (32, 32), seed=-1)
