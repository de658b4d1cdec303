"""The ``stylize`` stage: Fluidymation synthesis of one layer, frame by frame.

Every target frame is synthesized from patches of the whole moving exemplar
(paper section 3, appendix B; thesis chapter 3, sections 4.2–4.4; ALGORITHM.md) with the
patch distance

    |rgb|² + w_bound |shape|² + w_edge |df|² + w_ext (|ext+|² + |ext−|²) + m(q) w_temp |temp|²
    + w_dir |tan(S_dir − θ − T_dir)| + w_uni λ Ω/ω*

(ext± divided by ``ext_unit``; ext+ and ext− swapped where source and target flows are
opposite), segment-restricted matching (border/interior), two flow-aligned rotations per
candidate, and the per-segment 3D uniformity budget. The first synthesized frame starts
from a random field refined by a guides-only pass, then is synthesized ``settle_passes``
more times with itself as the previous frame (beyond the paper); every later frame starts from
``NNF_prev = SHIFTNNF(NNF_{j−1})``, merged per pyramid level with the upscaled field,
and its temporal guide is the exemplar voted through ``NNF_prev``, weighted by m(q).

Frames are processed in order (or from the last to the first with ``reverse``); the
target guides are computed over the whole sequence in processing order and streamed
from an on-disk cache, so memory does not grow with the number of frames. With
``source_window`` only that many consecutive exemplar frames are read (from a
:class:`~fluidymation.stages.exemplar_store.StoredSource`) and prepared at a time, sliding along the exemplar as the frames
are processed, so memory does not grow with the exemplar's length either.
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass
from typing import Callable, Iterator, NamedTuple

import numpy as np
from scipy import ndimage

from fluidymation.engine.nnf import NNF
from fluidymation.engine.random import counter_hash
from fluidymation.engine.sampling import sample_back
from fluidymation.engine.shiftnnf import shift_nnf, temporal_modulation, transport_nnf
from fluidymation.engine.synthesis import SynthesisParams, TargetInputs, concatenate_prepared, synthesize_prepared
from fluidymation.engine.synthesis import prepare_source as prepare_engine_source
from fluidymation.engine.vote import vote
from fluidymation.errors import StageError
from fluidymation.stages import guides
from fluidymation.stages.exemplar_store import Source, StoredSource, border_clamped, concatenate
from fluidymation.stages.stylize_params import Params

NAME = "stylize"

#: Target guide channels, in order; the source compares shape, ext+, ext− and its colour (as S_temp).
_GUIDES = ("shape", "edge", "ext_plus", "ext_minus", "temp_r", "temp_g", "temp_b")
_OPPOSITE = np.array([0, 1, 3, 2, 4, 5, 6], np.int64)
_WEIGHT_MAP = np.array([-1, -1, -1, -1, 0, 0, 0], np.int64)



def parameter_names() -> tuple[str, ...]:
    """Names of every stylize parameter."""
    return tuple(field.name for field in dataclasses.fields(Params))


def window_start(step: int, steps: int, exemplar_frames: int, window: int) -> int:
    """First exemplar frame of the source window at processing step ``step`` of ``steps``.

    The window slides evenly, from the exemplar's first ``window`` frames at step 0 to
    its last ones at step ``steps − 1`` (rounded to the nearest frame): a pure function of
    the step, so partial, resumed and whole runs use the same windows.
    """
    span = max(exemplar_frames - window, 0)
    last = max(steps - 1, 1)
    return (2 * step * span + last) // (2 * last)


class StylizedFrame(NamedTuple):
    """One synthesized frame: its index in the sequence, RGBA (H, W, 4) float32 and the NNF.

    ``backlog`` (H, W) float32 is the motion not yet followed, carried to the next frame;
    with ``nnf`` it is the state a resumed run needs (``stylize_sequence(resume=...)``).
    """

    index: int
    rgba: np.ndarray
    nnf: NNF
    backlog: np.ndarray


def stylize_sequence(
    masks: Callable[[int], np.ndarray],
    frame_count: int,
    source: Source | StoredSource,
    *,
    params: Params,
    guide_params: guides.Params,
    cache_dir,
    frames: tuple[int, int] | None = None,
    resume: tuple[int, NNF, np.ndarray] | None = None,
    given_flow: Callable[[int], np.ndarray] | None = None,
) -> Iterator[StylizedFrame]:
    """Stylize a layer's mask sequence; yield each frame as soon as it is done.

    Parameters
    ----------
    masks : callable
        ``masks(j)`` gives frame j's (H, W) coverage in [0, 1] (float) or bool; it becomes
        the alpha channel (soft edges) and, through the guides, the target.
    frame_count : int
        Frames of the whole sequence (the guides span all of them).
    source : Source or StoredSource
        The exemplar; with ``params.source_window`` only the window's frames are read
        (from a :class:`~fluidymation.stages.exemplar_store.StoredSource`) and prepared at a time.
    params : Params
    guide_params : guides.Params
        Must be the parameters the source's guides were made with.
    cache_dir : path
        Folder for the target guides cache.
    frames : (first, stop), optional
        Only synthesize sequence frames first..stop−1 (the first one processed starts
        afresh). Default: all.
    resume : (index, nnf, backlog, rgb), optional
        Continue after the already processed frame ``index`` (one of ``frames``) from its
        :class:`StylizedFrame` ``nnf``, ``backlog`` and colour ``rgba[..., :3]``; the frames yielded are then exactly
        those an uninterrupted run yields after ``index``.
    given_flow : callable, optional
        ``given_flow(j)``: frame j's motion (H, W, 2), NaN where unknown (the masks' estimate
        fills in; :func:`~fluidymation.stages.guides.compute_guides`). Not used with
        ``params.reverse`` (the motion of a reversed sequence is the masks' estimate).

    Yields
    ------
    StylizedFrame
        In processing order (descending indices with ``reverse``); its NNF numbers
        exemplar frames from the exemplar's first, whatever the window.
    """
    first, stop = (0, frame_count) if frames is None else frames
    if not 0 <= first < stop <= frame_count:
        raise StageError(f"stylize: frames {first}:{stop} outside 0:{frame_count}")
    order = list(range(frame_count - 1, -1, -1)) if params.reverse else list(range(frame_count))
    flow = None if given_flow is None or params.reverse else given_flow
    target = guides.compute_guides(lambda k: masks(order[k]), frame_count, params=guide_params, cache_dir=cache_dir,
                                   given_flow=flow)
    steps = [k for k in range(frame_count) if first <= order[k] < stop]
    previous = None
    if resume is not None:
        done = resume[0]
        done_step = next((k for k in steps if order[k] == done), None)
        if done_step is None:
            raise StageError(f"stylize: cannot resume after frame {done}, which is not among frames {first}:{stop}")
        previous = _resumed(resume, target.frame(done_step), masks(done), (target.height, target.width))
        steps = steps[steps.index(done_step) + 1:]
    sequence = _Sequence.set_up(target, source, params)
    for k in steps:
        stylized, previous = _stylize_step(sequence, k, order[k], masks(order[k]), previous)
        yield stylized


class _Previous(NamedTuple):
    """The frame processed before, as the next step continues from it."""

    nnf: NNF  #: its matches, in exemplar frame numbers
    inside: np.ndarray  #: (H, W) bool, where the layer covers it
    ext_plus: np.ndarray  #: (H, W) float32, its ext+ guide: the motion since is measured from it
    backlog: np.ndarray  #: (H, W) float32, the motion it has not yet followed
    #: (H, W, 3) its colour, kept where its paint is unchanged (None while it settles; NaN where carried, moved)
    rgb: np.ndarray | None


def _resumed(resume: tuple, frame: guides.FrameGuides, mask, shape: tuple[int, int]) -> _Previous:
    """The state after the already processed frame of ``resume`` = (index, nnf, backlog, rgb); ``frame`` and
    ``mask`` are its guides and coverage."""
    index, nnf, backlog, rgb = resume
    inside = _inside(frame, _coverage(mask, shape, index))
    return _Previous(nnf, inside, frame.ext_plus, np.asarray(backlog, np.float32), rgb)


@dataclass(frozen=True)
class _Sequence:
    """What every processing step of one sequence reads and none changes (the window's frames slide).

    Attributes
    ----------
    params : Params
    target : guides.GuideCache
        The target guides, in processing order.
    synthesis : SynthesisParams
        The engine's parameters; each pass reseeds them.
    unit : np.float32
        ``1 / ext_unit``: ext+ and ext− are compared in this unit.
    guide_weights : np.ndarray
        (6,) float32, the weights of the guide channels (``_GUIDES``).
    d : int
        The larger target side; the temporal modulation's bounds are fractions of it.
    window : _SlidingWindow
        The exemplar frames held and searched.
    """

    params: Params
    target: guides.GuideCache
    synthesis: SynthesisParams
    unit: np.float32
    guide_weights: np.ndarray
    d: int
    window: _SlidingWindow

    @classmethod
    def set_up(cls, target: guides.GuideCache, source: Source | StoredSource, params: Params) -> _Sequence:
        """The fixed inputs of stylizing ``target`` (its guides) from ``source`` with ``params``.

        No exemplar frame is read yet: the window fills at the first step.
        """
        synthesis = SynthesisParams(
            patch_size=params.patch_size, pyramid_levels=params.pyramid_levels, search_vote_iters=params.opt_iters,
            patchmatch_iters=params.pm_iters, vote_only_finest=params.vote_only_finest,
            finest_propagation_passes=params.finest_propagation,
            guided_initialization=params.guided_init, alpha=params.alpha,
            uniformity_weight=params.w_uni * params.uniformity_lambda, uniformity_radius=params.cuboid_radius,
            histogram_matching=params.histogram_matching, orientation_weight=params.w_dir,
            orientation_clamp=params.dir_clamp, rotation="flow", seed=params.seed,
        )
        unit = np.float32(1.0 / params.ext_unit)
        length = source.frame_count if params.source_window is None else min(params.source_window, source.frame_count)
        guide_range, colour_range = _quantization_ranges(target, source, unit, sliding=length < source.frame_count)
        prepare = functools.partial(_prepare_exemplar, unit=unit, border_width=target.border_width,
                                    guide_range=guide_range, colour_range=colour_range,
                                    synthesis=synthesis)
        return cls(
            params=params, target=target, synthesis=synthesis, unit=unit,
            guide_weights=np.array([params.w_bound, params.w_edge, params.w_ext, params.w_ext] + [params.w_temp] * 3,
                                   np.float32),
            d=max(target.height, target.width), window=_SlidingWindow(source, length, target.frame_count, prepare),
        )


#: Relative margin of the fixed quantization ranges of a sliding source window.
_RANGE_MARGIN = 1e-3


def _quantization_ranges(target: guides.GuideCache, source: Source | StoredSource, unit: np.float32, *,
                         sliding: bool) -> tuple:
    """(guide_range, colour_range) the exemplar's features are quantized over.

    The target's guides span shape [0, 1], ext± up to the sequence's largest and a temporal
    guide of exemplar colours (0 where unvoted); the exemplar's own colour range is measured
    (None). A sliding window prepares a few frames at a time: then every frame is quantized
    over the same ranges, covering the whole exemplar (colour in [0, 1]) with a margin for
    the pyramid's rounding.
    """
    ext_max = max(target.meta["ext_plus_max"], target.meta["ext_minus_max"]) * unit
    if not sliding:
        return ([0.0, -1.0] + [0.0] * 5, [1.0, 1.0, ext_max, ext_max, 1.0, 1.0, 1.0]), None
    low, high = -_RANGE_MARGIN, 1.0 + _RANGE_MARGIN
    ext_max = max(ext_max, source.ext_max * float(unit)) * high
    return ([low, -high] + [low] * 5, [high, high, ext_max, ext_max, high, high, high]), ([low] * 3, [high] * 3)


def _prepare_exemplar(frames: Source, *, unit: np.float32, border_width: float, guide_range, colour_range,
                      synthesis: SynthesisParams):
    """The engine's prepared source (pyramid, features) of exemplar ``frames``.

    Its guides pair with the target's (``_GUIDES``): shape, edge (:func:`edge_guide`), ext± in ``unit``, and its colour,
    which the temporal guide is compared with.
    """
    return prepare_engine_source(
        frames.rgb, np.concatenate([
            frames.shape[..., None], edge_guide(frames.dist, border_width)[..., None],
            frames.ext_plus[..., None] * unit, frames.ext_minus[..., None] * unit, frames.rgb,
        ], axis=3),
        guide_weight_map=_WEIGHT_MAP, opposite_guide=_OPPOSITE, source_angle=frames.angle,
        source_segment=frames.segment, guide_range=guide_range, colour_range=colour_range, params=synthesis,
    )


def segment_blend(dist: np.ndarray, border_width: float) -> np.ndarray:
    """How much of the border's (0) and the interior's (1) histogram remapping each pixel takes, (2, H, W).

    Each segment's remapping holds alone from its middle on: the border's up to half a border
    width from the edge, the interior's from one and a half; in between they blend linearly
    with the distance, as adaptive equalization blends between tile centres. Applied each to
    its own segment, they would draw a seam ring along the split (docs/stylize.md).
    """
    interior = np.clip(np.asarray(dist, np.float32) / np.float32(border_width) - 0.5, 0.0, 1.0)
    return np.stack([1.0 - interior, interior])


def edge_guide(dist: np.ndarray, border_width: float) -> np.ndarray:
    """The thesis's border channel ``df = min(dist / border_width, 1)`` (section 3.4), floored at −1 outside."""
    return np.clip(np.asarray(dist, np.float32) / np.float32(border_width), -1.0, 1.0)


def _stylize_step(sequence: _Sequence, k: int, index: int, mask, previous: _Previous | None,
                  ) -> tuple[StylizedFrame, _Previous]:
    """Processing step ``k``: sequence frame ``index`` with coverage ``mask``, continued from ``previous``
    (None: a fresh start, settled); return the frame and the state the next step continues from.

    Where its paint is the previous frame's, unshifted, the previous colour stays.
    """
    sequence.window.slide_to(k)
    target = sequence.target
    frame = target.frame(k)
    coverage = _coverage(mask, (target.height, target.width), index)
    inside = _inside(frame, coverage)
    if previous is None:
        result, backlog = _fresh_start(sequence, k, frame, inside)
        rgb = np.clip(result.image, 0.0, 1.0)
    else:
        if sequence.params.carry:
            previous = _carried(previous, frame, target.frame(k - 1))
        result, backlog = _synthesize(sequence, k, frame, inside, previous, settle_pass=0)
        unchanged = _unchanged_paint(result.nnf, previous.nnf, sequence.params.patch_size)
        unchanged &= np.isfinite(previous.rgb[..., 0])
        rgb = np.where(unchanged[..., None], previous.rgb, np.clip(result.image, 0.0, 1.0))
    rgba = np.concatenate([rgb, coverage[..., None]], axis=2)
    stylized = StylizedFrame(index=index, rgba=rgba, nnf=result.nnf, backlog=backlog)
    return stylized, _Previous(result.nnf, inside, frame.ext_plus, backlog, rgb)


#: px: changes of the target's edge distance along its material smaller than this are none (``carry``)
_DISTANCE_RESOLUTION = 0.5


def _carried(previous: _Previous, frame: guides.FrameGuides, before: guides.FrameGuides) -> _Previous:
    """The previous frame's state moved along the target's motion into ``frame`` (``carry``; ``before`` is the
    previous frame's guides).

    Its matches move by :func:`~fluidymation.engine.shiftnnf.transport_nnf`, the rest comes from where each point
    came from. The motion SHIFTNNF then follows in exemplar time is the target's motion relative to its material,
    not the distance carried: how much farther from the edge each point got (the medium spreading; none on a
    rigid part, and none where an edge closes in), counted from half a pixel, the resolution of the distance
    fields (below it, their interpolation errors would add up frame after frame). It is given as the ext+ that
    makes that the increment. The colour stays only where nothing moved (a moved colour is the vote's).
    """
    flow = frame.flow
    nnf, origin = transport_nnf(previous.nnf, flow)
    known = origin >= 0

    def moved(values):
        return np.where(known, sample_back(values, flow), 0.0).astype(np.float32)

    spread = frame.dist - moved(before.dist)
    spread = np.where(spread > _DISTANCE_RESOLUTION, spread, 0.0)
    inside = known & previous.inside.ravel()[np.where(known, origin, 0)]
    rgb = np.where((known & np.all(flow == 0.0, axis=2))[..., None], previous.rgb, np.float32(np.nan))
    return _Previous(nnf, inside, (frame.ext_plus - spread).astype(np.float32), moved(previous.backlog),
                     rgb.astype(np.float32))


def _fresh_start(sequence: _Sequence, k: int, frame: guides.FrameGuides, inside: np.ndarray):
    """Synthesize step ``k`` with no previous frame, then settle it: ``settle_passes`` times
    again with itself as the previous frame (no motion), so the next frames do not re-trade
    its unconverged matches. Return (result, backlog)."""
    result, backlog = _synthesize(sequence, k, frame, inside, None, settle_pass=0)
    for settle_pass in range(1, sequence.params.settle_passes + 1):
        itself = _Previous(result.nnf, inside, frame.ext_plus, backlog, rgb=None)
        result, backlog = _synthesize(sequence, k, frame, inside, itself, settle_pass=settle_pass)
    return result, backlog


def _synthesize(sequence: _Sequence, k: int, frame: guides.FrameGuides, inside: np.ndarray,
                previous: _Previous | None, *, settle_pass: int):
    """One synthesis pass of step ``k`` in the held window; return (result, backlog).

    Without ``previous`` it starts from a random field. With it, it starts from SHIFTNNF of
    the previous matches along the target's motion (plus the previous backlog; motion under
    ``still_speed`` waits in the backlog), its temporal guide is the exemplar voted through
    that field, weighted by m(q), and (outside settle passes) carried-over matches are kept
    unless ``keep_margin`` better (:func:`carried_margin`). Every (step, pass) has its own
    seed. NNFs come and go in exemplar frame numbers; inside, they count from the window's start.
    """
    params, target, held = sequence.params, sequence.target, sequence.window
    exemplar = held.frames
    segment = np.where(inside, np.maximum(frame.segments.astype(np.int32) - 1, 0), -1).astype(np.int32)
    if len(held.labels) == 1:  # an exemplar painted to its frame's edge has no border: match its one segment
        segment = np.where(inside, held.labels[0], -1).astype(np.int32)
    temp = np.zeros((target.height, target.width, 3), np.float32)
    modulation = np.zeros((1, target.height, target.width), np.float32)
    initial = keep_margin = None
    backlog = np.zeros((target.height, target.width), np.float32)
    if previous is not None:
        # Motion smaller than one source frame's would be lost frame after frame: carry it over.
        wanted = frame.ext_plus - previous.ext_plus + np.where(previous.inside, previous.backlog, 0.0)
        # still paint stays in its exemplar frame; its motion waits in the backlog until it counts
        followed = np.where(np.abs(wanted) < params.still_speed, np.float32(0.0), wanted).astype(np.float32)
        initial, achieved = shift_nnf(
            held.inside(previous.nnf), target_motion=followed, target_angle=frame.direction,
            source_ext_plus=exemplar.ext_plus, source_ext_minus=exemplar.ext_minus, source_angle=exemplar.angle,
        )
        backlog = np.where(initial.frame >= 0, wanted - achieved, 0.0).astype(np.float32)
        if params.w_temp > 0:
            temp, _ = vote(exemplar.rgb, initial, patch_size=params.patch_size)
            modulation[0] = temporal_modulation(
                initial, target_dist=border_clamped(frame.dist, target.border_width), source_dist=exemplar.dist,
                previous_mask=previous.inside, lower=params.m_lower * sequence.d, upper=params.m_upper * sequence.d,
            )
            # a settle pass's previous frame is itself; carried paint moved with the pixels, which this does not see
            if settle_pass == 0 and k > 0 and params.recede_release > 0 and not params.carry:
                modulation[0] *= receding_release(target.read("dist", k - 1), frame.dist, target.border_width,
                                                  params.recede_release)
            if settle_pass == 0:  # a fresh start's settle passes converge freely
                keep_margin = carried_margin(modulation[0], wanted, previous.inside, params)
    unit = sequence.unit
    target_guides = np.concatenate([
        frame.shape[..., None], edge_guide(frame.dist, target.border_width)[..., None],
        frame.ext_plus[..., None] * unit, frame.ext_minus[..., None] * unit, temp,
    ], axis=2)
    result = synthesize_prepared(
        held.prepared,
        TargetInputs(
            target_guides=target_guides, colour_weights=np.ones(3, np.float32), guide_weights=sequence.guide_weights,
            weight_maps=modulation, target_angle=frame.direction, target_segment=segment, initial_nnf=initial,
            uniformity_scale=1.0 - (1.0 - np.float32(params.uni_carried)) * modulation[0],
            keep_margin=keep_margin, histogram_blend=segment_blend(frame.dist, target.border_width),
        ),
        dataclasses.replace(sequence.synthesis,
                            seed=int(counter_hash(params.seed, k, settle_pass) % np.uint64(2**31))),
    )
    return dataclasses.replace(result, nnf=held.outside(result.nnf)), backlog


def receding_release(before_dist: np.ndarray, dist: np.ndarray, border_width: float, release: float) -> np.ndarray:
    """Factor (H, W) on m(q) where the edge moved inward: 1 − (fall of the border-clamped edge distance since the
    previous frame) / ``release``, clipped to [0, 1] (``recede_release``; beyond the paper, docs/stylize.md)."""
    fall = border_clamped(before_dist, border_width) - border_clamped(dist, border_width)
    return np.clip(1.0 - fall / np.float32(release), 0.0, 1.0).astype(np.float32)


def _unchanged_paint(nnf: NNF, previous: NNF, patch_size: int) -> np.ndarray:
    """Pixels whose every covering patch is the previous frame's match, unshifted: their vote is the previous one."""
    same = (nnf.frame == previous.frame) & ((nnf.frame < 0) | np.all(nnf.coords == previous.coords, axis=2))
    covered = ndimage.minimum_filter(same.astype(np.uint8), size=patch_size, mode="constant", cval=1).astype(bool)
    return covered & (nnf.frame >= 0)


def carried_margin(modulation: np.ndarray, motion: np.ndarray, carried: np.ndarray, params: Params) -> np.ndarray:
    """Per target pixel, the relative improvement a match needs to replace the one carried over.

    ``modulation`` is m(q), ``motion`` the target's motion amount (px) to be followed in
    this step and ``carried`` where the previous frame had paint. Where the temporal term
    holds, a carried-over match is only traded for one ``keep_margin`` better (times m(q));
    where the target is still (``motion`` under ``still_speed``) it is kept outright,
    whatever m(q): paint that does not move does not change (beyond the paper;
    docs/stylize.md, "Stationary regions").
    """
    still = carried & (np.abs(motion) < params.still_speed)
    return np.where(still, np.float32(1.0), np.float32(params.keep_margin) * modulation).astype(np.float32)


class _SlidingWindow:
    """The ``length`` exemplar frames held at a time: a :class:`Source` and the engine's prepared source.

    At each of the ``step_count`` processing steps it holds the frames from :func:`window_start`.
    Sliding keeps the frames the old and new windows share and reads and prepares only
    the frames gained (the pyramid and quantization act on each frame alone).
    """

    def __init__(self, source, length: int, step_count: int, prepare: Callable):
        self.source, self.length, self.step_count, self.prepare = source, length, step_count, prepare
        self.start = self.stop = 0
        self.frames: Source | None = None
        self.prepared = None

    def slide_to(self, step: int) -> None:
        """Hold the window of processing step ``step``."""
        start = window_start(step, self.step_count, self.source.frame_count, self.length)
        self.move(start, start + self.length)

    def move(self, start: int, stop: int) -> None:
        if (start, stop) == (self.start, self.stop):
            return
        kept = (max(start, self.start), min(stop, self.stop))
        runs = [(start, stop)] if kept[0] >= kept[1] else [(start, kept[0]), kept, (kept[1], stop)]
        frames, prepared = [], []
        for first, last in runs:
            if first >= last:
                continue
            if (first, last) == kept:
                frames.append(self.frames.window(first - self.start, last - self.start))
                prepared.append(self.prepared.frames(first - self.start, last - self.start))
            else:
                frames.append(self.source.window(first, last))
                prepared.append(self.prepare(frames[-1]))
        self.frames, self.prepared = concatenate(frames), concatenate_prepared(prepared)
        self.start, self.stop = start, stop
        self.labels = np.unique(self.frames.segment[self.frames.segment >= 0])

    def inside(self, nnf: NNF) -> NNF:
        """``nnf`` (exemplar frame numbers) in window frame numbers; matches outside the window
        move to its nearest frame."""
        frame = np.where(nnf.frame >= 0, np.clip(nnf.frame, self.start, self.stop - 1) - self.start, -1)
        return NNF(frame.astype(np.int32), nnf.coords)

    def outside(self, nnf: NNF) -> NNF:
        """``nnf`` (window frame numbers) in exemplar frame numbers."""
        return NNF(np.where(nnf.frame >= 0, nnf.frame + self.start, -1).astype(np.int32), nnf.coords)


def _inside(frame, coverage: np.ndarray) -> np.ndarray:
    """Pixels the layer covers in a target frame: its guides' mask or any coverage."""
    return frame.mask | (coverage > 0)


def _coverage(mask, shape, index) -> np.ndarray:
    mask = np.asarray(mask)
    if mask.shape != shape:
        raise StageError(f"stylize: mask of frame {index} has shape {mask.shape}, expected {shape}")
    if mask.dtype == np.bool_:
        return mask.astype(np.float32)
    if mask.dtype == np.uint8:
        return mask.astype(np.float32) / np.float32(255.0)
    return np.clip(mask, 0.0, 1.0).astype(np.float32)
