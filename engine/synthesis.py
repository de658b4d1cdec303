"""Multi-scale guided patch synthesis: the driver that every stylizer calls.

For each pyramid level, coarsest first: initialise the NNF (random, or upscaled from the
coarser level, optionally merged per pixel with a supplied NNF downscaled to the level),
vote, then repeat ``search_vote_iters`` times: PatchMatch (``patchmatch_iters`` passes,
the uniformity map recomputed before each pass) and vote. Per-level schedules are given
coarsest first; the last value repeats for the finer levels.

:func:`synthesize` builds the source's pyramid and 16-bit features for its one target.
A sequence of targets from one source (the stylize stage's frames) builds them once with
:func:`prepare_source` and calls :func:`synthesize_prepared` per target; a window sliding
over a long source keeps the frames it has prepared (:meth:`PreparedSource.frames`,
:func:`concatenate_prepared`). Levels with few pixels run their kernels on one thread
(:func:`fluidymation.engine._jit.threads_for`).
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass

import numpy as np

from fluidymation.engine._jit import threads_for
from fluidymation.engine.histogram import join_tables, match_histograms, quantile_tables
from fluidymation.engine.nnf import (
    NNF, ROTATION_FLOW, ROTATION_NONE, downscale_nnf, fill_random, merge_nnf, segment_index, upscale_nnf,
)
from fluidymation.engine.patch_cost import SourceFeatures, patch_errors, quantize_source, target_patch_cost
from fluidymation.engine.patchmatch import TILE_ROWS, patchmatch_pass
from fluidymation.engine.pyramid import (
    downsample, downsample_angles, downsample_labels, gaussian_pyramid, levels_that_fit,
)
from fluidymation.engine.uniformity import budget_scales, occurrence_map, uniformity_penalty
from fluidymation.engine.vote import vote

_ROTATIONS = {"none": ROTATION_NONE, "flow": ROTATION_FLOW}


@dataclass(frozen=True)
class SynthesisParams:
    """Options of :func:`synthesize`.

    Attributes
    ----------
    patch_size : int
        Odd patch side n.
    pyramid_levels : int or None
        Level count; None (or more than fit) uses as many as keep the coarsest level's
        sides ≥ 2n + 1.
    search_vote_iters, patchmatch_iters : tuple of int
        Per level, coarsest first; the last value repeats.
    vote_only_finest : bool
        Do not optimise the finest level: only vote the upscaled NNF (when > 1 level).
    finest_propagation_passes : int
        With ``vote_only_finest``, PatchMatch passes of propagation only (no random search)
        on the finest level's upscaled field before its vote: they join the 2×2 blocks that
        each coarse match becomes into coherent matches.
    guided_initialization : bool
        After a random start, run one PatchMatch with the colour weight 0 (guides only).
    alpha : float
        Shrink factor of the random-search boxes.
    uniformity_weight : float
        λ of the uniformity penalty (0 disables it), in the squared units of the features.
    uniformity_radius : int
        r: a patch also occupies the r frames before and after its own.
    histogram_matching : float
        Strength (0–1) with which each vote's colour histogram is matched, per segment, to
        the source frames its matches use (:mod:`fluidymation.engine.histogram`); 0: off.
    orientation_weight, orientation_clamp : float
        Weight and clamp of the ``|tan(S_dir − θ − T_dir)|`` term (needs the angles).
    rotation : {"none", "flow"}
        θ = 0, or the two flow-aligned angles θ_S − θ_T and θ_S − θ_T + π (a patch turned by θ
        samples the source at R(θ) times its offsets: a source direction α shows at α − θ).
    seed : int
    tile_rows : int
        Height of the fixed parallel tiles.
    """

    patch_size: int = 5
    pyramid_levels: int | None = None
    search_vote_iters: tuple = (6,)
    patchmatch_iters: tuple = (4,)
    vote_only_finest: bool = False
    finest_propagation_passes: int = 0
    guided_initialization: bool = False
    alpha: float = 0.75
    uniformity_weight: float = 0.0
    uniformity_radius: int = 0
    histogram_matching: float = 0.0
    orientation_weight: float = 0.0
    orientation_clamp: float = 10.0
    rotation: str = "none"
    seed: int = 0
    tile_rows: int = TILE_ROWS

    def __post_init__(self):
        if self.patch_size < 3 or self.patch_size % 2 == 0:
            raise ValueError(f"patch_size must be an odd number ≥ 3, got {self.patch_size}")
        if self.pyramid_levels is not None and self.pyramid_levels < 1:
            raise ValueError(f"pyramid_levels must be ≥ 1, got {self.pyramid_levels}")
        for name in ("search_vote_iters", "patchmatch_iters"):
            value = tuple(getattr(self, name))
            if not value or min(value) < 0:
                raise ValueError(f"{name} must be a non-empty sequence of counts ≥ 0, got {value}")
            object.__setattr__(self, name, value)
        if not 0.0 < self.alpha < 1.0:
            raise ValueError(f"alpha must lie in (0, 1), got {self.alpha}")
        if self.uniformity_weight < 0 or self.uniformity_radius < 0 or self.orientation_weight < 0:
            raise ValueError("uniformity_weight, uniformity_radius and orientation_weight must be ≥ 0")
        if not 0.0 <= self.histogram_matching <= 1.0:
            raise ValueError(f"histogram_matching must lie in [0, 1], got {self.histogram_matching}")
        if self.rotation not in _ROTATIONS:
            raise ValueError(f"rotation must be one of {sorted(_ROTATIONS)}, got {self.rotation!r}")
        if self.finest_propagation_passes < 0:
            raise ValueError(f"finest_propagation_passes must be ≥ 0, got {self.finest_propagation_passes}")
        if self.seed < 0 or self.tile_rows < 1:
            raise ValueError("seed must be ≥ 0 and tile_rows ≥ 1")


@dataclass(frozen=True)
class SynthesisInputs:
    """Source sequence, target guides and everything the patch cost compares.

    Attributes
    ----------
    source_colour : ndarray, shape (T, Hs, Ws, Cc), float32
        What is synthesized (and compared with the current target colour).
    source_guides : ndarray, shape (T, Hs, Ws, G), float32
    target_guides : ndarray, shape (H, W, G), float32
    colour_weights : ndarray, shape (Cc,)
    guide_weights : ndarray, shape (G,)
    weight_maps : ndarray, shape (M, H, W), float32, optional
        Per-target-pixel multipliers, e.g. the temporal modulation m(q).
    guide_weight_map : ndarray of int, shape (G,), optional
        Which weight map scales each guide channel (-1: none).
    opposite_guide : ndarray of int, shape (G,), optional
        Source guide compared with guide g where source and target flows are opposite.
    source_angle, target_angle : ndarray, (T, Hs, Ws) and (H, W), float32, optional
        Flow orientations (radians) for ``rotation="flow"``, the orientation term and
        ``opposite_guide``.
    source_segment, target_segment : ndarray of int, (T, Hs, Ws) and (H, W), optional
        Labels; a target pixel matches only source centres of its label; target -1 is
        not synthesized, source -1 is never matched. Default: one segment.
    initial_nnf : NNF, optional
        A full-resolution field (e.g. the previous frame's, shifted) downscaled to each
        level and merged per pixel, by patch error, with the field from the coarser level.
    """

    source_colour: np.ndarray
    source_guides: np.ndarray
    target_guides: np.ndarray
    colour_weights: np.ndarray
    guide_weights: np.ndarray
    weight_maps: np.ndarray | None = None
    guide_weight_map: np.ndarray | None = None
    opposite_guide: np.ndarray | None = None
    source_angle: np.ndarray | None = None
    target_angle: np.ndarray | None = None
    source_segment: np.ndarray | None = None
    target_segment: np.ndarray | None = None
    initial_nnf: NNF | None = None


class _FinestVote:
    """The finest level's colour (its vote, when still owed) and the patch errors against it,
    each computed when first asked for: a settle pass wants only the NNF, a stylized frame no
    errors."""

    def __init__(self, colour, cost, nnf, pixels):
        self._colour = colour  # a zero-argument function that votes (and sets the cost's target colour)
        self._cost = cost
        self._nnf = nnf
        self._pixels = pixels

    @functools.cached_property
    def image(self):
        with threads_for(self._pixels):
            return self._colour()

    @functools.cached_property
    def error(self):
        self.image  # the errors are against the final colour
        with threads_for(self._pixels):
            return patch_errors(self._cost, self._nnf)


@dataclass(frozen=True)
class SynthesisResult:
    """Output of :func:`synthesize`.

    Attributes
    ----------
    image : ndarray, shape (H, W, Cc), float32
    nnf : NNF
    error : ndarray, shape (H, W), float32
        Final patch cost per pixel (without the uniformity penalty); inf where unmatched.

    ``image`` and ``error`` are computed when first read.
    """

    nnf: NNF
    finest: _FinestVote = dataclasses.field(repr=False)

    @property
    def image(self):
        return self.finest.image

    @property
    def error(self):
        return self.finest.error

    def mean_error(self):
        """Mean final patch cost over matched pixels."""
        finite = self.error[np.isfinite(self.error)]
        return float(finite.mean()) if finite.size else float("nan")


@dataclass(frozen=True)
class TargetInputs:
    """The target side of :func:`synthesize_prepared` (the fields of :class:`SynthesisInputs`
    that describe the target; ``target_guides`` in the prepared source's guide order),
    ``uniformity_scale`` (H, W): a per-pixel factor of the uniformity penalty (default 1), and
    ``keep_margin`` (H, W): the relative improvement in patch cost a match needs to replace the
    one held, including ``initial_nnf``'s in the per-level merge (default 0), and
    ``histogram_blend`` (K, H, W): how much of each segment's histogram remapping a pixel takes
    (:func:`~fluidymation.engine.histogram.match_histograms`; default: its own segment's)."""

    target_guides: np.ndarray
    colour_weights: np.ndarray
    guide_weights: np.ndarray
    weight_maps: np.ndarray | None = None
    target_angle: np.ndarray | None = None
    target_segment: np.ndarray | None = None
    initial_nnf: NNF | None = None
    uniformity_scale: np.ndarray | None = None
    keep_margin: np.ndarray | None = None
    histogram_blend: np.ndarray | None = None


@dataclass(frozen=True)
class SourceLevel:
    """One pyramid level of a :class:`PreparedSource`.

    Attributes
    ----------
    colour : ndarray, shape (T, Hs, Ws, Cc), float32
        What is voted.
    features : SourceFeatures
        Colour and guides, quantized.
    angle : ndarray, shape (T, Hs, Ws), float32, or None
    segment : ndarray, shape (T, Hs, Ws), int32
    index : tuple
        :func:`segment_index` of ``segment``.
    quantiles : ndarray or None
        :func:`~fluidymation.engine.histogram.quantile_tables` of ``colour`` (prepared for
        ``histogram_matching``).
    """

    colour: np.ndarray
    features: SourceFeatures
    angle: np.ndarray | None
    segment: np.ndarray
    index: tuple
    quantiles: np.ndarray | None = None


@dataclass(frozen=True)
class PreparedSource:
    """A source sequence's pyramid and features, built once by :func:`prepare_source` and
    shared by every target synthesized from it (e.g. every frame of a sequence).

    Attributes
    ----------
    levels : tuple of SourceLevel
        Finest first.
    """

    levels: tuple

    @property
    def shape(self):
        """(T, Hs, Ws, Cc) of the finest level's colour."""
        return self.levels[0].colour.shape

    @property
    def guide_channels(self):
        return self.levels[0].features.guide_order.shape[0]

    def frames(self, start, stop):
        """Source frames ``start..stop−1`` (views of this source's arrays, their own segment index)."""
        return PreparedSource(levels=tuple(
            SourceLevel(colour=level.colour[start:stop], features=_frame_features(level.features, start, stop),
                        angle=None if level.angle is None else level.angle[start:stop],
                        segment=level.segment[start:stop], index=segment_index(level.segment[start:stop]),
                        quantiles=None if level.quantiles is None else level.quantiles[start:stop])
            for level in self.levels))


def _frame_features(features, start, stop):
    return dataclasses.replace(features, codes=features.codes[start:stop])


def concatenate_prepared(parts):
    """Join prepared sources along time, in the order given, into one.

    Lets a sliding window over a long source keep the frames it already prepared and
    prepare only the frames it gains (per-frame work: the pyramid and quantization act
    on each frame alone). Every part must have been prepared with the same levels and
    quantization (e.g. from one ``guide_range`` and ``colour_range`` that cover every
    frame's values).

    Raises
    ------
    ValueError
        If the parts' levels or quantization differ.
    """
    first = parts[0]
    for part in parts[1:]:
        if len(part.levels) != len(first.levels) or any(
                not (np.array_equal(a.features.offset, b.features.offset)
                     and np.array_equal(a.features.scale, b.features.scale))
                for a, b in zip(part.levels, first.levels)):
            raise ValueError("the prepared sources differ in levels or quantization; prepare them with ranges "
                             "that cover every frame")
    if len(parts) == 1:
        return first
    levels = []
    for rank, level in enumerate(first.levels):
        stacked = [part.levels[rank] for part in parts]
        segment = np.concatenate([item.segment for item in stacked])
        levels.append(SourceLevel(
            colour=np.concatenate([item.colour for item in stacked]),
            features=dataclasses.replace(level.features,
                                         codes=np.concatenate([item.features.codes for item in stacked])),
            angle=None if level.angle is None else np.concatenate([item.angle for item in stacked]),
            segment=segment, index=segment_index(segment),
            quantiles=None if level.quantiles is None else join_tables([item.quantiles for item in stacked])))
    return PreparedSource(levels=tuple(levels))


def _check_source(colour, guides, angle, segment):
    if colour.ndim != 4:
        raise ValueError(f"source_colour must have shape (T, Hs, Ws, Cc), got {colour.shape}")
    if guides.ndim != 4 or guides.shape[:3] != colour.shape[:3]:
        raise ValueError(f"source_guides must have shape {colour.shape[:3] + ('G',)}, got {guides.shape}")
    for name, value in (("source_angle", angle), ("source_segment", segment)):
        if value is not None and value.shape != colour.shape[:3]:
            raise ValueError(f"{name} must have shape {colour.shape[:3]}, got {value.shape}")


def _check_target(target, colours, guides):
    target_guides = target.target_guides
    if target_guides.ndim != 3 or target_guides.shape[2] != guides:
        raise ValueError(f"target_guides must have shape (H, W, {guides}), got {target_guides.shape}")
    height, width = target_guides.shape[:2]
    if np.shape(target.colour_weights) != (colours,) or np.shape(target.guide_weights) != (guides,):
        raise ValueError("colour_weights and guide_weights need one weight per channel")
    shapes = {"weight_maps": (None, height, width), "target_angle": (height, width), "target_segment": (height, width),
              "uniformity_scale": (height, width), "keep_margin": (height, width),
              "histogram_blend": (None, height, width)}
    for name, shape in shapes.items():
        value = getattr(target, name)
        if value is not None and (value.ndim != len(shape)
                                  or any(s is not None and s != v for s, v in zip(shape, value.shape))):
            raise ValueError(f"{name} must have shape {shape}, got {value.shape}")
    if target.initial_nnf is not None and target.initial_nnf.shape != (height, width):
        raise ValueError(f"initial_nnf must have shape {(height, width)}, got {target.initial_nnf.shape}")


def _schedule(values, index):
    return values[min(index, len(values) - 1)]


def _pyramid_or_none(array, levels, halve):
    if array is None:
        return [None] * levels
    out = [np.ascontiguousarray(array)]
    for _ in range(levels - 1):
        out.append(halve(out[-1]))
    return out


def _downsample_maps(maps):
    return np.ascontiguousarray(np.moveaxis(downsample(np.moveaxis(maps, 0, -1)), -1, 0))


def _downsample_map(values):
    return _downsample_maps(values[None])[0]


def _channel_range(values):
    """Per-channel (min, max) of (..., C) values, float64."""
    flat = values.reshape(-1, values.shape[-1])
    return flat.min(axis=0, initial=np.inf).astype(np.float64), flat.max(axis=0, initial=-np.inf).astype(np.float64)


def _prepare(source_colour, source_guides, guide_weight_map, opposite_guide, source_angle, source_segment, ranges,
             colour_range=None, histograms=False):
    """Prepare ``len(ranges)`` levels; ``ranges[l]`` = the (low, high) guide values level l must cover,
    ``colour_range`` the (low, high) colour values every level must cover besides 0; ``histograms``:
    also each level's quantile tables."""
    levels = len(ranges)
    frames, source_height, source_width, colours = source_colour.shape
    if source_segment is None:
        source_segment = np.zeros((frames, source_height, source_width), np.int32)
    colour = gaussian_pyramid(source_colour, levels)
    angle = _pyramid_or_none(source_angle, levels, downsample_angles)
    segment = _pyramid_or_none(np.asarray(source_segment, np.int32), levels, downsample_labels)
    unvoted = np.zeros(colours)  # the colour before the first vote, and where no patch votes
    colour_low, colour_high = (unvoted, unvoted) if colour_range is None else (
        np.minimum(unvoted, np.asarray(colour_range[0], np.float64).reshape(colours)),
        np.maximum(unvoted, np.asarray(colour_range[1], np.float64).reshape(colours)))
    prepared = []
    guides = np.ascontiguousarray(source_guides, np.float32)
    for level, (low, high) in enumerate(ranges):
        if level:
            guides = downsample(guides)  # float guides one level at a time: only the codes are kept
        features = quantize_source(
            colour[level], guides, guide_weight_map=guide_weight_map, opposite_guide=opposite_guide,
            low=np.concatenate([colour_low, low]), high=np.concatenate([colour_high, high]),
        )
        tables = None
        if histograms:
            tables = quantile_tables(colour[level], segment[level], int(segment[level].max(initial=-1)) + 1)
        prepared.append(SourceLevel(colour=colour[level], features=features, angle=angle[level],
                                    segment=segment[level], index=segment_index(segment[level]), quantiles=tables))
    return PreparedSource(levels=tuple(prepared))


def prepare_source(source_colour, source_guides, *, guide_weight_map=None, opposite_guide=None, source_angle=None,
                   source_segment=None, guide_range=None, colour_range=None, params=SynthesisParams()):
    """Build a source's pyramid and quantized features once, for many :func:`synthesize_prepared` calls.

    Parameters
    ----------
    source_colour, source_guides, guide_weight_map, opposite_guide, source_angle, source_segment
        As in :class:`SynthesisInputs`.
    guide_range : (low, high), each array-like of shape (G,), optional
        Values the targets' guides may take besides the source's own: the features are
        quantized over the union, target values outside it are clipped to it.
    colour_range : (low, high), each array-like of shape (Cc,), optional
        Colour values to quantize over besides the source's own (and 0). With both
        ranges covering every frame's values, sources prepared from different frames
        share one quantization and can be joined (:func:`concatenate_prepared`).
    params : SynthesisParams
        Its ``patch_size`` and ``pyramid_levels`` decide the levels prepared.

    Returns
    -------
    PreparedSource
    """
    source_colour = np.asarray(source_colour, np.float32)
    source_guides = np.asarray(source_guides, np.float32)
    _check_source(source_colour, source_guides, source_angle, source_segment)
    fit = levels_that_fit([source_colour.shape[1:3]], patch_size=params.patch_size)
    levels = fit if params.pyramid_levels is None else min(params.pyramid_levels, fit)
    guides = source_guides.shape[3]
    low, high = (np.full(guides, np.inf), np.full(guides, -np.inf)) if guide_range is None else guide_range
    low = np.asarray(low, np.float64).reshape(guides)
    high = np.asarray(high, np.float64).reshape(guides)
    return _prepare(source_colour, source_guides, guide_weight_map, opposite_guide, source_angle, source_segment,
                    [(low, high)] * levels, colour_range, histograms=params.histogram_matching > 0)


def _level_count(source_shape, target_shape, params):
    fit = levels_that_fit([source_shape, target_shape], patch_size=params.patch_size)
    return fit if params.pyramid_levels is None else min(params.pyramid_levels, fit)


def synthesize(inputs, params=SynthesisParams()):
    """Synthesize a target image from a source sequence with guided patch optimisation.

    The source features are quantized over ranges spanning both the source and this
    target. To synthesize many targets from one source, use :func:`prepare_source` and
    :func:`synthesize_prepared`.

    Parameters
    ----------
    inputs : SynthesisInputs
    params : SynthesisParams

    Returns
    -------
    SynthesisResult
    """
    source_colour = np.asarray(inputs.source_colour, np.float32)
    source_guides = np.asarray(inputs.source_guides, np.float32)
    _check_source(source_colour, source_guides, inputs.source_angle, inputs.source_segment)
    target = TargetInputs(
        target_guides=inputs.target_guides, colour_weights=inputs.colour_weights, guide_weights=inputs.guide_weights,
        weight_maps=inputs.weight_maps, target_angle=inputs.target_angle, target_segment=inputs.target_segment,
        initial_nnf=inputs.initial_nnf,
    )
    _check_target(target, source_colour.shape[3], source_guides.shape[3])
    levels = _level_count(source_colour.shape[1:3], target.target_guides.shape[:2], params)
    target_guides = gaussian_pyramid(target.target_guides, levels)
    source = _prepare(source_colour, source_guides, inputs.guide_weight_map, inputs.opposite_guide,
                      inputs.source_angle, inputs.source_segment, [_channel_range(level) for level in target_guides],
                      histograms=params.histogram_matching > 0)
    return _synthesize(source, target, params, target_guides)


def synthesize_prepared(source, target, params=SynthesisParams()):
    """Synthesize a target image from a :class:`PreparedSource` (see :func:`synthesize`).

    Parameters
    ----------
    source : PreparedSource
        Prepared with the same ``patch_size`` and ``pyramid_levels`` as ``params``.
    target : TargetInputs
    params : SynthesisParams

    Returns
    -------
    SynthesisResult
    """
    _, source_height, source_width, colours = source.shape
    _check_target(target, colours, source.guide_channels)
    levels = _level_count((source_height, source_width), target.target_guides.shape[:2], params)
    if levels > len(source.levels):
        raise ValueError(f"the source was prepared with {len(source.levels)} levels, these params need {levels}")
    return _synthesize(source, target, params, gaussian_pyramid(target.target_guides, levels))


def _synthesize(source, target, params, target_guides):
    """The multi-scale loop over the levels of ``target_guides`` (a pyramid, finest first)."""
    levels = len(target_guides)
    height, width = target_guides[0].shape[:2]
    if _ROTATIONS[params.rotation] == ROTATION_FLOW and (source.levels[0].angle is None or target.target_angle is None):
        raise ValueError('rotation="flow" needs source_angle and target_angle')
    target_segment = target.target_segment
    if target_segment is None:
        target_segment = np.zeros((height, width), np.int32)
    weight_maps = _pyramid_or_none(target.weight_maps, levels, _downsample_maps)
    uniformity_scales = _pyramid_or_none(target.uniformity_scale, levels, _downsample_map)
    keep_margins = _pyramid_or_none(target.keep_margin, levels, _downsample_map)
    histogram_blends = _pyramid_or_none(target.histogram_blend, levels, _downsample_maps)
    target_angle = _pyramid_or_none(target.target_angle, levels, downsample_angles)
    target_segments = _pyramid_or_none(np.asarray(target_segment, np.int32), levels, downsample_labels)
    nnf = None
    for rank, level in enumerate(range(levels - 1, -1, -1)):
        level_height, level_width = target_guides[level].shape[:2]
        with threads_for(level_height * level_width):
            nnf, colour, cost = _synthesize_level(
                source.levels[level], target, params, rank=rank, level=level, nnf=nnf,
                optimise=not (level == 0 and levels > 1 and params.vote_only_finest), target_guides=target_guides[level],
                weight_maps=weight_maps[level], target_angle=target_angle[level], target_segment=target_segments[level],
                uniformity_scale=uniformity_scales[level], keep_margin=keep_margins[level],
                histogram_blend=histogram_blends[level],
            )
    return SynthesisResult(nnf=nnf, finest=_FinestVote(colour, cost, nnf, height * width))


def _synthesize_level(prepared, target, params, *, rank, level, nnf, optimise, target_guides, weight_maps, target_angle,
                      target_segment, uniformity_scale, keep_margin, histogram_blend):
    """One pyramid level: start from ``nnf`` (the coarser level's, or None), return (nnf, colour, cost), where
    colour is a function giving the level's colour (a last vote still owed is made when it is called)."""
    rotation_mode = _ROTATIONS[params.rotation]
    level_height, level_width = target_guides.shape[:2]
    level_source_shape = prepared.colour.shape[1:3]
    cost = target_patch_cost(
        prepared.features, target_colour=np.zeros((level_height, level_width, prepared.colour.shape[3]), np.float32),
        target_guides=target_guides, colour_weights=target.colour_weights, guide_weights=target.guide_weights,
        weight_maps=weight_maps, source_angle=prepared.angle, target_angle=target_angle,
        orientation_weight=params.orientation_weight, orientation_clamp=params.orientation_clamp,
        source_segment=prepared.segment, target_segment=target_segment, patch_size=params.patch_size,
    )

    def repair(field, salt):
        fill_random(
            field, target_segment=cost.target_segment, source_segment=cost.source_segment, seed=params.seed, salt=salt,
            replace_all=False, rotation_mode=rotation_mode, target_angle=target_angle, source_angle=prepared.angle,
            index=prepared.index,
        )

    def revote():
        colour, _ = vote(prepared.colour, nnf, patch_size=params.patch_size)
        if params.histogram_matching > 0:
            if prepared.quantiles is None:
                raise ValueError("histogram_matching needs a source prepared with it")
            colour = match_histograms(colour, nnf.frame, cost.target_segment, prepared.quantiles,
                                      params.histogram_matching, blend=histogram_blend)
        cost.set_target_colour(colour)
        return colour

    def downscaled_initial():
        field = downscale_nnf(target.initial_nnf, steps=level, target_shape=(level_height, level_width),
                              source_shape=level_source_shape)
        repair(field, _salt(level, 1, 0, 0))
        return field

    random_start = nnf is None and target.initial_nnf is None
    # the propagation-only finest level searches against the vote the merge was judged by, with
    # the merge's errors (one vote, remapping and error pass fewer)
    propagate_only = not optimise and params.finest_propagation_passes > 0
    error = None
    if nnf is None:
        nnf = downscaled_initial() if target.initial_nnf is not None else NNF.empty(level_height, level_width)
        repair(nnf, _salt(level, 0, 0, 0))
    else:
        nnf = upscale_nnf(nnf, target_shape=(level_height, level_width), source_shape=level_source_shape)
        repair(nnf, _salt(level, 0, 0, 0))
        if target.initial_nnf is not None:
            revote()
            other = downscaled_initial()
            held_error = patch_errors(cost, other)
            compared = held_error
            if keep_margin is not None:
                compared = held_error * np.where(np.isfinite(held_error), 1.0 - keep_margin, 1.0).astype(np.float32)
            upscaled_error = patch_errors(cost, nnf)
            nnf, took_held = merge_nnf(nnf, other, upscaled_error, compared)
            error = np.where(took_held, held_error, upscaled_error)
    if error is None or not propagate_only:
        colour = revote()
        error = None

    if random_start and params.guided_initialization:
        guides_cost = cost.guides_only()
        guides_error = patch_errors(guides_cost, nnf)
        for iteration in range(_schedule(params.patchmatch_iters, rank)):
            patchmatch_pass(guides_cost, nnf, guides_error, rotation_mode=rotation_mode, alpha=params.alpha,
                            seed=params.seed, salt=_salt(level, 2, 0, iteration), reverse=iteration % 2 == 1,
                            tile_rows=params.tile_rows)
        colour = revote()

    if not optimise and not propagate_only:
        return nnf, functools.partial(_same, colour), cost
    scales = None
    if params.uniformity_weight > 0:
        scales = budget_scales(source_segment=cost.source_segment, target_segment=cost.target_segment,
                               patch_size=params.patch_size, frame_radius=params.uniformity_radius,
                               weight=params.uniformity_weight)

    def search(passes, phase, em, random_search, error=None):
        error = patch_errors(cost, nnf) if error is None else error
        for iteration in range(passes):
            penalty = None
            if scales is not None:
                occurrence = occurrence_map(nnf, source_shape=cost.source_segment.shape,
                                            patch_size=params.patch_size, frame_radius=params.uniformity_radius)
                penalty = uniformity_penalty(occurrence, source_segment=cost.source_segment, scales=scales,
                                             patch_size=params.patch_size)
            patchmatch_pass(cost, nnf, error, penalty=penalty, penalty_scale=uniformity_scale, keep_margin=keep_margin,
                            rotation_mode=rotation_mode, alpha=params.alpha, random_search=random_search,
                            seed=params.seed, salt=_salt(level, phase, em, iteration), reverse=iteration % 2 == 1,
                            tile_rows=params.tile_rows)

    if propagate_only:
        search(params.finest_propagation_passes, 4, 0, random_search=False, error=error)
        return nnf, revote, cost
    for em in range(_schedule(params.search_vote_iters, rank)):
        search(_schedule(params.patchmatch_iters, rank), 3, em, random_search=True)
        colour = revote()
    return nnf, functools.partial(_same, colour), cost


def _same(value):
    """``value`` itself: the colour function of a level whose last vote is made."""
    return value


def _salt(level, phase, em, iteration):
    """A distinct random-stream number per (level, phase, search-vote and PatchMatch iteration)."""
    return ((level * 8 + phase) * 4096 + em) * 4096 + iteration
