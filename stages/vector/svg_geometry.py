"""The filled outlines of a static SVG in output pixels, and their motion between two frames.

An animated SVG is made static at each time by its reader (SMIL and CSS applied, every
transform written as a ``transform`` attribute). The same element of two such trees (found
by its place in the tree) is the same material; its outline points, cut the same way at
both times (:func:`~fluidymation.stages.vector.smil_path.subpath_rings`) and carried through
every transform, give :class:`~fluidymation.engine.vector_motion.MovingElement` objects
whose motion field no renderer is needed for (docs/guides.md, "Motion from the geometry").

Drawn here: ``path``, ``rect`` (rounded corners included), ``circle``, ``ellipse``,
``polygon`` and ``polyline`` with a fill or an undashed stroke (the band within half the
``stroke-width`` of the outline, :func:`~fluidymation.engine.vector_motion.stroke_rings`),
inside ``g`` groups and the root viewport (``viewBox``, ``preserveAspectRatio``). Anything
else that is displayed (dashed strokes, text, ``line``, ``use``, images, nested ``svg``) is
named in :func:`outlines`'s second result, so the caller falls back to the masks there.
"""

from __future__ import annotations

from dataclasses import dataclass
from xml.etree import ElementTree

import numpy as np
from fluidymation.engine.vector_motion import MovingElement, stroke_rings
from fluidymation.stages.vector.css_transform import (
    IDENTITY, Box, Matrix, matrix_of, multiply, origin_point, parse_origin, parse_svg_transform,
    resolve,
)
from fluidymation.stages.vector.css_syntax import tokens
from fluidymation.stages.vector.safety import local_name
from fluidymation.stages.vector.smil_path import PathData, subpath_lines, subpath_rings
from fluidymation.stages.vector.svg_reader import style_property, svg_size

_SHAPES = {"path", "rect", "circle", "ellipse", "polygon", "polyline"}
_CONTAINERS = {"g", "a", "switch"}
_NO_BOX = Box(0.0, 0.0, 0.0, 0.0)
#: Outline coordinates (output px) beyond this are left to the masks (float32 keeps them within 1 px).
_FARTHEST = 1e7
#: The inherited properties that decide what an element paints, with their initial values.
_PAINT_DEFAULTS = {"fill": "black", "fill-rule": "nonzero", "stroke": "none", "stroke-width": "1",
                   "stroke-dasharray": "none"}
_NOT_DRAWN = {"defs", "title", "desc", "metadata", "style", "script", "clipPath", "mask", "linearGradient",
              "radialGradient", "pattern", "marker", "symbol", "filter", "animate", "animateTransform",
              "animateMotion", "set", "mpath"}


@dataclass(frozen=True)
class Outline:
    """A filled element: where it is in the tree, its rings in output pixels and its fill rule."""

    key: tuple[int, ...]
    rings: list[np.ndarray]
    even_odd: bool


def _attribute(element: ElementTree.Element, name: str) -> str | None:
    value = style_property(element, name)
    return value if value is not None else element.get(name)


def _number(element: ElementTree.Element, name: str, default: float = 0.0) -> float:
    """A geometry property in px: from ``style`` first (a CSS animation writes it there), else the attribute."""
    text = _attribute(element, name)
    return default if text is None else _px(text, f"<{local_name(element.tag)}> {name}='{text}'")


def _px(text: str, what: str) -> float:
    try:
        return float(text.strip().removesuffix("px"))
    except ValueError:
        raise ValueError(f"{what} is not a number in px") from None


def _transform(element: ElementTree.Element) -> Matrix:
    """The element's transform: its CSS ``transform`` (as the reader writes it when CSS sets or animates
    one: a matrix about ``transform-origin``) over the ``transform`` attribute."""
    css = style_property(element, "transform")
    if css is not None:
        origin = origin_point(parse_origin(tokens(style_property(element, "transform-origin") or "0 0")), _NO_BOX)
        inner = matrix_of(resolve(parse_svg_transform(tokens(css)), _NO_BOX))  # the reader writes a matrix()
        return multiply(multiply((1.0, 0.0, 0.0, 1.0, *origin), inner), (1.0, 0.0, 0.0, 1.0, -origin[0], -origin[1]))
    text = element.get("transform")
    if not text:
        return IDENTITY
    functions = parse_svg_transform(tokens(text))
    return matrix_of(resolve(functions, _NO_BOX))  # an SVG transform's lengths are user units, never percentages


