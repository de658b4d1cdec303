"""A drawn clip as the cartoon method sees it (seed 004, docs/cartoon.md): its subject, motion and geometry.

A *clip* is a short hand-drawn or raster animation of one subject on a still background
(a video, an image folder or a pattern, read like a recorded exemplar). Its analysis:

* the **subject** of each frame: its mask (``auto`` or given), as the alpha of premultiplied RGBA;
* the **motion** between consecutive frames by grid PatchMatch
  (:func:`fluidymation.engine.motion.estimate_motion`; the seed's grid spacing d, search
  radius r, iterations n and block size w);
* the **geometry samples** of each frame (:func:`geometry_samples`): the centre of the
  subject's bounding rectangle and the farthest subject point along each of the eight rays
  from it at 45° steps;
* the **global motion pattern**: the samples' velocities between frames (eq. 2, :attr:`Clip.velocities`).

Clips the method cannot take are refused naming the frame: fewer than two frames, a frame
without a subject or with nothing but subject, and a moving background (the seed's limit).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from fluidymation.engine.motion import motion_sequence
from fluidymation.errors import InputError

#: The eight directions of the geometry samples, 45° apart (y down).
RAY_ANGLES = np.arange(8) * (np.pi / 4)
#: A background pixel "moves" when a channel changes by more than this between frames ...
BACKGROUND_CHANGE = 0.12
#: ... and the background moves when more than this share of its pixels do.
BACKGROUND_MOVING_SHARE = 0.02
#: A frame whose subject covers more than this share of it has no background to tell it from.
FULL_FRAME_SHARE = 0.95


@dataclass(frozen=True)
class MotionParams:
    """Grid PatchMatch of the clip's motion: grid spacing ``d`` px, ``search_radius`` r px per frame,
    ``iterations`` n and the odd block side ``patch_size`` (the seed's 3, 8, 70 and 16, made odd)."""

    spacing: int = 3
    search_radius: int = 8
    iterations: int = 70
    patch_size: int = 17


_ARRAYS = ("colour", "motion", "samples", "boxes")


@dataclass(frozen=True)
class Clip:
    """An analysed clip of T frames of H×W.

    ``colour`` (T, H, W, 4) float32 premultiplied RGBA, the subject's mask as alpha;
    ``motion`` (T, H, W, 2) float32: ``motion[k]`` brought frame k−1's material to frame k
    (frame 0 takes frame 1's); ``samples`` (T, 9, 2) the geometry samples (x, y);
    ``boxes`` (T, 4) each frame's subject rectangle (x0, y0, x1, y1), exclusive ends.
    """

    colour: np.ndarray
    motion: np.ndarray
    samples: np.ndarray
    boxes: np.ndarray

    @property
    def frame_count(self) -> int:
        return self.colour.shape[0]

    @property
    def velocities(self) -> np.ndarray:
        """Eq. 2: each sample's velocity into each frame, px/frame, (T, 9, 2); zero for frame 0."""
        velocity = np.zeros_like(self.samples)
        velocity[1:] = np.diff(self.samples, axis=0)
        return velocity

    def positions(self, frame: int) -> np.ndarray:
        """Each pixel of ``frame`` in its subject's rectangle, (H, W, 2) in [0, 1) across the rectangle."""
        height, width = self.colour.shape[1:3]
        ys, xs = np.mgrid[:height, :width].astype(np.float32)
        return box_positions(xs, ys, self.boxes[frame])

    def save(self, path) -> None:
        np.savez(path, **{name: getattr(self, name) for name in _ARRAYS})

    @classmethod
    def load(cls, path) -> Clip:
        with np.load(path) as stored:
            return cls(**{name: stored[name] for name in _ARRAYS})


def box_positions(xs: np.ndarray, ys: np.ndarray, box: np.ndarray) -> np.ndarray:
    """Points (xs, ys) in the coordinates of rectangle ``box`` = (x0, y0, x1, y1): 0 at its start, 1 at its end."""
    x0, y0, x1, y1 = (float(value) for value in box)
    return np.stack([(xs - x0) / max(x1 - x0, 1.0), (ys - y0) / max(y1 - y0, 1.0)], axis=-1).astype(np.float32)


def subject_box(alpha: np.ndarray) -> np.ndarray | None:
    """The rectangle (x0, y0, x1, y1) of the pixels with ``alpha`` ≥ 0.5, exclusive ends; None when there are none."""
    rows = np.flatnonzero((alpha >= 0.5).any(axis=1))
    if rows.size == 0:
        return None
    columns = np.flatnonzero((alpha >= 0.5).any(axis=0))
    return np.array([columns[0], rows[0], columns[-1] + 1, rows[-1] + 1], np.float64)


def geometry_samples(alpha: np.ndarray, box: np.ndarray) -> np.ndarray:
    """The seed's geometry samples of one frame (Fig. 5), (9, 2) px: the centre of the subject's rectangle, then
    along each ray at :data:`RAY_ANGLES` the farthest point where ``alpha`` falls through 0.5 (linearly
    interpolated between half-pixel steps; the rectangle's edge when the ray meets no subject)."""
    x0, y0, x1, y1 = box
    centre = np.array([(x0 + x1 - 1) / 2.0, (y0 + y1 - 1) / 2.0])
    reach = np.hypot(x1 - x0, y1 - y0)
    steps = np.arange(0.0, reach + 0.5, 0.5)
    points = [centre]
    for angle in RAY_ANGLES:
        direction = np.array([np.cos(angle), np.sin(angle)])
        along = centre[None] + steps[:, None] * direction[None]
        values = ndimage.map_coordinates(alpha, [along[:, 1], along[:, 0]], order=1, mode="constant", cval=0.0)
        inside = np.flatnonzero(values >= 0.5)
        if inside.size == 0:
            limit = min(_ray_to_edge(centre, direction, box), reach)
            points.append(centre + limit * direction)
            continue
        last = inside[-1]
        distance = steps[last]
        if last + 1 < steps.size:  # the 0.5 crossing between the last inside step and the next
            distance += 0.5 * (values[last] - 0.5) / max(values[last] - values[last + 1], 1e-9)
        points.append(centre + distance * direction)
    return np.array(points)


def _ray_to_edge(centre, direction, box):
    """How far from ``centre`` along ``direction`` the rectangle's edge lies (its last pixel centres)."""
    x0, y0, x1, y1 = box
    limits = []
    for axis, low, high in ((0, x0, x1 - 1), (1, y0, y1 - 1)):
        if abs(direction[axis]) > 1e-9:
            edge = high if direction[axis] > 0 else low
            limits.append((edge - centre[axis]) / direction[axis])
    return max(0.0, min(limits))


def fit_affine(source: np.ndarray, target: np.ndarray) -> np.ndarray:
    """The (2, 3) affine map taking points ``source`` (n, 2) closest to ``target`` (least squares); a
    translation by the mean difference when the source points are (nearly) on a line."""
    source = np.asarray(source, np.float64)
    target = np.asarray(target, np.float64)
    centred = source - source.mean(axis=0)
    singular = np.linalg.svd(centred, compute_uv=False)
    if singular.size < 2 or singular[1] < 1e-6 * max(singular[0], 1e-12) or singular[1] < 1e-3:
        return np.hstack([np.eye(2), (target.mean(axis=0) - source.mean(axis=0))[:, None]])
    design = np.hstack([source, np.ones((len(source), 1))])
    solution, *_ = np.linalg.lstsq(design, target, rcond=None)
    return solution.T


def apply_affine(affine: np.ndarray, xs: np.ndarray, ys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points (xs, ys) mapped by a (2, 3) affine."""
    return (affine[0, 0] * xs + affine[0, 1] * ys + affine[0, 2],
            affine[1, 0] * xs + affine[1, 1] * ys + affine[1, 2])


def invert_affine(affine: np.ndarray) -> np.ndarray:
    linear = np.linalg.inv(affine[:, :2])
    return np.hstack([linear, -linear @ affine[:, 2:]])


def analyse_clip(rgb: np.ndarray, mask: np.ndarray, *, name: str,
                 motion: MotionParams = MotionParams(), seed: int = 0, progress=None) -> Clip:
    """Subject, motion and geometry of a clip (see the module doc).

    ``rgb`` (T, H, W, 3) in [0, 1], ``mask`` (T, H, W) bool; ``name`` (the clip's path) is in
    every error; ``progress(done, total)`` after each frame pair's motion.
    """
    count = rgb.shape[0]
    if count < 2:
        raise InputError(f"{name}: a clip needs at least 2 frames to have a motion, it has {count}")
    boxes = []
    for index, frame_mask in enumerate(mask):
        share = float(frame_mask.mean())
        box = subject_box(frame_mask.astype(np.float32))
        if box is None:
            raise InputError(f"{name}: frame {index}: no subject found (its mask is empty; give the subject's masks "
                             "with --mask FOLDER, or a clip with a drawing on a plain background)")
        if share > FULL_FRAME_SHARE:
            raise InputError(f"{name}: frame {index}: the subject covers {share:.0%} of the frame, so there is no "
                             "background to tell it from; give its masks with --mask FOLDER")
        boxes.append(box)
    _check_still_background(rgb, mask, name)
    alpha = mask.astype(np.float32)
    colour = np.concatenate([rgb * alpha[..., None], alpha[..., None]], axis=-1).astype(np.float32)
    flow = motion_sequence(rgb, spacing=motion.spacing, patch_size=motion.patch_size,
                           search_radius=motion.search_radius, iterations=motion.iterations, seed=seed,
                           progress=progress)
    samples = np.stack([geometry_samples(alpha[index], boxes[index]) for index in range(count)])
    return Clip(colour=colour, motion=flow, samples=samples, boxes=np.array(boxes))


def _check_still_background(rgb, mask, name):
    """Refuse a clip whose background changes between frames (away from the subject in both)."""
    margin = 3
    for index in range(1, rgb.shape[0]):
        background = ~ndimage.binary_dilation(mask[index - 1] | mask[index], iterations=margin)
        pixels = int(background.sum())
        if pixels < 0.01 * background.size:
            continue
        changed = (np.abs(rgb[index] - rgb[index - 1]).max(axis=-1) > BACKGROUND_CHANGE) & background
        share = changed.sum() / pixels
        if share > BACKGROUND_MOVING_SHARE:
            raise InputError(f"{name}: frame {index}: the background moves ({share:.0%} of it changes from frame "
                             f"{index - 1}); cartoon re-synthesis needs a drawing on a still background")
