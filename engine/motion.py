"""Motion between two frames by grid-based PatchMatch (seed 004, "grid-based PatchMatch").

Correspondences are searched only at the vertices of a regular grid (spacing ``spacing``
px): each vertex's block in the current frame is matched in the previous frame by
PatchMatch (k-coherent propagation from the grid neighbours, random search in windows
halving from ``search_radius``), refined to sub-pixel precision by a parabola through
the costs of the neighbouring integer offsets, then the dense flow is the bilinear
interpolation of the vertex motions. The flow of frame k is the motion from frame k−1 to
k at frame k's pixels, ``(dx, dy)`` px/frame with y down, as everywhere in Fluidymation.
The vertices are visited in scan order (reverse on odd iterations), serially, and random
numbers come from a counter-based hash, so the result is deterministic; a vertex whose match
is exact (still paper) is not searched again. :func:`motion_sequence` estimates the
frame pairs of a sequence on numba's threads at once (the kernels release the GIL), each
pair as :func:`estimate_motion` alone would.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numba
import numpy as np

from fluidymation.engine._jit import kernel
from fluidymation.engine.random import _key4, _random_below


@kernel
def _block_cost(current, previous, cx, cy, dx, dy, half, limit):
    """SSD between the block around (cx, cy) in ``current`` and around (cx+dx, cy+dy) in
    ``previous``, coordinates clamped to the frames; stops early once over ``limit``."""
    height, width, channels = current.shape
    total = 0.0
    for oy in range(-half, half + 1):
        ya = min(max(cy + oy, 0), height - 1)
        yb = min(max(cy + dy + oy, 0), height - 1)
        for ox in range(-half, half + 1):
            xa = min(max(cx + ox, 0), width - 1)
            xb = min(max(cx + dx + ox, 0), width - 1)
            for c in range(channels):
                diff = current[ya, xa, c] - previous[yb, xb, c]
                total += diff * diff
        if total > limit:
            return total
    return total


@kernel
def _grid_patchmatch(current, previous, spacing, half, search_radius, iterations, seed, frame):
    """Integer displacement (dx, dy) into ``previous`` for each grid vertex of ``current``."""
    height, width = current.shape[:2]
    rows = (height - 1) // spacing + 1
    cols = (width - 1) // spacing + 1
    offset = np.zeros((rows, cols, 2), np.int64)
    cost = np.empty((rows, cols), np.float64)
    key = _key4(seed, frame, 0, 0)
    draw = 0
    windows = 0  # random-search windows per vertex: radii search_radius, halved, down to 1
    radius = search_radius
    while radius >= 1:
        windows += 1
        radius //= 2
    for gy in range(rows):
        for gx in range(cols):
            dx = _random_below(key, draw, 2 * search_radius + 1) - search_radius
            dy = _random_below(key, draw + 1, 2 * search_radius + 1) - search_radius
            draw += 2
            offset[gy, gx, 0] = dx
            offset[gy, gx, 1] = dy
            cost[gy, gx] = _block_cost(current, previous, gx * spacing, gy * spacing, dx, dy, half, np.inf)
    for iteration in range(iterations):
        step = 1 if iteration % 2 == 0 else -1
        improved = 0
        for index in range(rows * cols):
            flat = index if step == 1 else rows * cols - 1 - index
            gy = flat // cols
            gx = flat % cols
            if cost[gy, gx] == 0.0:  # an exact match (still paper, say): no candidate can be lower
                draw += 2 * windows  # the random numbers its search would have drawn
                continue
            cx = gx * spacing
            cy = gy * spacing
            best_dx = offset[gy, gx, 0]
            best_dy = offset[gy, gx, 1]
            best = cost[gy, gx]
            # k-coherent propagation: the neighbours' matches, and shifts by one grid step around them
            for n in range(5):
                ny = gy + (0, 0, 1, 0, -1)[n]
                nx = gx + (0, 1, 0, -1, 0)[n]
                if ny < 0 or ny >= rows or nx < 0 or nx >= cols:
                    continue
                for s in range(5):
                    dx = offset[ny, nx, 0] + (0, 1, 0, -1, 0)[s]
                    dy = offset[ny, nx, 1] + (0, 0, 1, 0, -1)[s]
                    if abs(dx) > search_radius or abs(dy) > search_radius:
                        continue
                    if dx == best_dx and dy == best_dy:
                        continue
                    candidate = _block_cost(current, previous, cx, cy, dx, dy, half, best)
                    if candidate < best:
                        best, best_dx, best_dy = candidate, dx, dy
            radius = search_radius
            while radius >= 1:
                dx = best_dx + _random_below(key, draw, 2 * radius + 1) - radius
                dy = best_dy + _random_below(key, draw + 1, 2 * radius + 1) - radius
                draw += 2
                if abs(dx) <= search_radius and abs(dy) <= search_radius:
                    candidate = _block_cost(current, previous, cx, cy, dx, dy, half, best)
                    if candidate < best:
                        best, best_dx, best_dy = candidate, dx, dy
                radius //= 2
            if best < cost[gy, gx]:
                improved += 1
            offset[gy, gx, 0] = best_dx
            offset[gy, gx, 1] = best_dy
            cost[gy, gx] = best
        if improved == 0:
            break
    return offset, cost


@kernel
def _subpixel(current, previous, offset, cost, spacing, half):
    """Refine integer offsets by a parabola through the costs at ±1 px in x and in y."""
    rows, cols = cost.shape
    refined = np.empty((rows, cols, 2), np.float32)
    for gy in range(rows):
        for gx in range(cols):
            cx = gx * spacing
            cy = gy * spacing
            centre = cost[gy, gx]
            for axis in range(2):
                ex = 1 if axis == 0 else 0
                ey = 1 - ex
                dx = offset[gy, gx, 0]
                dy = offset[gy, gx, 1]
                minus = _block_cost(current, previous, cx, cy, dx - ex, dy - ey, half, np.inf)
                plus = _block_cost(current, previous, cx, cy, dx + ex, dy + ey, half, np.inf)
                curvature = minus - 2.0 * centre + plus
                shift = 0.0
                if curvature > 1e-12 and minus >= centre and plus >= centre:
                    shift = 0.5 * (minus - plus) / curvature
                refined[gy, gx, axis] = offset[gy, gx, axis] + shift
    return refined


@kernel
def _bilinear_fill(vertex_values, spacing, height, width):
    """Dense (H, W, 2) field from values at grid vertices (x = gx·spacing, y = gy·spacing)."""
    rows, cols = vertex_values.shape[:2]
    dense = np.empty((height, width, 2), np.float32)
    for y in range(height):
        fy = y / spacing
        y0 = min(int(fy), rows - 1)
        y1 = min(y0 + 1, rows - 1)
        ty = fy - y0 if y1 > y0 else 0.0
        for x in range(width):
            fx = x / spacing
            x0 = min(int(fx), cols - 1)
            x1 = min(x0 + 1, cols - 1)
            tx = fx - x0 if x1 > x0 else 0.0
            for c in range(2):
                top = vertex_values[y0, x0, c] * (1 - tx) + vertex_values[y0, x1, c] * tx
                bottom = vertex_values[y1, x0, c] * (1 - tx) + vertex_values[y1, x1, c] * tx
                dense[y, x, c] = top * (1 - ty) + bottom * ty
    return dense


def estimate_motion(previous, current, *, spacing=3, patch_size=9, search_radius=16, iterations=12,
                    seed=0, frame=0):
    """Flow from ``previous`` to ``current`` at ``current``'s pixels.

    Parameters
    ----------
    previous, current : (H, W, C) float32
        Consecutive frames (colour in [0, 1]).
    spacing : int
        Grid spacing in px.
    patch_size : int
        Odd side of the compared blocks.
    search_radius : int
        Largest displacement searched, px per frame.
    iterations : int
        PatchMatch iterations at most (stops early when nothing improves).
    seed, frame : int
        Select the random numbers.

    Returns
    -------
    (H, W, 2) float32
        ``(dx, dy)`` px/frame: where the material at each pixel of ``current`` came from
        is ``pixel − flow``.
    """
    previous = np.ascontiguousarray(previous, dtype=np.float32)
    current = np.ascontiguousarray(current, dtype=np.float32)
    if previous.shape != current.shape or current.ndim != 3:
        raise ValueError(f"frames must be (H, W, C) of one shape, got {previous.shape} and {current.shape}")
    if spacing < 1 or patch_size < 1 or patch_size % 2 == 0 or search_radius < 1 or iterations < 1:
        raise ValueError("spacing, search_radius and iterations must be >= 1 and patch_size odd")
    half = patch_size // 2
    offset, cost = _grid_patchmatch(current, previous, spacing, half, search_radius, iterations, seed, frame)
    refined = _subpixel(current, previous, offset, cost, spacing, half)
    return -_bilinear_fill(refined, spacing, current.shape[0], current.shape[1])


def motion_sequence(frames, *, progress=None, seed=0, **options):
    """Flows of consecutive frames: ``flow[k]`` from frame k−1 to k (as :func:`estimate_motion` with ``frame=k``)
    for k ≥ 1, and ``flow[0] = flow[1]``; the pairs on numba's threads, the result independent of their count.

    Parameters
    ----------
    frames : (T, H, W, C) float32, T ≥ 2
    progress : callable, optional
        ``progress(done, total)`` as pairs finish, in order.
    seed, options
        As :func:`estimate_motion`.

    Returns
    -------
    (T, H, W, 2) float32
    """
    count = len(frames)
    flow = np.zeros(np.shape(frames)[:3] + (2,), np.float32)

    def pair(k):
        return estimate_motion(frames[k - 1], frames[k], seed=seed, frame=k, **options)

    with ThreadPoolExecutor(max_workers=max(1, min(numba.get_num_threads(), count - 1))) as pool:
        for k, result in enumerate(pool.map(pair, range(1, count)), start=1):
            flow[k] = result
            if progress is not None:
                progress(k, count - 1)
    flow[0] = flow[1]
    return flow
