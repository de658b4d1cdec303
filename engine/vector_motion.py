"""Motion fields from the vector geometry itself (issue 16; docs/guides.md, "Motion from the geometry").

A reader evaluates each drawn element (a filled path) at two frames: its outline at frame
j and, for every outline point, where that same point of the element was at frame j − 1
(the same vertex or curve parameter, carried through every transform: parenting, groups,
path keyframes). That is all this module needs, so it knows no file format and no renderer.

Per element, the point displacements ``d = now − before`` are fitted by an affine motion
``d(p) = b + A·p`` (least squares, each point weighted by the outline length it stands
for). A rigid, scaled or sheared part is exactly affine, so its whole interior reads its
motion exactly, points on the rotation axis included. What the fit does not explain (a
path that deforms) is left at the outline points and filled smoothly into the interior by
Laplace's equation (:func:`fluidymation.engine.flow.harmonic_fill`); affine fields are
harmonic, so the two parts add up to the harmonic interpolation of the outline's motion.

Elements are composited bottom to top: a pixel takes the motion of the topmost element
covering its centre. An element may be clipped (a Lottie layer's masks, its track matte,
a precomp's bounds): it then covers only the part of its outline the clip regions leave.
Flows are float32 ``(H, W, 2)`` holding ``(dx, dy)`` in px/frame, y down, and, as
elsewhere, ``flow[j]`` is the motion that brought the material to frame j.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from fluidymation.engine._jit import kernel
from fluidymation.engine.flow import harmonic_fill
from fluidymation.engine.sorting import argsort_prefix


_CLIP_MODES = ("add", "subtract", "intersect", "difference")


@dataclass(frozen=True)
class ClipPart:
    """One region of a :class:`Clip`: the union of ``elements``' coverage (their motion unused), complemented
    when ``inverted``, combined with the parts before it by ``mode``: ``add`` (union), ``subtract``,
    ``intersect`` or ``difference`` (exclusive or)."""

    elements: tuple
    mode: str = "add"
    inverted: bool = False

    def __post_init__(self):
        if self.mode not in _CLIP_MODES:
            raise ValueError(f"clip mode must be one of {', '.join(_CLIP_MODES)}, got {self.mode!r}")


@dataclass(frozen=True)
class Clip:
    """A region an element is cut to: its parts combined in order, as Lottie combines a layer's masks.

    The combination starts from everything when the first part subtracts or intersects,
    else from nothing.
    """

    parts: tuple
    _regions: dict = field(default_factory=dict, compare=False, repr=False)  # by raster shape: a clip shared by
    # many elements (a precomp's bounds) is filled once

    def region(self, shape: tuple[int, int]) -> np.ndarray:
        """(H, W) bool: the pixels the clip leaves."""
        shape = tuple(shape)
        if shape not in self._regions:
            self._regions[shape] = self._combined(shape)
        return self._regions[shape]

    def _combined(self, shape: tuple[int, int]) -> np.ndarray:
        left = np.full(shape, bool(self.parts) and self.parts[0].mode in ("intersect", "subtract"))
        for part in self.parts:
            region = np.zeros(shape, bool)
            for element in part.elements:
                region |= coverage(element, shape)
            if part.inverted:
                region = ~region
            if part.mode == "add":
                left |= region
            elif part.mode == "subtract":
                left &= ~region
            elif part.mode == "intersect":
                left &= region
            else:
                left ^= region
        return left


_MITER_LIMIT = 4.0  # SVG's default stroke-miterlimit: a sharper corner's offset is cut to this many half widths


def stroke_rings(points: np.ndarray, half_width: float, closed: bool) -> list[np.ndarray]:
    """The band within ``half_width`` of the line through ``points`` (N, 2) as rings to fill with nonzero winding.

    Each point is offset to both sides by the miter of the normals of the segments meeting
    there (along the normal on a smooth curve; at most ``_MITER_LIMIT`` half widths), so the
    same points at two frames give offsets that correspond. A closed line gives two rings of
    opposite turn; an open one a single ring around it, with flat ends.
    """
    points = np.asarray(points, np.float64)
    following = np.roll(points, -1, axis=0) if closed else points[1:]
    edges = following - (points if closed else points[:-1])
    length = np.linalg.norm(edges, axis=1)
    if not (length > 0).any():
        return []
    normals = np.column_stack([-edges[:, 1], edges[:, 0]]) / np.maximum(length, 1e-300)[:, None]
    kept = np.flatnonzero(length > 0)  # a zero-length segment takes the normal of the nearest one before it
    normals = normals[kept[np.maximum(np.searchsorted(kept, np.arange(len(edges)), side="right") - 1, 0)]]
    if closed:
        before, after = np.roll(normals, 1, axis=0), normals
    else:
        before, after = np.vstack([normals[:1], normals]), np.vstack([normals, normals[-1:]])
    miter = (before + after) / np.maximum(1.0 + (before * after).sum(axis=1), 2.0 / _MITER_LIMIT**2)[:, None]
    left, right = points + half_width * miter, points - half_width * miter
    return [left, right[::-1]] if closed else [np.vstack([left, right[::-1]])]


@dataclass(frozen=True)
class MovingElement:
    """One filled element at frame j and where its outline points were at frame j − 1.

    Attributes
    ----------
    now, before : ndarray, shape (N, 2), float32
        Outline points ``(x, y)`` in pixels at frame j and the same points at frame j − 1.
    ring_starts : ndarray, shape (R + 1,), int64
        Point ``ring_starts[r]`` up to ``ring_starts[r + 1]`` form closed ring r (an outline
        or a hole; the last point joins the first).
    even_odd : bool
        The element's fill rule: even-odd, or nonzero winding.
    clips : tuple of Clip
        Regions the element is cut to (its layer's masks, a track matte): it covers what its
        outline and every clip cover.
    """

    now: np.ndarray
    before: np.ndarray
    ring_starts: np.ndarray
    even_odd: bool = False
    clips: tuple = ()

    def __post_init__(self):
        now = np.ascontiguousarray(self.now, np.float32)
        before = np.ascontiguousarray(self.before, np.float32)
        starts = np.ascontiguousarray(self.ring_starts, np.int64)
        if now.ndim != 2 or now.shape[1] != 2 or before.shape != now.shape:
            raise ValueError(f"now and before must both be (N, 2), got {now.shape} and {before.shape}")
        if not (np.isfinite(now).all() and np.isfinite(before).all()):
            raise ValueError("outline points must be finite")
        if starts.ndim != 1 or starts.size < 2 or starts[0] != 0 or starts[-1] != now.shape[0] or np.any(
                np.diff(starts) < 0):
            raise ValueError("ring_starts must rise from 0 to the number of points")
        object.__setattr__(self, "now", now)
        object.__setattr__(self, "before", before)
        object.__setattr__(self, "ring_starts", starts)


@kernel
def _coverage(points, ring_starts, even_odd, out):
    """Mark the pixels whose centre lies inside the rings (scanline crossings per pixel row)."""
    height, width = out.shape
    total = points.shape[0]
    crossings = np.empty(total, np.float64)
    directions = np.empty(total, np.int64)
    order = np.empty(total, np.int64)
    for row in range(height):
        y = row + 0.5
        count = np.int64(0)  # not a literal 0: the sort would be compiled for it too
        for ring in range(ring_starts.shape[0] - 1):
            first = ring_starts[ring]
            last = ring_starts[ring + 1]
            for i in range(first, last):
                j = i + 1 if i + 1 < last else first
                y0 = points[i, 1]
                y1 = points[j, 1]
                if (y0 <= y) == (y1 <= y):  # half-open: a vertex on the line counts once
                    continue
                t = (y - y0) / (y1 - y0)
                crossings[count] = points[i, 0] + t * (points[j, 0] - points[i, 0])
                directions[count] = 1 if y1 > y0 else -1
                count += 1
        if count == 0:
            continue
        argsort_prefix(crossings, count, order)
        winding = 0
        for k in range(count - 1):
            winding += directions[order[k]]
            inside = (winding % 2 != 0) if even_odd else winding != 0
            if not inside:
                continue
            # clamped before the conversion: a far-away outline must not overflow the integers
            start = int(np.ceil(min(max(crossings[order[k]], -1.0), width + 1.0) - 0.5))
            stop = int(np.ceil(min(max(crossings[order[k + 1]], -1.0), width + 1.0) - 0.5))
            start = max(start, 0)
            stop = min(stop, width)
            for column in range(start, stop):
                out[row, column] = True


def coverage(element: MovingElement, shape: tuple[int, int]) -> np.ndarray:
    """(H, W) bool: the pixels whose centre the element covers at frame j, cut to each of its clips."""
    covered = np.zeros(shape, bool)
    _coverage(element.now.astype(np.float64), element.ring_starts, bool(element.even_odd), covered)
    for clip in element.clips:
        if covered.any():
            covered &= clip.region(shape)
    return covered


def _point_weights(element: MovingElement) -> np.ndarray:
    """Half the length of the two outline segments at each point: the share of the outline it stands for."""
    weights = np.zeros(element.now.shape[0], np.float64)
    for first, last in zip(element.ring_starts[:-1], element.ring_starts[1:]):
        ring = element.now[first:last].astype(np.float64)
        if ring.shape[0] == 0:
            continue
        lengths = np.linalg.norm(np.roll(ring, -1, axis=0) - ring, axis=1)
        weights[first:last] = 0.5 * (lengths + np.roll(lengths, 1))
    return weights


def _homogeneous(points: np.ndarray) -> np.ndarray:
    """(N, 2) points as rows ``(x, y, 1)``."""
    return np.column_stack([points, np.ones(points.shape[0])])


def affine_fit(element: MovingElement) -> np.ndarray:
    """The affine motion ``d(p) = M @ (x, y, 1)`` best fitting the outline's displacements, M (2, 3).

    Weighted least squares; with fewer than three independent points (a degenerate
    outline) the fit falls back to the mean displacement.
    """
    now = element.now.astype(np.float64)
    moved = now - element.before.astype(np.float64)
    weights = _point_weights(element)
    if weights.sum() <= 0.0:
        weights = np.ones_like(weights)
    design = _homogeneous(now) * np.sqrt(weights)[:, None]
    target = moved * np.sqrt(weights)[:, None]
    if np.linalg.matrix_rank(design) < 3:
        mean = (moved * weights[:, None]).sum(axis=0) / weights.sum()
        return np.array([[0.0, 0.0, mean[0]], [0.0, 0.0, mean[1]]])
    solution, *_ = np.linalg.lstsq(design, target, rcond=None)
    return solution.T


def element_flow(element: MovingElement, covered: np.ndarray, *, sweeps: int = 8) -> np.ndarray:
    """(N, 2) float32: the element's motion at the ``covered`` pixels, in the order of ``np.nonzero(covered)``.

    The affine fit, plus, where the outline deforms beyond it, the harmonic fill of the
    residual displacements from the outline points into ``covered``.
    """
    matrix = affine_fit(element)
    rows, columns = np.nonzero(covered)
    motion = _homogeneous(np.column_stack([columns + 0.5, rows + 0.5])) @ matrix.T
    now = element.now.astype(np.float64)
    residual = (now - element.before) - _homogeneous(now) @ matrix.T
    if np.abs(residual).max(initial=0.0) > 1e-3:
        values, fixed = _splat_outline(now, residual, covered.shape)
        motion += harmonic_fill(values, fixed, covered | fixed, sweeps=sweeps)[rows, columns]
    return motion.astype(np.float32)


def _splat_outline(points: np.ndarray, residual: np.ndarray, shape: tuple[int, int]):
    """The outline's residual displacements on the pixels nearest its points (mean where several meet)."""
    height, width = shape
    columns = np.clip(np.floor(points[:, 0]).astype(np.int64), 0, width - 1)
    rows = np.clip(np.floor(points[:, 1]).astype(np.int64), 0, height - 1)
    index = rows * width + columns
    counts = np.bincount(index, minlength=height * width)
    values = np.zeros((height * width, 2), np.float64)
    for axis in range(2):
        values[:, axis] = np.bincount(index, weights=residual[:, axis], minlength=height * width)
    fixed = counts > 0
    values[fixed] /= counts[fixed][:, None]
    return values.reshape(height, width, 2).astype(np.float32), fixed.reshape(height, width)


def vector_flow(elements: list[MovingElement], shape: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """The motion of the topmost element at each pixel, elements given bottom to top.

    Returns ``(flow, owned)``: (H, W, 2) float32, zero where no element covers a pixel, and
    (H, W) bool, the pixels some element covers.
    """
    flow = np.zeros(tuple(shape) + (2,), np.float32)
    owned = np.zeros(tuple(shape), bool)
    for element in elements:
        covered = coverage(element, shape)
        if not covered.any():
            continue
        flow[covered] = element_flow(element, covered)
        owned |= covered
    return flow, owned
