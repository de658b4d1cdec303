"""An SVG file's ``<style>`` sheets and ``style`` attributes, parsed with tinycss2 into what CSS animations need.

:func:`parse_stylesheets` gives the style rules (selectors and declarations, in order)
and the ``@keyframes`` by name; :func:`parse_declarations` parses a rule's or a
``style`` attribute's declarations. Only declarations that animations read or animate
are kept, parsed: the ``animation`` shorthand and its longhands, the properties of
:data:`~fluidymation.stages.vector.css_values.PROPERTIES`, ``transform-origin``,
``transform-box`` and ``color``. Everything else in a sheet is left to the rasterizer.
What cannot be followed is passed to ``report(where, message)``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable
from xml.etree import ElementTree

import tinycss2

from fluidymation.stages.vector.css_selectors import Selector, parse_selector_list
from fluidymation.stages.vector.css_syntax import (InvalidCss, UnsupportedCss, check_computable, ident, number,
                                                  significant, split_commas, text_of, time)
from fluidymation.stages.vector.css_timing import EASE, EASING_KEYWORDS, parse_easing
from fluidymation.stages.vector.css_transform import parse_origin
from fluidymation.stages.vector.css_values import PROPERTIES, ColorKind
from fluidymation.stages.vector.safety import local_name

Report = Callable[[str, str], None]
CSS_WIDE = frozenset({"inherit", "initial", "unset", "revert", "revert-layer"})
_DIRECTIONS = ("normal", "reverse", "alternate", "alternate-reverse")
_FILL_MODES = ("none", "forwards", "backwards", "both")
_PLAY_STATES = ("running", "paused")
#: The longhands of the ``animation`` shorthand and their initial values.
ANIMATION_DEFAULTS = {"animation-name": ("none",), "animation-duration": (0.0,), "animation-timing-function": (EASE,),
                      "animation-delay": (0.0,), "animation-iteration-count": (1.0,),
                      "animation-direction": ("normal",), "animation-fill-mode": ("none",),
                      "animation-play-state": ("running",)}
#: Longhands whose only supported value is their initial one (CSS Animations 2, Scroll-driven Animations).
_ONLY_INITIAL = {"animation-composition": "replace", "animation-timeline": "auto", "animation-range": "normal",
                 "animation-range-start": "normal", "animation-range-end": "normal"}
_COLOR = ColorKind(paint=False)
_TRANSFORM_BOXES = {"view-box": "view-box", "fill-box": "fill-box", "content-box": "fill-box"}


@dataclass(frozen=True)
class CssWide:
    """A CSS-wide keyword as a declaration's value (``inherit``, ``initial``, ``unset``...)."""

    keyword: str


@dataclass(frozen=True)
class Declaration:
    name: str
    value: object
    important: bool


@dataclass
class Rule:
    """A style rule: its selectors and its declarations, in sheet order."""

    selectors: list[Selector]
    declarations: list[Declaration]
    order: int


@dataclass(frozen=True)
class Keyframe:
    """One property's value at an offset of a ``@keyframes`` rule, and the easing of the interval it starts
    (None: the animation's ``animation-timing-function``)."""

    offset: float
    value: object
    easing: object


@dataclass
class Keyframes:
    """A ``@keyframes`` rule: each property's keyframes, in offset order (declaration order within an offset)."""

    name: str
    properties: dict[str, list[Keyframe]] = field(default_factory=dict)

    def add(self, name: str, keyframe: Keyframe) -> None:
        """Add a keyframe; one at the same offset with the same easing is replaced (browsers merge them)."""
        frames = self.properties.setdefault(name, [])
        for index, frame in enumerate(frames):
            if frame.offset == keyframe.offset and repr(frame.easing) == repr(keyframe.easing):
                frames[index] = keyframe
                return
        frames.append(keyframe)
        frames.sort(key=lambda frame: frame.offset)


@dataclass
class Stylesheet:
    rules: list[Rule] = field(default_factory=list)
    keyframes: dict[str, Keyframes] = field(default_factory=dict)


