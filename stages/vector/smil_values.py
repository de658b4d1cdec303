"""The value types SMIL animates, each with its parsing, interpolation, addition, distance and text form.

A :class:`ValueType` is chosen per animation from the attribute and its values
(:func:`value_type_for`): lengths and numbers (with one unit), colours, number lists
(dash arrays, points, viewBox), path data, ``animateTransform`` parameters, motion points,
and plain strings, which only change discretely. Addition serves ``additive``,
``accumulate`` and ``by``; distance serves ``calcMode="paced"``.
"""

from __future__ import annotations

import functools
import math
import re
from abc import ABC, abstractmethod
from typing import Any

from fluidymation.stages.vector.smil_path import PathData

_NUMBER = r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?"
_LENGTH = re.compile(rf"^\s*({_NUMBER})\s*(px|pt|pc|mm|cm|in|em|ex|%|deg)?\s*$")
_LIST_SPLIT = re.compile(r"\s*,\s*|\s+")
_PX_PER_UNIT = {"": 1.0, "px": 1.0, "pt": 96 / 72, "pc": 16.0, "mm": 96 / 25.4, "cm": 96 / 2.54, "in": 96.0}
_HEX = re.compile(r"^#([0-9a-fA-F]{3}|[0-9a-fA-F]{6})$")
_FUNCTIONAL = re.compile(r"^(rgba?)\(\s*([^)]*)\)$", re.IGNORECASE)

#: Attributes whose values are colours (when every value of an animation parses as one).
COLOUR_ATTRIBUTES = {"fill", "stroke", "stop-color", "flood-color", "lighting-color", "color"}
#: animateTransform types: (parameter count written at most, defaults for the ones left out).
TRANSFORM_PARAMETERS = {"translate": (2, (0.0, 0.0)), "scale": (2, (1.0, None)), "rotate": (3, (0.0, 0.0, 0.0)),
                        "skewX": (1, (0.0,)), "skewY": (1, (0.0,))}



@functools.cache
def _colour_keywords() -> dict[str, tuple]:
    """The colour keywords as cairosvg draws them (its own table, so an animated keyword looks like a static one);
    loaded on first use, as it loads cairo."""
    from cairosvg.colors import COLORS

    return {name: value for name, value in COLORS.items() if name not in ("none", "transparent")}

class ValueType(ABC):
    """How one kind of attribute value is read, blended and written back."""

    #: Whether values interpolate (else every calcMode is discrete).
    interpolates = True
    #: Whether ``additive``/``accumulate`` apply (SVG 1.1 lists the attributes that are additive).
    additive = True

    @abstractmethod
    def parse(self, text: str) -> Any:
        """The value of ``text``; a ValueError if it is not one."""

    def interpolate(self, a, b, fraction: float):
        return b if fraction >= 1 else a

    def add(self, a, b):
        return b

    def scale(self, a, factor: int):
        """``a`` added to itself ``factor`` times (0: the zero), for ``accumulate``."""
        return a

    def distance(self, a, b) -> float | None:
        """The distance between two values for paced animation; None when the type has none."""
        return None

    def zero(self):
        """The value that adds nothing (the start of a ``by`` animation)."""
        raise ValueError("no zero")

    def format(self, value) -> str:
        return str(value)

    def compatible(self, values: list) -> bool:
        """Whether the values can be interpolated with one another."""
        return True


class StringType(ValueType):
    """Any value, set as written; it changes only discretely."""

    interpolates = False
    additive = False

    def parse(self, text):
        return text.strip()


