"""A dry pigment (charcoal, pastel) area crumbling away from its edges.

The model is geometric rather than mechanical. Every pixel of the area gets the time at
which the eroding front reaches it: the geodesic distance from the area's boundary
through a random, smoothly varying resistance (shortest paths with Dijkstra on the
8-neighbour grid), so the front advances unevenly. The area is split into fragments
(Voronoi cells of random sites); a fragment breaks off nearly as a whole once the front
touches it, so the edge recedes in chunks, and hairline cracks open along the fragment
borders just before they fall. The velocity of the receding edge is exact for this
model: the front moves along ∇T with speed 1/|∇T| (T the smooth arrival time), so the
flow points inward, where the edge (the material's boundary) goes.
"""

from __future__ import annotations

import heapq

import numpy as np
from scipy import ndimage

from fluidymation.engine._jit import kernel

__all__ = ["arrival_times", "simulate_crumble"]

_SQRT2 = 1.4142135623730951


@kernel
def _arrival_times(cost, inside):
    """Dijkstra from the boundary: time for the front to reach each inside pixel."""
    height, width = cost.shape
    times = np.full((height, width), np.inf)
    heap = [(0.0, np.int64(0))]
    heap.pop()
    for y in range(height):
        for x in range(width):
            if not inside[y, x]:
                continue
            exposed = y == 0 or x == 0 or y == height - 1 or x == width - 1
            for dy in range(-1, 2):
                for dx in range(-1, 2):
                    ny, nx = y + dy, x + dx
                    if 0 <= ny < height and 0 <= nx < width and not inside[ny, nx]:
                        exposed = True
            if exposed:
                times[y, x] = 0.5 * cost[y, x]
                heapq.heappush(heap, (times[y, x], np.int64(y * width + x)))
    while len(heap) > 0:
        time, index = heapq.heappop(heap)
        y, x = index // width, index % width
        if time > times[y, x]:
            continue
        for dy in range(-1, 2):
            for dx in range(-1, 2):
                ny, nx = y + dy, x + dx
                if (dy == 0 and dx == 0) or ny < 0 or nx < 0 or ny >= height or nx >= width or not inside[ny, nx]:
                    continue
                step = _SQRT2 if dy != 0 and dx != 0 else 1.0
                candidate = time + 0.5 * (cost[y, x] + cost[ny, nx]) * step
                if candidate < times[ny, nx]:
                    times[ny, nx] = candidate
                    heapq.heappush(heap, (candidate, np.int64(ny * width + nx)))
    return times


def arrival_times(inside, cost):
    """Time for a front starting at the boundary of ``inside`` to reach each pixel.

    Parameters
    ----------
    inside : (H, W) bool
        The area; pixels next to the outside (or the canvas border) start the front.
    cost : (H, W) float
        Positive time per pixel of travel (the inverse of the local front speed).

    Returns
    -------
    (H, W) float64, ``inf`` outside the area.
    """
    inside = np.ascontiguousarray(inside, dtype=np.bool_)
    cost = np.ascontiguousarray(cost, dtype=np.float64)
    if inside.ndim != 2 or cost.shape != inside.shape:
        raise ValueError(f"inside and cost must be 2-D arrays of one shape, got {inside.shape} and {cost.shape}")
    if np.any(cost[inside] <= 0):
        raise ValueError("cost must be positive inside the area")
    return _arrival_times(cost, inside)


