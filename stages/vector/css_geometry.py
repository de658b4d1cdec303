"""Object bounding boxes of SVG elements (the ``fill-box`` that ``transform-box`` may refer to).

The fill box is the tight box of an element's geometry in its own user space, strokes
left out (SVG 2, "Object bounding box"): exact for basic shapes and for path data
(curve and arc extrema solved, not control points), and for a group the union of its
children's boxes under their transforms. Geometry and transforms are read through
callbacks, so animated values count. Text, ``use`` and images are not measured
(:func:`uncomputed` names them so they can be reported).
"""

from __future__ import annotations

import math
import re
from typing import Callable
from xml.etree import ElementTree

from fluidymation.stages.vector.css_transform import Box, Matrix
from fluidymation.stages.vector.safety import local_name

Point = tuple[float, float]
_POINTS_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
_GROUPS = {"g", "a", "switch"}
_SHAPES = {"rect", "circle", "ellipse", "line", "polyline", "polygon", "path"}
_NOT_GEOMETRY = {"title", "desc", "metadata", "style", "script", "defs", "linearGradient", "radialGradient",
                 "pattern", "clipPath", "mask", "filter", "marker", "symbol"}


def fill_box(element: ElementTree.Element, value: Callable[[ElementTree.Element, str], float],
             transform: Callable[[ElementTree.Element], Matrix]) -> Box:
    """The fill box of ``element``; ``value(element, name)`` gives a geometry property in px (0 when unset) and
    ``transform(element)`` an element's transform matrix."""
    points = _points(element, value, transform)
    if not points:
        return Box(0.0, 0.0, 0.0, 0.0)
    xs, ys = [x for x, _ in points], [y for _, y in points]
    return Box(min(xs), min(ys), max(xs) - min(xs), max(ys) - min(ys))


def _points(element, value, transform) -> list[Point]:
    """Points whose bounding box is the element's fill box."""
    tag = local_name(element.tag)
    if tag == "rect":
        x, y = value(element, "x"), value(element, "y")
        return [(x, y), (x + value(element, "width"), y + value(element, "height"))]
    if tag in ("circle", "ellipse"):
        cx, cy = value(element, "cx"), value(element, "cy")
        rx, ry = (value(element, "r"),) * 2 if tag == "circle" else (value(element, "rx"), value(element, "ry"))
        return [(cx - rx, cy - ry), (cx + rx, cy + ry)]
    if tag == "line":
        return [(_number(element.get("x1")), _number(element.get("y1"))),
                (_number(element.get("x2")), _number(element.get("y2")))]
    if tag in ("polyline", "polygon"):
        numbers = [float(token) for token in _POINTS_NUMBER.findall(element.get("points", ""))]
        return list(zip(numbers[0::2], numbers[1::2]))
    if tag == "path":
        return path_points(element.get("d", ""))
    if tag in _GROUPS:
        points = []
        for child in element:
            if local_name(child.tag) in _NOT_GEOMETRY:
                continue
            matrix = transform(child)
            points += [_apply(matrix, point) for point in _corners(_points(child, value, transform))]
        return points
    return []


def uncomputed(element: ElementTree.Element) -> list[str]:
    """Tags in the element's fill box whose geometry is not computed here (text, use, image...): they add nothing."""
    tag = local_name(element.tag)
    if tag in _GROUPS:
        return [name for child in element if local_name(child.tag) not in _NOT_GEOMETRY for name in uncomputed(child)]
    return [] if tag in _SHAPES else [tag]


def _corners(points: list[Point]) -> list[Point]:
    if not points:
        return []
    xs, ys = [x for x, _ in points], [y for _, y in points]
    return [(min(xs), min(ys)), (max(xs), min(ys)), (min(xs), max(ys)), (max(xs), max(ys))]


def _apply(matrix: Matrix, point: Point) -> Point:
    a, b, c, d, e, f = matrix
    return a * point[0] + c * point[1] + e, b * point[0] + d * point[1] + f


def _number(text: str | None) -> float:
    try:
        return float(text) if text else 0.0
    except ValueError:
        return 0.0


