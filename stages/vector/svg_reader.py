"""The plain-SVG readers: a single file (static, or animated) or a numbered sequence of files.

Layers are the top-level drawable elements of the root ``<svg>`` (groups, shapes, text,
use, image, link, nested svg), named by ``inkscape:label``, else ``id``, else ``group N``
for a group and the tag and its place among the other elements for the rest
(``circle 2``: the third element that is not a group). To isolate some layers, every other
top-level drawable element is given ``display: none`` in its style (over any style sheet
or animated value).

A single file may hold animations: each parser of :data:`ANIMATIONS` looks for its kind
(SMIL, CSS) and returns an :class:`Animation`; the document at a time is a copy of the
file's tree with every animation applied at that time, in table order.
"""

from __future__ import annotations

import copy
import functools
import math
import re
from abc import ABC, abstractmethod
from pathlib import Path
from typing import Callable, NamedTuple
from xml.etree import ElementTree

import tinycss2

from fluidymation.errors import InputError
from fluidymation.stages.files import sequence_paths
from fluidymation.stages.vector.base import (
    DEFAULT_FPS, Reader, Unsupported, VectorDocument, VectorLayer, frames_in,
)
from fluidymation.stages.vector.safety import check_svg_references, local_name, parse_xml, read_file

INKSCAPE_LABEL = "{http://www.inkscape.org/namespaces/inkscape}label"
SVG_NAMESPACE = "http://www.w3.org/2000/svg"
MAX_SEQUENCE_FILES = 100_000
_DRAWN = {"g", "path", "rect", "circle", "ellipse", "line", "polyline", "polygon", "text", "use", "image", "svg",
          "switch", "a", "foreignObject"}
#: The filter primitives cairosvg applies (feBlend: its mode only); it leaves out every other one.
_DRAWN_FILTER_PRIMITIVES = {"feOffset", "feFlood", "feBlend"}
_UNITS_PX = {"": 1.0, "px": 1.0, "pt": 96 / 72, "pc": 16.0, "mm": 96 / 25.4, "cm": 96 / 2.54, "in": 96.0}
_LENGTH = re.compile(r"^\s*([0-9.eE+-]+)\s*([a-z%]*)\s*$")


def load_svg(path: Path) -> ElementTree.Element:
    """Parse and vet an SVG file: well-formed, an <svg> root, no external references."""
    root = parse_xml(read_file(path), str(path))
    if local_name(root.tag) != "svg":
        raise InputError(f"{path}: the root element is <{local_name(root.tag)}>, not <svg>")
    check_svg_references(root, str(path))
    return root


def svg_size(root: ElementTree.Element, source: str) -> tuple[float, float]:
    """The document size in px from width/height (with units) or the viewBox."""
    box = (root.get("viewBox") or "").replace(",", " ").split()
    sizes = []
    for index, attribute in enumerate(("width", "height")):
        value = _length_px(root.get(attribute))
        if value is None and len(box) == 4:
            value = _number(box[2 + index])
        if value is None or value <= 0:
            raise InputError(f"{source}: cannot tell the SVG's {attribute}: give the <svg> element a "
                             "width/height or a viewBox, or set size in the scene")
        sizes.append(value)
    return sizes[0], sizes[1]


def _length_px(text: str | None) -> float | None:
    match = _LENGTH.match(text or "")
    if not match or match.group(2) not in _UNITS_PX:
        return None
    value = _number(match.group(1))
    return None if value is None else value * _UNITS_PX[match.group(2)]


def _number(text: str) -> float | None:
    try:
        return float(text)
    except ValueError:
        return None


def undrawn(root: ElementTree.Element) -> tuple[Unsupported, ...]:
    """What the file holds that cairosvg does not draw: filter primitives other than feOffset, feFlood, feBlend."""
    items = []
    for element in root.iter():
        if local_name(element.tag) != "filter":
            continue
        left_out = sorted({local_name(child.tag) for child in element if local_name(child.tag).startswith("fe")}
                          - _DRAWN_FILTER_PRIMITIVES)
        if left_out:
            label = f'<filter id="{element.get("id")}">' if element.get("id") else "<filter>"
            items.append(Unsupported(label, f"cairosvg does not draw {', '.join(f'<{tag}>' for tag in left_out)}: "
                                            "what the filter applies to is drawn without them"))
    return tuple(items)


def _top_layers(root: ElementTree.Element) -> list[tuple[ElementTree.Element, str]]:
    """The layers' elements and names: every top-level drawable element, groups and shapes alike.

    A group without a label or id is ``group N`` (N counts the groups), any other element
    ``<tag> N`` (N counts the top-level drawable elements that are not groups)."""
    layers = []
    counts = {"group": 0, "other": 0}
    for element in root:
        tag = local_name(element.tag)
        if tag not in _DRAWN:
            continue
        kind = "group" if tag == "g" else "other"
        fallback = f"group {counts[kind]}" if kind == "group" else f"{tag} {counts[kind]}"
        counts[kind] += 1
        layers.append((element, element.get(INKSCAPE_LABEL) or element.get("id") or fallback))
    return layers


