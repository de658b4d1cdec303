"""The filled outlines of a Lottie animation at two frames: the motion of its shapes (``flow: vector``).

Each property is evaluated at both frames as the player (ThorVG) evaluates it: keyframes
with their easing curves, hold keys, spatial position tangents (walked by arc length),
split positions. Shapes are carried through every transform that places them: shape
groups' ``tr``, the layer's transform, its parents (``parent``, evaluated at the same
frame), the precomposition layers it sits in (with their time remapping ``tm``, or start
``st`` and stretch ``sr``), and the fit of the composition into the output raster. Per
fill (solid or gradient), every path above it in its group and the groups above it forms
one element, filled with the fill's rule; the same vertex or curve parameter at the two
frames is the same point of the material. That is what
:class:`~fluidymation.engine.vector_motion.MovingElement` takes (docs/guides.md, "Motion
from the geometry").

Read: shape layers (paths, rectangles, ellipses, polygons and stars without rounded
points, groups), solid layers and precomps. Layer masks, alpha track mattes, precomps'
bounds and the canvas clip the elements, as the player clips what it draws. Round-corner modifiers are read as the
unrounded outline (a rigid part moves the same; the outline covers the drawn one).
What is drawn but not read — strokes, image and text layers, 3D and auto-oriented
layers, expressions, trim paths, repeaters and other path modifiers, layers or shapes
that appear between the two frames, paths whose vertex count changes — is named in the
second result, so the caller falls back to the masks there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from fluidymation.engine.vector_motion import Clip, ClipPart, MovingElement, stroke_rings

_PRECOMP, _SOLID, _NULL, _SHAPE = 0, 1, 3, 4
_NOT_SHAPE_LAYERS = {2: "an image layer", 5: "a text layer"}
_MODIFIERS = {"tm": "trim path", "rp": "repeater", "pb": "pucker/bloat", "op": "offset path", "zz": "zig zag",
              "tw": "twist"}
_MASK_MODES = {"a": "add", "s": "subtract", "i": "intersect", "f": "difference"}
_ALPHA_MATTE, _INVERTED_ALPHA_MATTE = 1, 2
_FILLS = {"fl", "gf"}
_STROKES = {"st", "gs"}
_SHAPES = {"sh", "rc", "el", "sr"}
_KAPPA = 0.5522847498  # cubic handle length of a quarter circle, as players draw ellipses
_EASING_STEPS = 40  # bisection steps solving an easing curve for its parameter
_ARC_SAMPLES = 64  # samples of a spatial position curve to walk it by arc length
_PIXELS_PER_STEP = 2.0  # outline points along curves, in output pixels
_MAX_STEPS = 64  # outline points per curve segment, at most
_MAX_POINTS = 200_000  # outline points per element; a larger element is left to the masks
_MAX_NESTING = 32  # precomps inside precomps, and parent chains, deeper than this are left to the masks
_FARTHEST = 1e7  # outline coordinates (output px) beyond this are left to the masks


class _Unread(Exception):
    """Something of the file that is drawn but not read for its motion (the message says what)."""


@dataclass
class _Ring:
    """A path at both frames: cubic segments (S, 4, 2) in output pixels, and what keeps it from being read."""

    before: np.ndarray
    now: np.ndarray
    unread: str | None = None
    closed: bool = True


# --- properties ---------------------------------------------------------------------------------------------------

def _vector(value) -> np.ndarray:
    array = np.atleast_1d(np.asarray(value, np.float64)).ravel()
    if array.size == 0 or not np.isfinite(array).all():
        raise _Unread(f"the value {value!r} is not a finite number or list of numbers")
    return array


def _path(value) -> tuple[np.ndarray, bool]:
    """A Lottie path value (``{v, i, o, c}``, or a list holding one) as (N, 3, 2) vertex, in, out, and closed."""
    if isinstance(value, list) and len(value) == 1:
        value = value[0]
    if not isinstance(value, dict):
        raise _Unread(f"the path value {value!r} is not a path")
    try:
        vertices = np.asarray(value.get("v", []), np.float64).reshape(-1, 2)
        ins = np.asarray(value.get("i", np.zeros_like(vertices)), np.float64).reshape(-1, 2)
        outs = np.asarray(value.get("o", np.zeros_like(vertices)), np.float64).reshape(-1, 2)
    except (TypeError, ValueError):
        vertices, ins, outs = np.zeros((0, 2)), None, None
    if ins is None or not (vertices.shape == ins.shape == outs.shape) or not np.isfinite(vertices).all():
        raise _Unread("a path whose vertices and tangents do not match")
    return np.stack([vertices, ins, outs], axis=1), bool(value.get("c", False))


def _first(value, default: float) -> float:
    if isinstance(value, list):
        value = value[0] if value else default
    return float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else default


def _bezier(t, p1: float, p2: float):
    """The cubic from 0 to 1 with control values ``p1``, ``p2`` at ``t``."""
    return 3 * (1 - t) ** 2 * t * p1 + 3 * (1 - t) * t**2 * p2 + t**3


def _eased(key: dict, progress: float) -> float:
    """Keyframe ``key``'s easing curve (its out and in tangents) at linear progress ``progress``."""
    out, into = key.get("o"), key.get("i")
    if not (isinstance(out, dict) and isinstance(into, dict)):
        return progress
    x1, y1 = _first(out.get("x"), 0.0), _first(out.get("y"), 0.0)
    x2, y2 = _first(into.get("x"), 1.0), _first(into.get("y"), 1.0)
    low, high = 0.0, 1.0
    for _ in range(_EASING_STEPS):
        middle = 0.5 * (low + high)
        if _bezier(middle, x1, x2) < progress:
            low = middle
        else:
            high = middle
    return float(_bezier(0.5 * (low + high), y1, y2))