class _PathScanner:
    """Reads SVG path data: commands, numbers and arc flags (which need no separator: ``a1 1 0 011 1``)."""

    _NUMBER = re.compile(r"[\s,]*([+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)")
    _COMMAND = re.compile(r"[\s,]*([MmZzLlHhVvCcSsQqTtAa])")
    _FLAG = re.compile(r"[\s,]*([01])")

    def __init__(self, data: str):
        self.data, self.position = data, 0

    def _take(self, pattern: re.Pattern) -> str | None:
        match = pattern.match(self.data, self.position)
        if match is None:
            return None
        self.position = match.end()
        return match.group(1)

    def command(self) -> str | None:
        return self._take(self._COMMAND)

    def numbers(self, count: int) -> list[float] | None:
        """``count`` numbers, or None (and nothing read) when they are not all there."""
        saved = self.position
        found = []
        for _ in range(count):
            token = self._take(self._NUMBER)
            if token is None:
                self.position = saved
                return None
            found.append(float(token))
        return found

    def arc(self) -> list[float] | None:
        """rx ry rotation large-arc sweep x y, or None."""
        saved = self.position
        radii = self.numbers(3)
        flags = [self._take(self._FLAG), self._take(self._FLAG)] if radii else [None]
        end = self.numbers(2) if None not in flags else None
        if end is None:
            self.position = saved
            return None
        return radii + [float(flag) for flag in flags] + end


_ARGUMENTS = {"M": 2, "L": 2, "T": 2, "H": 1, "V": 1, "C": 6, "S": 4, "Q": 4}


def path_points(data: str) -> list[Point]:
    """The end points and curve extrema of SVG path data: their box is the path's tight box.

    Like a browser, it stops at the first error and keeps the segments before it.
    """
    scanner = _PathScanner(data)
    points: list[Point] = []
    position = start = (0.0, 0.0)
    previous: tuple[str, Point] | None = None
    command = None
    while True:
        command = scanner.command() or command
        if command is None:
            break
        upper, relative = command.upper(), command.islower()
        if upper == "Z":
            position, previous, command = start, None, None
            continue
        numbers = scanner.arc() if upper == "A" else scanner.numbers(_ARGUMENTS[upper])
        if numbers is None:
            break
        origin = position if relative else (0.0, 0.0)

        def absolute(x: float, y: float, origin: Point = origin) -> Point:
            return origin[0] + x, origin[1] + y

        current: tuple[str, Point] | None = None
        if upper == "M":
            end = start = absolute(*numbers)
        elif upper in ("L", "T"):
            end = absolute(*numbers)
            if upper == "T":
                control = _reflect(previous, "quadratic", position)
                points += _quadratic_extrema(position, control, end)
                current = ("quadratic", control)
        elif upper == "H":
            end = (position[0] + numbers[0] if relative else numbers[0], position[1])
        elif upper == "V":
            end = (position[0], position[1] + numbers[0] if relative else numbers[0])
        elif upper in ("C", "S"):
            first = absolute(*numbers[:2]) if upper == "C" else _reflect(previous, "cubic", position)
            control, end = absolute(*numbers[-4:-2]), absolute(*numbers[-2:])
            points += _cubic_extrema(position, first, control, end)
            current = ("cubic", control)
        elif upper == "Q":
            control, end = absolute(*numbers[:2]), absolute(*numbers[2:])
            points += _quadratic_extrema(position, control, end)
            current = ("quadratic", control)
        else:
            end = absolute(*numbers[5:])
            points += _arc_extrema(position, *numbers[:5], end)
        points += [end] if upper == "M" else [position, end]
        position, previous = end, current
        if upper == "M":
            command = "l" if relative else "L"
    return points


def _reflect(previous: tuple[str, Point] | None, kind: str, position: Point) -> Point:
    """The first control point of a smooth segment: the previous segment's last control reflected, if of ``kind``."""
    if previous is None or previous[0] != kind:
        return position
    control = previous[1]
    return 2 * position[0] - control[0], 2 * position[1] - control[1]