class LengthType(ValueType):
    """A number with an optional unit (lengths, opacities, offsets); absolute units convert to px."""

    def parse(self, text):
        match = _LENGTH.match(text)
        if not match:
            raise ValueError(f"'{text.strip()}' is not a number or length")
        return float(match.group(1)), match.group(2) or ""

    def interpolate(self, a, b, fraction):
        pair = _same_unit(a, b)
        if pair is None:
            return b if fraction >= 0.5 else a
        (x, unit), (y, _) = pair
        return x + (y - x) * fraction, unit

    def add(self, a, b):
        pair = _same_unit(a, b)
        if pair is None:
            return b
        (x, unit), (y, _) = pair
        return x + y, unit

    def scale(self, a, factor):
        return a[0] * factor, a[1]

    def distance(self, a, b):
        pair = _same_unit(a, b)
        return None if pair is None else abs(pair[1][0] - pair[0][0])

    def zero(self):
        return 0.0, ""

    def format(self, value):
        return f"{value[0]:.6g}{value[1]}"

    def compatible(self, values):
        return all(_same_unit(values[0], value) is not None for value in values)


def _same_unit(a, b):
    """``a`` and ``b`` in one unit (a zero takes the other's; differing absolute units go to px), or None."""
    if a[1] == b[1] or b[0] == 0:
        return a, (b[0], a[1])
    if a[0] == 0:
        return (a[0], b[1]), b
    if a[1] in _PX_PER_UNIT and b[1] in _PX_PER_UNIT:
        return (a[0] * _PX_PER_UNIT[a[1]], "px"), (b[0] * _PX_PER_UNIT[b[1]], "px")
    return None


class ColourType(ValueType):
    """An sRGB colour (#rgb, #rrggbb, rgb(), rgba(), keywords), blended channel by channel."""

    def parse(self, text):
        text = text.strip()
        keyword = _colour_keywords().get(text.lower())
        if keyword is not None:
            return tuple(channel * 255 for channel in keyword[:3]) + (1.0,)
        match = _HEX.match(text)
        if match:
            digits = match.group(1)
            if len(digits) == 3:
                digits = "".join(digit * 2 for digit in digits)
            return tuple(float(int(digits[i:i + 2], 16)) for i in (0, 2, 4)) + (1.0,)
        match = _FUNCTIONAL.match(text)
        if match:
            parts = [part for part in re.split(r"\s*,\s*|\s+", match.group(2).strip()) if part]
            if len(parts) == (4 if match.group(1).lower() == "rgba" else 3):
                channels = [_channel(part) for part in parts[:3]]
                alpha = _channel(parts[3]) / 255 if len(parts) == 4 and parts[3].endswith("%") else (
                    float(parts[3]) if len(parts) == 4 else 1.0)
                return (*channels, alpha)
        raise ValueError(f"'{text}' is not a colour")

    def interpolate(self, a, b, fraction):
        return tuple(x + (y - x) * fraction for x, y in zip(a, b))

    def add(self, a, b):
        return tuple(x + y for x, y in zip(a[:3], b[:3])) + (max(a[3], b[3]),)

    def scale(self, a, factor):
        return tuple(x * factor for x in a[:3]) + (a[3],)

    def distance(self, a, b):
        return math.dist(a[:3], b[:3])

    def zero(self):
        return 0.0, 0.0, 0.0, 0.0

    def format(self, value):
        red, green, blue = (round(min(255.0, max(0.0, channel))) for channel in value[:3])
        alpha = min(1.0, max(0.0, value[3]))
        return f"rgb({red},{green},{blue})" if alpha >= 1 else f"rgba({red},{green},{blue},{alpha:.4g})"


def _channel(text: str) -> float:
    return float(text[:-1]) * 2.55 if text.endswith("%") else float(text)


class ListType(ValueType):
    """A list of numbers or lengths (``stroke-dasharray``, ``points``, ``viewBox``), blended item by item."""

    def __init__(self):
        self._item = LengthType()

    def parse(self, text):
        items = [item for item in _LIST_SPLIT.split(text.strip()) if item]
        if not items:
            raise ValueError("an empty list")
        return tuple(self._item.parse(item) for item in items)

    def interpolate(self, a, b, fraction):
        if len(a) != len(b):
            return b if fraction >= 0.5 else a
        return tuple(self._item.interpolate(x, y, fraction) for x, y in zip(a, b))

    def add(self, a, b):
        return tuple(self._item.add(x, y) for x, y in zip(a, b)) if len(a) == len(b) else b

    def scale(self, a, factor):
        return tuple(self._item.scale(x, factor) for x in a)

    def format(self, value):
        return " ".join(self._item.format(item) for item in value)

    def compatible(self, values):
        return all(len(value) == len(values[0]) and self._item.compatible(list(value) + list(values[0]))
                   for value in values)