def _viewport(root: ElementTree.Element, out_size: tuple[int, int]) -> Matrix:
    """User space of the root → output pixels: the viewBox fitted as ``preserveAspectRatio`` says, then scaled."""
    width, height = svg_size(root, "svg")
    to_output = (out_size[0] / width, 0.0, 0.0, out_size[1] / height, 0.0, 0.0)
    try:
        x, y, box_width, box_height = (float(value) for value in (root.get("viewBox") or "").replace(",", " ").split())
    except ValueError:  # none, or not four numbers: no viewBox, as the renderer takes it
        return to_output
    if not (box_width > 0 and box_height > 0):
        return to_output
    scale_x, scale_y = width / box_width, height / box_height
    align, *slice_ = (root.get("preserveAspectRatio") or "xMidYMid meet").split() or ["xMidYMid"]
    if align == "none":
        return multiply(to_output, (scale_x, 0.0, 0.0, scale_y, -x * scale_x, -y * scale_y))
    scale = max(scale_x, scale_y) if slice_ == ["slice"] else min(scale_x, scale_y)
    fraction = {"Min": 0.0, "Mid": 0.5, "Max": 1.0}
    shift_x = (width - box_width * scale) * fraction.get(align[1:4], 0.5)
    shift_y = (height - box_height * scale) * fraction.get(align[5:8], 0.5)
    return multiply(to_output, (scale, 0.0, 0.0, scale, shift_x - x * scale, shift_y - y * scale))


def _path_data(element: ElementTree.Element, *, stroked: bool = False) -> PathData | None:
    """The element's outline as path data (None: nothing to draw); ``stroked``: as its stroke follows it (a
    ``polyline`` stays open)."""
    kind = local_name(element.tag)
    if kind == "path":
        return PathData.parse(element.get("d") or "")
    if kind == "rect":
        x, y = _number(element, "x"), _number(element, "y")
        width, height = _number(element, "width"), _number(element, "height")
        if width <= 0 or height <= 0:
            return None
        rx_text, ry_text = _attribute(element, "rx"), _attribute(element, "ry")
        rx = _number(element, "rx") if rx_text is not None else _number(element, "ry") if ry_text is not None else 0.0
        ry = _number(element, "ry") if ry_text is not None else rx
        rx, ry = min(rx, width / 2), min(ry, height / 2)
        if rx <= 0 or ry <= 0:
            return PathData.parse(f"M{x},{y} H{x + width} V{y + height} H{x} Z")
        return PathData.parse(
            f"M{x + rx},{y} H{x + width - rx} A{rx},{ry} 0 0 1 {x + width},{y + ry} V{y + height - ry} "
            f"A{rx},{ry} 0 0 1 {x + width - rx},{y + height} H{x + rx} A{rx},{ry} 0 0 1 {x},{y + height - ry} "
            f"V{y + ry} A{rx},{ry} 0 0 1 {x + rx},{y} Z")
    if kind in ("circle", "ellipse"):
        cx, cy = _number(element, "cx"), _number(element, "cy")
        rx = _number(element, "r") if kind == "circle" else _number(element, "rx")
        ry = _number(element, "r") if kind == "circle" else _number(element, "ry")
        if rx <= 0 or ry <= 0:
            return None
        return PathData.parse(f"M{cx + rx},{cy} A{rx},{ry} 0 0 1 {cx},{cy + ry} A{rx},{ry} 0 0 1 {cx - rx},{cy} "
                              f"A{rx},{ry} 0 0 1 {cx},{cy - ry} A{rx},{ry} 0 0 1 {cx + rx},{cy} Z")
    numbers = (element.get("points") or "").replace(",", " ").split()
    if len(numbers) < 6:
        return None
    pairs = " ".join(f"{numbers[i]},{numbers[i + 1]}" for i in range(0, len(numbers) - 1, 2))
    return PathData.parse(f"M{pairs}" if stroked and kind == "polyline" else f"M{pairs} Z")


