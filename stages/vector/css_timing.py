"""CSS animation timing: easing functions (CSS Easing 1) and where an animation is at a time (Web Animations 1).

:class:`Timing` turns a document time into the iteration progress the keyframes are
sampled at, following the Web Animations model that CSS animations are defined by: the
delay, the iteration count (fractional or infinite), the direction and the fill mode.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from fluidymation.stages.vector.css_syntax import InvalidCss, UnsupportedCss, ident, number, split_commas, text_of


class CubicBezier:
    """``cubic-bezier(x1, y1, x2, y2)``: progress along a curve from (0, 0) to (1, 1)."""

    def __init__(self, x1: float, y1: float, x2: float, y2: float):
        if not (0 <= x1 <= 1 and 0 <= x2 <= 1):
            raise InvalidCss("cubic-bezier() x values must lie in [0, 1]")
        self.points = (x1, y1, x2, y2)

    def __call__(self, progress: float) -> float:
        if progress <= 0 or progress >= 1:
            return progress
        x1, y1, x2, y2 = self.points
        t = self._solve(progress, x1, x2)
        return _bezier(t, y1, y2)

    @staticmethod
    def _solve(x: float, x1: float, x2: float) -> float:
        """The curve parameter whose x is ``x`` (x(t) is monotonic since x1, x2 lie in [0, 1])."""
        t = x
        for _ in range(8):
            error = _bezier(t, x1, x2) - x
            if abs(error) < 1e-9:
                return t
            slope = 3 * (1 - t) ** 2 * x1 + 6 * (1 - t) * t * (x2 - x1) + 3 * t * t * (1 - x2)
            if abs(slope) < 1e-6:
                break
            t -= error / slope
        low, high = 0.0, 1.0
        t = x
        while high - low > 1e-10:
            if _bezier(t, x1, x2) < x:
                low = t
            else:
                high = t
            t = (low + high) / 2
        return t

    def __repr__(self):
        return f"cubic-bezier{self.points}"


def _bezier(t: float, p1: float, p2: float) -> float:
    """One coordinate of the cubic Bézier from 0 through control values p1, p2 to 1."""
    return 3 * (1 - t) ** 2 * t * p1 + 3 * (1 - t) * t * t * p2 + t**3


class Steps:
    """``steps(n, position)``: n equal jumps, placed by jump-start, jump-end, jump-none or jump-both."""

    def __init__(self, count: int, position: str = "jump-end"):
        position = {"start": "jump-start", "end": "jump-end"}.get(position, position)
        if position not in ("jump-start", "jump-end", "jump-none", "jump-both"):
            raise InvalidCss(f"'{position}' is not a steps() position")
        if count < (2 if position == "jump-none" else 1):
            raise InvalidCss(f"steps({count}, {position}) has too few steps")
        self.count, self.position = count, position

    def __call__(self, progress: float) -> float:
        step = math.floor(progress * self.count)
        if self.position in ("jump-start", "jump-both"):
            step += 1
        jumps = {"jump-start": self.count, "jump-end": self.count, "jump-none": self.count - 1,
                 "jump-both": self.count + 1}[self.position]
        if progress >= 0 and step < 0:
            step = 0
        if progress <= 1 and step > jumps:
            step = jumps
        return step / jumps

    def __repr__(self):
        return f"steps({self.count}, {self.position})"


def linear(progress: float) -> float:
    return progress


_NAMED = {
    "linear": linear,
    "ease": CubicBezier(0.25, 0.1, 0.25, 1),
    "ease-in": CubicBezier(0.42, 0, 1, 1),
    "ease-out": CubicBezier(0, 0, 0.58, 1),
    "ease-in-out": CubicBezier(0.42, 0, 0.58, 1),
    "step-start": Steps(1, "jump-start"),
    "step-end": Steps(1, "jump-end"),
}
EASE = _NAMED["ease"]
EASING_KEYWORDS = frozenset(_NAMED)


def parse_easing(value):
    """An easing function from one component value: a keyword, ``cubic-bezier()`` or ``steps()``."""
    keyword = ident(value)
    if keyword in _NAMED:
        return _NAMED[keyword]
    if value.type == "function" and value.lower_name == "cubic-bezier":
        arguments = split_commas(value.arguments)
        if len(arguments) != 4 or any(len(group) != 1 for group in arguments):
            raise InvalidCss(f"'{text_of([value])}' needs four numbers")
        return CubicBezier(*(number(group[0]) for group in arguments))
    if value.type == "function" and value.lower_name == "steps":
        arguments = split_commas(value.arguments)
        if len(arguments) not in (1, 2) or any(len(group) != 1 for group in arguments):
            raise InvalidCss(f"'{text_of([value])}' needs a step count and an optional position")
        count = arguments[0][0]
        if count.type != "number" or not count.is_integer:
            raise InvalidCss(f"'{text_of([value])}': the step count must be an integer")
        position = ident(arguments[1][0]) if len(arguments) == 2 else "jump-end"
        if position is None:
            raise InvalidCss(f"'{text_of([value])}': the position must be a keyword")
        return Steps(count.int_value, position)
    if value.type == "function" and value.lower_name == "linear":
        raise UnsupportedCss("the linear() easing function with stops is not evaluated")
    raise InvalidCss(f"'{text_of([value])}' is not an easing function")


@dataclass(frozen=True)
class Timing:
    """When and how one CSS animation plays: the ``animation-*`` values that place it in time."""

    duration: float = 0.0
    delay: float = 0.0
    iterations: float = 1.0
    direction: str = "normal"
    fill: str = "none"
    paused: bool = False

    def active_duration(self) -> float:
        if self.duration == 0 or self.iterations == 0:
            return 0.0
        return self.duration * self.iterations

    def end(self) -> float:
        """Seconds after which the animation shows nothing new: the end of its last iteration, or of its first
        full cycle when it repeats forever (a negative delay enters that cycle part-way, so one cycle still takes
        ``duration``); a paused animation never moves."""
        if self.paused:
            return 0.0
        if math.isinf(self.iterations):
            return max(self.delay, 0.0) + self.duration
        return max(self.delay + self.active_duration(), 0.0)

    def progress(self, time_seconds: float) -> float | None:
        """The iteration progress (0 to 1) at document time ``time_seconds``, or None when the animation has no effect.

        A paused animation stays where it is when the document loads (time 0).
        """
        local = 0.0 if self.paused else time_seconds
        active = self.active_duration()
        end_time = max(self.delay + active, 0.0)
        before_active = max(min(self.delay, end_time), 0.0)
        active_after = max(min(self.delay + active, end_time), 0.0)
        if local < before_active:
            if self.fill not in ("backwards", "both"):
                return None
            phase, active_time = "before", max(local - self.delay, 0.0)
        elif local >= active_after:
            if self.fill not in ("forwards", "both"):
                return None
            phase, active_time = "after", max(min(local - self.delay, active), 0.0)
        else:
            phase, active_time = "active", local - self.delay
        if self.duration == 0:
            overall = 0.0 if phase == "before" else self.iterations
        else:
            overall = active_time / self.duration
        simple = 0.0 if math.isinf(overall) else overall % 1.0
        if simple == 0 and phase != "before" and active_time == active and self.iterations != 0:
            simple = 1.0
        if phase == "after" and math.isinf(self.iterations):
            iteration = math.inf
        elif simple == 1.0:
            iteration = math.floor(overall) - 1
        else:
            iteration = math.floor(overall)
        return simple if self._forwards(iteration) else 1.0 - simple

    def _forwards(self, iteration: float) -> bool:
        if self.direction == "normal":
            return True
        if self.direction == "reverse":
            return False
        if math.isinf(iteration):
            return True
        return (iteration + (self.direction == "alternate-reverse")) % 2 == 0
