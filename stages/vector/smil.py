"""SMIL animation of an SVG document (SVG 1.1): the parser of :data:`svg_reader.ANIMATIONS`.

:func:`parse_smil` reads every ``animate``, ``set``, ``animateColor``, ``animateTransform``
and ``animateMotion`` of a file once: its target, its timing (:mod:`smil_timing`) and its
simple animation function (values, keyTimes, keySplines, calcMode; :mod:`smil_values`,
:mod:`smil_path`). :class:`SmilAnimation` sets a copy of the tree to a time: for each
animated attribute of each element it stacks the animations active or frozen at that
time in the sandwich order of SMIL (begin time, then syncbase dependency, then document
order), each replacing or adding to what lies below, starting from the attribute's own
value. CSS properties are written to the element's ``style`` (animated values override
style sheets); ``animateMotion`` adds its translation and rotation before the element's
``transform``. What cannot be played as the file means it is reported as
:class:`Unsupported`, naming the element.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass
from typing import Callable
from xml.etree import ElementTree

from fluidymation.errors import InputError
from fluidymation.stages.vector.base import Unsupported
from fluidymation.stages.vector.safety import XLINK_HREF, is_internal_reference, local_name
from fluidymation.stages.vector.smil_path import MotionPath, PathData
from fluidymation.stages.vector.smil_timing import (INDEFINITE, Condition, Interval, Timeline, TimelineError, Timing,
                                                    clock_value, parse_conditions)
from fluidymation.stages.vector.smil_values import (TRANSFORM_PARAMETERS, PointType, TransformType, ValueType,
                                                    value_type_for)
from fluidymation.stages.vector.svg_reader import Animation, set_style_property, style_property

ANIMATION_TAGS = ("animate", "set", "animateColor", "animateTransform", "animateMotion")
#: The timeline is resolved up to horizons of this many seconds times a power of two.
_HORIZON_BLOCK = 16.0
_MAX_HORIZON_DOUBLINGS = 12
_EPSILON = 1e-9

#: SVG 1.1 properties (presentation attributes); animating one sets it in the element's style.
PROPERTIES = frozenset("""alignment-baseline baseline-shift clip clip-path clip-rule color color-interpolation
color-interpolation-filters color-profile color-rendering cursor direction display dominant-baseline
enable-background fill fill-opacity fill-rule filter flood-color flood-opacity font font-family font-size
font-size-adjust font-stretch font-style font-variant font-weight glyph-orientation-horizontal
glyph-orientation-vertical image-rendering kerning letter-spacing lighting-color marker marker-end marker-mid
marker-start mask opacity overflow pointer-events shape-rendering stop-color stop-opacity stroke stroke-dasharray
stroke-dashoffset stroke-linecap stroke-linejoin stroke-miterlimit stroke-opacity stroke-width text-anchor
text-decoration text-rendering unicode-bidi visibility word-spacing writing-mode""".split())
#: Properties an element takes from its parent when it does not set them.
_INHERITED = frozenset("""clip-rule color color-interpolation color-interpolation-filters color-rendering cursor
direction fill fill-opacity fill-rule font font-family font-size font-size-adjust font-stretch font-style
font-variant font-weight glyph-orientation-horizontal glyph-orientation-vertical image-rendering kerning
letter-spacing marker marker-end marker-mid marker-start pointer-events shape-rendering stroke stroke-dasharray
stroke-dashoffset stroke-linecap stroke-linejoin stroke-miterlimit stroke-opacity stroke-width text-anchor
text-rendering visibility word-spacing writing-mode""".split())
_INITIAL = {"fill": "black", "stroke": "none", "stroke-width": "1", "stroke-dashoffset": "0",
            "stroke-dasharray": "none", "stroke-miterlimit": "4", "opacity": "1", "fill-opacity": "1",
            "stroke-opacity": "1", "stop-opacity": "1", "flood-opacity": "1", "stop-color": "black",
            "flood-color": "black", "lighting-color": "white", "color": "black", "visibility": "visible",
            "display": "inline", "font-size": "16px", "letter-spacing": "0", "word-spacing": "0"}
#: Other attributes SVG 1.1 animates (besides transforms, which take animateTransform).
ATTRIBUTES = frozenset("""x y width height cx cy r rx ry x1 y1 x2 y2 fx fy fr d points offset viewBox
preserveAspectRatio href xlink:href pathLength startOffset dx dy rotate textLength lengthAdjust method spacing
gradientUnits spreadMethod patternUnits patternContentUnits clipPathUnits maskUnits maskContentUnits
markerUnits markerWidth markerHeight refX refY orient class in in2 result stdDeviation values type mode
operator k1 k2 k3 k4 scale xChannelSelector yChannelSelector baseFrequency numOctaves seed stitchTiles radius
surfaceScale diffuseConstant specularConstant specularExponent kernelMatrix kernelUnitLength divisor bias
targetX targetY edgeMode preserveAlpha order azimuth elevation limitingConeAngle pointsAtX pointsAtY pointsAtZ
amplitude exponent intercept slope tableValues filterUnits primitiveUnits filterRes""".split())
TRANSFORM_ATTRIBUTES = ("transform", "gradientTransform", "patternTransform")
_MOTION = "motion"
_NAMESPACES = {"xlink": "{http://www.w3.org/1999/xlink}"}


class SmilError(ValueError):
    """An animation element that is in error (SVG 1.1: it has no effect); the message says why."""


@dataclass(frozen=True)
class Curve:
    """Where the simple animation function is at a progress: key times, splines and whether it jumps.

    ``key_times`` hold one time per value (discrete) or per segment boundary (interpolated);
    ``splines`` one (x1, y1, x2, y2) per segment when calcMode is spline.
    """

    key_times: tuple[float, ...]
    discrete: bool
    splines: tuple[tuple[float, float, float, float], ...] | None = None

    def locate(self, progress: float) -> tuple[int, float]:
        """(value index, fraction towards the next) at ``progress`` in [0, 1] of the simple duration."""
        times = self.key_times
        if self.discrete:
            return max(0, bisect.bisect_right(times, progress) - 1), 0.0
        if len(times) < 2:
            return 0, 0.0
        if progress >= times[-1]:
            return len(times) - 2, 1.0
        index = min(max(bisect.bisect_right(times, progress) - 1, 0), len(times) - 2)
        span = times[index + 1] - times[index]
        fraction = 0.0 if span <= 0 else (progress - times[index]) / span
        if self.splines:
            fraction = eased(self.splines[index], fraction)
        return index, fraction


def eased(spline: tuple[float, float, float, float], fraction: float) -> float:
    """The keySpline's y at x = ``fraction`` (a cubic Bézier from (0, 0) to (1, 1))."""
    x1, y1, x2, y2 = spline
    low, high = 0.0, 1.0
    for _ in range(60):  # bisection on the Bézier parameter: x(s) is increasing for x1, x2 in [0, 1]
        middle = (low + high) / 2
        if _bezier(middle, x1, x2) < fraction:
            low = middle
        else:
            high = middle
    return _bezier((low + high) / 2, y1, y2)


