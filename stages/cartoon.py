"""Cartoon synthesis (seed 004, docs/cartoon.md): new frames with a drawn clip's detail and motion.

Every output frame t is a guided patch synthesis (:mod:`fluidymation.engine.synthesis`,
coarse to fine, α = 0.5) from all the clip's frames, minimising eq. 3 over spatio-temporal
neighbourhoods (eq. 5–7): an output patch is compared with a clip patch by

* its colour (premultiplied RGBA, the vote of the current frame),
* its **shape** (the blurred subject mask it should have) and its **position** in the subject's
  rectangle (the sample-relative position feature of eq. 6, so a fish's head stays a head),
* its **temporal neighbourhood**: the ``temporal_size − 1`` previous output frames carried
  along the output's motion, against the clip patch's previous frames carried along the
  clip's motion.

Frame 0 starts from random matches (the seed's noise); every later frame starts from the
previous frame's matches carried along the output's motion and advanced one clip frame along
the clip's motion (the motion constraint of eq. 4 as initialisation), merged per level with
the coarser level's by patch error. What the output frames are, where their subject is and
how it moves, is a :class:`TargetFrame`: :func:`resynth_targets` makes them from the clip's
own global motion pattern (re-synthesis), the ``cartoon`` stylizer from a scene layer
(motion transfer).
"""

from __future__ import annotations

import dataclasses
from typing import Iterable, Iterator, NamedTuple

import numpy as np
from scipy import ndimage

from fluidymation.engine.nnf import NNF
from fluidymation.engine.sampling import sample_back
from fluidymation.engine.shiftnnf import transport_nnf
from fluidymation.engine.synthesis import SynthesisParams, TargetInputs, prepare_source, synthesize_prepared
from fluidymation.stages.cartoon_clip import (
    Clip, apply_affine, box_positions, fit_affine, invert_affine, subject_box,
)
from fluidymation.stages.cartoon_params import Params

NAME = "cartoon"
#: How far (px) past the target subject the voted outline may reach; what patches vote farther out is dropped.
OUTLINE_REACH = 2


class TargetFrame(NamedTuple):
    """What output frame t must be: its subject's ``coverage`` (H, W) in [0, 1], each pixel's ``position``
    (H, W, 2) in the subject's rectangle, and ``flow`` (H, W, 2), the motion into it from frame t−1 (None for
    the first frame)."""

    coverage: np.ndarray
    position: np.ndarray
    flow: np.ndarray | None


class CartoonFrame(NamedTuple):
    """A synthesized frame: ``index``, ``rgba`` (H, W, 4) premultiplied, its ``nnf`` and the ``history`` (k, H, W, 4)
    of the last ``temporal_size − 1`` frames, newest first (what the next frame's neighbourhoods compare)."""

    index: int
    rgba: np.ndarray
    nnf: NNF
    history: np.ndarray


def shape_guide(coverage: np.ndarray, patch_size: int) -> np.ndarray:
    """The subject's coverage blurred over a quarter patch, so nearby shapes still compare."""
    return ndimage.gaussian_filter(np.asarray(coverage, np.float32), patch_size / 4.0)


