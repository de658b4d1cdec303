"""SVG path data for SMIL: ``d`` values to interpolate, and motion paths to move along.

:class:`PathData` is a path as written (each command explicit, implicit repeats expanded),
which interpolates with another of the same command list, argument by argument, as SVG 1.1
asks. :class:`MotionPath` is a path as geometry: its drawing segments flattened to
polylines, for the position and direction at a distance along it (``animateMotion``).
"""

from __future__ import annotations

import bisect
import math
import re
from dataclasses import dataclass

_ARITY = {"m": 2, "l": 2, "h": 1, "v": 1, "c": 6, "s": 4, "q": 4, "t": 2, "a": 7, "z": 0}
_TOKEN = re.compile(r"\s*,?\s*([MmLlHhVvCcSsQqTtAaZz]|[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)")
_FLAG = re.compile(r"\s*,?\s*([01])")
#: Straight pieces a curve is cut into to measure and follow it.
_CURVE_PIECES = 64


@dataclass(frozen=True)
class PathData:
    """Path data as a list of (command letter, arguments), one entry per command."""

    commands: tuple[tuple[str, tuple[float, ...]], ...]

    @classmethod
    def parse(cls, text: str) -> PathData:
        """Parse ``d`` text; a ValueError names what is wrong."""
        commands, position, letter, waiting = [], 0, None, False  # waiting: a command letter without its numbers
        text = text.strip()
        while position < len(text):
            match = _TOKEN.match(text, position)
            if not match:
                raise ValueError(f"path data has '{text[position:position + 10]}' where a command or number belongs")
            token = match.group(1)
            if token.isalpha():
                if waiting:
                    raise ValueError(f"the '{letter}' command has no numbers")
                letter, position, waiting = token, match.end(), token not in "zZ"
                if not waiting:
                    commands.append((letter, ()))
                    letter = None
                continue
            if letter is None:
                raise ValueError("path data must begin with a moveto and numbers must follow a command")
            arguments, position = _arguments(text, position, letter)
            commands.append((letter, arguments))
            waiting = False
            if letter in "mM":
                letter = "l" if letter == "m" else "L"  # coordinates after a moveto are lineto's
        if waiting:
            raise ValueError(f"the '{letter}' command has no numbers")
        if commands and commands[0][0] not in "mM":
            raise ValueError("path data must begin with a moveto")
        return cls(tuple(commands))

    def letters(self) -> tuple[str, ...]:
        return tuple(letter for letter, _ in self.commands)

    def interpolate(self, other: PathData, fraction: float) -> PathData:
        """Argument by argument (the command lists must match); arc flags switch halfway."""
        commands = []
        for (letter, ours), (_, theirs) in zip(self.commands, other.commands):
            values = [a + (b - a) * fraction for a, b in zip(ours, theirs)]
            if letter in "aA":
                values[3:5] = (ours if fraction < 0.5 else theirs)[3:5]
            commands.append((letter, tuple(values)))
        return PathData(tuple(commands))

    def __str__(self) -> str:
        return " ".join(letter + " ".join(f"{value:.6g}" for value in arguments)
                        for letter, arguments in self.commands)


def _arguments(text: str, position: int, letter: str) -> tuple[tuple[float, ...], int]:
    values = []
    for index in range(_ARITY[letter.lower()]):
        pattern = _FLAG if letter in "aA" and index in (3, 4) else _TOKEN
        match = pattern.match(text, position)
        if not match or match.group(1).isalpha():
            raise ValueError(f"the '{letter}' command needs {_ARITY[letter.lower()]} numbers")
        values.append(float(match.group(1)))
        position = match.end()
    return tuple(values), position