def _layer_names(root: ElementTree.Element) -> list[str]:
    return [name for _, name in _top_layers(root)]


def _hide_other_layers(root: ElementTree.Element, names: list[str]) -> ElementTree.Element:
    """``root`` (changed in place) with every top-level drawable element but the layers ``names`` hidden."""
    keep = set(names)
    kept = {id(element) for element, name in _top_layers(root) if name in keep}
    for element in root:
        if local_name(element.tag) in _DRAWN and id(element) not in kept:
            set_style_property(element, "display", "none")
    return root


def _svg_bytes(root: ElementTree.Element) -> bytes:
    ElementTree.register_namespace("", SVG_NAMESPACE)
    return ElementTree.tostring(root)


def style_property(element: ElementTree.Element, name: str) -> str | None:
    """The value the element's ``style`` attribute gives the CSS property ``name``, if any (the last one wins)."""
    value = None
    for declaration in _style_declarations(element):
        if declaration.lower_name == name:
            value = tinycss2.serialize(declaration.value).strip()
    return value


def set_style_property(element: ElementTree.Element, name: str, value: str) -> None:
    """Set the CSS property ``name`` in the element's ``style`` attribute, in place of any declaration of it."""
    kept = [f"{declaration.name}: {tinycss2.serialize(declaration.value).strip()}"
            + (" !important" if declaration.important else "")
            for declaration in _style_declarations(element) if declaration.lower_name != name]
    element.set("style", "; ".join([*kept, f"{name}: {value}"]))


def _style_declarations(element: ElementTree.Element) -> list:
    style = element.get("style")
    if not style:
        return []
    return [item for item in tinycss2.parse_blocks_contents(style, skip_whitespace=True, skip_comments=True)
            if item.type == "declaration"]


class Animation(ABC):
    """What changes an SVG document over time (one animation language), parsed from its file's tree."""

    #: The animation language, as a user names it (``SMIL``, ``CSS``).
    language: str
    #: What it found in the file and cannot play faithfully.
    unsupported: tuple[Unsupported, ...] = ()

    @abstractmethod
    def apply(self, at: Callable[[ElementTree.Element], ElementTree.Element], time_seconds: float) -> None:
        """Set a fresh copy of the file's tree to how it shows at ``time_seconds``.

        ``at(element)`` gives the copy of an element of the tree the animation was parsed from.
        """

    @abstractmethod
    def duration(self) -> float:
        """Seconds it takes to play once through (the document's default frame range)."""


from fluidymation.stages.vector.smil import parse_smil  # noqa: E402  (it subclasses Animation)
from fluidymation.stages.vector.css_animation import parse_css_animation  # noqa: E402  (it subclasses Animation)

#: Parsers of the animation languages a file may hold: ``parse(root, source) -> Animation | None``.
ANIMATIONS: tuple[Callable[[ElementTree.Element, str], Animation | None], ...] = (parse_smil, parse_css_animation)


class SvgFrame(NamedTuple):
    """Layers of an SVG document isolated at a time: the SVG to draw and the file it comes from."""

    svg: bytes
    source: str


class _StaticTrees(VectorDocument):
    """An SVG kind whose frames are static trees (``static_tree``): its geometry is read for motion."""

    @abstractmethod
    def static_tree(self, names, time_seconds) -> ElementTree.Element:
        """The layers ``names`` as shown at ``time_seconds``, a static tree (animations applied)."""

    def moving_elements(self, names, before_seconds, now_seconds, size):
        from fluidymation.stages.vector.svg_geometry import moving_elements  # it reads this module's helpers

        names, size = tuple(names), tuple(size)
        return moving_elements(self._outlines(names, before_seconds, size), self._outlines(names, now_seconds, size))

    @functools.lru_cache(maxsize=2)  # frame j's outlines are frame j + 1's earlier ones
    def _outlines(self, names: tuple[str, ...], time_seconds: float, size: tuple[int, int]):
        from fluidymation.stages.vector.svg_geometry import outlines

        return outlines(self.static_tree(list(names), time_seconds), size)


