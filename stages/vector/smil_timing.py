"""The SMIL timing model of SVG 1.1 animations: clock values, begin/end conditions and active intervals.

Each animation element is a :class:`Timing` (its ``begin``, ``end``, ``dur``,
``repeatCount``, ``repeatDur``, ``min``, ``max``, ``restart``). A :class:`Timeline` resolves
the intervals of every element of a document together, since syncbase conditions
(``a.end+0.25s``, ``a.repeat(2)``) make one element's intervals depend on another's,
often in cycles (``begin="0;last.end"``). Intervals follow SMIL's "getFirstInterval" and
"getNextInterval" rules; the whole set is the fixed point of those rules over the
instance times the syncbases give, computed up to a horizon. Event conditions (``click``,
``a.beginEvent``, ``accessKey``, ``wallclock``) never happen here.
"""

from __future__ import annotations

import bisect
import math
import re
from collections import deque
from dataclasses import dataclass
from operator import attrgetter, itemgetter

INDEFINITE = math.inf
#: Recomputations of one element's intervals, per interval kept, before the timeline is said not to settle.
_MAX_ROUNDS_PER_INTERVAL = 50

_CLOCK_FULL = re.compile(r"^(?:(\d+):)?(\d{2}):(\d{2}(?:\.\d+)?)$")
_CLOCK_COUNT = re.compile(r"^(\d+(?:\.\d+)?|\.\d+)(h|min|s|ms)?$")
_METRIC = {"h": 3600.0, "min": 60.0, "s": 1.0, "ms": 0.001, None: 1.0}
_OFFSET = re.compile(r"^([+-])?\s*(.*)$")
_SYNCBASE = re.compile(r"^((?:[^.\\\s]|\\.)+)\.(begin|end)\s*(?:([+-])\s*(.+))?$")
_REPEAT = re.compile(r"^(?:((?:[^.\\\s]|\\.)+)\.)?repeat\((\d+)\)\s*(?:([+-])\s*(.+))?$")
_TIME = itemgetter(0)
_END = attrgetter("end")
#: The source recorded for an instance time given as an offset (sorts before any element's index).
_OFFSET_SOURCE = -1
_EVENT = re.compile(r"^(?:((?:[^.\\\s]|\\.)+)\.)?([A-Za-z][\w-]*)\s*(?:([+-])\s*(.+))?$")


def clock_value(text: str | None) -> float | None:
    """Seconds of a SMIL clock value (``02:30``, ``1:02:03.5``, ``1.5s``, ``250ms``, ``2``), or None if invalid."""
    text = (text or "").strip()
    match = _CLOCK_FULL.match(text)
    if match:
        hours, minutes, seconds = match.groups()
        if int(minutes) > 59 or float(seconds) >= 60:
            return None
        return int(hours or 0) * 3600 + int(minutes) * 60 + float(seconds)
    match = _CLOCK_COUNT.match(text)
    if match:
        return float(match.group(1)) * _METRIC[match.group(2)]
    return None


@dataclass(frozen=True)
class Condition:
    """One entry of a ``begin`` or ``end`` list.

    ``kind`` is ``offset`` (a time from the document's begin), ``syncbase`` (``base`` element's
    ``edge``, begin or end, plus ``offset``), ``repeat`` (``base``'s ``count``-th repeat plus
    ``offset``), ``event`` (never happens here) or ``indefinite``; ``text`` is how the file wrote it.
    """

    kind: str
    text: str
    offset: float = 0.0
    base: str | None = None
    edge: str | None = None
    count: int = 0


def parse_conditions(text: str) -> tuple[list[Condition], list[str]]:
    """The conditions of a ``begin``/``end`` list, and the entries that are not valid SMIL."""
    conditions, invalid = [], []
    for entry in (part.strip() for part in text.split(";")):
        if not entry:
            continue
        condition = _condition(entry)
        if condition is None:
            invalid.append(entry)
        else:
            conditions.append(condition)
    return conditions, invalid


def _condition(entry: str) -> Condition | None:
    if entry == "indefinite":
        return Condition("indefinite", entry)
    offset = _signed_clock(entry)
    if offset is not None:
        return Condition("offset", entry, offset)
    if entry.startswith(("accessKey(", "wallclock(")):
        return Condition("event", entry)
    for pattern, kind in ((_SYNCBASE, "syncbase"), (_REPEAT, "repeat"), (_EVENT, "event")):
        match = pattern.match(entry)
        if not match:
            continue
        base, detail, sign, clock = match.groups()
        offset = 0.0
        if sign:
            offset = clock_value(clock)
            if offset is None:
                return None
            offset = -offset if sign == "-" else offset
        base = base.replace("\\", "") if base else None
        if kind == "syncbase":
            return Condition(kind, entry, offset, base, edge=detail)
        if kind == "repeat":
            return Condition(kind, entry, offset, base, count=int(detail))
        return Condition(kind, entry, offset, base)
    return None