def _along_curve(start: np.ndarray, end: np.ndarray, out_tangent, in_tangent, fraction: float) -> np.ndarray:
    """The point ``fraction`` of the way by arc length along the spatial curve from ``start`` to ``end``."""
    controls = np.array([start[:2], start[:2] + _vector(out_tangent)[:2], end[:2] + _vector(in_tangent)[:2],
                         end[:2]])
    t = np.linspace(0.0, 1.0, _ARC_SAMPLES + 1)[:, None]
    basis = np.hstack([(1 - t) ** 3, 3 * (1 - t) ** 2 * t, 3 * (1 - t) * t**2, t**3])
    points = basis @ controls
    lengths = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
    if lengths[-1] <= 0:
        return start + (end - start) * fraction
    along = np.interp(fraction * lengths[-1], lengths, t[:, 0])
    point = np.array([(1 - along) ** 3, 3 * (1 - along) ** 2 * along, 3 * (1 - along) * along**2, along**3]) @ controls
    result = start + (end - start) * fraction
    result[:2] = point
    return result


def _keyframed(prop, frame: float, convert, *, spatial: bool = False):
    """A property's value at ``frame``, each keyframe value passed through ``convert``."""
    if not isinstance(prop, dict):
        raise _Unread(f"the property {prop!r} is not a Lottie property")
    if isinstance(prop.get("x"), str) and prop["x"].strip():
        raise _Unread("an expression")
    value = prop.get("k")
    if not (isinstance(value, list) and value and all(isinstance(key, dict) for key in value)) or not all(
            "t" in key for key in value):
        return convert(value)
    keys = sorted(value, key=lambda key: _first(key.get("t"), 0.0))
    times = [_first(key.get("t"), 0.0) for key in keys]
    index = max((i for i, time in enumerate(times) if time <= frame), default=None)
    if index is None:
        return convert(keys[0].get("s", keys[0].get("e")))
    key = keys[index]
    if index == len(keys) - 1:
        return convert(key["s"] if "s" in key else keys[index - 1].get("e") if index else None)
    start = convert(key.get("s"))
    if _first(key.get("h"), 0.0) == 1.0:
        return start
    end = convert(key["e"] if "e" in key else keys[index + 1].get("s"))
    span = times[index + 1] - times[index]
    fraction = _eased(key, (frame - times[index]) / span if span > 0 else 1.0)
    if isinstance(start, tuple):  # a path: vertex by vertex
        if start[0].shape != end[0].shape:
            raise _Unread("path keyframes with different vertex counts")
        return start[0] + (end[0] - start[0]) * fraction, start[1]
    if start.shape != end.shape:
        raise _Unread("keyframe values of different lengths")
    if spatial and start.size >= 2 and (np.any(_vector(key.get("to", 0.0))) or np.any(_vector(key.get("ti", 0.0)))):
        return _along_curve(start, end, key.get("to", [0.0, 0.0]), key.get("ti", [0.0, 0.0]), fraction)
    return start + (end - start) * fraction


