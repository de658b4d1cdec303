"""The properties CSS animations may animate in an SVG file, and how each one's values parse, resolve and interpolate.

:data:`PROPERTIES` maps a property to its :class:`Property`: whether it inherits, its
initial value and its :class:`Kind` (lengths, alpha numbers, colours and paints, dash
arrays, visibility, transform lists). A value is parsed once from the file, resolved for
an element (percentages against the viewport, ``currentColor``) and then interpolated
as CSS Values and Web Animations say; values that cannot interpolate (``none``,
``auto``, ``url()`` paints) flip half-way (discrete animation).
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Callable, NamedTuple

from tinycss2 import color4

from fluidymation.stages.vector.css_syntax import (InvalidCss, UnsupportedCss, ident, length, number, split_commas,
                                                  text_of, tokens)
from fluidymation.stages.vector.css_transform import Box, parse_css_transform, parse_individual, parse_svg_transform
from fluidymation.stages.vector.css_transform import interpolate as interpolate_transforms
from fluidymation.stages.vector.css_transform import resolve as resolve_transform

RGBA = tuple[float, float, float, float]


class Keyword(NamedTuple):
    """A value that only animates discretely (``none``, ``auto``, a ``url()`` paint, ``currentColor``)."""

    text: str


class Context(NamedTuple):
    """What an element's values resolve against: the viewport (px), its ``color`` and its ``transform-box``."""

    viewport: tuple[float, float]
    color: RGBA
    box: Callable[[], Box]


class Kind(ABC):
    """How one type of value parses (from CSS and from its SVG attribute), resolves, interpolates and is written."""

    @abstractmethod
    def parse(self, values):
        """The value of significant component values; raises InvalidCss or UnsupportedCss."""

    def parse_attribute(self, text: str):
        return self.parse(tokens(text))

    def resolve(self, value, context: Context):
        return value

    def blend(self, start, end, progress: float):
        """Interpolate two resolved values that both interpolate."""
        return start + (end - start) * progress

    def serialize(self, value) -> str:
        return value.text if isinstance(value, Keyword) else _number(value)

    def interpolate(self, start, end, progress: float):
        """Resolved ``start`` to ``end`` at ``progress``: blended, or discrete when either cannot interpolate."""
        if isinstance(start, Keyword) or isinstance(end, Keyword):
            return start if progress < 0.5 else end
        return self.blend(start, end, progress)


def _number(value: float) -> str:
    return format(value, ".10g")


def _single(values):
    if len(values) != 1:
        raise InvalidCss(f"'{text_of(values)}' is not a single value")
    return values[0]


class LengthKind(Kind):
    """A length, percentage or (as SVG allows for these properties) bare number; percentages of the viewport's
    width (``x``), height (``y``) or normalized diagonal (``xy``)."""

    def __init__(self, axis: str, *, nonnegative: bool = False, auto: bool = False):
        self.axis, self.nonnegative, self.auto = axis, nonnegative, auto

    def parse(self, values):
        value = _single(values)
        if self.auto and ident(value) == "auto":
            return Keyword("auto")
        parsed = length(value, unitless=True)
        if self.nonnegative and parsed.value < 0:
            raise InvalidCss(f"'{text_of(values)}' is negative")
        return parsed

    def resolve(self, value, context):
        return value if isinstance(value, Keyword) else value.px(_reference(self.axis, context.viewport))

    def blend(self, start, end, progress):
        value = start + (end - start) * progress
        return max(value, 0.0) if self.nonnegative else value


def _reference(axis: str, viewport: tuple[float, float]) -> float:
    width, height = viewport
    return {"x": width, "y": height, "xy": math.hypot(width, height) / math.sqrt(2)}[axis]


class AlphaKind(Kind):
    """``opacity`` and its kin: a number or percentage, clamped to [0, 1]."""

    def parse(self, values):
        value = _single(values)
        return float(value.value) / 100 if value.type == "percentage" else number(value)

    def serialize(self, value):
        return _number(min(max(value, 0.0), 1.0))


class ColorKind(Kind):
    """A colour, or for ``fill`` and ``stroke`` (``paint``) also ``none`` and ``url(#paint)``: interpolated in
    premultiplied sRGB, as browsers interpolate sRGB colours."""

    def __init__(self, *, paint: bool):
        self.paint = paint

    def parse(self, values):
        if self.paint and values and (values[0].type == "url" or
                                      (values[0].type == "function" and values[0].lower_name == "url")):
            return Keyword(text_of(values))
        value = _single(values)
        if self.paint and ident(value) in ("none", "context-fill", "context-stroke"):
            return Keyword(ident(value))
        parsed = color4.parse_color(value)
        if parsed is None:
            raise InvalidCss(f"'{text_of(values)}' is not a colour")
        if parsed == "currentcolor":
            return Keyword("currentcolor")
        if parsed.space not in ("srgb", "hsl", "hwb"):
            raise UnsupportedCss(f"the colour '{text_of(values)}' ({parsed.space}) is not interpolated")
        return tuple(parsed.to("srgb").coordinates) + (parsed.alpha,)

    def resolve(self, value, context):
        return context.color if value == Keyword("currentcolor") else value

    def blend(self, start, end, progress):
        alpha = start[3] + (end[3] - start[3]) * progress
        if alpha <= 0:
            return (0.0, 0.0, 0.0, 0.0)
        channels = (((a * start[3]) + ((b * end[3]) - (a * start[3])) * progress) / alpha
                    for a, b in zip(start[:3], end[:3]))
        return (*channels, min(alpha, 1.0))

    def serialize(self, value):
        if isinstance(value, Keyword):
            return value.text
        red, green, blue = (_number(min(max(channel, 0.0), 1.0) * 255) for channel in value[:3])
        return f"rgba({red}, {green}, {blue}, {_number(min(max(value[3], 0.0), 1.0))})"


