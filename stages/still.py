"""Still-exemplar stylization of flat-coloured layers (seed 002, docs/still.md).

One still painting and its colour-coded regions paint a layer whose fill colours say which
region each pixel is: guided synthesis with the region colours as the guide (style weight
α, guide weight β; the seed's SSD), matching restricted to the pixel's own region, and
the occurrence penalty with a budget per region, ω_best = |target region| / |exemplar
region| (the engine's per-segment uniformity). Beyond one image (docs/still.md):

* a frame whose coverage and regions equal the previous frame's is that frame again
  (counted in :class:`Counts`; a still layer is synthesized once and never flickers);
* with ``follow_motion`` the previous frame's matches are carried along the layer's motion
  and kept (the texture stays attached to the shape), only pixels the layer uncovers, or
  whose region changed, are synthesized;
* with ``edge_band`` a fresh frame starts from textures synthesized once per region at the
  frame's size and re-synthesizes only the band of that width along region edges (the
  seed's pre-synthesized textures; the band halves with each coarser level).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Iterator, NamedTuple

import numpy as np
from scipy import ndimage

from fluidymation.engine.nnf import NNF
from fluidymation.engine.shiftnnf import transport_nnf
from fluidymation.engine.synthesis import PreparedSource, TargetInputs, prepare_source
from fluidymation.engine.synthesis import synthesize_prepared
from fluidymation.stages.still_params import Params
from fluidymation.errors import ParameterError
from fluidymation.stages.regions import Regions, layer_palette, match_palette, region_guide, target_labels



@dataclass
class Counts:
    """What a run did per frame: ``synthesized`` fresh, ``followed`` (carried along the motion, the
    uncovered part synthesized), ``reused`` (the previous frame unchanged)."""

    synthesized: int = 0
    followed: int = 0
    reused: int = 0


class StillFrame(NamedTuple):
    """A stylized frame: ``index``, ``rgba`` (H, W, 4) with the coverage as alpha, its ``nnf``, and the
    ``labels`` it was synthesized for (kept to tell whether the next frame changed)."""

    index: int
    rgba: np.ndarray
    nnf: NNF
    labels: np.ndarray


@dataclass(frozen=True)
class Painting:
    """The exemplar as the synthesis sees it: one frame's colour (Hs, Ws, 3) and its :class:`Regions`."""

    rgb: np.ndarray
    regions: Regions


def resumed(index: int, nnf: NNF, rgb: np.ndarray, coverage: np.ndarray, labels: np.ndarray) -> StillFrame:
    """Finished frame ``index`` rebuilt from its saved NNF and colour and its coverage and labels (for resume)."""
    return StillFrame(index, np.concatenate([rgb, coverage[..., None]], axis=2).astype(np.float32), nnf, labels)


def painting_from(source, frame: int) -> Painting:
    """Frame ``frame`` of a stored exemplar with its regions; an exemplar without ``segments:`` is one region,
    its mask, coloured by its mean paint."""
    if frame >= source.frame_count:
        raise ParameterError("exemplar_frame", f"exemplar_frame {frame}: the exemplar has {source.frame_count} frames")
    window = source.window(frame, frame + 1)
    rgb = window.rgb[0]
    regions = source.regions
    if regions is None:
        labels = np.where(window.segment[0] >= 0, 0, -1).astype(np.int32)
        regions = Regions(labels, rgb[labels >= 0].mean(axis=0, keepdims=True).astype(np.float32))
    return Painting(rgb, regions)


@dataclass
class LayerRegions:
    """Which exemplar region each of a layer's fill colours takes (``palette`` (K, 3), ``labels`` (K,))."""

    palette: np.ndarray
    labels: np.ndarray

    def of(self, rgb: np.ndarray, coverage: np.ndarray) -> np.ndarray:
        return target_labels(rgb, coverage, self.palette, self.labels)


def layer_regions(frames, regions: Regions, *, mode: str, segment_map=(), where: str) -> LayerRegions:
    """The layer's fill colours (``mode`` ``by-color``) or its one dominant colour (``mask``) matched to ``regions``.
    ``frames`` yields (straight RGB, coverage) per frame."""
    palette = layer_palette(frames)
    if mode == "mask":
        palette = palette[:1]
    return LayerRegions(palette, match_palette(palette, regions, segment_map, where=where))