def _bezier(s: float, p1: float, p2: float) -> float:
    return 3 * (1 - s) ** 2 * s * p1 + 3 * (1 - s) * s ** 2 * p2 + s ** 3


@dataclass
class Function:
    """An attribute's simple animation function: its values (or ``to``/``by``) along a curve.

    ``mode`` is ``values`` (values, from-to, from-by), ``to`` (from the underlying value to
    ``values[1]``) or ``by`` (adds ``values[1]``); ``additive``/``accumulate`` are as the file
    sets them, already dropped where SVG 1.1 ignores them. ``appends``: the attribute is a
    transform list, to which an additive animation appends its transform.
    """

    value_type: ValueType
    values: list
    curve: Curve
    mode: str
    additive: bool
    accumulate: bool
    appends: bool = False

    def value(self, progress: float, iteration: int, underlying: str) -> str:
        """The attribute's text at ``progress`` of ``iteration``, over ``underlying`` (the sandwich below)."""
        kind = self.value_type
        index, fraction = self.curve.locate(progress)
        if self.mode == "to":
            below = _parsed(kind, underlying)
            if self.curve.discrete or below is None:
                return kind.format(self.values[1])
            return kind.format(kind.interpolate(below, self.values[1], fraction))
        values = self.values
        value = values[index] if (self.curve.discrete or index + 1 >= len(values)) else \
            kind.interpolate(values[index], values[index + 1], fraction)
        if self.mode == "by" and self.curve.discrete:
            value = values[-1]
        if self.accumulate and iteration > 0:
            value = kind.add(kind.scale(values[-1], iteration), value)
        if self.appends:
            return f"{underlying} {kind.format(value)}".strip() if self.additive else kind.format(value)
        if self.additive:
            below = _parsed(kind, underlying)
            if below is not None:
                value = kind.add(below, value)
        return kind.format(value)