def parse_stylesheets(root: ElementTree.Element, report: Report) -> Stylesheet:
    """Every CSS ``<style>`` element of the tree, in document order."""
    sheet = Stylesheet()
    for element in root.iter():
        if local_name(element.tag) != "style" or element.get("type", "text/css").strip().lower() != "text/css":
            continue
        media = (element.get("media") or "all").strip().lower()
        if media not in ("all", "screen", ""):
            report("<style>", f"media=\"{media}\" is not evaluated; its rules are applied")
        for rule in tinycss2.parse_stylesheet(element.text or "", skip_comments=True, skip_whitespace=True):
            _add_rule(sheet, rule, report)
    return sheet


def _add_media(sheet: Stylesheet, rule, report: Report) -> None:
    """A ``@media`` block: its rules join the sheet when the query holds; the rasterizer applies none of them, so
    what they set besides animations is reported."""
    where = f"<style> @media {text_of(rule.prelude)}"
    matches = media_matches(rule.prelude)
    if matches is None:
        report(where, "this media query is not evaluated; its rules are not applied")
    if not matches:
        return
    for inner in tinycss2.parse_rule_list(rule.content, skip_comments=True, skip_whitespace=True):
        _add_rule(sheet, inner, report)
        if inner.type == "qualified-rule":
            names = {item.lower_name for item in tinycss2.parse_blocks_contents(inner.content, skip_comments=True,
                                                                                skip_whitespace=True)
                     if item.type == "declaration" and not _played_from_media(item.lower_name)}
            if names:
                report(f"{where} {text_of(inner.prelude)}", f"{', '.join(sorted(names))}: the rasterizer does "
                       "not apply @media rules, so only their animations are played")


def _add_rule(sheet: Stylesheet, rule, report: Report) -> None:
    if rule.type == "error":
        report("<style>", f"CSS syntax error at line {rule.source_line}: {rule.message}; skipped")
    elif rule.type == "at-rule":
        keyword = rule.lower_at_keyword
        if keyword in ("keyframes", "-webkit-keyframes"):
            keyframes = _keyframes(rule, report)
            if keyframes is not None:
                sheet.keyframes[keyframes.name] = keyframes
        elif keyword == "media" and rule.content is not None:
            _add_media(sheet, rule, report)
        elif keyword != "charset":
            report(f"<style> @{keyword}", "this at-rule is not applied")
    else:
        where = f"<style> {text_of(rule.prelude)}"
        try:
            selectors = parse_selector_list(rule.prelude)
        except (InvalidCss, UnsupportedCss) as exc:
            report(where, f"{exc}; the rule is skipped")
            return
        declarations = parse_declarations(rule.content, where, report)
        if declarations:
            sheet.rules.append(Rule(selectors, declarations, len(sheet.rules)))


#: Media features as a browser with default settings on a screen answers them.
_MEDIA_FEATURES = {"prefers-reduced-motion": "no-preference", "prefers-color-scheme": "light",
                   "prefers-contrast": "no-preference", "forced-colors": "none", "prefers-reduced-transparency":
                   "no-preference", "prefers-reduced-data": "no-preference", "inverted-colors": "none",
                   "scripting": "enabled"}


def media_matches(prelude) -> bool | None:
    """Whether a ``@media`` query list holds on a screen with default preferences, or None when not evaluated
    (sizes, ``not``, ``or``, other features)."""
    try:
        answers = [_query_matches(query) for query in split_commas(prelude)]
    except InvalidCss:
        return None
    if True in answers:
        return True
    return False if all(answer is False for answer in answers) else None


def _query_matches(query: list) -> bool | None:
    """A query of media types and ``(feature: value)`` tests joined by ``and`` (``not`` and ``or``: None)."""
    if any(ident(value) in ("not", "or") for value in query):
        return None
    answers = []
    for value in query:
        word = ident(value)
        if word in ("and", "only"):
            continue
        if word is not None:
            answers.append({"screen": True, "all": True, "print": False, "speech": False}.get(word))
        elif value.type == "() block":
            feature = [ident(part) for part in significant(value.content) if part.type == "ident"]
            known = _MEDIA_FEATURES.get(feature[0]) if len(feature) == 2 else None
            answers.append(None if known is None else feature[1] == known)
        else:
            answers.append(None)
    if False in answers:
        return False
    return True if all(answers) else None


