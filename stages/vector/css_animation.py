"""CSS animations in an SVG file (``@keyframes`` and ``animation-*``), played as a browser plays them.

:func:`parse_css_animation` cascades the file's style rules and ``style`` attributes onto
its elements (specificity, order, ``!important``; presentation attributes below every
rule) to find each element's animations, and :class:`CssAnimation` sets a copy of the
tree to a time: every animated property's value is computed as Web Animations composes
CSS animations (later animations of an element replace earlier ones; a keyframe missing
at 0 % or 100 % takes the element's own value, which may be an earlier animation's) and
written into the element's ``style`` attribute, so it wins over static rules as an
animation does (``!important`` rules still win, as in browsers). Transforms are written
as one resolved ``matrix()`` with ``transform-origin`` and ``transform-box`` folded in,
since the rasterizer reads neither CSS transform units nor origins the way browsers do;
a file whose CSS sets transforms but animates nothing is handled the same way.

The default frame range (:meth:`CssAnimation.duration`) ends with the longest
animation: delay + iterations × duration for a finite one, one full cycle
(max(delay, 0) + duration) for an infinite one; a paused animation adds nothing.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Callable
from xml.etree import ElementTree

from fluidymation.stages.vector.base import Unsupported
from fluidymation.stages.vector.css_geometry import fill_box, uncomputed
from fluidymation.stages.vector.css_selectors import DocumentIndex
from fluidymation.stages.vector.css_stylesheet import (ANIMATION_DEFAULTS, CssWide, Keyframes, Stylesheet,
                                                      parse_declarations, parse_stylesheets)
from fluidymation.stages.vector.css_syntax import InvalidCss, Length, UnsupportedCss, length, tokens
from fluidymation.stages.vector.css_timing import Timing
from fluidymation.stages.vector.css_transform import (IDENTITY, Box, Matrix, matrix_of, multiply, origin_point,
                                                      parse_origin)
from fluidymation.stages.vector.css_values import PROPERTIES, TRANSFORM_PROPERTIES, ColorKind, Context, Keyword
from fluidymation.stages.vector.safety import local_name
from fluidymation.stages.vector.svg_reader import Animation

_GEOMETRY = ("x", "y", "width", "height", "cx", "cy", "r", "rx", "ry")
_TRANSFORM_DECLARATIONS = set(TRANSFORM_PROPERTIES) | {"transform-origin", "transform-box"}
#: Words in a style sheet or ``style`` attribute that may make a file's CSS matter here.
_CSS_TRIGGER = re.compile(r"animation|transform|translate|rotate|scale", re.IGNORECASE)
_COLOR = ColorKind(paint=False)
_BLACK = (0.0, 0.0, 0.0, 1.0)
_NOT_PRESENTATION = {"translate", "rotate", "scale"}
#: Stands for the element's own value in a run's keyframes at 0 or 1 when its rule has none there.
_UNDERLYING = object()


def describe(element: ElementTree.Element, index: DocumentIndex) -> str:
    """An element as a user finds it in the file: ``<circle id="dot">``, ``<rect class="bar">`` or ``<path> #3``."""
    tag = local_name(element.tag)
    if element.get("id"):
        return f'<{tag} id="{element.get("id")}">'
    if element.get("class"):
        return f'<{tag} class="{element.get("class")}">'
    same = [other for other in index.root.iter() if other.tag == element.tag]
    return f"<{tag}> #{same.index(element) + 1}"


@dataclass(frozen=True)
class _Playing:
    """One CSS animation running on one element."""

    keyframes: Keyframes
    timing: Timing
    easing: object


