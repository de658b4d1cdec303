"""The exemplar store: a moving exemplar's colour and guidance channels, on disk or in memory.

Every stylizer reads its exemplar from here. :func:`store_colour` writes an exemplar's
colour beside the guides cache that :func:`fluidymation.stages.guides.compute_guides`
made of its masks; :class:`StoredSource` opens such a folder and reads only the frames
asked for (:meth:`StoredSource.window`), so a stylizer holding a few frames at a time
does not load a long exemplar whole. :func:`in_memory` gathers a whole exemplar into a
:class:`Source` (tests and benchmarks).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fluidymation.engine import distance
from fluidymation.errors import StageError
from fluidymation.stages import guides
from fluidymation.stages.regions import Regions


@dataclass(frozen=True)
class Source:
    """The exemplar with its guidance channels, ``(T, Hs, Ws)`` unless noted.

    ``rgb`` (T, Hs, Ws, 3) float32 in [0, 1]; ``dist`` signed distance clamped at the
    border width; ``shape``, ``ext_plus``, ``ext_minus``, ``angle`` float32; ``segment``
    int32 (-1 outside the exemplar's mask, 0 border, 1 interior).
    """

    rgb: np.ndarray
    dist: np.ndarray
    shape: np.ndarray
    ext_plus: np.ndarray
    ext_minus: np.ndarray
    angle: np.ndarray
    segment: np.ndarray

    @property
    def frame_count(self) -> int:
        return self.rgb.shape[0]

    @property
    def ext_max(self) -> float:
        """The largest ext+ or ext− of the exemplar."""
        return float(max(self.ext_plus.max(), self.ext_minus.max()))

    def window(self, start: int, stop: int) -> Source:
        """Frames ``start..stop−1`` (views; the source itself for all frames)."""
        if (start, stop) == (0, self.frame_count):
            return self
        return Source(**{field.name: getattr(self, field.name)[start:stop] for field in dataclasses.fields(self)})


def concatenate(parts: list[Source]) -> Source:
    """Sources joined along time, in order."""
    if len(parts) == 1:
        return parts[0]
    return Source(**{field.name: np.concatenate([getattr(part, field.name) for part in parts])
                     for field in dataclasses.fields(Source)})


def _gather(rgb: np.ndarray, cache: guides.GuideCache, start: int, stop: int) -> Source:
    """Exemplar frames ``start..stop−1``: their colour ``rgb`` and their guides from ``cache``."""
    frames = [cache.frame(index) for index in range(start, stop)]
    return Source(
        rgb=rgb,
        dist=np.stack([border_clamped(f.dist, cache.border_width) for f in frames]),
        shape=np.stack([f.shape for f in frames]),
        ext_plus=np.stack([f.ext_plus for f in frames]),
        ext_minus=np.stack([f.ext_minus for f in frames]),
        angle=np.stack([f.direction for f in frames]),
        segment=np.stack([f.segments.astype(np.int32) - 1 for f in frames]),
    )


def in_memory(rgb: np.ndarray, cache: guides.GuideCache) -> Source:
    """Gather an exemplar's colour and its guides (from :func:`guides.compute_guides`) into a :class:`Source`."""
    rgb = np.ascontiguousarray(rgb, np.float32)
    if rgb.ndim != 4 or rgb.shape[3] != 3 or rgb.shape[:3] != (cache.frame_count, cache.height, cache.width):
        raise StageError(f"exemplar: colour of shape {rgb.shape} does not match its guides "
                         f"({cache.frame_count} frames of {cache.width}x{cache.height})")
    return _gather(rgb, cache, 0, cache.frame_count)


class StoredSource:
    """An exemplar left on disk: its guides cache with its colour stored beside them (:func:`store_colour`).

    :meth:`window` reads only the frames asked for, so a stylize run with a
    ``source_window`` holds that many frames, whatever the exemplar's length.
    ``rgb`` and ``segment`` read every frame (for statistics over the whole exemplar).
    """

    COLOUR_FILE = "rgb.f32"
    REGIONS_FILE = "regions.npz"

    def __init__(self, directory):
        self.cache = guides.GuideCache.open(directory)
        self._colour = self.cache.directory / self.COLOUR_FILE
        frame_shape = (self.cache.height, self.cache.width, 3)
        expected = self.cache.frame_count * int(np.prod(frame_shape)) * 4
        if not self._colour.is_file() or self._colour.stat().st_size != expected:
            raise StageError(f"{directory}: no exemplar colour ({self.COLOUR_FILE}) of {self.cache.frame_count} "
                             f"frames of {self.cache.width}x{self.cache.height} beside the guides")
        self._frame_shape = frame_shape

    @property
    def frame_count(self) -> int:
        return self.cache.frame_count

    @property
    def ext_max(self) -> float:
        """The largest ext+ or ext− of the exemplar (from the guides' summary)."""
        return float(max(self.cache.meta["ext_plus_max"], self.cache.meta["ext_minus_max"]))

    def colour(self, start: int, stop: int) -> np.ndarray:
        """Colour of frames ``start..stop−1``, (n, Hs, Ws, 3) float32, read through a mapping released at once."""
        view = guides.map_frames(self._colour, start, stop, self._frame_shape)
        rgb = np.array(view)
        del view
        return rgb

    def window(self, start: int, stop: int) -> Source:
        """Frames ``start..stop−1`` as a :class:`Source` in memory."""
        if not 0 <= start < stop <= self.frame_count:
            raise StageError(f"exemplar: frames {start}:{stop} outside 0:{self.frame_count}")
        return _gather(self.colour(start, stop), self.cache, start, stop)

    @property
    def rgb(self) -> np.ndarray:
        """Every frame's colour, (T, Hs, Ws, 3) float32."""
        return self.colour(0, self.frame_count)

    @property
    def regions(self) -> Regions | None:
        """A still exemplar's colour regions (its ``segments:`` image), or None when it has none."""
        path = self.cache.directory / self.REGIONS_FILE
        if not path.is_file():
            return None
        with np.load(path) as stored:
            return Regions(stored["labels"], stored["colours"])

    @property
    def segment(self) -> np.ndarray:
        """Every frame's segment labels, (T, Hs, Ws) int32 (as :class:`Source`)."""
        return np.stack([distance.segments(self.cache.read("dist", index), border_width=self.cache.border_width)
                         .astype(np.int32) - 1 for index in range(self.frame_count)])


def store_regions(regions: Regions, directory) -> None:
    """Write a still exemplar's colour regions beside its guides (read back by :attr:`StoredSource.regions`)."""
    np.savez(Path(directory) / StoredSource.REGIONS_FILE, labels=regions.labels, colours=regions.colours)


def store_colour(rgb: np.ndarray, directory) -> None:
    """Write an exemplar's colour (T, Hs, Ws, 3) beside its guides cache in ``directory``, for :class:`StoredSource`."""
    np.ascontiguousarray(rgb, np.float32).tofile(Path(directory) / StoredSource.COLOUR_FILE)




def border_clamped(dist: np.ndarray, border_width: float) -> np.ndarray:
    """Signed distance clamped at the border width (the distance m(q) compares)."""
    return np.minimum(np.asarray(dist, np.float32), np.float32(border_width))