def parse_declarations(content, where: str, report: Report) -> list[Declaration]:
    """The declarations animations use from a rule's content or a ``style`` attribute's text."""
    declarations = []
    for item in tinycss2.parse_blocks_contents(content, skip_comments=True, skip_whitespace=True):
        if item.type == "error":
            report(where, f"CSS syntax error: {item.message}; skipped")
        elif item.type != "declaration":
            report(where, "nested rules are not applied")
        else:
            declarations += _declaration(item, where, report)
    return declarations


def _declaration(item, where: str, report: Report) -> list[Declaration]:
    name, values = item.lower_name, significant(item.value)
    if not _read(name):
        return []
    try:
        check_computable(values)
        if len(values) == 1 and ident(values[0]) in CSS_WIDE:
            wide = CssWide(ident(values[0]))
            names = ANIMATION_DEFAULTS if name == "animation" else (name,)
            return [Declaration(longhand, wide, item.important) for longhand in names]
        if name == "animation":
            return [Declaration(longhand, value, item.important) for longhand, value in parse_shorthand(values).items()]
        return [Declaration(name, parse_value(name, values), item.important)]
    except InvalidCss as exc:
        report(where, f"'{name}: {text_of(item.value)}' is not valid CSS ({exc}); ignored, as browsers ignore it")
    except UnsupportedCss as exc:
        report(where, f"'{name}: {text_of(item.value)}': {exc}; ignored")
    return []


def _played_from_media(name: str) -> bool:
    """Properties this reader writes itself (animations and transforms), so a ``@media`` rule's value still counts."""
    return (name == "animation" or name in ANIMATION_DEFAULTS or name in _ONLY_INITIAL
            or name in ("transform", "translate", "rotate", "scale", "transform-origin", "transform-box"))


def _read(name: str) -> bool:
    return (name == "animation" or name in ANIMATION_DEFAULTS or name in _ONLY_INITIAL or name in PROPERTIES
            or name in ("transform-origin", "transform-box", "color"))


def parse_value(name: str, values):
    """The parsed value of a longhand this module reads."""
    if name in ANIMATION_DEFAULTS:
        return tuple(_animation_item(name, group) for group in split_commas(values))
    if name in _ONLY_INITIAL:
        if text_of(values).lower() != _ONLY_INITIAL[name]:
            raise UnsupportedCss(f"only '{_ONLY_INITIAL[name]}' is played")
        return _ONLY_INITIAL[name]
    if name == "transform-origin":
        return parse_origin(values)
    if name == "transform-box":
        keyword = ident(values[0]) if len(values) == 1 else None
        if keyword in ("stroke-box", "border-box"):
            raise UnsupportedCss("the stroke-box reference box is not computed")
        if keyword not in _TRANSFORM_BOXES:
            raise InvalidCss("not a transform-box")
        return _TRANSFORM_BOXES[keyword]
    if name == "color":
        return _COLOR.parse(values)
    return PROPERTIES[name].kind.parse(values)


def _animation_item(name: str, group: list):
    """One item of an ``animation-*`` longhand's comma-separated list."""
    if len(group) != 1:
        raise InvalidCss(f"'{text_of(group)}' is not one value")
    value = group[0]
    keyword = ident(value)
    if name == "animation-name":
        if value.type == "string":
            return value.value
        if keyword is None or keyword in CSS_WIDE or keyword == "default":
            raise InvalidCss(f"'{text_of(group)}' is not a keyframes name")
        return "none" if keyword == "none" else value.value
    if name == "animation-duration":
        if keyword == "auto":
            return 0.0
        seconds = time(value)
        if seconds < 0:
            raise InvalidCss("a negative duration")
        return seconds
    if name == "animation-delay":
        return time(value)
    if name == "animation-timing-function":
        return parse_easing(value)
    if name == "animation-iteration-count":
        if keyword == "infinite":
            return float("inf")
        count = number(value)
        if count < 0:
            raise InvalidCss("a negative iteration count")
        return count
    allowed = {"animation-direction": _DIRECTIONS, "animation-fill-mode": _FILL_MODES,
               "animation-play-state": _PLAY_STATES}[name]
    if keyword not in allowed:
        raise InvalidCss(f"'{text_of(group)}' is not one of {', '.join(allowed)}")
    return keyword


def parse_shorthand(values) -> dict[str, tuple]:
    """The ``animation`` shorthand: every longhand's list (CSS Animations 1, with Level 2's reset of the timeline)."""
    items = [_shorthand_item(group) for group in split_commas(values)]
    return {longhand: tuple(item[longhand] for item in items) for longhand in ANIMATION_DEFAULTS}