def _cubic_extrema(p0: Point, p1: Point, p2: Point, p3: Point) -> list[Point]:
    found = []
    for axis in (0, 1):
        a = -p0[axis] + 3 * p1[axis] - 3 * p2[axis] + p3[axis]
        b = 2 * (p0[axis] - 2 * p1[axis] + p2[axis])
        c = p1[axis] - p0[axis]
        for t in _roots(a, b, c):
            if 0 < t < 1:
                found.append(tuple(_cubic(t, p0[i], p1[i], p2[i], p3[i]) for i in (0, 1)))
    return found


def _cubic(t: float, a: float, b: float, c: float, d: float) -> float:
    return (1 - t) ** 3 * a + 3 * (1 - t) ** 2 * t * b + 3 * (1 - t) * t * t * c + t**3 * d


def _roots(a: float, b: float, c: float) -> list[float]:
    """Real roots of a·t² + b·t + c."""
    if abs(a) < 1e-12:
        return [-c / b] if abs(b) > 1e-12 else []
    discriminant = b * b - 4 * a * c
    if discriminant < 0:
        return []
    root = math.sqrt(discriminant)
    return [(-b + root) / (2 * a), (-b - root) / (2 * a)]


def _quadratic_extrema(p0: Point, p1: Point, p2: Point) -> list[Point]:
    found = []
    for axis in (0, 1):
        denominator = p0[axis] - 2 * p1[axis] + p2[axis]
        if abs(denominator) > 1e-12:
            t = (p0[axis] - p1[axis]) / denominator
            if 0 < t < 1:
                found.append(tuple((1 - t) ** 2 * p0[i] + 2 * (1 - t) * t * p1[i] + t * t * p2[i] for i in (0, 1)))
    return found


def _arc_extrema(p0: Point, rx: float, ry: float, rotation: float, large: float, sweep: float,
                 p1: Point) -> list[Point]:
    """Extreme points of an elliptical arc (SVG 2, implementation notes: endpoint to centre parameterization)."""
    rx, ry = abs(rx), abs(ry)
    if rx == 0 or ry == 0 or p0 == p1:
        return []
    phi = math.radians(rotation)
    cos_phi, sin_phi = math.cos(phi), math.sin(phi)
    dx, dy = (p0[0] - p1[0]) / 2, (p0[1] - p1[1]) / 2
    x1, y1 = cos_phi * dx + sin_phi * dy, -sin_phi * dx + cos_phi * dy
    scale = x1 * x1 / (rx * rx) + y1 * y1 / (ry * ry)
    if scale > 1:
        rx, ry = rx * math.sqrt(scale), ry * math.sqrt(scale)
    numerator = rx * rx * ry * ry - rx * rx * y1 * y1 - ry * ry * x1 * x1
    factor = math.sqrt(max(numerator, 0.0) / (rx * rx * y1 * y1 + ry * ry * x1 * x1))
    if bool(large) == bool(sweep):
        factor = -factor
    cx1, cy1 = factor * rx * y1 / ry, -factor * ry * x1 / rx
    cx = cos_phi * cx1 - sin_phi * cy1 + (p0[0] + p1[0]) / 2
    cy = sin_phi * cx1 + cos_phi * cy1 + (p0[1] + p1[1]) / 2
    start = math.atan2((y1 - cy1) / ry, (x1 - cx1) / rx)
    end = math.atan2((-y1 - cy1) / ry, (-x1 - cx1) / rx)
    sweep_angle = end - start
    if sweep and sweep_angle < 0:
        sweep_angle += 2 * math.pi
    elif not sweep and sweep_angle > 0:
        sweep_angle -= 2 * math.pi
    found = []
    for base in (math.atan2(-ry * sin_phi, rx * cos_phi), math.atan2(ry * cos_phi, rx * sin_phi)):
        for theta in (base, base + math.pi):
            offset = (theta - start) % (2 * math.pi) if sweep_angle > 0 else (start - theta) % (2 * math.pi)
            if offset < abs(sweep_angle):
                found.append((cx + rx * cos_phi * math.cos(theta) - ry * sin_phi * math.sin(theta),
                              cy + rx * sin_phi * math.cos(theta) + ry * cos_phi * math.sin(theta)))
    return found
