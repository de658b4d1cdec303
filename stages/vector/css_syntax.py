"""CSS value syntax shared by the CSS-animation modules: tinycss2 tokens to numbers, lengths, angles and times.

Only what the animation modules read is parsed here; a value outside it raises
:class:`InvalidCss` (browsers drop such a declaration too) or :class:`UnsupportedCss`
(valid CSS this reader does not evaluate, such as ``em`` lengths or ``calc()``).
"""

from __future__ import annotations

from typing import NamedTuple

import tinycss2

#: Absolute length units in px (CSS Values 4).
_LENGTH_UNITS = {"px": 1.0, "in": 96.0, "cm": 96 / 2.54, "mm": 96 / 25.4, "q": 96 / 101.6, "pt": 96 / 72, "pc": 16.0}
_ANGLE_UNITS = {"deg": 1.0, "grad": 0.9, "rad": 180 / 3.141592653589793, "turn": 360.0}
_TIME_UNITS = {"s": 1.0, "ms": 0.001}


class InvalidCss(ValueError):
    """A value that is not valid CSS for its property: browsers ignore the declaration, and so does this reader."""


class UnsupportedCss(ValueError):
    """Valid CSS that this reader does not evaluate."""


class Length(NamedTuple):
    """A length in px, or a percentage of a reference length."""

    value: float
    percent: bool = False

    def px(self, reference: float) -> float:
        return self.value * reference / 100 if self.percent else self.value


def tokens(text: str) -> list:
    """The significant component values of ``text`` (no whitespace or comments)."""
    return significant(tinycss2.parse_component_value_list(text, skip_comments=True))


def significant(values) -> list:
    """``values`` without whitespace and comments."""
    return [value for value in values if value.type not in ("whitespace", "comment")]


def split_commas(values) -> list[list]:
    """Comma-separated groups of significant values; an empty group is invalid."""
    groups: list[list] = [[]]
    for value in values:
        if value.type == "literal" and value.value == ",":
            groups.append([])
        elif value.type not in ("whitespace", "comment"):
            groups[-1].append(value)
    if any(not group for group in groups):
        raise InvalidCss("an empty item in a comma-separated list")
    return groups


def text_of(values) -> str:
    """``values`` serialized back to CSS text, for messages (a space where tinycss2 keeps tokens apart by a comment)."""
    return tinycss2.serialize(values).replace("/**/", " ").strip()


def check_computable(values) -> None:
    """Refuse values whose meaning this reader does not compute: ``var()``, ``calc()``, ``attr()`` and kin."""
    for value in values:
        if value.type == "function":
            if value.lower_name in ("var", "env", "attr", "calc", "min", "max", "clamp"):
                raise UnsupportedCss(f"{value.lower_name}() is not evaluated")
            check_computable(value.arguments)
        elif value.type in ("() block", "[] block", "{} block"):
            check_computable(value.content)


def number(value) -> float:
    if value.type != "number":
        raise InvalidCss(f"'{text_of([value])}' is not a number")
    return float(value.value)


def length(value, *, unitless: bool) -> Length:
    """A length or percentage; a bare number is px when ``unitless`` (SVG geometry and stroke properties) or is 0."""
    if value.type == "percentage":
        return Length(float(value.value), True)
    if value.type == "number" and (unitless or value.value == 0):
        return Length(float(value.value))
    if value.type == "dimension":
        unit = value.lower_unit
        if unit in _LENGTH_UNITS:
            return Length(float(value.value) * _LENGTH_UNITS[unit])
        if unit in ("em", "rem", "ex", "rex", "ch", "rch", "cap", "ic", "lh", "rlh", "vw", "vh", "vmin", "vmax",
                    "vi", "vb", "svw", "svh", "lvw", "lvh", "dvw", "dvh", "cqw", "cqh", "cqi", "cqb"):
            raise UnsupportedCss(f"the relative length unit '{unit}' is not evaluated")
    raise InvalidCss(f"'{text_of([value])}' is not a length")


def angle(value) -> float:
    """An angle in degrees (a bare 0 is allowed, as in transform functions)."""
    if value.type == "number" and value.value == 0:
        return 0.0
    if value.type == "dimension" and value.lower_unit in _ANGLE_UNITS:
        return float(value.value) * _ANGLE_UNITS[value.lower_unit]
    raise InvalidCss(f"'{text_of([value])}' is not an angle")


def time(value) -> float:
    """A time in seconds."""
    if value.type == "dimension" and value.lower_unit in _TIME_UNITS:
        return float(value.value) * _TIME_UNITS[value.lower_unit]
    raise InvalidCss(f"'{text_of([value])}' is not a time")


def ident(value) -> str | None:
    """The lower-case keyword of an ident token, else None."""
    return value.lower_value if value.type == "ident" else None