def _value(owner: dict, name: str, frame: float, default=None, *, spatial: bool = False) -> np.ndarray:
    if name not in owner:
        if default is None:
            raise _Unread(f"no '{name}'")
        return np.asarray(default, np.float64)
    return _keyframed(owner[name], frame, _vector, spatial=spatial)


def _scalar(owner: dict, name: str, frame: float, default: float) -> float:
    return float(_value(owner, name, frame, [default])[0])


# --- transforms ---------------------------------------------------------------------------------------------------

def _opaque(transform, frame: float) -> bool:
    """Whether a layer's or group's transform leaves what it holds visible (a nonzero opacity)."""
    return not isinstance(transform, dict) or _scalar(transform, "o", frame, 100.0) > 0.0


def _translation(x: float, y: float) -> np.ndarray:
    return np.array([[1.0, 0.0, x], [0.0, 1.0, y], [0.0, 0.0, 1.0]])


def _rotation(degrees: float) -> np.ndarray:
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _skew(angle_degrees: float, axis_degrees: float) -> np.ndarray:
    """The player's skew by ``angle`` along the axis at ``axis`` degrees (applied after rotation)."""
    tangent = math.tan(-math.radians(angle_degrees))
    c, s = math.cos(-math.radians(axis_degrees)), math.sin(-math.radians(axis_degrees))
    return np.array([[1 - s * c * tangent, c * c * tangent, 0.0], [-s * s * tangent, 1 + s * c * tangent, 0.0],
                     [0.0, 0.0, 1.0]])


def transform_matrix(transform: dict, frame: float) -> np.ndarray | None:
    """A layer's ``ks`` or a group's ``tr`` at ``frame``: position · rotation · skew · scale · −anchor (3×3).

    None when the transform collapses what it places (a zero scale, a skew of 90°). Its opacity is
    :func:`_opaque`'s.
    """
    if not isinstance(transform, dict):
        return np.eye(3)
    position = transform.get("p")
    if isinstance(position, dict) and position.get("s"):
        x, y = _scalar(position, "x", frame, 0.0), _scalar(position, "y", frame, 0.0)
    else:
        x, y = (_value(transform, "p", frame, [0.0, 0.0], spatial=True).tolist() + [0.0])[:2]
    anchor = (_value(transform, "a", frame, [0.0, 0.0]).tolist() + [0.0])[:2]
    scale = _value(transform, "s", frame, [100.0, 100.0])
    scale_x, scale_y = scale[0] / 100.0, (scale[1] if scale.size > 1 else scale[0]) / 100.0
    if scale_x == 0.0 or scale_y == 0.0:
        return None
    rotation = _scalar(transform, "r", frame, 0.0) if "r" in transform else _scalar(transform, "rz", frame, 0.0)
    matrix = _translation(x, y) @ _rotation(rotation)
    skew = _scalar(transform, "sk", frame, 0.0)
    if skew != 0.0:
        if abs(abs(math.fmod(skew, 180.0)) - 90.0) < 0.01:
            return None
        matrix = matrix @ _skew(math.fmod(skew, 180.0), _scalar(transform, "sa", frame, 0.0))
    return matrix @ np.diag([scale_x, scale_y, 1.0]) @ _translation(-anchor[0], -anchor[1])


# --- shapes as cubic segments -------------------------------------------------------------------------------------

def _segments(path: np.ndarray, closed: bool) -> np.ndarray:
    """(N, 3, 2) vertices with in/out tangents → (S, 4, 2) cubic control points."""
    count = path.shape[0]
    if count < 2:
        return np.zeros((0, 4, 2))
    ends = list(range(count)) if closed else list(range(count - 1))
    following = [(i + 1) % count for i in ends]
    vertices, ins, outs = path[:, 0], path[:, 1], path[:, 2]
    return np.stack([vertices[ends], vertices[ends] + outs[ends], vertices[following] + ins[following],
                     vertices[following]], axis=1)