class DashArrayKind(Kind):
    """``stroke-dasharray``: ``none`` or lengths; two lists interpolate item by item, each repeated to the least
    common multiple of their lengths (SVG 2)."""

    def parse(self, values):
        if len(values) == 1 and ident(values[0]) == "none":
            return Keyword("none")
        if not values:
            raise InvalidCss("an empty dash array")
        items = [value for group in split_commas(values) for value in group]
        parsed = tuple(length(value, unitless=True) for value in items)
        if any(item.value < 0 for item in parsed):
            raise InvalidCss(f"'{text_of(values)}' has a negative dash")
        return parsed

    def resolve(self, value, context):
        if isinstance(value, Keyword):
            return value
        reference = _reference("xy", context.viewport)
        return tuple(item.px(reference) for item in value)

    def blend(self, start, end, progress):
        count = math.lcm(len(start), len(end))
        start, end = start * (count // len(start)), end * (count // len(end))
        return tuple(max(a + (b - a) * progress, 0.0) for a, b in zip(start, end))

    def serialize(self, value):
        return value.text if isinstance(value, Keyword) else " ".join(_number(item) for item in value)


class VisibilityKind(Kind):
    """``visibility``: between ``visible`` and another value it stays visible for the whole interval."""

    def parse(self, values):
        keyword = ident(_single(values))
        if keyword not in ("visible", "hidden", "collapse"):
            raise InvalidCss(f"'{text_of(values)}' is not a visibility")
        return Keyword(keyword)

    def interpolate(self, start, end, progress):
        if "visible" in (start.text, end.text) and start != end and 0 < progress < 1:
            return Keyword("visible")
        return start if progress < 0.5 else end

    def serialize(self, value):
        return value.text


class TransformKind(Kind):
    """A transform list (``transform``) or one of the individual ``translate``, ``rotate``, ``scale`` properties;
    percentages are of the ``transform-box``."""

    def __init__(self, name: str):
        self.name = name

    def parse(self, values):
        return parse_css_transform(values) if self.name == "transform" else parse_individual(self.name, values)

    def parse_attribute(self, text):
        return parse_svg_transform(tokens(text))

    def resolve(self, value, context):
        relative = any(function.name == "translate" and (function.arguments[0].percent or function.arguments[1].percent)
                       for function in value)
        return resolve_transform(value, context.box() if relative else Box(0.0, 0.0, 0.0, 0.0))

    def interpolate(self, start, end, progress):
        return interpolate_transforms(start, end, progress)


@dataclass(frozen=True)
class Property:
    """An animated property: its kind, whether it inherits, and its initial value (CSS text)."""

    kind: Kind
    inherited: bool
    initial: str


_ALPHA = AlphaKind()
PROPERTIES: dict[str, Property] = {
    "opacity": Property(_ALPHA, False, "1"),
    "fill-opacity": Property(_ALPHA, True, "1"),
    "stroke-opacity": Property(_ALPHA, True, "1"),
    "stop-opacity": Property(_ALPHA, False, "1"),
    "fill": Property(ColorKind(paint=True), True, "black"),
    "stroke": Property(ColorKind(paint=True), True, "none"),
    "stop-color": Property(ColorKind(paint=False), False, "black"),
    "stroke-width": Property(LengthKind("xy", nonnegative=True), True, "1"),
    "stroke-dashoffset": Property(LengthKind("xy"), True, "0"),
    "stroke-dasharray": Property(DashArrayKind(), True, "none"),
    "cx": Property(LengthKind("x"), False, "0"),
    "cy": Property(LengthKind("y"), False, "0"),
    "r": Property(LengthKind("xy", nonnegative=True), False, "0"),
    "rx": Property(LengthKind("x", nonnegative=True, auto=True), False, "auto"),
    "ry": Property(LengthKind("y", nonnegative=True, auto=True), False, "auto"),
    "x": Property(LengthKind("x"), False, "0"),
    "y": Property(LengthKind("y"), False, "0"),
    "width": Property(LengthKind("x", nonnegative=True, auto=True), False, "auto"),
    "height": Property(LengthKind("y", nonnegative=True, auto=True), False, "auto"),
    "visibility": Property(VisibilityKind(), True, "visible"),
    "transform": Property(TransformKind("transform"), False, "none"),
    "translate": Property(TransformKind("translate"), False, "none"),
    "rotate": Property(TransformKind("rotate"), False, "none"),
    "scale": Property(TransformKind("scale"), False, "none"),
}
#: The transform properties, in the order they apply (CSS Transforms 2): translate, rotate, scale, then transform.
TRANSFORM_PROPERTIES = ("translate", "rotate", "scale", "transform")
