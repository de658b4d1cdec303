"""Mask preprocessing, signed distance fields and the channels derived from them.

Masks are ``(H, W)`` coverage arrays (float in [0, 1]). Preprocessing (thesis 4.1)
blurs them (:func:`gaussian_blur`) and thresholds them below 0.5 so the mask is smooth
and includes a little paper; :func:`signed_distance` does the thresholding and places
the boundary with sub-pixel precision, so the distance changes smoothly when a shape
moves by a fraction of a pixel. The mask itself is ``dist > 0``.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import ndimage

from fluidymation.engine._jit import kernel

#: Smallest |distance| given to a pixel, so that inside is exactly ``dist > 0``.
_MIN_DISTANCE = 1e-4
#: Largest sideways offset (px) of a boundary foot for which a pixel measures its
#: distance to the tangent there rather than to the foot point.
_TANGENT_REACH = 1.5
#: Half-size of the window around the nearest boundary pixel searched for the foot.
_FOOT_SEARCH = 2

OUTSIDE = 0
BORDER = 1
INTERIOR = 2


def gaussian_weights(sigma: float) -> np.ndarray:
    """Normalized Gaussian taps of standard deviation ``sigma`` truncated at 3·sigma.

    Returns a float32 array of odd length ``2r + 1`` with ``r = ceil(3·sigma)``;
    ``sigma <= 0`` gives the identity ``[1]``.
    """
    if sigma <= 0:
        return np.ones(1, dtype=np.float32)
    radius = int(math.ceil(3.0 * sigma))
    offsets = np.arange(-radius, radius + 1, dtype=np.float64)
    taps = np.exp(-0.5 * (offsets / sigma) ** 2)
    return (taps / taps.sum()).astype(np.float32)


@kernel
def _blur_rows(image, taps, out):
    height, width = image.shape
    radius = taps.shape[0] // 2
    for y in range(height):
        # the row extended by its end pixels, so the tap loop runs over contiguous memory
        padded = np.empty(width + 2 * radius, dtype=np.float32)
        padded[:radius] = image[y, 0]
        for x in range(width):
            padded[radius + x] = image[y, x]
        padded[radius + width:] = image[y, width - 1]
        for x in range(width):
            out[y, x] = 0.0
        for k in range(2 * radius + 1):
            weight = taps[k]
            for x in range(width):
                out[y, x] += weight * padded[x + k]


@kernel
def _blur_columns(image, taps, out):
    height, width = image.shape
    radius = taps.shape[0] // 2
    for y in range(height):
        for x in range(width):
            out[y, x] = 0.0
        for k in range(-radius, radius + 1):
            ys = min(max(y + k, 0), height - 1)
            weight = taps[k + radius]
            for x in range(width):
                out[y, x] += weight * image[ys, x]


def gaussian_blur(image: np.ndarray, *, sigma: float) -> np.ndarray:
    """Blur an ``(H, W)`` image with a Gaussian of standard deviation ``sigma`` px.

    Separable, truncated at 3·sigma, edges extended by repeating the border pixel.
    Only the bounding box of the nonzero pixels, widened by the kernel's radius, is
    computed (masks are mostly zero); the rest of the result is zero.
    Returns float32 ``(H, W)``.
    """
    image = np.ascontiguousarray(image, dtype=np.float32)
    if image.ndim != 2:
        raise ValueError(f"gaussian_blur expects an (H, W) image, got shape {image.shape}")
    taps = gaussian_weights(sigma)
    if taps.shape[0] == 1:
        return image.copy()
    radius = taps.shape[0] // 2
    out = np.zeros_like(image)
    rows = np.flatnonzero(image.any(axis=1))
    if rows.size == 0:
        return out
    columns = np.flatnonzero(image.any(axis=0))
    box = (
        slice(max(rows[0] - radius, 0), rows[-1] + radius + 1),
        slice(max(columns[0] - radius, 0), columns[-1] + radius + 1),
    )
    # beyond the box the image is zero for at least a radius, so the box's own
    # extended edges see the same zeros
    crop = np.ascontiguousarray(image[box])
    along_rows = np.empty_like(crop)
    _blur_rows(crop, taps, along_rows)
    _blur_columns(along_rows, taps, crop)
    out[box] = crop
    return out


@kernel
def _boundary_feet(coverage, threshold, mask, seed, foot_y, foot_x, normal_y, normal_x):
    """Mark pixels with a 4-neighbour on the other side of the mask as seeds and put
    on each the foot of the perpendicular to the level set ``coverage = threshold``
    (the feet and normals are left unset on other pixels)."""
    height, width = mask.shape
    for y in range(height):
        for x in range(width):
            inside = mask[y, x]
            seed[y, x] = (
                (x > 0 and mask[y, x - 1] != inside)
                or (x < width - 1 and mask[y, x + 1] != inside)
                or (y > 0 and mask[y - 1, x] != inside)
                or (y < height - 1 and mask[y + 1, x] != inside)
            )
            if not seed[y, x]:
                continue
            value = coverage[y, x] - threshold
            x0 = max(x - 1, 0)
            x1 = min(x + 1, width - 1)
            y0 = max(y - 1, 0)
            y1 = min(y + 1, height - 1)
            grad_x = (coverage[y, x1] - coverage[y, x0]) / max(x1 - x0, 1)
            grad_y = (coverage[y1, x] - coverage[y0, x]) / max(y1 - y0, 1)
            norm = math.sqrt(grad_x * grad_x + grad_y * grad_y)
            best = 2.0
            best_nx = 0.0
            best_ny = 0.0
            for k in range(4):
                dx = 1 if k == 0 else -1 if k == 1 else 0
                dy = 1 if k == 2 else -1 if k == 3 else 0
                nx = x + dx
                ny = y + dy
                if nx < 0 or nx >= width or ny < 0 or ny >= height or mask[ny, nx] == inside:
                    continue
                # where the coverage crosses the threshold along this axis, as a
                # fraction of the step, then projected on the level set's normal
                step = value / (coverage[y, x] - coverage[ny, nx]) if coverage[y, x] != coverage[ny, nx] else 0.5
                step = min(max(step, 0.0), 1.0)
                towards_x = float(dx)
                towards_y = float(dy)
                along = 1.0
                if norm > 0.0:
                    gx = -grad_x / norm if inside else grad_x / norm
                    gy = -grad_y / norm if inside else grad_y / norm
                    if gx * dx + gy * dy > 0.0:
                        towards_x = gx
                        towards_y = gy
                        along = gx * dx + gy * dy
                reach = step * along
                if reach < best:
                    best = reach
                    best_nx = towards_x
                    best_ny = towards_y
            foot_x[y, x] = x + best * best_nx
            foot_y[y, x] = y + best * best_ny
            normal_x[y, x] = best_nx
            normal_y[y, x] = best_ny


@kernel
def _nearby_seeds(seed_index, seed_y, seed_x, counts, neighbours):
    """For every seed, the seeds within ``_FOOT_SEARCH`` rows and columns of it (itself
    included), in row-major order."""
    height, width = seed_index.shape
    for seed in range(seed_y.shape[0]):
        count = 0
        for cy in range(max(seed_y[seed] - _FOOT_SEARCH, 0), min(seed_y[seed] + _FOOT_SEARCH + 1, height)):
            for cx in range(max(seed_x[seed] - _FOOT_SEARCH, 0), min(seed_x[seed] + _FOOT_SEARCH + 1, width)):
                if seed_index[cy, cx] >= 0:
                    neighbours[seed, count] = seed_index[cy, cx]
                    count += 1
        counts[seed] = count


@kernel
def _distance_to_feet(nearest, seed_index, counts, neighbours, feet, mask, out):
    """``feet`` holds per seed its foot (y, x) and the boundary normal there (y, x)."""
    height, width = mask.shape
    for y in range(height):
        for x in range(width):
            # the nearest boundary pixel by pixel centres need not have the nearest
            # foot: take the best foot among the boundary pixels around it
            near = seed_index[nearest[0, y, x], nearest[1, y, x]]
            best_squared = np.inf
            best = near
            for k in range(counts[near]):
                candidate = neighbours[near, k]
                squared = (y - feet[0, candidate]) ** 2 + (x - feet[1, candidate]) ** 2
                if squared < best_squared:
                    best_squared = squared
                    best = candidate
            dy = y - feet[0, best]
            dx = x - feet[1, best]
            # distance to the boundary's tangent at the foot, unless the foot lies far
            # to the side (corners), where the distance to the foot itself is better
            across = abs(dx * feet[3, best] + dy * feet[2, best])
            sideways = abs(dx * feet[2, best] - dy * feet[3, best])
            length = across if sideways <= _TANGENT_REACH else math.sqrt(best_squared)
            length = max(length, _MIN_DISTANCE)
            out[y, x] = length if mask[y, x] else -length


def signed_distance(coverage: np.ndarray, *, threshold: float = 0.5) -> np.ndarray:
    """Euclidean signed distance to the level set ``coverage = threshold``, positive inside.

    The boundary is located with sub-pixel precision: on every pixel next to the other
    side, the crossing of the threshold is interpolated linearly along the pixel axes
    and projected on the coverage gradient; every pixel then measures its distance to
    the boundary's tangent at the foot point of its nearest such boundary pixel
    (found by scipy's exact EDT). For a binary
    mask the crossing lies on the pixel edge, so neighbours across a straight boundary
    get +0.5 and -0.5.

    Parameters
    ----------
    coverage : (H, W) float or bool
        Inside is ``coverage >= threshold``.
    threshold : float

    Returns
    -------
    (H, W) float32
        Positive inside (at least 1e-4), negative outside. A mask that is empty (or
        full) has no boundary: every pixel gets minus (plus) the image diagonal.
    """
    coverage = np.ascontiguousarray(coverage, dtype=np.float32)
    if coverage.ndim != 2:
        raise ValueError(f"signed_distance expects an (H, W) array, got shape {coverage.shape}")
    mask = coverage >= np.float32(threshold)
    if not mask.any() or mask.all():
        diagonal = math.hypot(*mask.shape)
        return np.full(mask.shape, diagonal if mask.all() else -diagonal, dtype=np.float32)
    seed = np.empty(mask.shape, dtype=np.bool_)
    foot_y, foot_x, normal_y, normal_x = np.empty((4,) + mask.shape, dtype=np.float32)
    _boundary_feet(coverage, np.float32(threshold), mask, seed, foot_y, foot_x, normal_y, normal_x)
    nearest = ndimage.distance_transform_edt(~seed, return_distances=False, return_indices=True)
    seed_y, seed_x = np.nonzero(seed)
    seed_index = np.full(mask.shape, -1, dtype=np.int64)
    seed_index[seed_y, seed_x] = np.arange(seed_y.size)
    counts = np.empty(seed_y.size, dtype=np.int64)
    neighbours = np.empty((seed_y.size, (2 * _FOOT_SEARCH + 1) ** 2), dtype=np.int64)
    _nearby_seeds(seed_index, seed_y, seed_x, counts, neighbours)
    feet = np.stack([array[seed_y, seed_x] for array in (foot_y, foot_x, normal_y, normal_x)])
    out = np.empty(mask.shape, dtype=np.float32)
    _distance_to_feet(np.ascontiguousarray(nearest, dtype=np.int32), seed_index, counts, neighbours, feet, mask, out)
    return out


def shape_channel(mask: np.ndarray, *, radius: float) -> np.ndarray:
    """The ``shape`` guide: the binary mask blurred by a Gaussian of radius ``radius`` px.

    The radius is the kernel's extent, 3 standard deviations. Returns float32 ``(H, W)``
    in [0, 1].
    """
    return gaussian_blur(np.asarray(mask, dtype=np.float32), sigma=radius / 3.0)


def edge_factor(dist: np.ndarray, *, border_width: float) -> np.ndarray:
    """``df = min(dist / border_width, 1)`` (thesis 3.4), float32 ``(H, W)``."""
    if border_width <= 0:
        raise ValueError(f"border_width must be positive, got {border_width}")
    return np.minimum(np.asarray(dist, dtype=np.float32) / np.float32(border_width), np.float32(1.0))


def segments(dist: np.ndarray, *, border_width: float) -> np.ndarray:
    """Split a mask into border and interior segments by its signed distance.

    Returns uint8 ``(H, W)``: ``OUTSIDE`` (0) where ``dist <= 0``, ``BORDER`` (1) where
    ``0 < dist < border_width`` (df < 1) and ``INTERIOR`` (2) where ``df = 1``.
    """
    if border_width <= 0:
        raise ValueError(f"border_width must be positive, got {border_width}")
    dist = np.asarray(dist, dtype=np.float32)
    labels = np.full(dist.shape, OUTSIDE, dtype=np.uint8)
    labels[dist > 0] = BORDER
    labels[dist >= np.float32(border_width)] = INTERIOR
    return labels