def _is_arc(condition: Condition, ids: dict[str, int]) -> bool:
    """Whether the condition is a syncbase or repeat condition naming a timed element."""
    return condition.kind in ("syncbase", "repeat") and condition.base in ids


def _signed_clock(entry: str) -> float | None:
    sign, rest = _OFFSET.match(entry).groups()
    value = clock_value(rest)
    if value is None:
        return None
    return -value if sign == "-" else value


@dataclass(frozen=True)
class Interval:
    """An active interval [begin, end) of an element; ``source`` is the element whose interval gave the begin."""

    begin: float
    end: float
    source: int | None = None


@dataclass(frozen=True)
class Timing:
    """The timing attributes of one animation element, already validated.

    ``dur`` is the simple duration (INDEFINITE when absent), ``repeat_count`` and
    ``repeat_dur`` None when absent, ``minimum``/``maximum`` the active-duration bounds.
    ``has_end`` says whether an ``end`` attribute was given.
    """

    begins: tuple[Condition, ...]
    ends: tuple[Condition, ...]
    has_end: bool
    dur: float = INDEFINITE
    repeat_count: float | None = None
    repeat_dur: float | None = None
    minimum: float = 0.0
    maximum: float = INDEFINITE
    restart: str = "always"

    def repeat_duration(self) -> float:
        """How long the simple duration plays, repeats included, before any end or min/max (SMIL's IAD)."""
        if self.dur == 0:
            return 0.0
        if self.repeat_count is None and self.repeat_dur is None:
            return self.dur
        bounds = []
        if self.repeat_count is not None:
            bounds.append(self.dur * self.repeat_count)
        if self.repeat_dur is not None:
            bounds.append(self.repeat_dur)
        return min(bounds)

    def active_duration(self, begin: float, end: float | None) -> float:
        """The active duration of an interval from ``begin`` whose end condition resolved to ``end`` (None: none)."""
        duration = self.repeat_duration() if end is None else min(self.repeat_duration(), end - begin)
        return min(self.maximum, max(self.minimum, duration))

    def end_is_open(self) -> bool:
        """Whether the end list holds conditions that may resolve later (events, syncbases, indefinite)."""
        return any(condition.kind != "offset" for condition in self.ends)


class TimelineError(ValueError):
    """The intervals do not settle (a cycle of syncbases that keeps changing); ``index`` names the element."""

    def __init__(self, index: int):
        super().__init__(index)
        self.index = index