class StillSynthesis:
    """Synthesizes frames of one layer from one :class:`Painting` (the source prepared once)."""

    def __init__(self, painting: Painting, params: Params):
        self.painting = painting
        self.params = params
        self.synthesis = params.synthesis()
        guide = painting.regions.guide()
        self.prepared: PreparedSource = prepare_source(
            painting.rgb[None], guide[None], source_segment=painting.regions.labels[None],
            guide_range=(np.zeros(4), np.ones(4)), params=self.synthesis)
        self.colour_weights = np.full(3, params.w_style, np.float32)
        self.guide_weights = np.full(4, params.w_guide, np.float32)
        self._textures: dict[int, NNF] = {}

    def target(self, labels: np.ndarray, coverage: np.ndarray, *, initial: NNF | None = None,
               keep: np.ndarray | None = None) -> TargetInputs:
        guide = region_guide(labels, self.painting.regions.colours)
        guide[..., 3] = np.where(labels >= 0, 1.0, np.minimum(coverage, 0.5))
        return TargetInputs(target_guides=guide, colour_weights=self.colour_weights, guide_weights=self.guide_weights,
                            target_segment=labels, initial_nnf=initial,
                            keep_margin=None if keep is None else keep.astype(np.float32))

    def synthesize(self, labels, coverage, *, initial=None, keep=None):
        """(nnf, rgb) of a frame; pixels in ``keep`` hold their ``initial`` matches."""
        result = synthesize_prepared(self.prepared, self.target(labels, coverage, initial=initial, keep=keep),
                                     self.synthesis)
        return result.nnf, filled(result.image, result.nnf, self.params.patch_size)

    def texture(self, label: int, shape: tuple[int, int]) -> NNF:
        """A frame-sized texture of region ``label`` alone (synthesized once; the seed's pre-synthesized texture)."""
        if label not in self._textures:
            labels = np.full(shape, label, np.int32)
            self._textures[label] = self.synthesize(labels, np.ones(shape, np.float32))[0]
        return self._textures[label]

    def band_start(self, labels: np.ndarray) -> tuple[NNF, np.ndarray]:
        """The pre-synthesized textures laid out by ``labels`` and where they are kept (farther than the band
        from a region edge)."""
        frame = np.full(labels.shape, -1, np.int32)
        coords = np.zeros(labels.shape + (3,), np.float32)
        for label in np.unique(labels[labels >= 0]):
            texture = self.texture(int(label), labels.shape)
            here = labels == label
            frame[here] = texture.frame[here]
            coords[here] = texture.coords[here]
        return NNF(frame, coords), edge_distance(labels) > self.params.edge_band


def edge_distance(labels: np.ndarray) -> np.ndarray:
    """Distance (px) of each pixel to the nearest pixel of another label (−1 counts as a label)."""
    edge = np.zeros(labels.shape, bool)
    edge[:-1] |= labels[:-1] != labels[1:]
    edge[1:] |= labels[:-1] != labels[1:]
    edge[:, :-1] |= labels[:, :-1] != labels[:, 1:]
    edge[:, 1:] |= labels[:, :-1] != labels[:, 1:]
    if not edge.any():
        return np.full(labels.shape, np.inf)
    return ndimage.distance_transform_edt(~edge)


def filled(image: np.ndarray, nnf: NNF, patch_size: int) -> np.ndarray:
    """The vote with pixels no patch reached (beyond the layer's edge) given their nearest voted colour, so a
    soft edge does not darken."""
    reached = ndimage.binary_dilation(nnf.frame >= 0, iterations=patch_size // 2)
    if reached.all() or not reached.any():
        return np.clip(image, 0.0, 1.0)
    _, (rows, columns) = ndimage.distance_transform_edt(~reached, return_indices=True)
    return np.clip(image[rows, columns], 0.0, 1.0)


def carried_start(previous: StillFrame, flow: np.ndarray, labels: np.ndarray, painting: Painting):
    """The previous frame's matches moved along ``flow`` and where they stay: carried, of the pixel's region."""
    carried, _ = transport_nnf(previous.nnf, flow)
    source_labels = painting.regions.labels
    height, width = source_labels.shape
    matched = carried.frame >= 0
    x = np.clip(np.rint(carried.coords[..., 0]), 0, width - 1).astype(np.int64)
    y = np.clip(np.rint(carried.coords[..., 1]), 0, height - 1).astype(np.int64)
    keep = matched & (labels >= 0) & (source_labels[y, x] == labels)
    frame = np.where(keep, carried.frame, -1).astype(np.int32)
    return NNF(frame, carried.coords), keep


def stylize_frames(masks: Callable[[int], np.ndarray], colours: Callable[[int], np.ndarray], frames: tuple[int, int],
                   synthesis: StillSynthesis, regions: LayerRegions, *, flow: Callable[[int], np.ndarray] | None,
                   previous: StillFrame | None = None, counts: Counts | None = None) -> Iterator[StillFrame]:
    """Frames ``frames`` = (first, stop) of a layer, in order, each after ``previous`` (None: the first is fresh)."""
    counts = counts if counts is not None else Counts()
    params = synthesis.params
    for index in range(*frames):
        coverage = masks(index)
        labels = regions.of(colours(index), coverage)
        if previous is not None and np.array_equal(labels, previous.labels) and \
                np.array_equal(coverage, previous.rgba[..., 3]):
            counts.reused += 1
            previous = StillFrame(index, previous.rgba, previous.nnf, labels)
            yield previous
            continue
        initial = keep = None
        if previous is not None and params.follow_motion and flow is not None:
            initial, keep = carried_start(previous, flow(index), labels, synthesis.painting)
            counts.followed += 1
        else:
            if params.edge_band > 0:
                initial, keep = synthesis.band_start(labels)
            counts.synthesized += 1
        nnf, rgb = synthesis.synthesize(labels, coverage, initial=initial, keep=keep)
        rgba = np.concatenate([rgb, coverage[..., None]], axis=2).astype(np.float32)
        previous = StillFrame(index, rgba, nnf, labels)
        yield previous