def _ellipse(center: np.ndarray, size: np.ndarray, reversed_: bool) -> np.ndarray:
    rx, ry = size[0] / 2.0, size[1] / 2.0
    cx, cy = center[0], center[1]
    vertices = np.array([[cx, cy - ry], [cx + rx, cy], [cx, cy + ry], [cx - rx, cy]])
    handles = np.array([[_KAPPA * rx, 0.0], [0.0, _KAPPA * ry], [-_KAPPA * rx, 0.0], [0.0, -_KAPPA * ry]])
    path = np.stack([vertices, -handles, handles], axis=1)
    return _reversed(path) if reversed_ else path


def _rectangle(center: np.ndarray, size: np.ndarray, radius: float, reversed_: bool) -> np.ndarray:
    """A rectangle as eight vertices (corner arcs of zero length when unrounded, so the structure never changes)."""
    half_w, half_h = abs(size[0]) / 2.0, abs(size[1]) / 2.0
    r = max(0.0, min(radius, half_w, half_h))
    left, right, top, bottom = center[0] - half_w, center[0] + half_w, center[1] - half_h, center[1] + half_h
    k = _KAPPA * r
    vertices = np.array([[right - r, top], [right, top + r], [right, bottom - r], [right - r, bottom],
                         [left + r, bottom], [left, bottom - r], [left, top + r], [left + r, top]])
    zero = [0.0, 0.0]
    ins = np.array([zero, [0.0, -k], zero, [k, 0.0], zero, [0.0, k], zero, [-k, 0.0]])
    outs = np.array([[k, 0.0], zero, [0.0, k], zero, [-k, 0.0], zero, [0.0, -k], zero])
    path = np.stack([vertices, ins, outs], axis=1)
    return _reversed(path) if reversed_ else path


def _star(shape: dict, frame: float) -> np.ndarray:
    """A polystar (``sy`` 1 star, 2 polygon) without rounded points, as straight segments."""
    for name in ("os", "is"):
        if name in shape and _scalar(shape, name, frame, 0.0) != 0.0:
            raise _Unread("a star with rounded points")
    points = _scalar(shape, "pt", frame, 5.0)
    if points != round(points) or not 3 <= points <= 10_000:
        raise _Unread(f"a star of {points:g} points (fractional or out of range)")
    star = _first(shape.get("sy"), 1.0) == 1.0
    count = int(points) * (2 if star else 1)
    outer = _scalar(shape, "or", frame, 0.0)
    inner = _scalar(shape, "ir", frame, 0.0) if star else outer
    angles = np.radians(-90.0) + np.arange(count) * (2 * math.pi / count)
    radii = np.where(np.arange(count) % 2 == 0, outer, inner) if star else np.full(count, outer)
    vertices = np.column_stack([radii * np.cos(angles), radii * np.sin(angles)])
    place = _translation(*_value(shape, "p", frame, [0.0, 0.0], spatial=True)[:2]) @ _rotation(
        _scalar(shape, "r", frame, 0.0))
    vertices = vertices @ place[:2, :2].T + place[:2, 2]
    path = np.stack([vertices, np.zeros_like(vertices), np.zeros_like(vertices)], axis=1)
    return _reversed(path) if _first(shape.get("d"), 1.0) == 3.0 else path


def _reversed(path: np.ndarray) -> np.ndarray:
    """The same path drawn the other way: vertices reversed, in and out tangents swapped."""
    backwards = path[::-1]
    return np.stack([backwards[:, 0], backwards[:, 2], backwards[:, 1]], axis=1)


def _shape_segments(shape: dict, frame: float) -> tuple[np.ndarray, bool]:
    """A shape item's outline at ``frame`` as cubic segments in its group's coordinates, and whether it is closed."""
    kind = shape.get("ty")
    if kind == "sh":
        path, closed = _keyframed(shape.get("ks"), frame, _path)
        return _segments(path, closed), closed
    if kind == "sr":
        return _segments(_star(shape, frame), True), True
    center = _value(shape, "p", frame, [0.0, 0.0], spatial=True)
    size = _value(shape, "s", frame)
    if size.size < 2:
        raise _Unread(f"a size of {size.size} number(s)")
    reversed_ = _first(shape.get("d"), 1.0) == 3.0
    if kind == "el":
        return _segments(_ellipse(center, size, reversed_), True), True
    return _segments(_rectangle(center, size, _scalar(shape, "r", frame, 0.0), reversed_), True), True


