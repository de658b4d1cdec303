"""User exemplars: a recording of a real medium (video file or image sequence) and its masks.

Frames come from a video (decoded by imageio-ffmpeg), an image sequence (a folder, a
glob pattern such as ``frames/*.png`` or a printf pattern such as ``frames/%04d.png``)
or one still image (a recording of one frame).
Masks come from an image sequence with one image per source frame, ``"full"`` (paint
everywhere: a painting that fills its canvas), or ``"auto"``:
the paper colour is the median of a band along the frame's borders, pixels farther
from it than a threshold are paint, small specks are removed and holes filled, and the
result is blurred and thresholded (thesis 4.1) so its outline is smooth. The source
frames are then cut to ``[start, end)``, every ``step``-th kept, optionally reversed
and scaled.
"""

from __future__ import annotations

import gc
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy import ndimage

from fluidymation.engine.motion import motion_sequence
from fluidymation.errors import InputError, StageError
from fluidymation.stages.files import read_image, sequence_paths

NAME = "exemplar_user"
VERSION = 1

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp", ".webp")
VIDEO_SUFFIXES = (".mp4", ".mov", ".m4v", ".mkv", ".avi", ".webm", ".gif")


@dataclass(frozen=True)
class Params:
    """How to read a user exemplar.

    ``source`` is a video file or an image sequence; ``mask`` an image sequence or
    ``"auto"``; ``start``/``end`` (end exclusive, ``None`` = to the last frame) and
    ``step`` select source frames; ``scale`` resizes; ``reverse`` plays backwards.
    ``mask_threshold`` is the colour distance (RGB in [0, 1]) above which a pixel is
    paint (``None``: from the noise of the border band); ``mask_blur`` (px, after
    scaling) and ``mask_level`` smooth the automatic mask; ``border`` is the width
    of the band the paper colour is taken from, as a share of the smaller side.
    """

    source: str
    mask: str = "auto"
    scale: float = 1.0
    step: int = 1
    start: int = 0
    end: int | None = None
    reverse: bool = False
    mask_threshold: float | None = None
    mask_blur: float = 2.0
    mask_level: float = 0.5
    border: float = 0.04

    def __post_init__(self):
        if not 0.01 <= self.scale <= 8.0:
            raise StageError(f"exemplar scale must be between 0.01 and 8, got {self.scale}")
        if self.step < 1:
            raise StageError(f"exemplar step must be a positive whole number, got {self.step}")
        if self.start < 0 or (self.end is not None and self.end <= self.start):
            raise StageError(f"exemplar frames must satisfy 0 <= start < end, got start={self.start}, end={self.end}")
        if self.mask_threshold is not None and not 0.0 < self.mask_threshold < 2.0:
            raise StageError(f"exemplar mask_threshold must be in (0, 2), got {self.mask_threshold}")
        if self.mask_blur < 0 or not 0.0 < self.mask_level < 1.0 or not 0.0 < self.border < 0.5:
            raise StageError("exemplar mask_blur must be >= 0, mask_level in (0, 1) and border in (0, 0.5)")


@dataclass(frozen=True)
class UserExemplar:
    """``rgb`` (T, H, W, 3) float32 in [0, 1], ``mask`` (T, H, W) bool, the ``paper``
    colour (3,) float32 (median of the border bands) and the source frame index of
    each frame (``source_frames``, (T,) int)."""

    rgb: np.ndarray
    mask: np.ndarray
    paper: np.ndarray
    source_frames: np.ndarray