class MotionPath:
    """A path's drawing segments as one polyline: its length, and the point and direction at a distance.

    Each piece keeps the curve's exact tangents at its ends, so the direction turns smoothly
    along a curve and not in steps. A moveto inside the path is a jump: it adds no distance.
    """

    def __init__(self, path: PathData):
        polylines, start = _drawing_polylines(path)
        self._points, self._distances, self._tangents, self.spans = [start], [0.0], [], []
        for polyline in polylines:
            if polyline[0][:2] != self._points[-1]:
                self._points.append(polyline[0][:2])
                self._distances.append(self._distances[-1])
                self._tangents.append((polyline[0][2:], polyline[0][2:]))
            begin = self._distances[-1]
            for (_, _, *tangent_before), (x1, y1, *tangent) in zip(polyline, polyline[1:]):
                x0, y0 = self._points[-1]
                self._points.append((x1, y1))
                self._distances.append(self._distances[-1] + math.hypot(x1 - x0, y1 - y0))
                self._tangents.append((tuple(tangent_before), tuple(tangent)))
            self.spans.append((begin, self._distances[-1]))  # distances where each drawing segment begins and ends
        self.length = self._distances[-1]

    def at(self, distance: float) -> tuple[float, float, float]:
        """(x, y, direction in degrees) at ``distance`` along the path, clamped to its ends."""
        if len(self._points) < 2:
            return self._points[0][0], self._points[0][1], 0.0
        distance = min(max(distance, 0.0), self.length)
        piece = min(bisect.bisect_right(self._distances, distance) - 1, len(self._points) - 2)
        (x0, y0), (x1, y1) = self._points[piece], self._points[piece + 1]
        span = self._distances[piece + 1] - self._distances[piece]
        fraction = 0.0 if span == 0 else (distance - self._distances[piece]) / span
        return x0 + (x1 - x0) * fraction, y0 + (y1 - y0) * fraction, self._direction(piece, fraction)

    def _direction(self, piece: int, fraction: float) -> float:
        """The tangent's direction within ``piece``; where the path has none, the nearest piece's, forward first."""
        for index in [piece, *range(piece + 1, len(self._tangents)), *range(piece - 1, -1, -1)]:
            (ax, ay), (bx, by) = (_unit(tangent) for tangent in self._tangents[index])
            if index != piece:
                fraction = 0.0 if index > piece else 1.0
            x, y = ax + (bx - ax) * fraction, ay + (by - ay) * fraction
            if x or y:
                return math.degrees(math.atan2(y, x))
        return 0.0


def _unit(vector: tuple[float, float]) -> tuple[float, float]:
    length = math.hypot(*vector)
    return (0.0, 0.0) if length < 1e-12 else (vector[0] / length, vector[1] / length)


def _drawing_polylines(path: PathData) -> tuple[list[list[tuple[float, float, float, float]]], tuple[float, float]]:
    """Each drawing command of ``path`` as a polyline of (x, y, tangent x, tangent y), absolute; the first point."""
    polylines, _, first, _ = _drawing_segments(path)
    return polylines, first


def subpath_rings(path: PathData) -> list[list[tuple[float, float]]]:
    """Each subpath of ``path`` as a closed ring of absolute points (as a fill closes it).

    Every command is cut into the same number of pieces whatever its arguments, so the same
    path at two times, command for command, gives rings whose points correspond.
    """
    return [ring for ring, _ in subpath_lines(path) if len(ring) >= 3]


def subpath_lines(path: PathData) -> list[tuple[list[tuple[float, float]], bool]]:
    """Each subpath of ``path`` as its points and whether ``Z`` closes it (as a stroke draws it), cut as
    :func:`subpath_rings` cuts them."""
    polylines, subpaths, _, closed = _drawing_segments(path)
    lines: dict[int, list[tuple[float, float]]] = {}
    for polyline, subpath in zip(polylines, subpaths):
        line = lines.setdefault(subpath, [polyline[0][:2]])
        line.extend(point[:2] for point in polyline[1:])
    return [(line, subpath in closed) for subpath, line in lines.items()]


def _drawing_segments(path: PathData):
    """(polylines, the subpath number of each, the first point, the subpaths closed by ``Z``) of
    :func:`_drawing_polylines`."""
    polylines, subpaths, subpath, closed = [], [], -1, set()
    x = y = start_x = start_y = 0.0
    control = None  # the last curve's second control point, for S and T
    first = None
    for letter, values in path.commands:
        relative, kind = letter.islower(), letter.upper()
        dx, dy = (x, y) if relative else (0.0, 0.0)
        if kind == "M":
            x, y = values[0] + dx, values[1] + dy
            start_x, start_y, control = x, y, None
            first = first or (x, y)
            subpath += 1
            continue
        if kind == "Z":
            end = (start_x, start_y)
            curve = _line((x, y), end)
        elif kind in "LHV":
            end = (values[0] + dx, values[1] + dy) if kind == "L" else \
                (values[0] + dx, y) if kind == "H" else (x, values[0] + dy)
            curve = _line((x, y), end)
        elif kind in "CS":
            first_control = (values[0] + dx, values[1] + dy) if kind == "C" else _reflected(control, x, y, "C")
            rest = values[2:] if kind == "C" else values
            second, end = (rest[0] + dx, rest[1] + dy), (rest[2] + dx, rest[3] + dy)
            curve = _cubic((x, y), first_control, second, end)
            control = ("C", second)
        elif kind in "QT":
            middle = (values[0] + dx, values[1] + dy) if kind == "Q" else _reflected(control, x, y, "Q")
            end = (values[-2] + dx, values[-1] + dy)
            curve = _cubic((x, y), _towards((x, y), middle), _towards(end, middle), end)
            control = ("Q", middle)
        else:
            end = (values[5] + dx, values[6] + dy)
            curve = _arc((x, y), values[0], values[1], values[2], values[3] != 0, values[4] != 0, end)
        if kind not in "CSQT":
            control = None
        polylines.append(curve)
        subpaths.append(subpath)
        x, y = end
        if kind == "Z":  # a drawing command after closepath starts a new subpath at the same point
            closed.add(subpath)
            subpath += 1
    return polylines, subpaths, first or (0.0, 0.0), closed