def _shorthand_item(group: list) -> dict:
    """One animation of the shorthand: a keyword goes to the first longhand it fits that is still unset, so
    ``animation: ease ease`` names keyframes "ease"; the first time is the duration, the second the delay."""
    found: dict = {}
    for value in group:
        keyword = ident(value)
        if value.type == "dimension" and value.lower_unit in ("s", "ms"):
            longhand = "animation-delay" if "animation-duration" in found else "animation-duration"
            target = longhand if longhand not in found else None
        elif value.type == "function" or (keyword in EASING_KEYWORDS and "animation-timing-function" not in found):
            target = "animation-timing-function"
        elif (value.type == "number" or keyword == "infinite") and "animation-iteration-count" not in found:
            target = "animation-iteration-count"
        elif keyword in _DIRECTIONS and "animation-direction" not in found:
            target = "animation-direction"
        elif keyword in _FILL_MODES and "animation-fill-mode" not in found:
            target = "animation-fill-mode"
        elif keyword in _PLAY_STATES and "animation-play-state" not in found:
            target = "animation-play-state"
        else:
            target = "animation-name"
        if target is None or target in found:
            raise InvalidCss(f"'{text_of(group)}' sets a value twice")
        found[target] = _animation_item(target, [value])
    return {longhand: found.get(longhand, default[0]) for longhand, default in ANIMATION_DEFAULTS.items()}


def _keyframes(rule, report: Report) -> Keyframes | None:
    prelude = significant(rule.prelude)
    if len(prelude) != 1 or prelude[0].type not in ("ident", "string") or rule.content is None:
        report(f"<style> @keyframes {text_of(rule.prelude)}", "not a valid @keyframes rule; skipped")
        return None
    keyframes = Keyframes(prelude[0].value)
    where = f"<style> @keyframes {keyframes.name}"
    for block in tinycss2.parse_blocks_contents(rule.content, skip_comments=True, skip_whitespace=True):
        if block.type != "qualified-rule":
            report(where, "a declaration or at-rule outside a keyframe; skipped")
            continue
        try:
            offsets = [_offset(group) for group in split_commas(block.prelude)]
        except InvalidCss as exc:
            report(where, f"the keyframe '{text_of(block.prelude)}': {exc}; skipped, as browsers skip it")
            continue
        _add_keyframe(keyframes, offsets, block.content, f"{where} {text_of(block.prelude)}", report)
    return keyframes


def _offset(group: list) -> float:
    if len(group) == 1:
        keyword = ident(group[0])
        if keyword in ("from", "to"):
            return 0.0 if keyword == "from" else 1.0
        if group[0].type == "percentage" and 0 <= group[0].value <= 100:
            return group[0].value / 100
    raise InvalidCss(f"'{text_of(group)}' is not a keyframe selector (from, to or 0% to 100%)")


def _add_keyframe(keyframes: Keyframes, offsets: list[float], content, where: str, report: Report) -> None:
    easing = None
    values = []
    for item in tinycss2.parse_blocks_contents(content, skip_comments=True, skip_whitespace=True):
        if item.type != "declaration":
            report(where, "not a declaration; skipped")
            continue
        if item.important:
            continue  # !important is ignored inside @keyframes (CSS Animations 1)
        name, tokens = item.lower_name, significant(item.value)
        try:
            check_computable(tokens)
            if name == "animation-timing-function":
                easing = _animation_item(name, tokens)
            elif name == "animation-composition":
                parse_value(name, tokens)
            elif name in PROPERTIES:
                keyword = ident(tokens[0]) if len(tokens) == 1 else None
                values.append((name, CssWide(keyword) if keyword in CSS_WIDE else parse_value(name, tokens)))
            elif not name.startswith("--"):
                report(f"<style> @keyframes {keyframes.name}", f"property '{name}' is not animated; drawn without it")
        except InvalidCss as exc:
            report(where, f"'{name}: {text_of(item.value)}' is not valid CSS ({exc}); ignored, as browsers ignore it")
        except UnsupportedCss as exc:
            report(where, f"'{name}: {text_of(item.value)}': {exc}; not animated")
    for offset in offsets:
        for name, value in values:
            keyframes.add(name, Keyframe(offset, value, easing))