class SvgDocument(_StaticTrees):
    """An SVG file: the same picture at every time, unless it holds :data:`ANIMATIONS`."""

    kind = "svg"
    native_fps = None

    def __init__(self, path: Path, root: ElementTree.Element):
        self.path = path
        self.reader, self.reader_version = SVG_READER.name, SVG_READER.version
        self.files = [path]
        self.root = root
        self.width, self.height = svg_size(root, str(path))
        self.layers = [VectorLayer(name, z) for z, name in enumerate(_layer_names(root))]
        self.animations = _animations(root, str(path))
        self.unsupported = undrawn(root) + tuple(item for animation in self.animations
                                                 for item in animation.unsupported)

    def frame_range(self, fps):
        if not self.animations:
            return 0, 1
        duration = max(animation.duration() for animation in self.animations)
        if not math.isfinite(duration * fps):  # e.g. animation-iteration-count: 1e308 of a 1 s animation
            raise InputError(f"{self.path}: the animations run for {duration:g} s, too long to count its frames; "
                             "give the scene's frames: {start, end}")
        return 0, frames_in(duration, fps)

    def isolate(self, names, time_seconds) -> SvgFrame:
        return SvgFrame(_svg_bytes(self.static_tree(names, time_seconds)), str(self.path))

    def static_tree(self, names, time_seconds) -> ElementTree.Element:
        """The document as shown at ``time_seconds`` (animations applied), only the layers ``names`` displayed."""
        return _hide_other_layers(_at_time(self.root, self.animations, time_seconds), names)


class SvgSequenceDocument(_StaticTrees):
    """Numbered SVG files, one per frame at ``fps``; layers (and what is not drawn) are those of the first file."""

    kind = "svg-sequence"
    native_fps = None

    def __init__(self, pattern: str, files: list[Path], fps: float):
        self.path = Path(pattern)
        self.reader, self.reader_version = SEQUENCE_READER.name, SEQUENCE_READER.version
        self.files = files
        self.fps = fps
        first = load_svg(files[0])
        self.width, self.height = svg_size(first, str(files[0]))
        self.layers = [VectorLayer(name, z) for z, name in enumerate(_layer_names(first))]
        moving = [animation for animation in _animations(first, str(files[0])) if animation.duration() > 0]
        self.unsupported = undrawn(first) + tuple(
            Unsupported(f"{files[0].name}: {animation.language} animations", "the files of a sequence are stills: "
                        "their animations are shown as at time 0") for animation in moving)

    def frame_range(self, fps):
        return 0, len(self.files)

    def isolate(self, names, time_seconds) -> SvgFrame:
        return SvgFrame(_svg_bytes(self.static_tree(names, time_seconds)), str(self._file_at(time_seconds)))

    def static_tree(self, names, time_seconds) -> ElementTree.Element:
        """The file of the frame at ``time_seconds`` (its CSS resolved), only the layers ``names`` displayed."""
        path = self._file_at(time_seconds)
        root = load_svg(path)  # its CSS transforms are resolved even when nothing moves
        return _hide_other_layers(_at_time(root, _animations(root, str(path)), 0.0), names)

    def _file_at(self, time_seconds) -> Path:
        frame = math.floor(time_seconds * self.fps + 1e-6)
        if not 0 <= frame < len(self.files):
            raise InputError(f"{self.path}: frame {frame} is outside the sequence (0 to {len(self.files) - 1})")
        return self.files[frame]


def _animations(root: ElementTree.Element, source: str) -> tuple[Animation, ...]:
    """The animations the file holds, one per parser of :data:`ANIMATIONS` that finds its kind."""
    return tuple(animation for parse in ANIMATIONS if (animation := parse(root, source)))


def _at_time(root: ElementTree.Element, animations: tuple[Animation, ...], time_seconds: float) -> ElementTree.Element:
    """A copy of ``root`` with every animation applied at ``time_seconds``."""
    copies: dict[int, object] = {}
    copied = copy.deepcopy(root, copies)
    for animation in animations:
        animation.apply(lambda element: copies[id(element)], time_seconds)
    return copied


def open_svg(path: Path, *, split: tuple[str, ...] = (), fps: float | None = None) -> SvgDocument:
    """Open an SVG file, still or animated (``split`` and ``fps`` do not apply)."""
    return SvgDocument(path, load_svg(path))


def open_svg_sequence(pattern: Path, *, split: tuple[str, ...] = (), fps: float | None = None) -> SvgSequenceDocument:
    """Open the numbered SVG files of ``pattern``: file k is shown from time k / ``fps``.

    ``fps`` is the scene's frame rate; a sequence has none of its own, so None means
    :data:`DEFAULT_FPS`, as for the scene.
    """
    return SvgSequenceDocument(str(pattern), sequence_files(pattern), fps or DEFAULT_FPS)


SVG_READER = Reader("svg", 4, (".svg",), open_svg)
SEQUENCE_READER = Reader("svg-sequence", 3, (".svg",), open_svg_sequence, sequence=True)


def sequence_files(pattern: Path) -> list[Path]:
    """Files of a ``frames/%04d.svg`` or glob pattern, in frame order; an InputError when none or too many."""
    files = sequence_paths(str(pattern))
    if not files:
        raise InputError(f"{pattern}: no files match this sequence pattern")
    if len(files) > MAX_SEQUENCE_FILES:
        raise InputError(f"{pattern}: {len(files)} files is over the limit of {MAX_SEQUENCE_FILES} frames")
    return files

