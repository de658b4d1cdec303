"""The vector protocol: a document (read from a file) and a renderer (draws its layers).

A *reader* opens a file into a :class:`VectorDocument`: size, timing, named layers and the
layers isolated at a time. A :class:`Renderer` turns a document's layers at a time in
seconds into coverage. Readers and renderers are listed in tables in
:mod:`fluidymation.stages.vector`.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from fluidymation.stages.files import is_sequence_pattern

DEFAULT_FPS = 24.0


@dataclass(frozen=True)
class Unsupported:
    """Something in a vector file that a reader or renderer does not draw as the file means it.

    ``element`` names it the way a user finds it in the file (``<animate id="spin">``,
    ``layers[3] 'arm' (expression on the rotation)``); ``message`` says what is done instead.
    """

    element: str
    message: str


@dataclass(frozen=True)
class VectorLayer:
    """A layer of the vector file: its name and z-order (0 = bottom, drawn first)."""

    name: str
    z: int


class VectorDocument(ABC):
    """A vector animation as read from its file(s): named layers, size and timing.

    Subclasses set ``path``, ``kind`` (lottie, dotlottie, tgs, svg,
    svg-sequence), ``reader`` and ``reader_version`` (the reader that opened it),
    ``width``, ``height`` (native size, px), ``native_fps`` (None when the file has no
    frame rate), ``layers`` (bottom to top) and ``files`` (every file whose content is
    read), and implement :meth:`frame_range` and :meth:`isolate`. ``unsupported`` lists
    what the reader found it cannot render faithfully (warned about, refused with ``--strict``);
    ``choices`` what was picked inside the file (a dotLottie's animation and theme, by id).
    """

    path: Path
    kind: str
    reader: str
    reader_version: int
    width: float
    height: float
    native_fps: float | None
    layers: list[VectorLayer]
    files: list[Path]
    unsupported: tuple[Unsupported, ...] = ()
    choices: dict[str, str] = {}

    @abstractmethod
    def frame_range(self, fps: float) -> tuple[int, int]:
        """The animation's own frames at ``fps``: (first, end exclusive)."""

    @abstractmethod
    def isolate(self, names: Sequence[str], time_seconds: float) -> Any:
        """Only the layers ``names`` as shown at ``time_seconds``, in the form this kind's renderers draw."""

    @abstractmethod
    def moving_elements(self, names: Sequence[str], before_seconds: float, now_seconds: float,
                        size: tuple[int, int]) -> tuple[list, list[str]]:
        """The filled elements of layers ``names`` at ``now_seconds`` with where their outline points were at
        ``before_seconds``, in pixels of a raster of ``size`` (width, height), and what is drawn but not read
        (:mod:`fluidymation.engine.vector_motion`; ``flow: vector``, docs/guides.md). What is not read takes
        the masks' estimate, so a kind whose geometry is not read at all names all of it."""

    def layer_names(self) -> list[str]:
        return [layer.name for layer in self.layers]


class Renderer(ABC):
    """Draws layers of a document at a time; ``kinds`` lists the document kinds it can draw."""

    name: str
    version: int
    kinds: tuple[str, ...]

    @abstractmethod
    def render(self, document: VectorDocument, layers: Sequence[str], time_seconds: float,
               size: tuple[int, int]) -> np.ndarray:
        """Only ``layers`` of ``document`` at ``time_seconds``, at ``size`` = (W, H) px.

        Returns (H, W, 4) uint8 premultiplied RGBA; the alpha is the layers' coverage.
        """


@dataclass(frozen=True)
class Reader:
    """A row of the reader table: which paths a reader takes and how it opens them.

    A path is taken when its suffix is one of ``suffixes``, it is a numbered pattern
    (``frames/%04d.svg``) if ``sequence`` is set, and ``claims(path)`` (when given, a look
    at the content) agrees. ``open(path, split=..., fps=..., **options)`` returns the
    document; ``options`` names the scene keys it takes besides (a dotLottie's ``animation``).
    """

    name: str
    version: int
    suffixes: tuple[str, ...]
    open: Callable[..., VectorDocument]
    sequence: bool = False
    claims: Callable[[Path], bool] | None = None
    options: tuple[str, ...] = ()

    def takes(self, path: Path) -> bool:
        """Whether this reader opens ``path``."""
        return (path.suffix.lower() in self.suffixes and (not self.sequence or is_sequence_pattern(path.name))
                and (self.claims is None or self.claims(path)))


def frames_in(duration_seconds: float, fps: float) -> int:
    """Frames needed to cover ``duration_seconds`` at ``fps`` (at least one)."""
    return max(1, math.ceil(duration_seconds * fps - 1e-6))