class PathType(ValueType):
    """Path data (``d``); values interpolate only when their command lists match (SVG 1.1)."""

    additive = False

    def parse(self, text):
        return PathData.parse(text)

    def interpolate(self, a, b, fraction):
        return a.interpolate(b, fraction) if a.letters() == b.letters() else (b if fraction >= 0.5 else a)

    def compatible(self, values):
        return all(value.letters() == values[0].letters() for value in values)


class TransformType(ValueType):
    """The parameters of one ``animateTransform`` type; its text is the transform function."""

    def __init__(self, kind: str):
        self.kind = kind
        self._count, self._defaults = TRANSFORM_PARAMETERS[kind]

    def parse(self, text):
        items = [item for item in _LIST_SPLIT.split(text.strip()) if item]
        if not 1 <= len(items) <= self._count or self.kind == "rotate" and len(items) == 2:
            raise ValueError(f"'{text.strip()}' is not a {self.kind} value")
        values = [float(item) for item in items]
        for index in range(len(values), self._count):
            default = self._defaults[index]
            values.append(values[0] if default is None else default)
        return tuple(values)

    def interpolate(self, a, b, fraction):
        return tuple(x + (y - x) * fraction for x, y in zip(a, b))

    def add(self, a, b):
        return tuple(x + y for x, y in zip(a, b))

    def scale(self, a, factor):
        return tuple(x * factor for x in a)

    def distance(self, a, b):
        if self.kind in ("translate", "scale"):
            return math.dist(a, b)
        return abs(b[0] - a[0])

    def zero(self):
        return tuple(1.0 if self.kind == "scale" else 0.0 for _ in range(self._count))

    def format(self, value):
        return f"{self.kind}({' '.join(f'{v:.6g}' for v in value)})"


class PointType(ValueType):
    """An (x, y) point of ``animateMotion`` values."""

    def parse(self, text):
        items = [item for item in _LIST_SPLIT.split(text.strip()) if item]
        if len(items) != 2:
            raise ValueError(f"'{text.strip()}' is not an x,y point")
        return float(items[0]), float(items[1])

    def interpolate(self, a, b, fraction):
        return a[0] + (b[0] - a[0]) * fraction, a[1] + (b[1] - a[1]) * fraction

    def add(self, a, b):
        return a[0] + b[0], a[1] + b[1]

    def scale(self, a, factor):
        return a[0] * factor, a[1] * factor

    def distance(self, a, b):
        return math.dist(a, b)

    def zero(self):
        return 0.0, 0.0


STRING = StringType()


def value_type_for(attribute: str, texts: list[str]) -> tuple[ValueType, list, bool]:
    """The value type of an attribute animated through ``texts``, the parsed values, and whether they clash.

    Colour attributes take colours, ``d`` path data, anything else lengths, then lists. Values
    that do not all parse as one type are strings (discrete); so are values that parse but
    cannot be interpolated with one another (path data with other commands, lists of other
    lengths, units that do not convert), which is what the third item says.
    """
    if attribute == "d":
        candidates = [PathType()]
    elif attribute in COLOUR_ATTRIBUTES:
        candidates = [ColourType()]
    else:
        candidates = [LengthType(), ListType()]
    clash = False
    for value_type in candidates:
        try:
            values = [value_type.parse(text) for text in texts]
        except ValueError:
            continue
        if value_type.compatible(values):
            return value_type, values, False
        clash = True
    return STRING, [STRING.parse(text) for text in texts], clash
