"""CSS transforms in 2D: transform lists (CSS syntax and the SVG ``transform`` attribute), their interpolation
(CSS Transforms 1 and 2) and ``transform-origin``.

A transform list is a tuple of :class:`Function` whose lengths may still be percentages of
the reference box (``transform-box``); :func:`resolve` makes them px. Interpolation follows
CSS Transforms 2: the shorter list is padded with identity functions, pairs with the same
primitive (translate, scale, rotate, skewX, skewY, skew) interpolate their arguments, and
from the first pair that does not match on, the rest of both lists is multiplied out and
interpolated through the matrix decomposition of :func:`decompose`.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from fluidymation.stages.vector.css_syntax import (InvalidCss, Length, UnsupportedCss, angle, ident, length, number,
                                                  split_commas, text_of)

Matrix = tuple[float, float, float, float, float, float]
IDENTITY: Matrix = (1.0, 0.0, 0.0, 1.0, 0.0, 0.0)
_IDENTITY_ARGUMENTS = {"translate": (0.0, 0.0), "scale": (1.0, 1.0), "rotate": (0.0,), "skewX": (0.0,),
                       "skewY": (0.0,), "skew": (0.0, 0.0), "matrix": IDENTITY}
_3D = {"matrix3d", "translate3d", "translatez", "scale3d", "scalez", "rotate3d", "rotatex", "rotatey", "perspective"}
_ORIGIN_KEYWORDS = {"x": {"left": 0.0, "center": 50.0, "right": 100.0},
                    "y": {"top": 0.0, "center": 50.0, "bottom": 100.0}}
_CENTER = Length(50.0, True)


class Function(NamedTuple):
    """One transform function by its 2D primitive: translate (x, y), scale (sx, sy), rotate (deg), skewX, skewY,
    skew (deg, deg) or matrix (a, b, c, d, e, f). Translate arguments are :class:`Length` until resolved."""

    name: str
    arguments: tuple


class Box(NamedTuple):
    """A reference box in user units (``transform-box``)."""

    x: float
    y: float
    width: float
    height: float


def parse_css_transform(values) -> tuple[Function, ...]:
    """The ``transform`` property: ``none`` or a list of CSS transform functions."""
    if len(values) == 1 and ident(values[0]) == "none":
        return ()
    if not values:
        raise InvalidCss("an empty transform")
    return tuple(_css_function(value) for value in values)


def _css_function(value) -> Function:
    if value.type != "function":
        raise InvalidCss(f"'{text_of([value])}' is not a transform function")
    name = value.lower_name
    if name in _3D:
        raise UnsupportedCss(f"the 3D transform function {name}() is not drawn")
    arguments = [group[0] if len(group) == 1 else None for group in split_commas(value.arguments)] \
        if value.arguments else []
    if None in arguments:
        raise InvalidCss(f"'{text_of([value])}': transform arguments are separated by commas")
    count = len(arguments)
    if name == "matrix" and count == 6:
        return Function("matrix", tuple(number(argument) for argument in arguments))
    if name == "translate" and count in (1, 2):
        x = length(arguments[0], unitless=False)
        return Function("translate", (x, length(arguments[1], unitless=False) if count == 2 else Length(0.0)))
    if name in ("translatex", "translatey") and count == 1:
        moved = length(arguments[0], unitless=False)
        return Function("translate", (moved, Length(0.0)) if name == "translatex" else (Length(0.0), moved))
    if name == "scale" and count in (1, 2):
        x = _scale(arguments[0])
        return Function("scale", (x, _scale(arguments[1]) if count == 2 else x))
    if name in ("scalex", "scaley") and count == 1:
        return Function("scale", (_scale(arguments[0]), 1.0) if name == "scalex" else (1.0, _scale(arguments[0])))
    if name in ("rotate", "rotatez") and count == 1:
        return Function("rotate", (angle(arguments[0]),))
    if name == "skew" and count in (1, 2):
        return Function("skew", (angle(arguments[0]), angle(arguments[1]) if count == 2 else 0.0))
    if name in ("skewx", "skewy") and count == 1:
        return Function("skewX" if name == "skewx" else "skewY", (angle(arguments[0]),))
    raise InvalidCss(f"'{text_of([value])}' is not a transform function")


def _scale(value) -> float:
    return float(value.value) / 100 if value.type == "percentage" else number(value)


def parse_individual(property_name: str, values) -> tuple[Function, ...]:
    """The ``translate``, ``rotate`` and ``scale`` properties (CSS Transforms 2) as one-function lists."""
    if len(values) == 1 and ident(values[0]) == "none":
        return ()
    if property_name == "translate" and len(values) in (1, 2):
        x = length(values[0], unitless=False)
        return (Function("translate", (x, length(values[1], unitless=False) if len(values) == 2 else Length(0.0))),)
    if property_name == "rotate":
        if len(values) == 2 and ident(values[0]) == "z":
            values = values[1:]
        if len(values) == 1:
            return (Function("rotate", (angle(values[0]),)),)
        raise UnsupportedCss(f"'rotate: {text_of(values)}' (a 3D rotation) is not drawn")
    if property_name == "scale" and len(values) in (1, 2):
        x = _scale(values[0])
        return (Function("scale", (x, _scale(values[1]) if len(values) == 2 else x)),)
    raise InvalidCss(f"'{property_name}: {text_of(values)}' is not valid")


def parse_svg_transform(values) -> tuple[Function, ...]:
    """The SVG ``transform`` attribute: functions of unitless numbers (degrees for angles), commas optional."""
    functions: list[Function] = []
    for value in values:
        if value.type == "literal" and value.value == ",":
            continue
        if value.type != "function":
            raise InvalidCss(f"'{text_of([value])}' is not a transform function")
        arguments = [number(argument) for argument in value.arguments
                     if argument.type not in ("whitespace", "comment") and
                     not (argument.type == "literal" and argument.value == ",")]
        name, count = value.name, len(arguments)
        if name == "matrix" and count == 6:
            functions.append(Function("matrix", tuple(arguments)))
        elif name == "translate" and count in (1, 2):
            functions.append(Function("translate", (Length(arguments[0]), Length(arguments[1] if count == 2 else 0))))
        elif name == "scale" and count in (1, 2):
            functions.append(Function("scale", (arguments[0], arguments[-1])))
        elif name == "rotate" and count == 1:
            functions.append(Function("rotate", (arguments[0],)))
        elif name == "rotate" and count == 3:
            degrees, cx, cy = arguments
            functions += [Function("translate", (Length(cx), Length(cy))), Function("rotate", (degrees,)),
                          Function("translate", (Length(-cx), Length(-cy)))]
        elif name in ("skewX", "skewY") and count == 1:
            functions.append(Function(name, (arguments[0],)))
        else:
            raise InvalidCss(f"'{text_of([value])}' is not an SVG transform")
    return tuple(functions)


def resolve(functions: tuple[Function, ...], box: Box) -> tuple[Function, ...]:
    """``functions`` with translate percentages made px of the reference ``box``."""
    return tuple(Function("translate", (function.arguments[0].px(box.width), function.arguments[1].px(box.height)))
                 if function.name == "translate" else function for function in functions)


def parse_origin(values, *, unitless: bool = False) -> tuple[Length, Length]:
    """``transform-origin``: one to three values (keywords, lengths, percentages); a z offset must be 0.

    ``unitless`` takes bare numbers as px, as the SVG ``transform-origin`` attribute does.
    """
    if len(values) == 3:
        if length(values[2], unitless=unitless) != Length(0.0):
            raise UnsupportedCss("a 3D transform-origin (z offset) is not drawn")
        values = values[:2]
    if len(values) == 1:
        if ident(values[0]) in ("top", "bottom"):
            return _CENTER, _origin_offset(values[0], "y", unitless)
        return _origin_offset(values[0], "x", unitless), _CENTER
    if len(values) != 2:
        raise InvalidCss(f"'{text_of(values)}' is not a transform-origin")
    first, second = values
    if ident(first) in ("top", "bottom") or ident(second) in ("left", "right"):
        if ident(first) is None or ident(second) is None:
            raise InvalidCss(f"'{text_of(values)}' is not a transform-origin")
        first, second = second, first
    return _origin_offset(first, "x", unitless), _origin_offset(second, "y", unitless)


def _origin_offset(value, axis: str, unitless: bool) -> Length:
    keyword = ident(value)
    if keyword is None:
        return length(value, unitless=unitless)
    if keyword not in _ORIGIN_KEYWORDS[axis]:
        raise InvalidCss(f"'{keyword}' is not a transform-origin keyword for the {axis} axis")
    return Length(_ORIGIN_KEYWORDS[axis][keyword], True)


def origin_point(origin: tuple[Length, Length], box: Box) -> tuple[float, float]:
    return box.x + origin[0].px(box.width), box.y + origin[1].px(box.height)


def multiply(first: Matrix, then: Matrix) -> Matrix:
    """The matrix that applies ``then`` to points and ``first`` to the result (first · then, SVG matrices)."""
    a1, b1, c1, d1, e1, f1 = first
    a2, b2, c2, d2, e2, f2 = then
    return (a1 * a2 + c1 * b2, b1 * a2 + d1 * b2, a1 * c2 + c1 * d2, b1 * c2 + d1 * d2,
            a1 * e2 + c1 * f2 + e1, b1 * e2 + d1 * f2 + f1)


def matrix_of(functions: tuple[Function, ...]) -> Matrix:
    """The product of resolved ``functions``, the first outermost (as written)."""
    result = IDENTITY
    for function in functions:
        result = multiply(result, _function_matrix(function))
    return result


def _function_matrix(function: Function) -> Matrix:
    name, arguments = function
    if name == "translate":
        return (1.0, 0.0, 0.0, 1.0, float(arguments[0]), float(arguments[1]))
    if name == "scale":
        return (arguments[0], 0.0, 0.0, arguments[1], 0.0, 0.0)
    if name == "rotate":
        radians = math.radians(arguments[0])
        return (math.cos(radians), math.sin(radians), -math.sin(radians), math.cos(radians), 0.0, 0.0)
    if name == "skewX":
        return (1.0, 0.0, math.tan(math.radians(arguments[0])), 1.0, 0.0, 0.0)
    if name == "skewY":
        return (1.0, math.tan(math.radians(arguments[0])), 0.0, 1.0, 0.0, 0.0)
    if name == "skew":
        return (1.0, math.tan(math.radians(arguments[1])), math.tan(math.radians(arguments[0])), 1.0, 0.0, 0.0)
    return tuple(arguments)


def interpolate(start: tuple[Function, ...], end: tuple[Function, ...], progress: float) -> tuple[Function, ...]:
    """Resolved transform lists ``start`` to ``end`` at ``progress`` (CSS Transforms 2)."""
    start, end = _padded(start, end), _padded(end, start)
    result = []
    for index, (first, second) in enumerate(zip(start, end)):
        if first.name != second.name:
            blended = interpolate_matrices(matrix_of(start[index:]), matrix_of(end[index:]), progress)
            return tuple(result) + (Function("matrix", blended),)
        if first.name == "matrix":
            result.append(Function("matrix", interpolate_matrices(first.arguments, second.arguments, progress)))
        else:
            result.append(Function(first.name, tuple(a + (b - a) * progress
                                                     for a, b in zip(first.arguments, second.arguments))))
    return tuple(result)


def _padded(functions: tuple[Function, ...], other: tuple[Function, ...]) -> tuple[Function, ...]:
    return functions + tuple(Function(function.name, _IDENTITY_ARGUMENTS[function.name])
                             for function in other[len(functions):])


class Decomposed(NamedTuple):
    """A 2D matrix taken apart: translate · rotate(angle) · skew · scale."""

    translate: tuple[float, float]
    scale: tuple[float, float]
    skew: float
    angle: float


def decompose(matrix: Matrix) -> Decomposed | None:
    """The unmatrix decomposition (CSS Transforms 2, "Decomposing a 3D matrix") of a 2D matrix; None when singular.

    For a 2D matrix it keeps x/y scale, the xy skew and a rotation about z. CSS Transforms 1's
    own 2D algorithm (a leftover 2×2 matrix instead of the skew) gives other in-between
    matrices when a skew is interpolated; Chromium interpolates as this one does.
    """
    a, b, c, d, e, f = matrix
    if a * d - b * c == 0:
        return None
    scale_x = math.hypot(a, b)
    a, b = a / scale_x, b / scale_x
    skew = a * c + b * d
    c, d = c - a * skew, d - b * skew
    scale_y = math.hypot(c, d)
    c, d, skew = c / scale_y, d / scale_y, skew / scale_y
    if a * d - b * c < 0:
        a, b, skew, scale_x = -a, -b, -skew, -scale_x
    return Decomposed((e, f), (scale_x, scale_y), skew, math.degrees(math.atan2(b, a)))


def recompose(parts: Decomposed) -> Matrix:
    """The matrix :func:`decompose` took apart."""
    radians = math.radians(parts.angle)
    cosine, sine = math.cos(radians), math.sin(radians)
    scale_x, scale_y = parts.scale
    linear = multiply((cosine, sine, -sine, cosine, 0.0, 0.0), (scale_x, 0.0, parts.skew * scale_y, scale_y, 0.0, 0.0))
    return (*linear[:4], *parts.translate)


def interpolate_matrices(start: Matrix, end: Matrix, progress: float) -> Matrix:
    """Matrices interpolated through their decompositions (the rotation the shorter way round, as a quaternion
    slerp turns); discretely (the start until half-way) when either is singular (Web Animations)."""
    first, second = decompose(start), decompose(end)
    if first is None or second is None:
        return start if progress < 0.5 else end
    turn = (second.angle - first.angle + 180) % 360 - 180

    def blend(a, b):
        return tuple(x + (y - x) * progress for x, y in zip(a, b))

    return recompose(Decomposed(blend(first.translate, second.translate), blend(first.scale, second.scale),
                                first.skew + (second.skew - first.skew) * progress, first.angle + turn * progress))