def _placed(segments: np.ndarray, matrix: np.ndarray) -> np.ndarray:
    return segments @ matrix[:2, :2].T + matrix[:2, 2]


# --- groups, layers, compositions ---------------------------------------------------------------------------------

@dataclass(frozen=True)
class _Frames:
    """The two frames an element is evaluated at, in the frame numbers of the composition being walked."""

    before: float
    now: float

    def pair(self):
        return (self.before, self.now)


class _Walk:
    """Collects the elements of one call, top of the painting order first, and what is not read."""

    def __init__(self):
        self.elements: list[MovingElement] = []
        self.unread: list[str] = []
        self._indices: dict[int, dict] = {}  # per composition walked (its layers list): layer index by ``ind``

    def group(self, items, matrices, frames: _Frames, where: str, taint: str | None = None) -> list[_Ring]:
        """Walk a shape group's ``items`` (top first); returns its paths for the fills below it.

        ``taint`` names a path modifier of an enclosing group: it changes every path inside, so
        nothing painted here is read."""
        items = [item for item in items if isinstance(item, dict) and not item.get("hd")] if isinstance(
            items, list) else []
        transform = next((item for item in items if item.get("ty") == "tr"), None)
        if transform is not None:
            own = [transform_matrix(transform, frame) for frame in frames.pair()]
            if own[1] is None or not _opaque(transform, frames.now):
                return []
            if own[0] is None:
                self.unread.append(f"{where} (appears between the two frames)")
                return []
            matrices = [matrices[0] @ own[0], matrices[1] @ own[1]]
        modifier = next((item for item in items if item.get("ty") in _MODIFIERS), None)
        if modifier is not None and taint is None:
            taint = f"{where} (a {_MODIFIERS[modifier['ty']]})"
        rings: list[_Ring] = []
        for index, item in enumerate(items):
            kind, name = item.get("ty"), f"{where}[{index}] '{item.get('nm', '')}'"
            if kind == "gr":
                rings += self.group(item.get("it"), matrices, frames, f"{name} it", taint)
            elif kind in _SHAPES:
                rings.append(self._ring(item, matrices, frames, name, taint))
            elif kind in _FILLS:
                self._paint(item, rings, frames, name, lambda drawn: _element(
                    drawn, _first(item.get("r"), 1.0) == 2.0))
            elif kind in _STROKES:
                self._stroke(item, rings, matrices, frames, name)
        if taint is not None:
            for ring in rings:
                ring.unread = ring.unread or taint
        return rings

    def _ring(self, item: dict, matrices, frames: _Frames, name: str, taint: str | None) -> _Ring:
        try:
            (before, _), (now, closed) = (_shape_segments(item, frame) for frame in frames.pair())
            before, now = _placed(before, matrices[0]), _placed(now, matrices[1])
        except _Unread as reason:
            return _Ring(np.zeros((0, 4, 2)), np.zeros((0, 4, 2)), f"{name} ({reason})")
        if before.shape != now.shape:
            return _Ring(before, now, f"{name} (its outline changed structure)")
        return _Ring(before, now, taint, closed)

    def _stroke(self, stroke: dict, rings: list[_Ring], matrices, frames: _Frames, name: str) -> None:
        """A stroke of the paths above it: their outlines widened by its width (``w``, in its group's units)."""
        if isinstance(stroke.get("d"), list) and stroke["d"]:
            if rings:
                self.unread.append(f"{name} (a dashed stroke)")
            return
        try:
            widths = [_scalar(stroke, "w", frame, 0.0) * math.sqrt(abs(np.linalg.det(matrix[:2, :2])))
                      for frame, matrix in zip(frames.pair(), matrices)]
        except _Unread as reason:
            self.unread.append(f"{name} ({reason})")
            return
        if widths[1] <= 0.0:
            return
        self._paint(stroke, rings, frames, name, lambda drawn: _stroke_element(drawn, widths))

    def _paint(self, paint: dict, rings: list[_Ring], frames: _Frames, name: str, make) -> None:
        """One element painted by ``paint`` (a fill or a stroke) over ``rings``: ``make(rings)``, unless it is
        transparent or a ring is not read."""
        rings = [ring for ring in rings if ring.now.shape[0] or ring.unread is not None]
        if not rings:
            return
        try:
            if _scalar(paint, "o", frames.now, 100.0) <= 0.0:
                return
        except _Unread as reason:
            self.unread.append(f"{name} ({reason})")
            return
        reasons = [ring.unread for ring in rings if ring.unread is not None]
        if reasons:
            self.unread.append(f"{name} ({'strokes' if paint.get('ty') in _STROKES else 'fills'} {reasons[0]})")
            return
        element = make(rings)
        if element is None:
            self.unread.append(f"{name} (its outline is too large or out of range)")
        else:
            self.elements.append(element)

    def layer(self, layers: list, index: int, frames: _Frames, outer, composition: dict, where: str,
              children: set[int] | None = None, depth: int = 0, matte_source: bool = False) -> None:
        """Walk layer ``index`` of ``layers`` (a composition), placed by ``outer`` (the two frames' matrices).

        A track-matte source is walked only as one (``matte_source``): it is never drawn itself.
        """
        layer = layers[index]
        name = f"{where}layers[{index}] '{layer.get('nm', '')}'"
        if layer.get("hd") or (layer.get("td") and not matte_source) or layer.get("ty") == _NULL:
            return
        visible = [_first(layer.get("ip"), -math.inf) <= frame < _first(layer.get("op"), math.inf)
                   for frame in frames.pair()]
        if not visible[1]:
            return
        try:
            if not visible[0]:
                raise _Unread("appears between the two frames")
            if layer.get("ddd") == 1:
                raise _Unread("a 3D layer")
            if layer.get("ao") == 1:
                raise _Unread("an auto-oriented layer")
            if layer.get("ty") in _NOT_SHAPE_LAYERS:
                raise _Unread(_NOT_SHAPE_LAYERS[layer["ty"]])
            by_ind = self._indices.setdefault(id(layers), {
                other.get("ind"): i for i, other in enumerate(layers) if isinstance(other, dict) and "ind" in other})
            own = [_chain(layers, by_ind, index, frame) for frame in frames.pair()]
            if own[1] is None or not _opaque(layer.get("ks"), frames.now):
                return
            if own[0] is None:
                raise _Unread("appears between the two frames")
            matrices = [outer[0] @ own[0], outer[1] @ own[1]]
            first, kind = len(self.elements), layer.get("ty")
            if kind == _SHAPE:
                self.group(layer.get("shapes"), matrices, frames, f"{name} shapes")
            elif kind == _SOLID:
                rectangle = _box(_first(layer.get("sw"), 0.0), _first(layer.get("sh"), 0.0))
                self._paint({}, [_Ring(_placed(rectangle, matrices[0]), _placed(rectangle, matrices[1]))],
                            frames, name, lambda drawn: _element(drawn, False))
            elif kind == _PRECOMP:
                self._precomp(layer, frames, matrices, composition, name, children, depth)
            else:
                raise _Unread(f"a layer of type {kind!r}")
            clips = _masks(layer, matrices[1], frames.now) + self._matte(layers, index, frames, outer, composition,
                                                                         where, depth)
            if kind == _PRECOMP:  # the player draws a precomp only within its own bounds
                clips += (_bounds_clip(_first(layer.get("w"), 0.0), _first(layer.get("h"), 0.0), matrices[1]),)
            if clips:
                self.elements[first:] = [replace(element, clips=element.clips + clips)
                                         for element in self.elements[first:]]
        except _Unread as reason:
            self.unread.append(f"{name} ({reason})")
        except (TypeError, ValueError, KeyError, IndexError, OverflowError) as error:  # malformed: the masks
            self.unread.append(f"{name} (not read: {error})")

    def _matte(self, layers: list, index: int, frames: _Frames, outer, composition: dict, where: str,
               depth: int) -> tuple[Clip, ...]:
        """The alpha track matte layer ``index`` is drawn through, as a clip (a luma matte: none, the outline covers
        what is drawn)."""
        kind = layers[index].get("tt")
        if kind not in (_ALPHA_MATTE, _INVERTED_ALPHA_MATTE):
            return ()
        if "tp" in layers[index]:
            source = next((i for i, layer in enumerate(layers) if layer.get("ind") == layers[index]["tp"]), None)
        else:
            source = index - 1 if index > 0 else None
        walk = _Walk()
        if source is not None:
            walk.layer(layers, source, frames, outer, composition, where, depth=depth, matte_source=True)
        return (Clip((ClipPart(tuple(walk.elements), "add", kind == _INVERTED_ALPHA_MATTE),)),)

    def _precomp(self, layer: dict, frames: _Frames, matrices, composition: dict, name: str,
                 children: set[int] | None, depth: int) -> None:
        if depth >= _MAX_NESTING:
            raise _Unread(f"precomps nested deeper than {_MAX_NESTING}")
        asset = next((asset for asset in composition.get("assets") or [] if isinstance(asset, dict)
                      and asset.get("id") == layer.get("refId") and isinstance(asset.get("layers"), list)), None)
        if asset is None:
            return
        rate = float(composition["fr"])
        inner = _Frames(*(_remapped(layer, frame, rate) for frame in frames.pair()))
        inside = asset["layers"]
        for child in range(len(inside)):
            if children is None or child in children:
                self.layer(inside, child, inner, matrices, composition, f"{name} → ", depth=depth + 1)


