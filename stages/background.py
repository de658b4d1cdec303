"""The ``background`` stage: one static paper image per scene, (H, W, 3) float32 sRGB.

Three sources: a solid colour; an image file, scaled to cover the frame and
centre-cropped; or a paper texture synthesized with the patch engine from a sample of
the exemplar's own paper (:func:`paper_sample`, :func:`synthesized`).

Synthesis is unguided texture synthesis. Smooth random noise in two guide channels, drawn
independently for the sample and the output, sends every output region to some random
but locally coherent place of the sample, so the patches spread over the whole sample
and the texture does not repeat; the colour term joins them without seams. (The
engine's uniformity term did not help here: in measurements it lowered the number of
sample positions used and the output contrast, so it is off.) Patch centres keep a
patch radius away from the sample's edge at every pyramid level. Only the coarser levels
are optimised; the full-size level is the vote of the upscaled field, a fraction of the
cost. Voting averages where neighbouring patches disagree, so about two thirds of the
sample's contrast (standard deviation) remains.
"""

from __future__ import annotations

import os

import numpy as np
from scipy import ndimage

from fluidymation.engine.pyramid import levels_that_fit
from fluidymation.engine.synthesis import SynthesisInputs, SynthesisParams, synthesize
from fluidymation.errors import StageError
from fluidymation.stages.colour import as_srgb, linear_to_srgb, srgb_to_linear
from fluidymation.stages.files import read_image

NAME = "background"
VERSION = 1

#: Smallest usable paper sample side (px).
MIN_SAMPLE_SIDE = 16
#: Noise guide channels, their blur as a fraction of the patch side, and their weight
#: relative to the sample's colour variance (so the balance does not depend on contrast).
_NOISE_CHANNELS = 2
_NOISE_BLUR = 0.5
_NOISE_WEIGHT = 0.5
#: Search-vote and PatchMatch iterations per level, coarsest first (the finest level is only voted).
_SEARCH_VOTE_ITERS = (2, 1)
_PATCHMATCH_ITERS = (2, 2)


def solid(color_srgb, size) -> np.ndarray:
    """An image of one colour.

    Parameters
    ----------
    color_srgb : (3,) float in [0, 1], or str
        sRGB colour, or ``"#rrggbb"``.
    size : (int, int)
        (width, height).
    """
    width, height = _check_size(size)
    try:
        colour = as_srgb(color_srgb)
    except ValueError as exc:
        raise StageError(f"background: {exc}") from None
    return np.tile(colour, (height, width, 1))


def image(path: str | os.PathLike, size) -> np.ndarray:
    """An image file scaled to cover ``size`` = (width, height) and centre-cropped.

    Transparency is composited over white; scaling is bilinear in linear light, with a
    Gaussian pre-filter when shrinking. A missing or unreadable file raises InputError.
    """
    width, height = _check_size(size)
    rgba = read_image(path, channels=4)
    alpha = rgba[:, :, 3:]
    linear = srgb_to_linear(rgba[:, :, :3]) * alpha + (1.0 - alpha)
    return linear_to_srgb(_cover(linear, width, height))


def paper_sample(source_rgb: np.ndarray, source_segment: np.ndarray, *, margin: int = 2) -> np.ndarray:
    """The largest rectangle of the exemplar that is paper in every frame, as an image.

    Parameters
    ----------
    source_rgb : (T, Hs, Ws, 3) float32, sRGB
    source_segment : (T, Hs, Ws) int
        -1 where the exemplar is unpainted.
    margin : int
        Pixels next to paint (within this distance in any frame) do not count as
        paper, so the paint's faint halo stays out of the sample.

    Returns
    -------
    (h, w, 3) float32: per pixel, the median over the frames.

    Raises
    ------
    StageError
        If no such rectangle of at least 16×16 px exists.
    """
    source_rgb = np.asarray(source_rgb, dtype=np.float32)
    if source_rgb.ndim != 4 or source_rgb.shape[3] != 3 or np.shape(source_segment) != source_rgb.shape[:3]:
        raise StageError(f"background: exemplar colour {source_rgb.shape} and segments {np.shape(source_segment)} "
                         "must have shapes (T, H, W, 3) and (T, H, W)")
    painted = (np.asarray(source_segment) >= 0).any(axis=0)
    if margin > 0:
        painted = ndimage.binary_dilation(painted, iterations=int(margin))
    found = largest_rectangle(~painted, min_side=MIN_SAMPLE_SIDE)
    if found is None:
        raise StageError(f"background: the exemplar has no unpainted area of at least {MIN_SAMPLE_SIDE}x"
                         f"{MIN_SAMPLE_SIDE} px to take the paper from; give background.path (a paper image) "
                         "or use a solid background instead")
    top, left, height, width = found
    return np.median(source_rgb[:, top : top + height, left : left + width], axis=0).astype(np.float32)