def _parsed(kind: ValueType, text: str):
    try:
        return kind.parse(text)
    except ValueError:
        return None


@dataclass
class Motion:
    """``animateMotion``'s function: a point (and direction) along a path or through values."""

    path: MotionPath | None
    points: list | None
    curve: Curve
    key_points: tuple[float, ...] | None
    paced: bool
    rotate: str | float
    additive: bool
    accumulate: bool

    def value(self, progress: float, iteration: int, underlying: str) -> str:
        x, y, direction = self._at(progress)
        if self.accumulate and iteration > 0:
            end_x, end_y, _ = self._at(1.0)
            x, y = x + end_x * iteration, y + end_y * iteration
        angle = self.rotate if isinstance(self.rotate, float) else direction + (180.0 if self.rotate == "auto-reverse"
                                                                                 else 0.0)
        text = f"translate({x:.6g},{y:.6g})" + (f" rotate({angle:.6g})" if angle else "")
        return f"{underlying} {text}".strip() if self.additive else text

    def _at(self, progress: float) -> tuple[float, float, float]:
        if self.path is None:
            index, fraction = self.curve.locate(progress)
            points = self.points
            if self.curve.discrete or len(points) == 1:
                if index + 1 < len(points):
                    return (*points[index], _direction(points[index], points[index + 1]))
                return (*points[index], _direction(points[index - 1], points[index]) if index else 0.0)
            a, b = points[index], points[index + 1]
            return a[0] + (b[0] - a[0]) * fraction, a[1] + (b[1] - a[1]) * fraction, _direction(a, b)
        if self.paced:
            return self.path.at(progress * self.path.length)
        index, fraction = self.curve.locate(progress)
        if self.key_points is not None:
            a = self.key_points[index]
            b = self.key_points[min(index + 1, len(self.key_points) - 1)]
            return self.path.at((a + (b - a) * (0.0 if self.curve.discrete else fraction)) * self.path.length)
        spans = self.path.spans
        if index >= len(spans):
            return self.path.at(self.path.length)
        start, end = spans[index]
        return self.path.at(start + (end - start) * (0.0 if self.curve.discrete else fraction))


def _direction(a, b) -> float:
    return math.degrees(math.atan2(b[1] - a[1], b[0] - a[0])) if a != b else 0.0


@dataclass
class Animated:
    """One animation element as parsed: what it animates, when, and how."""

    label: str
    index: int  # in document order, among timed elements
    target: ElementTree.Element
    channel: str  # the attribute (qualified name), or "motion"
    is_property: bool
    function: Function | Motion | None  # None when in error: it keeps its timing for syncbases, without effect
    freeze: bool


@dataclass
class Channel:
    """An attribute of one element that animations change, with its value when none does."""

    target: ElementTree.Element
    name: str
    is_property: bool
    base: str
    animations: list[Animated]