def simulate_crumble(
    area, *, paper_height, seed, frames, fragment_size=6.0, roughness=0.7, chunkiness=0.75, remaining=0.25,
    crack_frames=4.0, max_speed=6.0,
):
    """Erode ``area`` from its edges over ``frames`` frames; yield one record per frame.

    Parameters
    ----------
    area : (H, W) bool
        The intact pigment at frame 0.
    paper_height : (H, W) float
        Paper height in [0, 1]; dry pigment sits on the peaks.
    seed : int
        Seed of the fragment sites and the resistance field.
    frames : int
        Number of frames; frame 0 is intact, the last keeps ``remaining`` of the area.
    fragment_size : float
        Typical fragment diameter in pixels.
    roughness : float
        Spread of the log resistance (0: a uniform, distance-driven front).
    chunkiness : float in [0, 1]
        0: pixels fall one by one; 1: each fragment falls at once.
    crack_frames : float
        How many frames before a fragment falls its border cracks start to open.
    max_speed : float
        Cap on the reported edge speed, px/frame (the front's speed diverges on ridges).

    Yields
    ------
    thickness : (H, W) float32
        Pigment layer thickness (about 1 for intact charcoal).
    mask : (H, W) bool
        The intact material; shrinks monotonically.
    flow : (H, W, 2) float32
        Velocity of the receding edge inside the mask, px/frame, (dx, dy), y down.
    """
    area = np.asarray(area, dtype=bool)
    paper_height = np.asarray(paper_height, dtype=np.float32)
    if area.ndim != 2 or paper_height.shape != area.shape:
        raise ValueError("area and paper_height must be 2-D arrays of one shape")
    if not area.any():
        raise ValueError("area is empty")
    if frames < 2 or not 0.0 < remaining < 1.0 or not 0.0 <= chunkiness <= 1.0 or fragment_size < 1.0:
        raise ValueError("need frames >= 2, 0 < remaining < 1, 0 <= chunkiness <= 1, fragment_size >= 1")
    rng = np.random.default_rng(seed)
    shape = area.shape

    field = ndimage.gaussian_filter(rng.standard_normal(shape), 2.0 * fragment_size, mode="wrap")
    cost = np.exp(roughness * field / max(float(field.std()), 1e-12))
    smooth_time = arrival_times(area, cost)

    labels = _fragments(shape, fragment_size, rng)
    count = int(labels.max()) + 1
    first_touch = np.full(count, np.inf)
    np.minimum.at(first_touch, labels[area], smooth_time[area])
    jitter = rng.uniform(0.0, 0.5 * fragment_size * float(np.median(cost[area])), count)
    fragment_time = first_touch + jitter
    fall_time = np.where(area, (1.0 - chunkiness) * smooth_time + chunkiness * fragment_time[labels], np.inf)

    end_time = float(np.quantile(fall_time[area], 1.0 - remaining))
    time_per_frame = end_time / (frames - 1)
    velocity = _front_velocity(np.where(area, smooth_time, 0.0), area, time_per_frame, max_speed)
    crack = _fragment_borders(labels) & area
    texture = (0.45 + 0.75 * paper_height**1.5).astype(np.float32)
    streaks = ndimage.gaussian_filter(rng.standard_normal(shape), (0.8, 5.0))
    texture *= (1.0 + 0.15 * streaks / max(float(streaks.std()), 1e-12)).astype(np.float32)
    texture = np.clip(texture, 0.05, None)
    for frame in range(frames):
        now = frame * time_per_frame
        mask = area & (fall_time > now)
        thickness = np.where(mask, texture, 0.08 * texture * area).astype(np.float32)
        opening = np.clip(1.0 - (fall_time - now) / (crack_frames * time_per_frame), 0.0, 1.0)
        thickness = np.where(mask & crack, thickness * (1.0 - 0.8 * opening), thickness).astype(np.float32)
        flow = np.where(mask[:, :, None], velocity, 0.0).astype(np.float32)
        yield thickness, mask, flow


def _fragments(shape, fragment_size, rng):
    """Voronoi labels (H, W) int64 of random sites about ``fragment_size`` apart."""
    sites = rng.random(shape) < 1.0 / (fragment_size * fragment_size)
    if not sites.any():
        sites[shape[0] // 2, shape[1] // 2] = True
    _, (rows, cols) = ndimage.distance_transform_edt(~sites, return_indices=True)
    _, labels = np.unique(rows * shape[1] + cols, return_inverse=True)
    return labels.reshape(shape)


def _fragment_borders(labels):
    border = np.zeros(labels.shape, dtype=bool)
    border[:, 1:] |= labels[:, 1:] != labels[:, :-1]
    border[1:, :] |= labels[1:, :] != labels[:-1, :]
    return border


def _front_velocity(times, area, time_per_frame, max_speed):
    """(H, W, 2) float32: ∇T/|∇T|² per frame, the speed capped at ``max_speed``."""
    smooth = ndimage.gaussian_filter(times, 1.5)
    weight = ndimage.gaussian_filter(area.astype(np.float64), 1.5)
    smooth = np.where(area, smooth / np.maximum(weight, 1e-6), 0.0)
    grad_y, grad_x = np.gradient(smooth)
    norm2 = grad_x * grad_x + grad_y * grad_y
    speed = time_per_frame / np.sqrt(np.maximum(norm2, 1e-12))
    scale = np.minimum(speed, max_speed) / np.sqrt(np.maximum(norm2, 1e-12))
    velocity = np.stack([grad_x * scale, grad_y * scale], axis=-1)
    return np.where(area[:, :, None], velocity, 0.0).astype(np.float32)
