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
from dataclasses import dataclass

INDEFINITE = math.inf
#: Recomputations of one element's intervals, per interval kept, before the timeline is said not to settle.
_MAX_ROUNDS_PER_INTERVAL = 50

_CLOCK_FULL = re.compile(r"^(?:(\d+):)?(\d{2}):(\d{2}(?:\.\d+)?)$")
_CLOCK_COUNT = re.compile(r"^(\d+(?:\.\d+)?|\.\d+)(h|min|s|ms)?$")
_METRIC = {"h": 3600.0, "min": 60.0, "s": 1.0, "ms": 0.001, None: 1.0}
_OFFSET = re.compile(r"^([+-])?\s*(.*)$")
_SYNCBASE = re.compile(r"^((?:[^.\\\s]|\\.)+)\.(begin|end)\s*(?:([+-])\s*(.+))?$")
_REPEAT = re.compile(r"^(?:((?:[^.\\\s]|\\.)+)\.)?repeat\((\d+)\)\s*(?:([+-])\s*(.+))?$")
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


def _arcs(conditions: tuple[Condition, ...], ids: dict[str, int]) -> list[tuple[Condition, int]]:
    """The syncbase and repeat conditions among ``conditions`` that name a timed element, with its index."""
    return [(c, ids[c.base]) for c in conditions if c.kind in ("syncbase", "repeat") and c.base in ids]


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
    """

    def __init__(self, timings: list[Timing], ids: dict[str, int], horizon: float):
        self.timings = timings
        self.horizon = horizon
        self.intervals: list[list[Interval]] = [[] for _ in timings]
        self._static_begins = [sorted(c.offset for c in t.begins if c.kind == "offset") for t in timings]
        self._static_ends = [sorted(c.offset for c in t.ends if c.kind == "offset") for t in timings]
        self._begin_arcs = [_arcs(t.begins, ids) for t in timings]
        self._end_arcs = [_arcs(t.ends, ids) for t in timings]
        self._dependents: list[list[int]] = [[] for _ in timings]
        for index in range(len(timings)):
            for _, base in (*self._begin_arcs[index], *self._end_arcs[index]):
                if index not in self._dependents[base]:
                    self._dependents[base].append(index)
        self._resolve()
        self._begins = [[interval.begin for interval in intervals] for intervals in self.intervals]

    def _resolve(self) -> None:
        pending = list(range(len(self.timings)))
        queued = set(pending)
        rounds = [0] * len(self.timings)
        while pending:
            index = pending.pop(0)
            queued.discard(index)
            rounds[index] += 1
            if rounds[index] > _MAX_ROUNDS_PER_INTERVAL * (len(self.intervals[index]) + 2):
                raise TimelineError(index)
            intervals = self._intervals(index)
            if intervals == self.intervals[index]:
                continue
            self.intervals[index] = intervals
            for dependent in self._dependents[index]:
                if dependent not in queued:
                    pending.append(dependent)
                    queued.add(dependent)

    def _instances(self, arcs: list[tuple[Condition, int]], static: list[float]) -> list[tuple[float, int | None]]:
        """Instance times now: the static offsets and what the syncbases' (``arcs``) intervals give."""
        times = [(t, None) for t in static]
        for condition, base in arcs:
            for interval in self.intervals[base]:
                if condition.kind == "syncbase":
                    edge = interval.begin if condition.edge == "begin" else interval.end
                    if edge != INDEFINITE:
                        times.append((edge + condition.offset, base))
                else:
                    simple = self.timings[base].dur
                    start = interval.begin + condition.count * simple
                    if condition.count > 0 and start < interval.end and simple != INDEFINITE:
                        times.append((start + condition.offset, base))
        times.sort(key=lambda item: (item[0], -1 if item[1] is None else item[1]))
        return times

    def _intervals(self, index: int) -> list[Interval]:
        timing = self.timings[index]
        begins = self._instances(self._begin_arcs[index], self._static_begins[index])
        ends = [t for t, _ in self._instances(self._end_arcs[index], self._static_ends[index])]
        begin_times = [t for t, _ in begins]
        intervals: list[Interval] = []
        begin_after = -INDEFINITE
        after_zero = False
        while True:
            position = (bisect.bisect_right if after_zero else bisect.bisect_left)(begin_times, begin_after)
            if position == len(begins) or begins[position][0] >= self.horizon:
                break
            begin, source = begins[position]
            if timing.has_end:
                end_at = bisect.bisect_left(ends, begin)
                if end_at < len(ends) and ends[end_at] == begin and intervals and after_zero:
                    end_at += 1
                if end_at < len(ends):
                    end = begin + timing.active_duration(begin, ends[end_at])
                elif timing.end_is_open() or not ends:
                    end = begin + timing.active_duration(begin, None)
                else:
                    break
            else:
                end = begin + timing.active_duration(begin, None)
            if timing.restart == "always":
                later = bisect.bisect_right(begin_times, begin)
                if later < len(begin_times) and begin_times[later] < end:
                    end = begin_times[later]
            if not intervals and not (end > 0 or begin == end == 0):
                begin_after, after_zero = end, False
                continue
            intervals.append(Interval(begin, end, source))
            if timing.restart == "never" or end == INDEFINITE:
                break
            begin_after, after_zero = end, end == begin
        return intervals

    def state(self, index: int, time: float) -> tuple[Interval, bool] | None:
        """The interval that shows at ``time`` and whether it is active (else it is over: frozen or removed)."""
        position = bisect.bisect_right(self._begins[index], time) - 1
        if position < 0:
            return None
        interval = self.intervals[index][position]
        return interval, time < interval.end