class SmilAnimation(Animation):
    """A file's SMIL animations: parsed once, then applied to copies of its tree at any time."""

    language = "SMIL"

    def __init__(self, source: str, animated: list[Animated], timings: list[Timing], ids: dict[str, int],
                 channels: list[Channel], unsupported: list[Unsupported]):
        self.source = source
        self.animated = animated
        self.timings = timings
        self.ids = ids
        self.channels = channels
        self.unsupported = tuple(unsupported)
        self._timelines: dict[int, Timeline] = {}

    def timeline(self, time_seconds: float) -> Timeline:
        """The resolved timeline that covers ``time_seconds`` (always the same one for the same time)."""
        level = 0
        while level < _MAX_HORIZON_DOUBLINGS and time_seconds > _HORIZON_BLOCK * 2 ** level / 2:
            level += 1
        if level not in self._timelines:
            try:
                self._timelines[level] = Timeline(self.timings, self.ids, _HORIZON_BLOCK * 2 ** level)
            except TimelineError as exc:
                raise InputError(f"{self.source}: {self.animated[exc.index].label}: its begin and end times "
                                 "depend on each other in a cycle that never settles") from None
        return self._timelines[level]

    def apply(self, at: Callable[[ElementTree.Element], ElementTree.Element], time_seconds: float) -> None:
        timeline = self.timeline(time_seconds)
        motions: dict[int, tuple[ElementTree.Element, str]] = {}
        transforms: dict[int, tuple[ElementTree.Element, str]] = {}
        for channel in self.channels:
            value = self._composed(channel, timeline, time_seconds)
            if value is None:
                continue
            if channel.name == _MOTION:
                motions[id(channel.target)] = (channel.target, value)
            elif channel.name == "transform":
                transforms[id(channel.target)] = (channel.target, value)
            elif channel.is_property:
                set_style_property(at(channel.target), channel.name, value)
            else:
                at(channel.target).set(_qualified(channel.name), value)
        for key, (target, value) in transforms.items():
            at(target).set("transform", value)
        for key, (target, motion) in motions.items():
            transform = transforms[key][1] if key in transforms else target.get("transform", "")
            at(target).set("transform", f"{motion} {transform}".strip())

    def _composed(self, channel: Channel, timeline: Timeline, time_seconds: float) -> str | None:
        """The channel's text at ``time_seconds``, or None when no animation touches it then."""
        layers = []
        for animated in channel.animations:
            if animated.function is None:
                continue
            position = _position(timeline, self.timings[animated.index], animated, time_seconds)
            if position is not None:
                interval, iteration, progress = position
                layers.append((interval.begin, _rank(timeline, interval), animated.index, iteration, progress,
                               animated))
        if not layers:
            return None
        value = channel.base
        for *_, iteration, progress, animated in sorted(layers, key=lambda layer: layer[:3]):
            value = animated.function.value(progress, iteration, value)
        return value

    def duration(self) -> float:
        """When the last animation's last active interval ends.

        An animation that repeats forever (``repeatCount="indefinite"``, no end) counts until
        the end of its first simple duration. Animations that keep restarting through
        syncbases (``begin="0;last.end"``) count one cycle: from the first begin among them,
        the longest time between two begins of one of them.
        """
        for level in range(_MAX_HORIZON_DOUBLINGS + 1):
            horizon = _HORIZON_BLOCK * 2 ** level
            timeline = self.timeline(horizon / 2)
            ends, cycles, undecided = [0.0], [], False
            for intervals, timing, continues in zip(timeline.intervals, self.timings, timeline.continues):
                if intervals and intervals[-1].end == INDEFINITE:
                    ends.append(intervals[0].begin + (timing.dur if timing.dur != INDEFINITE else 0.0))
                elif continues and len(intervals) >= 2:
                    cycles.append((intervals[0].begin, intervals[1].begin - intervals[0].begin))
                elif continues:
                    undecided = True  # it begins (again) beyond this horizon
                elif intervals:
                    ends.append(intervals[-1].end)
            if cycles:
                ends.append(min(start for start, _ in cycles) + max(period for _, period in cycles))
            latest = max(ends)
            if not undecided and latest < horizon / 2:
                return max(latest, 0.0)
        return max(latest, 0.0)


def _position(timeline: Timeline, timing: Timing, animated: Animated, time_seconds: float):
    """(interval, iteration, progress) of the animation at ``time_seconds``, or None when it has no effect."""
    state = timeline.state(animated.index, time_seconds)
    if state is None:
        return None
    interval, active = state
    played = timing.repeat_duration()
    if active and time_seconds - interval.begin < played:
        return (interval, *_iteration(time_seconds - interval.begin, timing.dur, ended=False))
    if not animated.freeze:
        return None
    return (interval, *_iteration(min(interval.end - interval.begin, played), timing.dur, ended=True))


def _iteration(active_time: float, simple: float, *, ended: bool) -> tuple[int, float]:
    """(iteration, progress in the simple duration) at ``active_time``; at an end on a repeat boundary, 1.0."""
    if simple == INDEFINITE or simple <= 0:
        return 0, 0.0
    iteration = math.floor(active_time / simple + _EPSILON)
    progress = max(0.0, active_time / simple - iteration)
    if ended and iteration > 0 and progress < _EPSILON:
        return iteration - 1, 1.0
    return iteration, min(progress, 1.0)


def _rank(timeline: Timeline, interval: Interval) -> int:
    """How many syncbases that began at the same time this interval's begin hangs from (SMIL: dependents on top)."""
    rank, depth = 0, 0
    while interval.source is not None and depth < len(timeline.timings):
        state = timeline.state(interval.source, interval.begin)
        if state is None or state[0].begin != interval.begin:
            break
        interval, rank, depth = state[0], rank + 1, depth + 1
    return rank