def load_user_exemplar(params: Params) -> UserExemplar:
    """Read, select, mask and scale a user exemplar (see the module doc)."""
    frames = _read_frames(params.source)
    if not frames:
        raise InputError(f"{params.source}: no frames found")
    indices = _selected_indices(len(frames), params)
    shape = frames[0].shape
    for number, frame in enumerate(frames):
        if frame.shape != shape:
            raise InputError(f"{params.source}: frame {number} is {frame.shape[1]}x{frame.shape[0]}, "
                             f"frame 0 is {shape[1]}x{shape[0]}; all frames must have one size")
    rgb = np.stack([frames[i] for i in indices])
    band = _border_band(shape[:2], params.border)
    paper = np.median(rgb[:, band].reshape(-1, 3), axis=0).astype(np.float32)
    if params.mask == "auto":
        masks = np.stack([_auto_mask(frame, band, params) for frame in rgb])
        origin = f"{params.source} (mask: auto)"
    elif params.mask == "full":
        masks = np.ones(rgb.shape[:3], bool)
        origin = params.source
    else:
        masks = _read_masks(params.mask, len(frames), shape[:2], params.source)[indices]
        origin = params.mask
    if params.scale != 1.0:
        rgb = np.stack([_resize(frame, params.scale) for frame in rgb])
        masks = np.stack([_resize(mask.astype(np.float32), params.scale) > 0.5 for mask in masks])
    if not masks.any():
        hint = " (lower mask_threshold?)" if params.mask == "auto" else ""
        raise InputError(f"{origin}: the mask is empty in every selected frame{hint}")
    return UserExemplar(rgb=np.clip(rgb, 0.0, 1.0).astype(np.float32), mask=masks, paper=paper,
                        source_frames=np.asarray(indices, dtype=np.int64))


def _selected_indices(count, params):
    end = count if params.end is None else params.end
    if params.start >= count:
        raise InputError(f"{params.source}: start frame {params.start} is past the last frame ({count - 1})")
    if end > count:
        raise InputError(f"{params.source}: end frame {end} is past the frame count ({count})")
    indices = list(range(params.start, end, params.step))
    return indices[::-1] if params.reverse else indices


# --------------------------------------------------------------------------- reading


def image_sequence(spec: str) -> list[Path]:
    """Image files of a sequence: a folder (its images), a glob or a printf pattern, in order."""
    path = Path(spec)
    if path.is_dir():
        return [p for p in sequence_paths(str(path / "*")) if p.suffix.lower() in IMAGE_SUFFIXES]
    return [p for p in sequence_paths(spec) if not p.is_dir()]  # a pattern's folders are no frames


def _read_frames(spec: str) -> list[np.ndarray]:
    path = Path(spec)
    if path.is_file() and path.suffix.lower() in VIDEO_SUFFIXES:
        return _read_video(path)
    if path.is_file() and path.suffix.lower() in IMAGE_SUFFIXES:
        return [read_image(path, channels=3)]  # a still: a recording of one frame
    if path.is_file():
        raise InputError(f"{spec}: not a video ({', '.join(VIDEO_SUFFIXES)}), an image ({', '.join(IMAGE_SUFFIXES)}) "
                         "nor an image sequence (a folder, a glob like frames/*.png, or a pattern like frames/%04d.png)")
    files = image_sequence(spec)
    if not files:
        raise InputError(f"{spec}: no such video and no images match it as a sequence "
                         "(a folder, a glob like frames/*.png, or a pattern like frames/%04d.png)")
    return [read_image(file, channels=3) for file in files]


def _read_video(path: Path) -> list[np.ndarray]:
    import imageio_ffmpeg

    frames, error = [], None
    with warnings.catch_warnings():
        # imageio-ffmpeg leaves ffmpeg's stderr pipe for the garbage collector to close.
        warnings.simplefilter("ignore", ResourceWarning)
        reader = imageio_ffmpeg.read_frames(str(path))
        try:
            width, height = next(reader)["size"]
            for data in reader:
                frames.append(np.frombuffer(data, dtype=np.uint8).reshape(height, width, 3).astype(np.float32) / 255.0)
        except (OSError, RuntimeError, StopIteration, KeyError, ValueError) as exc:
            error = str(exc)  # raised below: this exception's traceback holds the ffmpeg process and its pipes
        finally:
            reader.close()
        gc.collect()  # the pipes are closed here, where their ResourceWarning is ignored
    if error is not None:
        raise InputError(f"{path}: cannot decode the video ({error})")
    return frames