def _masks(layer: dict, matrix: np.ndarray, frame: float) -> tuple[Clip, ...]:
    """A layer's masks at ``frame`` as one clip, their paths placed by the layer's ``matrix``."""
    parts = []
    for index, mask in enumerate(mask for mask in layer.get("masksProperties") or [] if isinstance(mask, dict)):
        mode = mask.get("mode", "a")
        if mode == "n":
            continue
        if mode not in _MASK_MODES:
            raise _Unread(f"masksProperties[{index}] of mode {mode!r}")
        path, _ = _keyframed(mask.get("pt"), frame, _path)
        element = _region(_placed(_segments(path, True), matrix), f"masksProperties[{index}]")
        parts.append(ClipPart((element,), _MASK_MODES[mode], bool(mask.get("inv"))))
    return (Clip(tuple(parts)),) if parts else ()


def _box(width: float, height: float) -> np.ndarray:
    """The rectangle (0, 0)–(``width``, ``height``) as cubic segments."""
    size = np.array([width, height])
    return _segments(_rectangle(size / 2, size, 0.0, False), True)


def _bounds_clip(width: float, height: float, matrix: np.ndarray) -> Clip:
    """:func:`_box` placed by ``matrix``, as a clip."""
    return Clip((ClipPart((_region(_placed(_box(width, height), matrix), "bounds"),)),))