def _qualified(name: str) -> str:
    prefix, _, local = name.rpartition(":")
    return _NAMESPACES[prefix] + local if prefix in _NAMESPACES else name


# --- parsing --------------------------------------------------------------------------------------------------


def parse_smil(root: ElementTree.Element, source: str) -> SmilAnimation | None:
    """The SMIL animation of the tree under ``root``, or None when it has no animation elements."""
    elements = [element for element in root.iter() if local_name(element.tag) in ANIMATION_TAGS]
    unsupported = [Unsupported(_label(element), "SMIL's <discard> (SVG 2) is not played; the element stays")
                   for element in root.iter() if local_name(element.tag) == "discard"]
    if not elements:
        return SmilAnimation(source, [], [], {}, [], unsupported) if unsupported else None
    by_id = {element.get("id"): element for element in root.iter() if element.get("id")}
    parents = {child: parent for parent in root.iter() for child in parent}
    ids = {element.get("id"): index for index, element in enumerate(elements) if element.get("id")}
    animated, timings = [], []
    for index, element in enumerate(elements):
        label = _label(element)
        report = lambda message, label=label: unsupported.append(Unsupported(label, message))  # noqa: E731
        timings.append(_timing(element, ids, by_id, report))
        target = _target(element, by_id, parents)
        try:
            if target is None:
                raise SmilError(f"its target '{element.get('href') or element.get(XLINK_HREF)}' is not in the file")
            channel, is_property, function = _function(element, target, by_id, parents, report)
        except SmilError as exc:
            unsupported.append(Unsupported(label, f"{exc}; it is not played"))
            animated.append(Animated(label, index, target, "", False, None, False))
            continue
        animated.append(Animated(label, index, target, channel, is_property, function,
                                 element.get("fill", "remove").strip() == "freeze"))
    channels = _channels(animated, parents)
    animation = SmilAnimation(source, animated, timings, ids, channels, unsupported)
    animation.timeline(0.0)
    return animation


def _label(element: ElementTree.Element) -> str:
    """How a user finds the element in the file: ``<animate id="a" attributeName="r">``."""
    shown = [f'{name}="{element.get(name)}"' for name in ("id", "attributeName", "type") if element.get(name)]
    return "<" + " ".join([local_name(element.tag), *shown]) + ">"


def _target(element, by_id, parents) -> ElementTree.Element | None:
    reference = element.get("href") or element.get(XLINK_HREF)
    if reference is None:
        return parents.get(element)
    return by_id.get(reference.strip()[1:]) if reference.strip().startswith("#") else None


def _timing(element, ids, by_id, report) -> Timing:
    """The element's timing attributes; invalid ones are reported and taken as absent, as SMIL says."""
    begins = _conditions(element, "begin", ids, by_id, report) if element.get("begin") is not None else \
        [Condition("offset", "0")]
    ends = _conditions(element, "end", ids, by_id, report) if element.get("end") is not None else []
    return Timing(tuple(begins), tuple(ends), element.get("end") is not None,
                  dur=_duration(element, "dur", report, default=INDEFINITE, positive=True),
                  repeat_count=_repeat_count(element, report),
                  repeat_dur=_duration(element, "repeatDur", report, default=None, positive=True),
                  minimum=_duration(element, "min", report, default=0.0, positive=False),
                  maximum=_duration(element, "max", report, default=INDEFINITE, positive=True),
                  restart=_restart(element, report))


def _conditions(element, attribute, ids, by_id, report) -> list[Condition]:
    conditions, invalid = parse_conditions(element.get(attribute))
    for entry in invalid:
        report(f"{attribute} '{entry}' is not a SMIL time; that entry is ignored")
    kept = []
    for condition in conditions:
        if condition.kind == "event":
            effect = "the animation does not start by it" if attribute == "begin" else "it does not end the animation"
            report(f"{attribute} '{condition.text}' waits for an event (a click, a key, the clock), which never "
                   f"comes in a render: {effect}")
        elif condition.kind in ("syncbase", "repeat") and condition.base not in ids:
            what = "an element that is not an animation" if condition.base in by_id else "no element of the file"
            report(f"{attribute} '{condition.text}' refers to {what}; that entry is ignored")
            continue
        kept.append(condition)
    return kept