def parse_css_animation(root: ElementTree.Element, source: str) -> CssAnimation | None:
    """The file's CSS animations and CSS transforms, or None when it has neither (nor any that cannot play).

    A file whose CSS only sets transforms (``transform``, ``rotate``, ``transform-origin``,
    ...) comes here too: the rasterizer misreads CSS transform units and origins, so the
    resolved matrices are written for it even when nothing moves.
    """
    texts = [element.text or "" for element in root.iter() if local_name(element.tag) == "style"]
    texts += [element.get("style", "") for element in root.iter()]
    if not (any(_CSS_TRIGGER.search(text) for text in texts)
            or any(element.get("transform-origin") is not None for element in root.iter())):
        return None
    animation = CssAnimation(root, source)
    if not animation.moves() and not animation.transforms() and not animation.unsupported:
        return None
    return animation


class CssAnimation(Animation):
    """The CSS animations of an SVG file's tree; see the module's docstring for how a time is applied."""

    language = "CSS"

    def __init__(self, root: ElementTree.Element, source: str):
        self.source = source
        self.index = DocumentIndex(root)
        found: list[Unsupported] = []
        self._report: Callable[[str, str], None] = lambda where, message: found.append(Unsupported(where, message))
        sheet = parse_stylesheets(root, self._report)
        self._declared = self._cascade(root, sheet)
        self._playing = {id(element): playing for element in root.iter()
                         if (playing := self._animations(element, sheet))}
        animated = {name for playing in self._playing.values() for run in playing for name in run.keyframes.properties}
        self._transformed = [element for element in root.iter() if self._has_css_transform(element)]
        fill_boxes = [element for element in root.iter() if self.declared_value(element, "transform-box") == "fill-box"]
        for element in fill_boxes:
            for tag in dict.fromkeys(uncomputed(element)):
                self._report(describe(element, self.index), f"transform-box: fill-box: the box of <{tag}> is not "
                             "computed; it adds nothing to the box")
        self._fill_box = bool(fill_boxes)
        self._attributes = self._presentation_attributes(root, animated)
        self._elements = [element for element in root.iter() if id(element) in self._playing]
        self._viewports: dict[int, tuple[float, float]] = {}
        self._colors: dict[int, tuple] = {}
        self._initial: dict[tuple[int, str], object] = {}
        #: Resolved keyframes that do not change with time, by (element, property, run): see ``_Frame._points``.
        self.points: dict[tuple[int, str, int], list[tuple]] = {}
        self.unsupported = tuple(dict.fromkeys(found))

    # The cascade: what each element declares, before any animation.

    def _cascade(self, root, sheet: Stylesheet) -> dict[int, dict[str, object]]:
        """The winning declared value of each property read here, per element: rules by importance, origin
        (``style`` attribute over rules), specificity and order."""
        declared = {}
        for element in root.iter():
            candidates = []
            for rule in sheet.rules:
                specificity = max((selector.specificity for selector in rule.selectors
                                   if selector.matches(element, self.index)), default=None)
                if specificity is not None:
                    candidates += [((item.important, 1, specificity, rule.order, position), item)
                                   for position, item in enumerate(rule.declarations)]
            if element.get("style"):
                def report(_, message, element=element):
                    self._report(f"{describe(element, self.index)} style", message)

                candidates += [((item.important, 2, (0, 0, 0), 0, position), item)
                               for position, item in enumerate(parse_declarations(element.get("style"), "", report))]
            winners = {item.name: item.value for _, item in sorted(candidates, key=lambda candidate: candidate[0])}
            if winners:
                declared[id(element)] = winners
        return declared

    def declared_value(self, element, name: str):
        """The cascaded value of a property on ``element`` (``inherit`` followed up for animation properties)."""
        value = self._declared.get(id(element), {}).get(name)
        if isinstance(value, CssWide) and name in ANIMATION_DEFAULTS:
            parent = self.index.parent(element)
            if value.keyword == "inherit" and parent is not None:
                return self.declared_value(parent, name)
            return None
        return value

    def _animations(self, element, sheet: Stylesheet) -> list[_Playing]:
        """The element's animations, one per ``animation-name`` item, the other lists repeated to its length."""
        lists = {name: self.declared_value(element, name) or default for name, default in ANIMATION_DEFAULTS.items()}
        names = lists["animation-name"]
        playing = []
        for number, name in enumerate(names):
            if name == "none":
                continue
            if name not in sheet.keyframes:
                self._report(describe(element, self.index), f"animation-name '{name}' names no @keyframes rule; "
                             "nothing plays (as in browsers)")
                continue
            item = {longhand: values[number % len(values)] for longhand, values in lists.items()}
            timing = Timing(item["animation-duration"], item["animation-delay"], item["animation-iteration-count"],
                            item["animation-direction"], item["animation-fill-mode"],
                            item["animation-play-state"] == "paused")
            playing.append(_Playing(sheet.keyframes[name], timing, item["animation-timing-function"]))
        return playing

    def _has_css_transform(self, element) -> bool:
        """Whether CSS sets or animates the element's transform, origin or box (its matrix is then written)."""
        declared = self._declared.get(id(element), {})
        animated = {name for run in self.playing(element) for name in run.keyframes.properties}
        return (bool(_TRANSFORM_DECLARATIONS & (declared.keys() | animated))
                or element.get("transform-origin") is not None)

    def _presentation_attributes(self, root, animated: set[str]) -> dict[tuple[int, str], object]:
        """Parsed presentation attributes of the properties this file's animations read."""
        wanted = (animated - _NOT_PRESENTATION) | {"color"}
        if self._transformed:
            wanted |= {"transform", "transform-origin"}
        if self._fill_box:
            wanted |= set(_GEOMETRY)
        parsed = {}
        for element in root.iter():
            for name in wanted:
                text = element.get(name)
                if text is None:
                    continue
                try:
                    parsed[(id(element), name)] = _parse_attribute(name, text)
                except (InvalidCss, UnsupportedCss) as exc:
                    self._report(describe(element, self.index), f"{name}=\"{text}\": {exc}; ignored")
        return parsed

    def specified(self, element, name: str):
        """The element's own value of a property: declared by CSS, else its presentation attribute, else None."""
        declared = self._declared.get(id(element), {}).get(name)
        return declared if declared is not None else self._attributes.get((id(element), name))

    def playing(self, element) -> list[_Playing]:
        return self._playing.get(id(element), [])

    def initial(self, element, name: str):
        """A property's initial value, resolved for the element."""
        key = (id(element), name)
        if key not in self._initial:
            kind = PROPERTIES[name].kind
            self._initial[key] = kind.resolve(kind.parse(tokens(PROPERTIES[name].initial)),
                                              Context(self.viewport(element), self.color(element), lambda: None))
        return self._initial[key]

    def viewport(self, element) -> tuple[float, float]:
        """The size of the element's nearest SVG viewport: its viewBox, else its width and height."""
        if id(element) not in self._viewports:
            viewport = self.index.parent(element) or element
            while local_name(viewport.tag) != "svg" and self.index.parent(viewport) is not None:
                viewport = self.index.parent(viewport)
            self._viewports[id(element)] = self._viewport_size(viewport)
        return self._viewports[id(element)]

    def _viewport_size(self, svg) -> tuple[float, float]:
        box = (svg.get("viewBox") or "").replace(",", " ").split()
        try:
            return float(box[2]), float(box[3])
        except (IndexError, ValueError):
            pass
        sizes = []
        for side in ("width", "height"):
            try:
                sizes.append(length(tokens(svg.get(side, ""))[0], unitless=True))
            except (IndexError, InvalidCss, UnsupportedCss):
                sizes.append(Length(100.0, True))
        parent = self.index.parent(svg)
        outer = self.viewport(parent) if parent is not None else (0.0, 0.0)
        return sizes[0].px(outer[0]), sizes[1].px(outer[1])

    def color(self, element) -> tuple:
        """The element's ``color`` (for ``currentColor``): not animated here, inherited, black at the root."""
        if id(element) not in self._colors:
            specified = self.specified(element, "color")
            parent = self.index.parent(element)
            if isinstance(specified, tuple):
                self._colors[id(element)] = specified
            else:
                self._colors[id(element)] = self.color(parent) if parent is not None else _BLACK
        return self._colors[id(element)]

    # Playing it.

    def apply(self, at, time_seconds):
        frame = _Frame(self, time_seconds)
        for element in self._elements:
            declarations = [f"{name}:{PROPERTIES[name].kind.serialize(frame.value(element, name))}"
                            for name in frame.animated_names(element) if name not in TRANSFORM_PROPERTIES]
            _add_style(at(element), declarations)
        for element in self._transformed:
            a, b, c, d, e, f = frame.matrix(element)
            _add_style(at(element), [f"transform:matrix({a!r} {b!r} {c!r} {d!r} {e!r} {f!r})", "transform-origin:0 0"])

    def duration(self):
        return max((run.timing.end() for playing in self._playing.values() for run in playing), default=0.0)

    def moves(self) -> bool:
        """Whether any CSS animation plays on an element."""
        return bool(self._playing)

    def transforms(self) -> bool:
        """Whether CSS sets or animates any element's transform (its matrix is then written)."""
        return bool(self._transformed)