def _read_masks(spec, count, shape, source) -> np.ndarray:
    files = image_sequence(spec)
    if not files:
        raise InputError(f"{spec}: no mask images found (a folder, a glob or a %04d pattern, or `auto`)")
    if len(files) != count:
        raise InputError(f"{spec}: {len(files)} mask images but {count} frames in {source}; "
                         "give one mask per source frame")
    masks = []
    for file in files:
        image = read_image(file, channels=1)[:, :, 0]
        if image.shape != shape:
            raise InputError(f"{file}: mask is {image.shape[1]}x{image.shape[0]} but the frames of {source} are "
                             f"{shape[1]}x{shape[0]}")
        masks.append(image > 0.5)
    return np.stack(masks)


# --------------------------------------------------------------------------- masks


def _border_band(shape, share):
    width = max(1, round(share * min(shape)))
    band = np.zeros(shape, dtype=bool)
    band[:width, :] = band[-width:, :] = True
    band[:, :width] = band[:, -width:] = True
    return band


def _auto_mask(frame, band, params):
    """Paint where the colour differs from the paper (border median); cleaned and smoothed."""
    paper = np.median(frame[band], axis=0)
    distance = np.sqrt(((frame - paper) ** 2).sum(axis=2))
    threshold = params.mask_threshold
    if threshold is None:
        noise = distance[band]
        threshold = max(0.05, float(np.quantile(noise, 0.99)) + 0.03)
    paint = distance > threshold
    paint = ndimage.binary_opening(paint, iterations=1)
    labels, count = ndimage.label(paint)
    if count:
        sizes = ndimage.sum(paint, labels, index=np.arange(1, count + 1))
        keep = np.zeros(count + 1, dtype=bool)
        keep[1:] = sizes >= max(4, 1e-4 * paint.size)
        paint = keep[labels]
    paint = ndimage.binary_fill_holes(paint)
    sigma = params.mask_blur / params.scale
    if sigma > 0:
        paint = ndimage.gaussian_filter(paint.astype(np.float32), sigma) > params.mask_level
    return paint


def _resize(image, scale):
    """Bilinear resize by ``scale`` with a Gaussian pre-filter when shrinking."""
    if scale < 1.0:
        sigma = 0.5 * (1.0 / scale - 1.0)
        image = ndimage.gaussian_filter(image, (sigma, sigma) + (0,) * (image.ndim - 2))
    height, width = image.shape[:2]
    out_h, out_w = max(1, round(height * scale)), max(1, round(width * scale))
    rows = (np.arange(out_h) + 0.5) * height / out_h - 0.5
    cols = (np.arange(out_w) + 0.5) * width / out_w - 0.5
    grid = np.meshgrid(rows, cols, indexing="ij")
    if image.ndim == 2:
        return ndimage.map_coordinates(image, grid, order=1, mode="nearest").astype(np.float32)
    return np.stack([ndimage.map_coordinates(image[:, :, c], grid, order=1, mode="nearest")
                     for c in range(image.shape[2])], axis=-1).astype(np.float32)


def motion_flow(rgb: np.ndarray, *, seed: int = 0, progress=None) -> np.ndarray:
    """Flow of a recording estimated from its frames (``flow: motion``), not its masks.

    For media whose masks do not show how the paint moves (paper's exemplar 04). Grid
    PatchMatch between consecutive frames (:func:`fluidymation.engine.motion.estimate_motion`);
    ``flow[k]`` is the motion from frame k−1 to k, and frame 0 takes frame 1's.

    Parameters
    ----------
    rgb : (T, H, W, 3) float32
    progress : callable, optional
        ``progress(done, total)`` after each frame pair.

    Returns
    -------
    (T, H, W, 2) float32, px/frame, y down.
    """
    if rgb.shape[0] < 2:
        return np.zeros(rgb.shape[:3] + (2,), np.float32)
    return motion_sequence(rgb, seed=seed, progress=progress)