def _stroke_outline(element: ElementTree.Element, key: tuple[int, ...], matrix: Matrix,
                    width_text: str) -> Outline | None:
    """The band the element's stroke paints (``stroke-width`` ``width_text``, scaled by ``matrix``), or None."""
    width = _px(width_text, f"stroke-width '{width_text}'")
    data = _path_data(element, stroked=True)
    if data is None or width <= 0:
        return None
    a, b, c, d, _, _ = matrix
    half = width * abs(a * d - b * c) ** 0.5 / 2
    rings = [ring for points, closed in subpath_lines(data) if len(points) >= 2
             for ring in stroke_rings(_apply(matrix, points), half, closed)]
    return Outline(key + (-1,), rings, False) if rings else None


def _apply(matrix: Matrix, ring: list[tuple[float, float]]) -> np.ndarray:
    a, b, c, d, e, f = matrix
    points = np.asarray(ring, np.float64)
    return np.column_stack([a * points[:, 0] + c * points[:, 1] + e, b * points[:, 0] + d * points[:, 1] + f])


def outlines(root: ElementTree.Element, out_size: tuple[int, int]) -> tuple[list[Outline], list[str]]:
    """The displayed filled elements of static SVG ``root`` in painting order, and what is displayed but not read.

    ``out_size`` is (width, height) of the raster the document is drawn to.
    """
    found: list[Outline] = []
    unread: list[str] = []

    def add(outline: Outline | None, kind: str, key) -> None:
        if outline is not None and all(np.abs(ring).max() < _FARTHEST for ring in outline.rings):  # NaN fails too
            found.append(outline)
        elif outline is not None:
            unread.append(f"<{kind}> at {key} (coordinates out of range)")

    def visit(element, key, matrix, paint):
        if _attribute(element, "display") == "none":
            return
        paint = {name: _attribute(element, name) or inherited for name, inherited in paint.items()}
        kind = local_name(element.tag)
        try:
            matrix = multiply(matrix, _transform(element))
            if kind in _SHAPES:
                data = _path_data(element) if paint["fill"] != "none" else None
                stroked = paint["stroke"] != "none" and paint["stroke-dasharray"] == "none"
                stroke = _stroke_outline(element, key, matrix, paint["stroke-width"]) if stroked else None
        except ValueError as error:  # drawn as the renderer reads it; its motion is left to the masks
            unread.append(f"<{kind}> at {key} ({error})")
            return
        if kind in _SHAPES:
            rings = [] if data is None else [_apply(matrix, ring) for ring in subpath_rings(data)]
            add(Outline(key, rings, paint["fill-rule"] == "evenodd") if rings else None, kind, key)
            if paint["stroke"] != "none" and not stroked:
                unread.append(f"<{kind}> at {key} (its dashed stroke)")
            add(stroke, kind, key)
            return
        if kind in _CONTAINERS:
            for index, child in enumerate(element):
                visit(child, key + (index,), matrix, paint)
            return
        if kind not in _NOT_DRAWN and isinstance(element.tag, str):
            unread.append(f"<{kind}> at {key}")

    viewport = _viewport(root, out_size)
    paint = {name: _attribute(root, name) or default for name, default in _PAINT_DEFAULTS.items()}
    for index, child in enumerate(root):
        visit(child, (index,), viewport, paint)
    return found, unread


def moving_elements(before: tuple[list[Outline], list[str]],
                    now: tuple[list[Outline], list[str]]) -> tuple[list[MovingElement], list[str]]:
    """The elements of frame ``now`` with where their outline points were in frame ``before``, each
    frame given as :func:`outlines` found it.

    Returns the elements (painting order) and what is left to the masks: elements not read
    in ``now``, new in it, or whose outline changed its structure (points that do not correspond).
    """
    found_now, unread = now[0], list(now[1])
    found_before = {outline.key: outline for outline in before[0]}
    elements = []
    for outline in found_now:
        earlier = found_before.get(outline.key)
        if earlier is None or [len(ring) for ring in earlier.rings] != [len(ring) for ring in outline.rings]:
            unread.append(f"element at {outline.key} ({'new' if earlier is None else 'its outline changed structure'})")
            continue
        starts = np.cumsum([0] + [len(ring) for ring in outline.rings])
        elements.append(MovingElement(now=np.concatenate(outline.rings), before=np.concatenate(earlier.rings),
                                      ring_starts=starts, even_odd=outline.even_odd))
    return elements, unread
