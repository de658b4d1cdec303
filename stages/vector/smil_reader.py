"""The SMIL-SVG reader: an SVG with SMIL animation, imported as a Lottie document.

The lottie package's SVG importer turns each top-level ``<g>`` into a group of one shape
layer; those groups are the document's layers. The importer gives the animation its own
frame rate, but the file has none (``native_fps`` is None).
"""

from __future__ import annotations

from pathlib import Path
from xml.etree import ElementTree

from lottie.parsers.svg.importer import parse_svg_etree

from fluidymation.errors import InputError
from fluidymation.stages.vector.base import Reader
from fluidymation.stages.vector.lottie_reader import LottieDocument
from fluidymation.stages.vector.svg_reader import has_smil, load_svg


def open_smil_svg(path: Path, *, split: tuple[str, ...] = (), fps: float | None = None) -> LottieDocument:
    """Import an SVG with SMIL animation (``split`` and ``fps`` do not apply)."""
    root = load_svg(path)
    try:
        animation = parse_svg_etree(ElementTree.ElementTree(root))
    except Exception as exc:  # the importer raises many types on odd SVG
        raise InputError(f"{path}: the SMIL animation cannot be imported ({type(exc).__name__}: {exc})") from None
    return LottieDocument(path, animation.to_dict(), kind="svg-smil", reader=READER, groups_as_layers=True)


def _is_smil(path: Path) -> bool:
    return has_smil(load_svg(path))


READER = Reader("svg-smil", 1, (".svg",), open_smil_svg, claims=_is_smil)