def _duration(element, attribute, report, *, default, positive):
    text = element.get(attribute)
    if text is None or text.strip() == "media":
        return default
    if text.strip() == "indefinite" and attribute != "min":
        return INDEFINITE
    value = clock_value(text)
    if value is None or value < 0 or positive and value == 0:
        report(f"{attribute} '{text}' is not a valid duration; it is ignored")
        return default
    return value


def _repeat_count(element, report) -> float | None:
    text = element.get("repeatCount")
    if text is None:
        return None
    if text.strip() == "indefinite":
        return INDEFINITE
    try:
        value = float(text)
    except ValueError:
        value = 0.0
    if not value > 0:
        report(f"repeatCount '{text}' is not a positive number; it is ignored")
        return None
    return value


def _restart(element, report) -> str:
    value = (element.get("restart") or "always").strip()
    if value not in ("always", "whenNotActive", "never"):
        report(f"restart '{value}' is not always, whenNotActive or never; taken as always")
        return "always"
    return value


def _function(element, target, by_id, parents, report) -> tuple[str, bool, Function | Motion]:
    """(channel, whether it is a CSS property, function) of an animation element; a SmilError when in error."""
    tag = local_name(element.tag)
    if tag == "animateMotion":
        return _MOTION, False, _motion(element, by_id, report)
    name = (element.get("attributeName") or "").strip()
    if not name:
        raise SmilError("it has no attributeName")
    if tag == "animateTransform":
        if name not in TRANSFORM_ATTRIBUTES:
            raise SmilError(f"animateTransform animates transform, gradientTransform or patternTransform, "
                            f"not '{name}'")
        kind = (element.get("type") or "translate").strip()
        if kind not in TRANSFORM_PARAMETERS:
            raise SmilError(f"type '{kind}' is not translate, scale, rotate, skewX or skewY")
        if element.get("values") is None and element.get("from") is None and element.get("by") is None:
            raise SmilError("a to-animation of a transform has no underlying value of its type to start from "
                            "(SVG 1.1 leaves it undefined)")
        return name, False, _attribute_function(element, TransformType(kind), name, report)
    if name in TRANSFORM_ATTRIBUTES:
        raise SmilError(f"<{tag}> cannot animate '{name}' (animateTransform does)")
    if name not in PROPERTIES and name not in ATTRIBUTES:
        raise SmilError(f"attributeName '{name}' is not an attribute SVG 1.1 animates")
    function = _attribute_function(element, None, name, report, is_set=tag == "set")
    if name in ("href", "xlink:href") and not all(is_internal_reference(function.value_type.format(value))
                                                   for value in function.values if value is not None):
        raise InputError(f"{_label(element)} sets '{name}' to a resource outside the document; Fluidymation never "
                         "fetches files or URLs named inside an input")
    return name, name in PROPERTIES, function


def _base_value(target, name, parents) -> str:
    """The attribute's own value: from the style, the attribute, the parent (if inherited), or the initial value."""
    element = target
    while element is not None:
        if name in PROPERTIES:
            value = style_property(element, name)
            if value is not None:
                return value
        value = element.get(_qualified(name))
        if value is not None:
            return value
        if name not in _INHERITED:
            break
        element = parents.get(element)
    return _INITIAL.get(name, "0" if name not in PROPERTIES else "")


