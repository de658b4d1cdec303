"""rasterize stage: each scene layer alone, per frame, as anti-aliased coverage and a mask.

Coverage is the alpha of the selected vector layers drawn together by the input's
renderer, in [0, 1]; the binary mask is coverage >= 0.5. The layer's fill colour is the
most common colour of its fully covered pixels over the frames rendered.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass

import numpy as np

from fluidymation.stages.vector import Renderer, VectorDocument

NAME = "rasterize"
VERSION = 2  # 2: the layer's straight colour is written beside its coverage
MASK_THRESHOLD = 0.5


@dataclass(frozen=True)
class Params:
    size: tuple[int, int]  # (width, height) px
    fps: float


@dataclass
class LayerRaster:
    """One frame of one layer: coverage (H, W) float32 in [0, 1] and premultiplied RGBA."""

    coverage: np.ndarray
    rgba: np.ndarray

    @property
    def mask(self) -> np.ndarray:
        return self.coverage >= MASK_THRESHOLD

    @property
    def straight_rgb(self) -> np.ndarray:
        """(H, W, 3) float32 in [0, 1]: the layer's own colour where it shows, 0 elsewhere."""
        return unpremultiplied(self.rgba)


def unpremultiplied(rgba: np.ndarray) -> np.ndarray:
    """(..., 3) float32 in [0, 1]: the colour of 8-bit premultiplied ``rgba`` (..., 4) with the alpha divided out
    (0 where the alpha is 0)."""
    alpha = rgba[..., 3:4].astype(np.float32)
    return np.clip(rgba[..., :3].astype(np.float32) / np.maximum(alpha, 1.0), 0.0, 1.0)


def rasterize_frame(renderer: Renderer, document: VectorDocument, vector_layers: tuple[str, ...], frame: int,
                    params: Params) -> LayerRaster:
    """Render ``vector_layers`` of ``document`` alone at scene ``frame`` (time ``frame / fps``)."""
    rgba = renderer.render(document, vector_layers, frame / params.fps, params.size)
    return LayerRaster(rgba[:, :, 3].astype(np.float32) / np.float32(255.0), rgba)


class ColorTally:
    """Counts the colours of fully covered pixels over frames to find the dominant fill."""

    def __init__(self):
        self.opaque = Counter()
        self.partial = Counter()

    def add(self, rgba: np.ndarray) -> None:
        alpha = rgba[:, :, 3]
        opaque = rgba[alpha == 255][:, :3]
        if opaque.size:
            self.opaque.update(_count_colors(opaque))
        elif not self.opaque:
            covered = rgba[alpha > 0]
            if covered.size:
                self.partial.update(_count_colors(np.rint(unpremultiplied(covered) * 255.0).astype(np.uint8)))

    def dominant(self) -> str | None:
        """'#rrggbb' of the most common colour, or None when the layer never shows."""
        counts = self.opaque or self.partial
        if not counts:
            return None
        packed = max(counts.items(), key=lambda item: (item[1], -item[0]))[0]
        return f"#{packed:06x}"


def _count_colors(rgb: np.ndarray) -> dict[int, int]:
    packed = (rgb[:, 0].astype(np.int64) << 16) | (rgb[:, 1].astype(np.int64) << 8) | rgb[:, 2]
    values, counts = np.unique(packed, return_counts=True)
    return dict(zip(values.tolist(), counts.tolist()))