def _region(outline: np.ndarray, what: str) -> MovingElement:
    """A closed outline (cubic segments in output px) as an element whose coverage a clip takes."""
    element = _element([_Ring(outline, outline)], False)
    if element is None:
        raise _Unread(f"{what} out of range")
    return element


def _remapped(layer: dict, frame: float, rate: float) -> float:
    """The frame inside a precomp layer's composition at ``frame`` of the one holding it (as the player maps it)."""
    if "tm" in layer:
        return _scalar(layer, "tm", frame, 0.0) * rate
    stretch = _first(layer.get("sr"), 1.0) or 1.0
    return (frame - _first(layer.get("st"), 0.0)) / stretch


def _chain(layers: list, by_ind: dict, index: int, frame: float) -> np.ndarray | None:
    """Layer ``index``'s matrix at ``frame`` through its parents (``parent`` names a layer's ``ind``; ``by_ind``
    maps each ``ind`` to its layer's index)."""
    matrix, current = np.eye(3), index
    for _ in range(_MAX_NESTING):
        own = transform_matrix(layers[current].get("ks"), frame)
        if own is None:
            return None
        matrix = own @ matrix
        parent = layers[current].get("parent")
        if parent is None:
            return matrix
        if parent not in by_ind:
            raise _Unread(f"its parent {parent!r} is not a layer of its composition")
        current = by_ind[parent]
    raise _Unread(f"a parent chain longer than {_MAX_NESTING} (a cycle?)")