def _attribute_function(element, value_type: ValueType | None, name: str, report, *, is_set=False) -> Function:
    """The function of animate/set/animateColor/animateTransform from values/from/to/by and the curve attributes.

    ``value_type`` is the transform type for animateTransform, else None: found from the values.
    """
    if is_set:
        to = element.get("to")
        if to is None:
            raise SmilError("<set> has no 'to'")
        value_type, values, _ = value_type_for(name, [to])
        return Function(value_type, [values[0], values[0]], Curve((0.0,), True), "values", False, False)
    texts, mode = _value_texts(element)
    if value_type is None:
        value_type, values, clash = value_type_for(name, [text for text in texts if text is not None])
        if clash:
            report("its values cannot be interpolated with one another (path data with other commands, lists of "
                   "other lengths, or units that do not convert): they change discretely, as SVG 1.1 says")
    else:
        try:
            values = [value_type.parse(text) for text in texts if text is not None]
        except ValueError as exc:
            raise SmilError(str(exc)) from None
    if mode == "to":
        values = [None, values[0]]
    elif mode in ("by", "from-by"):
        if not value_type.additive:
            raise SmilError(f"'by' needs values that add, which '{name}' values do not")
        start = values[0] if mode == "from-by" else value_type.zero()
        values = [start, value_type.add(start, values[-1])]
    calc = _calc_mode(element, "linear", report)
    if not value_type.interpolates:
        calc = "discrete"
    elif calc == "paced" and (mode == "to" or len(values) < 2):
        calc = "linear"  # a single interval: paced and linear agree
    elif calc == "paced" and any(value_type.distance(a, b) is None for a, b in zip(values, values[1:])):
        report(f"calcMode 'paced' needs a distance between values, which '{name}' values lack: played as linear")
        calc = "linear"
    curve = _curve(element, calc, values, value_type)
    additive = (element.get("additive") or "replace").strip() == "sum" or mode == "by"
    accumulate = (element.get("accumulate") or "none").strip() == "sum"
    if mode == "to" or not value_type.additive:
        additive = accumulate = False
    return Function(value_type, values, curve, "to" if mode == "to" else "by" if mode == "by" else "values",
                    additive, accumulate, appends=isinstance(value_type, TransformType))


def _value_texts(element) -> tuple[list[str | None], str]:
    """The value texts and the kind of animation: values, from-to, from-by, by or to."""
    values = element.get("values")
    if values is not None:
        items = _split_list(values)
        if not items:
            raise SmilError("its values list is empty")
        return items, "values"
    start, to, by = element.get("from"), element.get("to"), element.get("by")
    if to is not None:
        return ([start, to], "from-to") if start is not None else ([to], "to")
    if by is not None:
        return ([start, by], "from-by") if start is not None else ([by], "by")
    raise SmilError("it has none of values, from, to and by")


def _split_list(text: str) -> list[str]:
    """A semicolon-separated list; one trailing semicolon is allowed, other empty items are an error."""
    items = [item.strip() for item in text.split(";")]
    if items and items[-1] == "":
        items.pop()
    if any(item == "" for item in items):
        raise SmilError(f"the list '{text}' has an empty item")
    return items


def _calc_mode(element, default, report) -> str:
    mode = (element.get("calcMode") or default).strip()
    if mode not in ("discrete", "linear", "paced", "spline"):
        raise SmilError(f"calcMode '{mode}' is not discrete, linear, paced or spline")
    return mode


def _curve(element, calc: str, values: list, value_type: ValueType) -> Curve:
    """The key times (given, even, or paced by distance) and splines of ``values`` under ``calc``."""
    if calc == "paced":
        return Curve(_paced_times([value_type.distance(a, b) for a, b in zip(values, values[1:])]), False)
    return _keyed_curve(element, calc, len(values))


def _paced_times(steps: list[float]) -> tuple[float, ...]:
    total = sum(steps)
    if total <= 0:
        return tuple(index / len(steps) for index in range(len(steps) + 1))
    times, reached = [0.0], 0.0
    for step in steps:
        reached += step
        times.append(reached / total)
    times[-1] = 1.0
    return tuple(times)


def _keyed_curve(element, calc: str, count: int) -> Curve:
    """keyTimes (one per value) and keySplines (one per interval), checked as SVG 1.1 asks."""
    discrete = calc == "discrete"
    text = element.get("keyTimes")
    if text is None:
        times = tuple(index / count for index in range(count)) if discrete else \
            tuple(index / (count - 1) for index in range(count)) if count > 1 else (0.0,)
    else:
        try:
            times = tuple(float(item) for item in _split_list(text))
        except ValueError:
            raise SmilError(f"keyTimes '{text}' is not a list of numbers") from None
        if len(times) != count:
            raise SmilError(f"keyTimes has {len(times)} times for {count} values")
        if times[0] != 0 or any(b < a for a, b in zip(times, times[1:])) or times[-1] > 1 or \
                (not discrete and times[-1] != 1):
            raise SmilError(f"keyTimes '{text}' must rise from 0 to 1" + ("" if not discrete else " at most"))
    splines = None
    if calc == "spline":
        splines = _key_splines(element, max(count - 1, 1))
    return Curve(times, discrete, splines)


