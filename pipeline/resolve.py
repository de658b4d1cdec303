"""From a validated scene to a concrete plan: the opened input and its renderer, fps, frames, size, layers.

Scene frame numbers count from time 0 of the input at the scene's fps; the plan's range
is ``start``..``end`` (exclusive), and output files are numbered from ``start``.
"""

from __future__ import annotations

import fnmatch
import logging
import re
from dataclasses import dataclass, replace

from fluidymation.errors import InputError, SceneError
from fluidymation.pipeline.cache import file_digest
from fluidymation.pipeline.scene import MAX_FRAMES, MAX_SIZE, LayerSpec, Scene
from fluidymation.stages.vector import DEFAULT_FPS, Renderer, VectorDocument, open_document, renderer_for

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class PlannedLayer:
    """A scene layer with the vector layers it selects (bottom to top) and its z-order."""

    spec: LayerSpec
    vector_layers: tuple[str, ...]
    z: int

    @property
    def name(self) -> str:
        return self.spec.name

    @property
    def flow(self) -> str:
        """Where its motion comes from: ``vector`` (the geometry) or ``masks``."""
        return self.spec.flow

    @property
    def dirname(self) -> str:
        """The layer's name made safe as a folder name."""
        return re.sub(r"[^A-Za-z0-9_.\- ]", "_", self.name).lstrip(".") or "_"


@dataclass(frozen=True)
class Plan:
    scene: Scene
    document: VectorDocument
    renderer: Renderer
    fps: float
    start: int
    end: int
    size: tuple[int, int]
    layers: tuple[PlannedLayer, ...]

    @property
    def frame_count(self) -> int:
        return self.end - self.start

    def drawing_record(self) -> dict:
        """What the layers' drawings depend on besides the layer, frame and size: the input's content (every
        file of a numbered sequence), its reader, what was picked inside it, and the renderer (a stage key's part)."""
        document, renderer = self.document, self.renderer
        return {"files": [file_digest(path) for path in document.files],
                "reader": [document.reader, document.reader_version], "choices": document.choices,
                "renderer": [renderer.name, renderer.version]}

    def layer(self, name: str) -> PlannedLayer:
        for layer in self.layers:
            if layer.name == name:
                return layer
        raise SceneError(f"{self.scene.path}: no layer called '{name}'; the scene's layers are: "
                         f"{', '.join(layer.name for layer in self.layers)}")

    def frames(self, window: tuple[int | None, int | None] | None = None) -> range:
        """Scene frames to process: the plan's range, narrowed by a ``--frames A:B`` window."""
        if window is None:
            return range(self.start, self.end)
        first = self.start if window[0] is None else window[0]
        last = self.end if window[1] is None else window[1]
        if first < self.start or last > self.end or first >= last:
            raise SceneError(f"--frames {_fmt(window)} is not a non-empty part of the scene's range "
                             f"{self.start}:{self.end}")
        return range(first, last)


def plan_scene(scene: Scene, *, strict: bool = False) -> Plan:
    """Open the scene's input, choose its renderer and work out frames, size and each layer's selection.

    What the input holds that cannot be rendered faithfully is logged as a warning, each
    naming the file and the element; with ``strict`` it is an InputError instead.
    """
    document = open_document(scene.input, split=scene.split, fps=scene.fps, animation=scene.animation,
                             theme=scene.theme)
    report_unsupported(document, strict=strict)
    fps = scene.fps or document.native_fps or DEFAULT_FPS
    default_start, default_end = document.frame_range(fps)
    start = scene.frames.start if scene.frames else default_start
    end = scene.frames.end if scene.frames and scene.frames.end is not None else default_end
    if end <= start:
        raise SceneError(f"{scene.path}: the frame range {start}:{end} is empty (the animation has frames "
                         f"{default_start}:{default_end} at {fps:g} fps)")
    if end - start > MAX_FRAMES:
        raise SceneError(f"{scene.path}: {end - start} frames is over the limit of {MAX_FRAMES}")
    if document.kind == "svg-sequence" and end > default_end:
        raise SceneError(f"{scene.path}: frames.end {end} is past the end of the sequence "
                         f"({default_end} files)")
    return Plan(scene, document, renderer_for(document), fps, start, end, _size(scene, document),
                _layers(scene, document))


def report_unsupported(document: VectorDocument, *, strict: bool) -> None:
    """Warn about each unsupported element of ``document``, or refuse them all with ``strict``."""
    if not document.unsupported:
        return
    lines = [f"{document.path}: {item.element}: {item.message}" for item in document.unsupported]
    if strict:
        more = f" (and {len(lines) - 10} more)" if len(lines) > 10 else ""
        raise InputError(f"--strict: {len(lines)} unsupported element(s):\n  " + "\n  ".join(lines[:10]) + more)
    for line in lines:
        log.warning("unsupported: %s", line)


def parse_window(text: str | None) -> tuple[int | None, int | None] | None:
    """'A:B', 'A:' or ':B' (scene frame numbers, B exclusive) to a window."""
    if text is None:
        return None
    parts = text.split(":")
    try:
        if len(parts) != 2:
            raise ValueError
        return tuple(int(part) if part.strip() else None for part in parts)
    except ValueError:
        raise SceneError(f"--frames {text!r}: expected A:B (scene frame numbers, B exclusive)") from None


def _fmt(window) -> str:
    return ":".join("" if part is None else str(part) for part in window)


def _size(scene: Scene, document: VectorDocument) -> tuple[int, int]:
    if scene.size:
        return scene.size
    scale = scene.scale or 1.0
    width, height = (max(1, round(extent * scale)) for extent in (document.width, document.height))
    if width > MAX_SIZE or height > MAX_SIZE:
        raise SceneError(f"{scene.path}: the output would be {width}x{height} px, over the limit of "
                         f"{MAX_SIZE} px a side; set size or a smaller scale")
    return width, height


def _layers(scene: Scene, document: VectorDocument) -> tuple[PlannedLayer, ...]:
    z_of = {layer.name: layer.z for layer in document.layers}
    if scene.layers is None:
        specs = [_default_layer(scene, name) for name in dict.fromkeys(document.layer_names())]
        return tuple(PlannedLayer(spec, (spec.name,), z_of[spec.name]) for spec in specs)
    planned = []
    for index, spec in enumerate(scene.layers):
        chosen = []
        for pattern in spec.select:
            matches = [name for name in z_of if fnmatch.fnmatchcase(name, pattern)]
            if not matches:
                raise SceneError(f"{scene.path}: layers[{index}].select: '{pattern}' matches no layer of "
                                 f"{scene.input.name}; its layers are: {', '.join(z_of) or '(none)'}")
            chosen.extend(name for name in matches if name not in chosen)
        chosen.sort(key=z_of.__getitem__)
        planned.append(PlannedLayer(spec, tuple(chosen), max(z_of[name] for name in chosen)))
    return tuple(planned)


def _default_layer(scene: Scene, name: str) -> LayerSpec:
    return replace(scene.defaults, name=name, select=(name,))
