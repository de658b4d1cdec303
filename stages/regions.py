"""Colour regions: an exemplar's colour-coded segments and a layer's fill colours, matched to each other.

The ``still`` stylizer (seed 002, docs/still.md) lets a target pixel match only exemplar
pixels of its own region. An exemplar's regions come from its segments image (each flat
colour one region; anti-aliased pixels go to the nearest region colour, transparent ones
to none). A layer's regions come from its fill colours (:func:`layer_palette`), each
matched to the exemplar region of the nearest colour unless a ``segment_map:`` says
otherwise (:func:`match_palette`).
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fluidymation.errors import InputError
from fluidymation.stages.files import read_image

#: A colour is a region (or a fill) when it covers at least this share of the opaque pixels.
MIN_SHARE = 0.002


@dataclass(frozen=True)
class Regions:
    """``labels`` (H, W) int32 (−1: no region) and ``colours`` (K, 3) float32 in [0, 1], one per label."""

    labels: np.ndarray
    colours: np.ndarray

    def resized(self, shape: tuple[int, int]) -> Regions:
        """The same regions at ``shape`` (H, W), nearest-neighbour (for an exemplar read at a ``scale``)."""
        height, width = self.labels.shape
        if (height, width) == tuple(shape):
            return self
        rows = np.minimum((np.arange(shape[0]) + 0.5) * height / shape[0], height - 1).astype(np.int64)
        columns = np.minimum((np.arange(shape[1]) + 0.5) * width / shape[1], width - 1).astype(np.int64)
        return Regions(self.labels[rows[:, None], columns[None, :]], self.colours)

    def guide(self) -> np.ndarray:
        """(H, W, 4) float32: each pixel's region colour and whether it has a region (the synthesis guide)."""
        return region_guide(self.labels, self.colours)


def region_guide(labels: np.ndarray, colours: np.ndarray) -> np.ndarray:
    """Region colour (RGB) and presence (A) per pixel, zero where ``labels`` is −1."""
    guide = np.zeros(labels.shape + (4,), np.float32)
    inside = labels >= 0
    guide[inside, :3] = colours[labels[inside]]
    guide[inside, 3] = 1.0
    return guide


def flat_colour_counts(rgb: np.ndarray, where: np.ndarray) -> Counter:
    """8-bit colours (packed 0xRRGGBB) of the pixels in ``where`` whose four neighbours have the same colour, with
    their counts: flat fills count, the anti-aliased seams between them do not."""
    codes = np.rint(np.clip(rgb, 0.0, 1.0) * 255.0).astype(np.int64)
    packed = (codes[..., 0] << 16) | (codes[..., 1] << 8) | codes[..., 2]
    flat = where.copy()
    flat[1:-1, 1:-1] &= ((packed[1:-1, 1:-1] == packed[:-2, 1:-1]) & (packed[1:-1, 1:-1] == packed[2:, 1:-1])
                         & (packed[1:-1, 1:-1] == packed[1:-1, :-2]) & (packed[1:-1, 1:-1] == packed[1:-1, 2:]))
    flat[[0, -1], :] = False
    flat[:, [0, -1]] = False
    values, counts = np.unique(packed[flat], return_counts=True)
    return Counter(dict(zip(values.tolist(), counts.tolist())))


def dominant_colours(counts: Counter) -> np.ndarray:
    """The colours of ``counts`` (from :func:`flat_colour_counts`) covering ≥ :data:`MIN_SHARE` of its pixels, most
    common first, (K, 3) float32."""
    total = sum(counts.values())
    kept = sorted((value for value, count in counts.items() if count >= max(1, MIN_SHARE * total)),
                  key=lambda value: (-counts[value], value))
    values = np.asarray(kept, np.int64)
    return (np.stack([values >> 16, (values >> 8) & 255, values & 255], axis=1) / 255.0).astype(np.float32)


def nearest_label(rgb: np.ndarray, colours: np.ndarray) -> np.ndarray:
    """Index of the nearest of ``colours`` (K, 3) for each pixel of ``rgb`` (..., 3), int32."""
    distance = ((rgb[..., None, :] - colours) ** 2).sum(axis=-1)
    return np.argmin(distance, axis=-1).astype(np.int32)


def read_regions(path: Path, shape: tuple[int, int]) -> Regions:
    """An exemplar's segments image as :class:`Regions`; ``shape`` (H, W) is its painting's (errors name the file)."""
    image = read_image(path, channels=4)
    if image.shape[:2] != tuple(shape):
        raise InputError(f"{path}: the segments image is {image.shape[1]}x{image.shape[0]}, the painting "
                         f"{shape[1]}x{shape[0]}; they must be the same size")
    opaque = image[..., 3] >= 0.5
    if not opaque.any():
        raise InputError(f"{path}: the segments image is transparent everywhere: no region")
    colours = dominant_colours(flat_colour_counts(image[..., :3], opaque))
    if len(colours) == 0:
        raise InputError(f"{path}: the segments image has no flat colour regions")
    labels = np.where(opaque, nearest_label(image[..., :3], colours), -1).astype(np.int32)
    return Regions(labels, colours)


def layer_palette(frames) -> np.ndarray:
    """The fill colours of a layer over its frames: ``frames`` yields (straight RGB (H, W, 3), coverage (H, W));
    the flat colours of its fully covered pixels, (K, 3) float32 (most common first)."""
    counts = Counter()
    for rgb, coverage in frames:
        counts.update(flat_colour_counts(rgb, coverage >= 0.999))
    return dominant_colours(counts)


def match_palette(palette: np.ndarray, regions: Regions, segment_map: tuple[tuple[str, str], ...], *,
                  where: str) -> np.ndarray:
    """The exemplar region label of each fill colour of ``palette``: the region colour ``segment_map`` names for it,
    else the nearest region colour. ``where`` names the layer in errors."""
    labels = nearest_label(palette, regions.colours) if len(palette) else np.zeros(0, np.int32)
    codes = [_hex(colour) for colour in palette]
    region_codes = [_hex(colour) for colour in regions.colours]
    for fill, region in segment_map:
        if fill not in codes:
            raise InputError(f"{where}: segment_map: {fill} is not one of the layer's fill colours "
                             f"({', '.join(codes) or 'none'})")
        if region not in region_codes:
            raise InputError(f"{where}: segment_map: {region} is not a region colour of the exemplar's segments "
                             f"({', '.join(region_codes)})")
        labels[codes.index(fill)] = region_codes.index(region)
    return labels


def target_labels(rgb: np.ndarray, coverage: np.ndarray, palette: np.ndarray, palette_labels: np.ndarray) -> np.ndarray:
    """Exemplar region label per target pixel: its nearest fill colour's, −1 where the layer is not (coverage < ½)."""
    if len(palette) == 0:
        return np.full(coverage.shape, -1, np.int32)
    labels = palette_labels[nearest_label(rgb, palette)]
    return np.where(coverage >= 0.5, labels, -1).astype(np.int32)


def _hex(colour: np.ndarray) -> str:
    red, green, blue = (int(round(float(c) * 255.0)) for c in colour)
    return f"#{red:02x}{green:02x}{blue:02x}"

