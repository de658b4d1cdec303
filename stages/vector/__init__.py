"""Vector animations: the reader table (files to documents) and the renderer table (documents to pixels).

:func:`open_document` opens a Lottie (.json/.lottie/.tgs) or SVG (still, animated, numbered
sequence) input with the first reader of :data:`READERS` that takes its path;
:func:`renderer_for` picks the first renderer of :data:`RENDERERS` that draws the
document's kind.
"""

from __future__ import annotations

from pathlib import Path

from fluidymation.errors import InputError
from fluidymation.stages.vector import lottie_reader, svg_reader
from fluidymation.stages.vector.base import DEFAULT_FPS, Reader, Renderer, Unsupported, VectorDocument, VectorLayer
from fluidymation.stages.vector.cairosvg_renderer import CairoSvgRenderer
from fluidymation.stages.vector.thorvg_renderer import ThorVGRenderer

__all__ = ["DEFAULT_FPS", "READERS", "RENDERERS", "Reader", "Renderer", "Unsupported", "VectorDocument",
           "VectorLayer", "open_document", "renderer_for"]

READERS: tuple[Reader, ...] = (
    svg_reader.SEQUENCE_READER,
    lottie_reader.READER,
    svg_reader.SVG_READER,
)
RENDERERS: tuple[Renderer, ...] = (ThorVGRenderer(), CairoSvgRenderer())


def open_document(path: Path, *, split: tuple[str, ...] = (), fps: float | None = None,
                  **options: str | None) -> VectorDocument:
    """Open the vector animation at ``path`` (a file, or a pattern of numbered SVG files).

    ``split`` lists precomp layer names (or globs) to be split into their children; ``fps``
    is the scene's frame rate, if it sets one (a numbered sequence shows a file per frame).
    ``options`` are the scene's reader options (``animation``, ``theme``); None is unset.
    """
    given = {name: value for name, value in options.items() if value is not None}
    for reader in READERS:
        if reader.takes(path):
            for name in given:
                if name not in reader.options:
                    raise InputError(f"{path}: the scene's '{name}' does not apply to this input (the {reader.name} "
                                     f"reader takes {', '.join(reader.options) or 'no options'})")
            return reader.open(path, split=split, fps=fps, **given)
    raise InputError(f"{path}: unknown input type '{path.suffix.lower() or path.name}'; expected a Lottie .json, "
                     ".lottie or .tgs file, an .svg file, or a numbered SVG pattern such as frames/%04d.svg")


def renderer_for(document: VectorDocument) -> Renderer:
    """The default renderer of the document's kind: the first of :data:`RENDERERS` that draws it."""
    for renderer in RENDERERS:
        if document.kind in renderer.kinds:
            return renderer
    raise LookupError(f"no renderer draws {document.kind} documents")