def _line(start, end) -> list[tuple[float, float, float, float]]:
    direction = (end[0] - start[0], end[1] - start[1])
    return [(*start, *direction), (*end, *direction)]


def _reflected(control, x: float, y: float, family: str) -> tuple[float, float]:
    """The previous control point reflected about the current point, if the previous command was of ``family``."""
    if control is None or control[0] != family:
        return x, y
    cx, cy = control[1]
    return 2 * x - cx, 2 * y - cy


def _towards(point, middle) -> tuple[float, float]:
    """A quadratic's control point as the matching cubic's control point on ``point``'s side."""
    return point[0] + 2 / 3 * (middle[0] - point[0]), point[1] + 2 / 3 * (middle[1] - point[1])


def _cubic(p0, p1, p2, p3) -> list[tuple[float, float, float, float]]:
    points = []
    for step in range(_CURVE_PIECES + 1):
        t = step / _CURVE_PIECES
        a, b, c, d = (1 - t) ** 3, 3 * (1 - t) ** 2 * t, 3 * (1 - t) * t ** 2, t ** 3
        da, db, dc = 3 * (1 - t) ** 2, 6 * (1 - t) * t, 3 * t ** 2  # the derivative's weights of p1-p0, p2-p1, p3-p2
        points.append((a * p0[0] + b * p1[0] + c * p2[0] + d * p3[0], a * p0[1] + b * p1[1] + c * p2[1] + d * p3[1],
                       da * (p1[0] - p0[0]) + db * (p2[0] - p1[0]) + dc * (p3[0] - p2[0]),
                       da * (p1[1] - p0[1]) + db * (p2[1] - p1[1]) + dc * (p3[1] - p2[1])))
    return points


def _arc(start, rx: float, ry: float, angle: float, large: bool, sweep: bool,
         end) -> list[tuple[float, float, float, float]]:
    """An elliptical arc as a polyline (SVG 1.1 appendix F.6: endpoint to centre parameterization)."""
    rx, ry = abs(rx), abs(ry)
    if start == end or rx == 0 or ry == 0:
        return _line(start, end)
    phi = math.radians(angle)
    cos_phi, sin_phi = math.cos(phi), math.sin(phi)
    hx, hy = (start[0] - end[0]) / 2, (start[1] - end[1]) / 2
    x1, y1 = cos_phi * hx + sin_phi * hy, -sin_phi * hx + cos_phi * hy
    scale = (x1 / rx) ** 2 + (y1 / ry) ** 2
    if scale > 1:
        rx, ry = rx * math.sqrt(scale), ry * math.sqrt(scale)
    numerator = rx * rx * ry * ry - rx * rx * y1 * y1 - ry * ry * x1 * x1
    root = math.sqrt(max(0.0, numerator / (rx * rx * y1 * y1 + ry * ry * x1 * x1)))
    if large == sweep:
        root = -root
    cx1, cy1 = root * rx * y1 / ry, -root * ry * x1 / rx
    cx = cos_phi * cx1 - sin_phi * cy1 + (start[0] + end[0]) / 2
    cy = sin_phi * cx1 + cos_phi * cy1 + (start[1] + end[1]) / 2
    theta = math.atan2((y1 - cy1) / ry, (x1 - cx1) / rx)
    delta = math.atan2((-y1 - cy1) / ry, (-x1 - cx1) / rx) - theta
    if sweep and delta < 0:
        delta += 2 * math.pi
    elif not sweep and delta > 0:
        delta -= 2 * math.pi
    points = []
    for step in range(_CURVE_PIECES + 1):
        a = theta + delta * step / _CURVE_PIECES
        ex, ey = rx * math.cos(a), ry * math.sin(a)
        tx, ty = -rx * math.sin(a) * delta, ry * math.cos(a) * delta
        points.append((cos_phi * ex - sin_phi * ey + cx, sin_phi * ex + cos_phi * ey + cy,
                       cos_phi * tx - sin_phi * ty, sin_phi * tx + cos_phi * ty))
    points[0] = (*start, *points[0][2:])
    points[-1] = (*end, *points[-1][2:])
    return points