def largest_rectangle(mask: np.ndarray, *, min_side: int = 1) -> tuple[int, int, int, int] | None:
    """The largest-area axis-aligned rectangle of True pixels with both sides ≥ ``min_side``.

    Every row is the base of a histogram of the True runs above it; the widest span
    under each bar (found with a stack) gives every maximal rectangle once.

    Returns
    -------
    (top, left, height, width), or None if there is none; ties go to the first found
    (topmost bottom row, then leftmost).
    """
    mask = np.asarray(mask, dtype=bool)
    heights = np.zeros(mask.shape[1] + 1, np.int64)  # a zero sentinel empties the stack at each row's end
    best, best_area = None, 0
    for row in range(mask.shape[0]):
        heights[:-1] = np.where(mask[row], heights[:-1] + 1, 0)
        stack = []
        for column, bar in enumerate(heights.tolist()):
            start = column
            while stack and stack[-1][1] >= bar:
                start, tall = stack.pop()
                wide = column - start
                if tall >= min_side and wide >= min_side and tall * wide > best_area:
                    best, best_area = (row - tall + 1, start, tall, wide), tall * wide
            stack.append((start, bar))
    return best


def synthesized(sample: np.ndarray, size, *, seed: int = 0, patch_size: int = 7) -> np.ndarray:
    """A paper texture of ``size`` = (width, height) synthesized from ``sample``.

    Seamless and without repetition (see the module doc); the same sample, size and seed
    give the same image.

    Parameters
    ----------
    sample : (h, w, 3) float32, sRGB
        A paper image, e.g. from :func:`paper_sample`; at least 16×16 px.
    size : (int, int)
    seed : int
    patch_size : int
        Odd patch side.

    Returns
    -------
    (height, width, 3) float32, sRGB.
    """
    width, height = _check_size(size)
    sample = np.ascontiguousarray(sample, dtype=np.float32)
    if sample.ndim != 3 or sample.shape[2] != 3 or min(sample.shape[:2]) < MIN_SAMPLE_SIDE:
        raise StageError(f"background: the paper sample must be an (h, w, 3) image of at least "
                         f"{MIN_SAMPLE_SIDE}x{MIN_SAMPLE_SIDE} px, got shape {sample.shape}")
    if patch_size < 3 or patch_size % 2 == 0:
        raise StageError(f"background: patch_size must be an odd number ≥ 3, got {patch_size}")
    if not 0 <= seed < 2**31:
        raise StageError(f"background: seed must be between 0 and 2^31 − 1, got {seed}")
    levels = levels_that_fit([sample.shape[:2], (height, width)], patch_size=patch_size)
    # No patch centre within a patch radius of the edge at any level (edge-clamped patches
    # show as streaks); levels_that_fit leaves ≥ 2n + 1 px per side, so centres remain.
    band = (patch_size // 2) << (levels - 1)
    segment = np.full((1,) + sample.shape[:2], -1, np.int32)
    segment[:, band : sample.shape[0] - band, band : sample.shape[1] - band] = 0
    variance = 2.0 * float(sample.reshape(-1, 3).var(axis=0).sum())  # mean SSD of two random pixels
    rng = np.random.default_rng(seed)
    blur = _NOISE_BLUR * patch_size
    inputs = SynthesisInputs(
        source_colour=sample[None],
        source_guides=_smooth_noise(sample.shape[:2], blur, rng)[None],
        target_guides=_smooth_noise((height, width), blur, rng),
        colour_weights=np.ones(3, np.float32),
        guide_weights=np.full(_NOISE_CHANNELS, _NOISE_WEIGHT * variance, np.float32),
        source_segment=segment,
    )
    params = SynthesisParams(
        patch_size=patch_size, pyramid_levels=levels, search_vote_iters=_SEARCH_VOTE_ITERS,
        patchmatch_iters=_PATCHMATCH_ITERS, vote_only_finest=True, guided_initialization=True, seed=seed,
    )
    return np.clip(synthesize(inputs, params).image, 0.0, 1.0)


def _smooth_noise(shape, blur, rng):
    """Gaussian-blurred white noise, (H, W, channels) float32 with unit variance."""
    noise = ndimage.gaussian_filter(rng.standard_normal(shape + (_NOISE_CHANNELS,)), (blur, blur, 0), mode="wrap")
    return (noise / noise.std()).astype(np.float32)


def _cover(image, width, height):
    """Resample ``image`` (h, w, C) to (height, width, C), scaled to cover it and centre-cropped."""
    source_height, source_width = image.shape[:2]
    scale = max(width / source_width, height / source_height)
    if scale < 1.0:
        sigma = 0.5 * (1.0 / scale - 1.0)
        image = ndimage.gaussian_filter(image, (sigma, sigma, 0))
    rows = (np.arange(height) + 0.5 - height / 2) / scale + source_height / 2 - 0.5
    columns = (np.arange(width) + 0.5 - width / 2) / scale + source_width / 2 - 0.5
    grid = np.meshgrid(rows, columns, indexing="ij")
    return np.stack([ndimage.map_coordinates(image[:, :, c], grid, order=1, mode="nearest")
                     for c in range(image.shape[2])], axis=-1).astype(np.float32)


def _check_size(size):
    """(width, height) as two positive ints."""
    try:
        width, height = (int(v) for v in size)
    except (TypeError, ValueError):
        raise StageError(f"background: size must be (width, height), got {size!r}") from None
    if width < 1 or height < 1:
        raise StageError(f"background: size must be positive, got {width}x{height}")
    return width, height