class CartoonSynthesis:
    """Synthesizes output frames from one analysed :class:`Clip` (its pyramid and features prepared once)."""

    def __init__(self, clip: Clip, params: Params):
        self.clip = clip
        self.params = params
        self.depth = params.temporal_size - 1
        self.synthesis = SynthesisParams(patch_size=params.patch_size, pyramid_levels=params.levels_for(clip),
                                         search_vote_iters=tuple(params.opt_iters),
                                         patchmatch_iters=tuple(params.pm_iters), alpha=0.5, seed=params.seed)
        colour = clip.colour
        guides = [np.stack([shape_guide(frame[..., 3], params.patch_size) for frame in colour])[..., None],
                  np.stack([clip.positions(index) for index in range(clip.frame_count)])]
        guides += clip_history(colour, clip.motion, self.depth)
        low = np.r_[0.0, -0.5, -0.5, np.zeros(4 * self.depth)]
        high = np.r_[1.0, 1.5, 1.5, np.ones(4 * self.depth)]
        segment = np.where(colour[..., 3] >= 0.5, 0, -1).astype(np.int32)
        self.prepared = prepare_source(colour, np.concatenate(guides, axis=-1), source_segment=segment,
                                       guide_range=(low, high), params=self.synthesis)
        self.colour_weights = np.full(4, params.w_colour, np.float32)

    def frame(self, index: int, target: TargetFrame, previous: CartoonFrame | None) -> CartoonFrame:
        """Output frame ``index`` after ``previous`` (None: a fresh start)."""
        params = self.params
        carried = []
        initial = None
        if previous is not None and target.flow is not None:
            carried = [sample_back(frame, target.flow).astype(np.float32) for frame in previous.history]
            initial = advance_in_clip(transport_nnf(previous.nnf, target.flow)[0], self.clip)
        height, width = target.coverage.shape
        history = np.zeros((self.depth, height, width, 4), np.float32)
        for k, frame in enumerate(carried[:self.depth]):
            history[k] = frame
        guide_weights = np.r_[params.w_shape, np.full(2, params.w_position),
                              np.repeat([params.w_temporal if k < len(carried) else 0.0 for k in range(self.depth)], 4)]
        guides = np.concatenate([shape_guide(target.coverage, params.patch_size)[..., None], target.position,
                                 history.transpose(1, 2, 0, 3).reshape(height, width, 4 * self.depth)], axis=-1)
        segment = np.where(target.coverage >= 0.5, 0, -1).astype(np.int32)
        if not (segment >= 0).any():
            rgba = np.zeros((height, width, 4), np.float32)
            nnf = NNF.empty(height, width)
        else:
            inputs = TargetInputs(target_guides=guides.astype(np.float32), colour_weights=self.colour_weights,
                                  guide_weights=guide_weights.astype(np.float32), target_segment=segment,
                                  initial_nnf=initial)
            synthesis = dataclasses.replace(self.synthesis, seed=(params.seed * 1_000_003 + index) % 2 ** 31,
                                            **({} if initial is not None else {"search_vote_iters": params.fresh_iters}))
            result = synthesize_prepared(self.prepared, inputs, synthesis)
            rgba = np.clip(result.image, 0.0, 1.0).astype(np.float32)
            rgba[..., :3] = np.minimum(rgba[..., :3], rgba[..., 3:])
            rgba *= ndimage.binary_dilation(segment >= 0, iterations=OUTLINE_REACH)[..., None]  # no stray specks
            nnf = result.nnf
        newest = np.concatenate([rgba[None], history[:-1]]) if self.depth else history
        return CartoonFrame(index, rgba, nnf, newest)


def clip_history(colour: np.ndarray, motion: np.ndarray, depth: int) -> list[np.ndarray]:
    """For each clip frame f, frames f−1 … f−depth carried to f along the clip's motion, each (T, H, W, 4)
    (frames before the first stay the first)."""
    history = []
    earlier = colour
    for _ in range(depth):
        moved = np.empty_like(colour)
        moved[0] = earlier[0]
        for index in range(1, colour.shape[0]):
            moved[index] = sample_back(earlier[index - 1], motion[index])
        history.append(moved)
        earlier = moved
    return history


def advance_in_clip(nnf: NNF, clip: Clip) -> NNF:
    """Eq. 4 on matches: each match (f, x, y) moved one clip frame on along the clip's motion, (f+1, (x, y) +
    motion); past the last frame the clip loops to frame 1, carried there by the map between the last frame's and
    the first frame's geometry samples. Matches that land off the subject are dropped."""
    count = clip.frame_count
    height, width = clip.colour.shape[1:3]
    frame = nnf.frame.copy()
    coords = nnf.coords.copy()
    matched = frame >= 0
    f = frame[matched].astype(np.int64)
    x = coords[..., 0][matched].astype(np.float64)
    y = coords[..., 1][matched].astype(np.float64)
    wrap = f + 1 >= count
    if wrap.any():
        x[wrap], y[wrap] = apply_affine(fit_affine(clip.samples[count - 1], clip.samples[0]), x[wrap], y[wrap])
    nxt = np.where(wrap, 1, f + 1)
    xi = np.clip(np.rint(x), 0, width - 1).astype(np.int64)
    yi = np.clip(np.rint(y), 0, height - 1).astype(np.int64)
    x = np.clip(x + clip.motion[nxt, yi, xi, 0], 0, width - 1)
    y = np.clip(y + clip.motion[nxt, yi, xi, 1], 0, height - 1)
    on_subject = clip.colour[nxt, np.rint(y).astype(np.int64), np.rint(x).astype(np.int64), 3] >= 0.5
    frame[matched] = np.where(on_subject, nxt, -1).astype(np.int32)
    coords[..., 0][matched] = x
    coords[..., 1][matched] = y
    return NNF(frame, coords)