def _parse_attribute(name: str, text: str):
    if name == "transform-origin":
        return parse_origin(tokens(text), unitless=True)
    if name == "color":
        return _COLOR.parse(tokens(text))
    return PROPERTIES[name].kind.parse_attribute(text)


def _add_style(element: ElementTree.Element, declarations: list[str]) -> None:
    """Append declarations to the element's ``style`` (later declarations win over its own)."""
    if not declarations:
        return
    existing = (element.get("style") or "").strip().rstrip(";")
    element.set("style", ";".join(([existing] if existing else []) + declarations))


class _Frame:
    """The file's computed values at one time, each computed once."""

    def __init__(self, animation: CssAnimation, time_seconds: float):
        self.animation, self.time = animation, time_seconds
        self._values: dict[tuple[int, str], object] = {}
        self._progress: dict[int, float | None] = {}
        self._contexts: dict[int, Context] = {}
        self._boxes: dict[int, Box] = {}
        self._matrices: dict[int, Matrix] = {}

    def progress(self, run: _Playing) -> float | None:
        if id(run) not in self._progress:
            self._progress[id(run)] = run.timing.progress(self.time)
        return self._progress[id(run)]

    def animated_names(self, element) -> list[str]:
        """Properties some animation of the element sets at this time."""
        names: dict[str, None] = {}
        for run in self.animation.playing(element):
            if self.progress(run) is not None:
                names.update(dict.fromkeys(run.keyframes.properties))
        return list(names)

    def value(self, element, name: str):
        """The computed value of a property (resolved: px, sRGB, transform functions) at this time."""
        key = (id(element), name)
        if key not in self._values:
            result = self._base(element, name)
            for run in self.animation.playing(element):
                if name in run.keyframes.properties and self.progress(run) is not None:
                    result = self._sample(element, name, run, result)
            self._values[key] = result
        return self._values[key]

    def _base(self, element, name: str):
        """The value without animations of this element: its own, or inherited, or the initial value."""
        specified = self.animation.specified(element, name)
        if specified is None or isinstance(specified, CssWide):
            return self._wide(element, name, specified.keyword if specified else "unset")
        return PROPERTIES[name].kind.resolve(specified, self.context(element))

    def _wide(self, element, name: str, keyword: str):
        """``inherit``, ``initial`` or ``unset`` (what an unset property computes to)."""
        parent = self.animation.index.parent(element)
        inherits = keyword == "inherit" or (keyword != "initial" and PROPERTIES[name].inherited)
        if inherits and parent is not None:
            return self.value(parent, name)
        return self.animation.initial(element, name)

    def _sample(self, element, name: str, run: _Playing, underlying):
        """The keyframes' value at the run's progress (Web Animations 1, "the effect value of a keyframe effect")."""
        progress = self.progress(run)
        points = [(offset, underlying if value is _UNDERLYING else value, easing)
                  for offset, value, easing in self._points(element, name, run)]
        if progress >= 1 and sum(point[0] == 1 for point in points) > 1:
            return points[-1][1]
        start = max((i for i, point in enumerate(points) if point[0] <= progress and point[0] < 1),
                    default=max(i for i, point in enumerate(points) if point[0] == 0))
        (start_offset, start_value, start_easing), (end_offset, end_value, _) = points[start], points[start + 1]
        distance = (progress - start_offset) / (end_offset - start_offset)
        return PROPERTIES[name].kind.interpolate(start_value, end_value, start_easing(distance))

    def _points(self, element, name: str, run: _Playing) -> list[tuple]:
        """The run's keyframes of a property as (offset, resolved value, easing), with the element's own value
        (:data:`_UNDERLYING`) at 0 and 1 when the rule has no keyframe there. Kept across frames unless a value
        depends on the time (``inherit`` from an animated parent, a transform relative to an animated box)."""
        key = (id(element), name, id(run))
        cached = self.animation.points.get(key)
        if cached is not None:
            return cached
        frames = run.keyframes.properties[name]
        points = [(frame.offset, self._keyframe_value(element, name, frame.value), frame.easing or run.easing)
                  for frame in frames]
        if points[0][0] != 0:
            points.insert(0, (0.0, _UNDERLYING, run.easing))
        if points[-1][0] != 1:
            points.append((1.0, _UNDERLYING, run.easing))
        if name not in TRANSFORM_PROPERTIES and not any(isinstance(frame.value, CssWide) for frame in frames):
            self.animation.points[key] = points
        return points

    def _keyframe_value(self, element, name: str, value):
        if isinstance(value, CssWide):
            return self._wide(element, name, value.keyword)
        return PROPERTIES[name].kind.resolve(value, self.context(element))

    def context(self, element) -> Context:
        if id(element) not in self._contexts:
            self._contexts[id(element)] = Context(self.animation.viewport(element), self.animation.color(element),
                                                  lambda: self._reference_box(element))
        return self._contexts[id(element)]

    def _reference_box(self, element) -> Box:
        """The ``transform-box``: the viewport (view-box, the default) or the element's fill box."""
        if id(element) not in self._boxes:
            if self.animation.declared_value(element, "transform-box") == "fill-box":
                self._boxes[id(element)] = fill_box(element, self._geometry, self.matrix)
            else:
                self._boxes[id(element)] = Box(0.0, 0.0, *self.animation.viewport(element))
        return self._boxes[id(element)]

    def _geometry(self, element, name: str) -> float:
        """A geometry property in px for the fill box (``auto`` radii take the other radius, else 0)."""
        value = self.value(element, name)
        if isinstance(value, Keyword):
            other = {"rx": "ry", "ry": "rx"}.get(name)
            value = self.value(element, other) if other else 0.0
            return 0.0 if isinstance(value, Keyword) else value
        return value

    def matrix(self, element) -> Matrix:
        """The element's whole transform at this time: translate, rotate, scale and transform about the origin."""
        if id(element) not in self._matrices:
            functions = tuple(function for name in TRANSFORM_PROPERTIES for function in self.value(element, name))
            origin = self.animation.specified(element, "transform-origin")
            if not isinstance(origin, tuple):
                origin = (Length(0.0), Length(0.0))
            x, y = origin_point(origin, self._reference_box(element))
            about = multiply((1.0, 0.0, 0.0, 1.0, x, y), matrix_of(functions))
            self._matrices[id(element)] = multiply(about, (1.0, 0.0, 0.0, 1.0, -x, -y)) if functions else IDENTITY
        return self._matrices[id(element)]
