"""What every vector input offers the rasterize stage: layers, size, timing, rendering."""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass
from pathlib import Path

import numpy as np

DEFAULT_FPS = 24.0


@dataclass(frozen=True)
class VectorLayer:
    """A layer of the vector file: its name and z-order (0 = bottom, drawn first)."""

    name: str
    z: int


class VectorSource(ABC):
    """A vector animation: named layers that can be rendered alone at any frame and size.

    Subclasses set ``path``, ``width``, ``height`` (native size, px), ``native_fps``
    (None when the file has no frame rate) and ``layers`` (bottom to top), and implement
    :meth:`default_range` and :meth:`render`.
    """

    kind: str
    path: Path
    width: float
    height: float
    native_fps: float | None
    layers: list[VectorLayer]

    @abstractmethod
    def default_range(self, fps: float) -> tuple[int, int]:
        """The animation's own frames at ``fps``: (first, end exclusive)."""

    @abstractmethod
    def render(self, names: list[str], frame: int, fps: float, size: tuple[int, int]) -> np.ndarray:
        """Render only the layers ``names`` at scene ``frame`` (at ``fps``), size (W, H).

        Returns (H, W, 4) uint8 premultiplied RGBA.
        """

    def layer_names(self) -> list[str]:
        return [layer.name for layer in self.layers]


def frames_in(duration_seconds: float, fps: float) -> int:
    """Frames needed to cover ``duration_seconds`` at ``fps`` (at least one)."""
    return max(1, math.ceil(duration_seconds * fps - 1e-6))