def _key_splines(element, count: int) -> tuple[tuple[float, float, float, float], ...]:
    text = element.get("keySplines")
    if text is None:
        raise SmilError("calcMode 'spline' without keySplines")
    splines = []
    for item in _split_list(text):
        try:
            numbers = tuple(float(number) for number in item.replace(",", " ").split())
        except ValueError:
            numbers = ()
        if len(numbers) != 4 or not all(0 <= number <= 1 for number in numbers):
            raise SmilError(f"keySplines '{item}' is not four numbers between 0 and 1")
        splines.append(numbers)
    if len(splines) != count:
        raise SmilError(f"keySplines has {len(splines)} splines for {count} intervals")
    return tuple(splines)


def _motion(element, by_id, report) -> Motion:
    """animateMotion: mpath, then path, then values, then from/to/by; keyPoints; rotate."""
    path = _motion_path(element, by_id)
    calc = _calc_mode(element, "paced", report)
    additive = (element.get("additive") or "replace").strip() == "sum"
    accumulate = (element.get("accumulate") or "none").strip() == "sum"
    rotate = _rotate(element)
    if path is not None:
        motion = MotionPath(path)
        key_points = element.get("keyPoints")
        if calc == "paced":
            return Motion(motion, None, Curve((0.0, 1.0), False), None, True, rotate, additive, accumulate)
        if key_points is not None:
            try:
                points = tuple(float(item) for item in _split_list(key_points))
            except ValueError:
                raise SmilError(f"keyPoints '{key_points}' is not a list of numbers") from None
            if not all(0 <= point <= 1 for point in points):
                raise SmilError(f"keyPoints '{key_points}' must lie between 0 and 1")
            if element.get("keyTimes") is None:
                raise SmilError("keyPoints without keyTimes")
            return Motion(motion, None, _keyed_curve(element, calc, len(points)), points, False, rotate, additive,
                          accumulate)
        return Motion(motion, None, _keyed_curve(element, calc, len(motion.spans) + 1), None, False, rotate,
                      additive, accumulate)
    point = PointType()
    texts, mode = _value_texts(element)
    try:
        values = [point.parse(text) for text in texts if text is not None]
    except ValueError as exc:
        raise SmilError(str(exc)) from None
    if mode == "to":
        values = [point.zero(), values[0]]
    elif mode in ("by", "from-by"):
        start = values[0] if mode == "from-by" else point.zero()
        values = [start, point.add(start, values[-1])]
        additive = additive or mode == "by"
    if calc == "paced" and len(values) > 1:
        curve = Curve(_paced_times([point.distance(a, b) for a, b in zip(values, values[1:])]), False)
    else:
        curve = _keyed_curve(element, "linear" if calc == "paced" else calc, len(values))
    return Motion(None, values, curve, None, False, rotate, additive, accumulate)


def _motion_path(element, by_id) -> PathData | None:
    for child in element:
        if local_name(child.tag) == "mpath":
            reference = (child.get("href") or child.get(XLINK_HREF) or "").strip()
            path = by_id.get(reference[1:]) if reference.startswith("#") else None
            if path is None or local_name(path.tag) != "path":
                raise SmilError(f"<mpath> refers to '{reference}', which is not a <path> of the file")
            return _path_data(path.get("d") or "")
    text = element.get("path")
    return None if text is None else _path_data(text)


def _path_data(text: str) -> PathData:
    try:
        path = PathData.parse(text)
    except ValueError as exc:
        raise SmilError(f"its motion path is invalid ({exc})") from None
    if not path.commands:
        raise SmilError("its motion path is empty")
    return path


def _rotate(element) -> str | float:
    text = (element.get("rotate") or "0").strip()
    if text in ("auto", "auto-reverse"):
        return text
    try:
        return float(text)
    except ValueError:
        raise SmilError(f"rotate '{text}' is not auto, auto-reverse or an angle") from None


def _channels(animated: list[Animated], parents) -> list[Channel]:
    """The animated attributes, each with its animations in document order and its own value."""
    channels: dict[tuple[int, str], Channel] = {}
    for item in animated:
        if item.function is None:
            continue
        key = (id(item.target), item.channel)
        if key not in channels:
            if item.channel == _MOTION:
                base = ""
            elif item.channel in TRANSFORM_ATTRIBUTES:
                base = item.target.get(item.channel, "")
            else:
                base = _base_value(item.target, item.channel, parents)
            channels[key] = Channel(item.target, item.channel, item.is_property, base, [])
        channels[key].animations.append(item)
    return list(channels.values())