class Timeline:
    """The intervals of a document's timed elements, resolved together up to ``horizon`` seconds.

    ``timings`` are in document order (an element's index is its priority among equal
    begins); ``ids`` maps element ids to indices, for syncbases. Intervals that begin at
    or after the horizon are not computed; the timeline is exact before it.

    Resolution is a worklist over elements: when an element's intervals change, the instance
    times its dependents derive from them are updated, and each dependent recomputes only its
    intervals from the earliest instance time that moved (those ending before it stay).
    """

    def __init__(self, timings: list[Timing], ids: dict[str, int], horizon: float):
        self.timings = timings
        self.horizon = horizon
        self.intervals: list[list[Interval]] = [[] for _ in timings]
        self._truncated = [False] * len(timings)  # it begins again at or after the horizon
        self._static_begins = [[(c.offset, _OFFSET_SOURCE) for c in t.begins if c.kind == "offset"] for t in timings]
        self._static_ends = [[(c.offset, _OFFSET_SOURCE) for c in t.ends if c.kind == "offset"] for t in timings]
        # Syncbase and repeat conditions: (is a begin condition, condition, base index); per arc, the instance
        # time each of the base's intervals gives (or None), in the order of the base's intervals.
        self._arcs = [[(True, c, ids[c.base]) for c in t.begins if _is_arc(c, ids)] +
                      [(False, c, ids[c.base]) for c in t.ends if _is_arc(c, ids)] for t in timings]
        self._derived: list[list[list]] = [[[] for _ in arcs] for arcs in self._arcs]
        self._dependents: list[list[tuple[int, int]]] = [[] for _ in timings]
        for index, arcs in enumerate(self._arcs):
            for slot, (_, _, base) in enumerate(arcs):
                self._dependents[base].append((index, slot))
        self._resolve()
        self._begins = [[interval.begin for interval in intervals] for intervals in self.intervals]
        #: Whether an element's intervals go on past the horizon: it begins again at or after it, or it still
        #: began in the horizon's second half following (through syncbases) an element that goes on.
        self.continues = list(self._truncated)
        spreading = True
        while spreading:
            spreading = False
            for index, arcs in enumerate(self._arcs):
                if (not self.continues[index] and self.intervals[index] and
                        self.intervals[index][-1].begin >= horizon / 2 and
                        any(self.continues[base] for _, _, base in arcs)):
                    self.continues[index] = spreading = True

    def _resolve(self) -> None:
        count = len(self.timings)
        pending, queued = deque(range(count)), set(range(count))
        since = [-INDEFINITE] * count  # per element: the earliest instance time that may have moved
        rounds = [0] * count
        while pending:
            index = pending.popleft()
            queued.discard(index)
            rounds[index] += 1
            if rounds[index] > _MAX_ROUNDS_PER_INTERVAL * (len(self.intervals[index]) + 2):
                raise TimelineError(index)
            old = self.intervals[index]
            new, kept, self._truncated[index] = self._intervals(index, since[index])
            since[index] = INDEFINITE
            first = next((kept + k for k, (a, b) in enumerate(zip(old[kept:], new[kept:])) if a != b),
                         min(len(old), len(new)))
            if first == len(old) == len(new):
                continue
            self.intervals[index] = new
            for dependent, slot in self._dependents[index]:
                moved = self._derive(dependent, slot, old, new, first)
                if moved < since[dependent]:
                    since[dependent] = moved
                    if dependent not in queued:
                        pending.append(dependent)
                        queued.add(dependent)

    def _derive(self, index: int, slot: int, old: list[Interval], new: list[Interval], first: int) -> float:
        """Update arc ``slot`` of element ``index`` from its base's intervals (changed from ``first`` on).

        Returns the earliest instance time that moved, or INDEFINITE when none did.
        """
        _, condition, base = self._arcs[index][slot]
        before = [self._instance(condition, base, interval) for interval in old[first:]]
        after = [self._instance(condition, base, interval) for interval in new[first:]]
        self._derived[index][slot][first:] = after
        moved = [time for time, _ in filter(None, before + after)]
        return min(moved, default=INDEFINITE) if before != after else INDEFINITE

    def _instance(self, condition: Condition, base: int, interval: Interval) -> tuple[float, int] | None:
        """The instance time a base interval gives through ``condition``, with the base's index, if any."""
        if condition.kind == "syncbase":
            edge = interval.begin if condition.edge == "begin" else interval.end
            return None if edge == INDEFINITE else (edge + condition.offset, base)
        simple = self.timings[base].dur
        start = interval.begin + condition.count * simple
        if condition.count > 0 and simple != INDEFINITE and start < interval.end:
            return start + condition.offset, base
        return None

    def _instances(self, index: int, begins: bool) -> list[tuple[float, int]]:
        """The element's begin (or end) instance times now, sorted, each with the element that gave it (or -1)."""
        times = list(self._static_begins[index] if begins else self._static_ends[index])
        for (is_begin, _, _), derived in zip(self._arcs[index], self._derived[index]):
            if is_begin == begins:
                times.extend(filter(None, derived))
        times.sort()
        return times

    def _intervals(self, index: int, since: float) -> tuple[list[Interval], int, bool]:
        """The element's intervals, keeping those that end before ``since``.

        Returns them, how many were kept, and whether the element begins again past the horizon.
        """
        timing = self.timings[index]
        begins = self._instances(index, True)
        ends = self._instances(index, False)
        kept = bisect.bisect_left(self.intervals[index], since, key=_END)
        intervals = self.intervals[index][:kept]
        if intervals and (timing.restart == "never" or intervals[-1].end == INDEFINITE):
            return intervals, kept, False
        begin_after = intervals[-1].end if intervals else -INDEFINITE
        after_zero = bool(intervals) and intervals[-1].end == intervals[-1].begin
        while True:
            find = bisect.bisect_right if after_zero else bisect.bisect_left
            position = find(begins, begin_after, key=_TIME)
            if position == len(begins):
                break
            begin, source = begins[position]
            if begin >= self.horizon:
                return intervals, kept, True
            if timing.has_end:
                end_at = bisect.bisect_left(ends, begin, key=_TIME)
                if end_at < len(ends) and ends[end_at][0] == begin and intervals and after_zero:
                    end_at += 1
                if end_at < len(ends):
                    end = begin + timing.active_duration(begin, ends[end_at][0])
                elif timing.end_is_open() or not ends:
                    end = begin + timing.active_duration(begin, None)
                else:
                    break
            else:
                end = begin + timing.active_duration(begin, None)
            if timing.restart == "always":
                later = bisect.bisect_right(begins, begin, key=_TIME)
                if later < len(begins) and begins[later][0] < end:
                    end = begins[later][0]
            if not intervals and not (end > 0 or begin == end == 0):
                begin_after, after_zero = end, False
                continue
            intervals.append(Interval(begin, end, None if source == _OFFSET_SOURCE else source))
            if timing.restart == "never" or end == INDEFINITE:
                break
            begin_after, after_zero = end, end == begin
        return intervals, kept, False

    def state(self, index: int, time: float) -> tuple[Interval, bool] | None:
        """The interval that shows at ``time`` and whether it is active (else it is over: frozen or removed)."""
        position = bisect.bisect_right(self._begins[index], time) - 1
        if position < 0:
            return None
        interval = self.intervals[index][position]
        return interval, time < interval.end