def _element(rings: list[_Ring], even_odd: bool) -> MovingElement | None:
    """The rings' outline points at both frames, curves cut the same way at both (None: too large)."""
    before_points, now_points, starts = [], [], [0]
    for ring in rings:
        before, now = _cut(ring.before, ring.now)
        before_points.append(before)
        now_points.append(now)
        starts.append(starts[-1] + now.shape[0])
    return _checked_element(np.concatenate(now_points), np.concatenate(before_points), starts, even_odd)


def _checked_element(now: np.ndarray, before: np.ndarray, starts: list[int], even_odd: bool) -> MovingElement | None:
    if now.shape[0] > _MAX_POINTS or not (np.isfinite(now).all() and np.isfinite(before).all()
                                          and np.abs(now).max(initial=0.0) < _FARTHEST
                                          and np.abs(before).max(initial=0.0) < _FARTHEST):
        return None
    return MovingElement(now=now, before=before, ring_starts=np.array(starts), even_odd=even_odd)


def _stroke_element(rings: list[_Ring], widths: list[float]) -> MovingElement | None:
    """The band within half a width of the rings' outlines at both frames (None: too large), by
    :func:`~fluidymation.engine.vector_motion.stroke_rings` at each frame: a point's offsets move with it."""
    before_points, now_points, starts = [], [], [0]
    for ring in rings:
        points = _cut(ring.before, ring.now)
        if not ring.closed:  # the end point, which closing would have supplied
            points = tuple(np.vstack([cut, segments[-1, 3]]) for cut, segments in zip(points, (ring.before, ring.now)))
        bands = [stroke_rings(cut, width / 2.0, ring.closed) for cut, width in zip(points, widths)]
        for before, now in zip(*bands):
            before_points.append(before)
            now_points.append(now)
            starts.append(starts[-1] + now.shape[0])
    return _checked_element(np.concatenate(now_points), np.concatenate(before_points), starts, False)


def _cut(before: np.ndarray, now: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points along the cubic segments (S, 4, 2) of both frames, at the same parameters in both."""
    lengths = np.maximum(np.linalg.norm(np.diff(before, axis=1), axis=2).sum(axis=1),
                         np.linalg.norm(np.diff(now, axis=1), axis=2).sum(axis=1))
    straight = np.all(np.isclose(before[:, 1], before[:, 0]) & np.isclose(before[:, 2], before[:, 3]), axis=1) & \
        np.all(np.isclose(now[:, 1], now[:, 0]) & np.isclose(now[:, 2], now[:, 3]), axis=1)
    curved_steps = np.clip(np.ceil(np.nan_to_num(lengths) / _PIXELS_PER_STEP), 2, _MAX_STEPS)
    steps = np.where(straight, 1, curved_steps).astype(int)
    t = np.concatenate([np.arange(count) / count for count in steps])
    segment = np.repeat(np.arange(len(steps)), steps)
    basis = np.column_stack([(1 - t) ** 3, 3 * (1 - t) ** 2 * t, 3 * (1 - t) * t**2, t**3])
    return (np.einsum("nk,nkd->nd", basis, before[segment]), np.einsum("nk,nkd->nd", basis, now[segment]))


def moving_elements(composition: dict, units: list[tuple[int, set[int] | None]], before_frame: float,
                    now_frame: float, size: tuple[int, int]) -> tuple[list[MovingElement], list[str]]:
    """The filled elements of the ``units`` of ``composition`` (a Lottie animation's JSON) at ``now_frame``, with
    where their outline points were at ``before_frame``, in pixels of a raster of ``size`` (width, height).

    A unit is a top-level layer's index and, for a split precomp, the indices of its children drawn (else None).
    Frames are the composition's own frame numbers. Returns the elements bottom to top and what is not read.
    """
    scale = min(size[0] / float(composition["w"]), size[1] / float(composition["h"]))
    viewport = _translation((size[0] - composition["w"] * scale) / 2, (size[1] - composition["h"] * scale) / 2) \
        @ np.diag([scale, scale, 1.0])
    walk = _Walk()
    frames = _Frames(before_frame, now_frame)
    for index, children in sorted(units, key=lambda unit: unit[0]):
        walk.layer(composition["layers"], index, frames, [viewport, viewport], composition, "", children)
    canvas = _bounds_clip(float(composition["w"]), float(composition["h"]), viewport)  # nothing outside the canvas
    return [replace(element, clips=element.clips + (canvas,)) for element in walk.elements[::-1]], walk.unread
