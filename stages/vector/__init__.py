"""Readers for vector animations: Lottie (.json/.lottie/.tgs), SVG (static, SMIL, sequences).

:func:`open_vector` picks the reader from the path and returns a
:class:`~fluidymation.stages.vector.base.VectorSource`.
"""

from __future__ import annotations

from pathlib import Path

from fluidymation.errors import InputError
from fluidymation.stages.files import is_sequence_pattern
from fluidymation.stages.vector.base import DEFAULT_FPS, VectorLayer, VectorSource
from fluidymation.stages.vector.lottie_input import open_lottie, open_smil_svg
from fluidymation.stages.vector.svg_input import (
    SvgSequenceSource,
    SvgSource,
    has_smil,
    load_svg,
    sequence_files,
)

__all__ = ["DEFAULT_FPS", "VectorLayer", "VectorSource", "open_vector"]

_LOTTIE_SUFFIXES = (".json", ".lottie", ".tgs")


def open_vector(path: Path, *, split: tuple[str, ...] = ()) -> VectorSource:
    """Open the vector animation at ``path`` (a file, or a pattern of numbered SVG files).

    ``split`` lists precomp layer names (or globs) to be split into their children.
    """
    text = str(path)
    suffix = path.suffix.lower()
    if suffix == ".svg" and is_sequence_pattern(path.name):
        return SvgSequenceSource(text, sequence_files(path))
    if suffix in _LOTTIE_SUFFIXES:
        return open_lottie(path, split=split)
    if suffix == ".svg":
        root = load_svg(path)
        return open_smil_svg(path, root) if has_smil(root) else SvgSource(path, root)
    raise InputError(f"{path}: unknown input type '{suffix or path.name}'; expected a Lottie .json, .lottie "
                     "or .tgs file, an .svg file, or a numbered SVG pattern such as frames/%04d.svg")