def synthesize_frames(synthesis: CartoonSynthesis, targets: Iterable[tuple[int, TargetFrame]],
                      previous: CartoonFrame | None = None) -> Iterator[CartoonFrame]:
    """The frames of ``targets`` ((index, target) in order), each after the one before (``previous`` first)."""
    for index, target in targets:
        previous = synthesis.frame(index, target, previous)
        yield previous


# ---------------------------------------------------------------------------------------------- re-synthesis


def clip_time(index: int, count: int) -> int:
    """The clip frame whose geometry and motion output frame ``index`` takes: the clip once through, then looping
    over frames 1 … T−1 (each loop's first step is the clip's first)."""
    return index if index < count else 1 + (index - 1) % (count - 1)


class ResynthPath:
    """The output's global motion (eq. 4 on the geometry samples): the samples start where the clip's do and move
    by the velocities of the clip frames :func:`clip_time` picks; output frame t is clip frame τ(t) mapped by the
    affine fitted from its samples to the output's."""

    def __init__(self, clip: Clip, frames: int):
        self.clip = clip
        velocities = clip.velocities
        samples = [clip.samples[0]]
        for index in range(1, frames):
            samples.append(samples[-1] + velocities[clip_time(index, clip.frame_count)])
        self.samples = np.array(samples)

    def mapping(self, index: int) -> np.ndarray:
        """The affine from clip frame τ(index) to output frame ``index``."""
        return fit_affine(self.clip.samples[clip_time(index, self.clip.frame_count)], self.samples[index])

    def target(self, index: int) -> TargetFrame:
        clip = self.clip
        tau = clip_time(index, clip.frame_count)
        height, width = clip.colour.shape[1:3]
        ys, xs = np.mgrid[:height, :width].astype(np.float64)
        cx, cy = apply_affine(invert_affine(self.mapping(index)), xs, ys)  # where each output pixel is in the clip
        coverage = ndimage.map_coordinates(clip.colour[tau, ..., 3], [cy, cx], order=1, mode="constant", cval=0.0)
        position = box_positions(cx, cy, clip.boxes[tau])
        flow = None
        if index > 0:
            motion = [ndimage.map_coordinates(clip.motion[tau, ..., c], [cy, cx], order=1, mode="nearest")
                      for c in range(2)]
            before = fit_affine(clip.samples[tau - 1], self.samples[index - 1])  # clip frame τ−1 → output t−1
            px, py = apply_affine(before, cx - motion[0], cy - motion[1])
            flow = np.stack([xs - px, ys - py], axis=-1).astype(np.float32)
        return TargetFrame(coverage.astype(np.float32), position, flow)


def layer_target(coverage: np.ndarray, flow: np.ndarray | None) -> TargetFrame:
    """A scene layer's frame as a target (motion transfer): its coverage, positions in its own rectangle and its
    own motion."""
    height, width = coverage.shape
    box = subject_box(coverage)
    ys, xs = np.mgrid[:height, :width].astype(np.float32)
    position = box_positions(xs, ys, box if box is not None else np.array([0, 0, width, height]))
    return TargetFrame(np.asarray(coverage, np.float32), position, flow)


def straight(rgba: np.ndarray) -> np.ndarray:
    """Premultiplied RGBA made straight (colour 0 where alpha is 0)."""
    alpha = rgba[..., 3:]
    rgb = np.where(alpha > 1e-6, rgba[..., :3] / np.maximum(alpha, 1e-6), 0.0)
    return np.concatenate([np.clip(rgb, 0.0, 1.0), alpha], axis=-1).astype(np.float32)
