"""Quality metrics of stylized layers (issue 15): seams, blocks, wash-out, coherence, fidelity.

Plain numpy/scipy functions on float RGB frames (sRGB in [0, 1], (H, W, 3) or more
channels, of which the first three are used) and masks ((H, W) coverage in [0, 1] or
bool; a pixel is inside at coverage ≥ 0.5). Luminance is the mean of R, G and B.
``tests/benchmarks/bench_quality.py`` applies them to stylized scenes and to the
exemplar's own frames; docs/quality.md explains each figure and the thresholds.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from fluidymation.engine.sampling import sample_back


def luminance(rgb: np.ndarray) -> np.ndarray:
    """Mean of the R, G and B channels, float64 (H, W)."""
    return rgb[..., :3].mean(axis=-1, dtype=np.float64)


def inside(mask: np.ndarray) -> np.ndarray:
    """Where the layer is: coverage ≥ 0.5 (bool masks as they are)."""
    return np.asarray(mask) >= 0.5


def inside_eroded(mask: np.ndarray, margin: int) -> np.ndarray:
    """:func:`inside`, eroded by ``margin`` px (0: as it is; scipy would erode a 0-iteration call to nothing)."""
    kept = inside(mask)
    return ndimage.binary_erosion(kept, iterations=margin) if margin else kept


def edge_distance(mask: np.ndarray) -> np.ndarray:
    """Euclidean distance (px) of each inside pixel to the nearest outside pixel centre; 0 outside.

    A pixel next to the outside is at 1, so band k of :func:`gradient_profile` is the
    k-th ring of pixels in from the edge (k ≤ distance < k + 1).
    """
    return ndimage.distance_transform_edt(inside(mask))


def gradient_profile(frames, masks, *, bands: int = 41) -> tuple[np.ndarray, np.ndarray]:
    """Mean luminance-gradient magnitude per 1-px band of distance from the mask edge, over all frames.

    The gradient is the central difference (``np.gradient``) of the luminance; band k
    holds the inside pixels with k ≤ :func:`edge_distance` < k + 1. A seam parallel to
    the edge (a light line where two differently synthesized regions meet) shows as a
    peak of this profile at its distance. Returns (profile, pixel counts), both (bands,).
    """
    sums = np.zeros(bands)
    counts = np.zeros(bands, np.int64)
    for rgb, mask in zip(frames, masks):
        gy, gx = np.gradient(luminance(rgb))
        band = np.floor(edge_distance(mask)).astype(np.int64)
        keep = inside(mask) & (band < bands)
        sums += np.bincount(band[keep], weights=np.hypot(gx, gy)[keep], minlength=bands)
        counts += np.bincount(band[keep], minlength=bands)
    with np.errstate(invalid="ignore"):
        return sums / counts, counts


def fitting_bands(counts: np.ndarray, *, first: int = 5, last: int = 40, min_pixels: int = 100) -> range:
    """The bands ``first..last`` of a :func:`gradient_profile` that fit the shape: each holds at least
    ``min_pixels`` pixels, stopping at the first that does not (near the medial axis a band holds few)."""
    usable = counts[first:last + 1] >= min_pixels
    return range(first, first + (int(np.argmin(usable)) if not usable.all() else len(usable)))


def profile_peak_ratio(profile: np.ndarray, counts: np.ndarray, **bands) -> tuple[float, int]:
    """Peak over median of a :func:`gradient_profile` over the :func:`fitting_bands` (1.0: flat).

    ``bands`` are :func:`fitting_bands`' options. Returns (ratio, band of the peak);
    (nan, −1) when fewer than three bands fit.
    """
    chosen = fitting_bands(counts, **bands)
    if len(chosen) < 3:
        return float("nan"), -1
    values = profile[chosen.start:chosen.stop]
    return float(values.max() / np.median(values)), chosen.start + int(np.argmax(values))


def blockiness(frames, masks, *, periods=(2,), margin: int = 2) -> tuple[float, int]:
    """How much a pixel grid of period p shows: the largest ratio of mean |Δ luminance| across
    boundaries on the grid to that across the other boundaries (1.0: no grid).

    For each axis (x, y) the absolute luminance differences of horizontally (vertically)
    adjacent pixel pairs are taken where both pixels are inside the mask eroded by
    ``margin`` px, pooled over all frames. A pair straddles the boundary at position i
    (between pixels i − 1 and i); for period p and phase φ < p the ratio is
    mean(|Δ| where i ≡ φ mod p) / mean(|Δ| where i ≢ φ mod p). Blockiness is the maximum
    over axes, phases and ``periods``. With the default p = 2 it is max(even/odd, odd/even)
    boundaries over both axes: the stylizer's blocks are 2 px (at period 4 their pattern
    is the period-2 one). Returns (blockiness, the period that gave it).
    """
    sums = {(axis, p): np.zeros(p) for axis in (0, 1) for p in periods}
    counts = {(axis, p): np.zeros(p) for axis in (0, 1) for p in periods}
    for rgb, mask in zip(frames, masks):
        lum = luminance(rgb)
        region = inside_eroded(mask, margin)
        for axis in (0, 1):
            step = np.abs(np.diff(lum, axis=axis))
            both = region[1:] & region[:-1] if axis == 0 else region[:, 1:] & region[:, :-1]
            position = np.arange(1, lum.shape[axis])
            position = np.broadcast_to(position[:, None] if axis == 0 else position[None, :], step.shape)
            for p in periods:
                sums[axis, p] += np.bincount(position[both] % p, weights=step[both], minlength=p)
                counts[axis, p] += np.bincount(position[both] % p, minlength=p)
    best, best_period = 1.0, periods[0]
    for (axis, p), total in sums.items():
        count = counts[axis, p]
        with np.errstate(divide="ignore", invalid="ignore"):
            on = total / count
            off = (total.sum() - total) / (count.sum() - count)
            ratios = on / off
        for ratio in ratios[~np.isnan(ratios)]:  # nan: no pairs, or no steps at all (a flat axis)
            if ratio > best:
                best, best_period = float(ratio), p
    return best, best_period


def local_contrast(rgb: np.ndarray, region: np.ndarray, *, erosion: int = 3) -> float:
    """Mean 5×5 standard deviation of the luminance inside ``region`` eroded by ``erosion`` px (wash-out);
    nan when nothing of the region is left."""
    kept = inside_eroded(region, erosion)
    if not kept.any():
        return float("nan")
    lum = luminance(rgb)
    mean = ndimage.uniform_filter(lum, 5)
    spread = np.sqrt(np.maximum(ndimage.uniform_filter(lum * lum, 5) - mean * mean, 0))
    return float(spread[kept].mean())


def frame_usage(match_frames: np.ndarray, region: np.ndarray, frame_count: int, *, erosion: int = 3) -> np.ndarray:
    """Share of the matches inside ``region`` (eroded as in :func:`local_contrast`) that come from each
    exemplar frame, (frame_count,); ``match_frames`` (H, W) holds each target pixel's exemplar frame
    (−1: none). All zeros when no pixel of the eroded region has a match."""
    kept = inside_eroded(region, erosion)
    used = match_frames[kept & (match_frames >= 0)]
    counts = np.bincount(used, minlength=frame_count)[:frame_count].astype(np.float64)
    return counts / counts.sum() if counts.sum() > 0 else counts


def used_contrast(usage: np.ndarray, exemplar_contrasts) -> float:
    """The local contrast of the exemplar frames a target frame draws from, each weighted by its share of
    the matches (:func:`frame_usage`): what an output that keeps the contrast of its sources shows.
    nan when nothing is drawn."""
    if usage.sum() == 0:
        return float("nan")
    return float(np.dot(usage, np.asarray(exemplar_contrasts, np.float64)))


def change(before: np.ndarray, after: np.ndarray) -> np.ndarray:
    """Per-pixel frame-to-frame change: |after − before| averaged over R, G and B, (H, W)."""
    return np.abs(after[..., :3].astype(np.float64) - before[..., :3]).mean(axis=-1)


def ratio(numerator: float, denominator: float) -> float:
    """numerator / denominator as numpy divides (inf over 0, nan for 0 / 0 or with a nan)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return float(np.float64(numerator) / denominator)


def pooled_mean(maps, regions, *, min_pixels: int = 1) -> float:
    """Mean of ``maps`` over their ``regions`` pooled (every pixel of every pair weighs the same);
    nan with fewer than ``min_pixels`` pixels in all."""
    total = sum(float(m[r].sum()) for m, r in zip(maps, regions))
    count = sum(int(r.sum()) for r in regions)
    return total / count if count >= min_pixels else float("nan")


def still_region(mask_before, mask_after, displacement, *, tolerance: float = 0.1, margin: float = 2.0) -> np.ndarray:
    """Target pixels that do not move between two frames.

    Inside both masks at least ``margin`` px from the edge in both, with an edge
    distance (:func:`edge_distance`) that changes by less than ``tolerance`` px and a
    known displacement of the shape ((H, W, 2) px, the scene's own motion) shorter than
    ``tolerance``: the shape neither moves there nor does its nearest edge.
    """
    before, after = edge_distance(mask_before), edge_distance(mask_after)
    return ((before >= margin) & (after >= margin) & (np.abs(after - before) < tolerance)
            & (np.hypot(displacement[..., 0], displacement[..., 1]) < tolerance))


def compensated_residual(before, after, displacement, mask_before, mask_after, *, margin: int = 3) -> float:
    """How much the texture changes apart from the shape's motion: mean |after(q) − before(q − d(q))| (R, G, B
    averaged; ``before`` sampled bilinearly) over the pixels ``margin`` px inside ``mask_after`` whose origin
    q − d(q) lies ``margin`` px inside ``mask_before``; ``displacement`` (H, W, 2) is the shape's motion d into
    the later frame. Near 0 when the paint travels with the shape (``carry``)."""
    kept_before = inside_eroded(mask_before, margin)
    came_from = sample_back(kept_before, displacement, order=0) > 0
    region = inside_eroded(mask_after, margin) & came_from
    moved = sample_back(np.asarray(before)[..., :3], displacement)
    return float(change(moved, after)[region].mean()) if region.any() else float("nan")


def moving_band(mask_before, mask_after, *, width: float = 10.0, motion: float = 0.5) -> np.ndarray:
    """Pixels near an edge that moves: inside both masks, within ``width`` px of the edge in the
    later frame, and whose edge distance changes by at least ``motion`` px."""
    before, after = edge_distance(mask_before), edge_distance(mask_after)
    return (before > 0) & (after > 0) & (after <= width) & (np.abs(after - before) >= motion)


def exemplar_stationary(mask_before, mask_after, flow_after, *, speed: float = 0.05, margin: int = 2) -> np.ndarray:
    """Exemplar paint that stays put: in its mask in both frames, flow (into the later frame)
    slower than ``speed`` px/frame, and at least ``margin`` px from where that stops."""
    slow = np.hypot(flow_after[..., 0], flow_after[..., 1]) < speed
    return ndimage.binary_erosion(inside(mask_before) & inside(mask_after) & slow, iterations=margin)


def iou(alpha: np.ndarray, mask: np.ndarray) -> float:
    """Intersection over union of ``alpha`` ≥ 0.5 and ``mask`` ≥ 0.5 (1.0 when both are empty)."""
    a, b = inside(alpha), inside(mask)
    union = (a | b).sum()
    return float((a & b).sum() / union) if union else 1.0


def patches(rgb: np.ndarray, centres: np.ndarray, size: int = 5) -> np.ndarray:
    """The size×size RGB patches around ``centres`` ((N, 2) rows, columns) as (N, size²·3) float64 vectors.

    Centres must lie at least size // 2 px from the image border.
    """
    half = size // 2
    offsets = np.arange(-half, half + 1)
    rows = centres[:, 0, None, None] + offsets[None, :, None]
    cols = centres[:, 1, None, None] + offsets[None, None, :]
    return rgb[rows, cols, :3].reshape(len(centres), -1).astype(np.float64)


def patch_centres(mask: np.ndarray, size: int = 5, *, whole: bool = True) -> np.ndarray:
    """(N, 2) centres of size×size patches: inside pixels whose patch lies within the image,
    and with ``whole`` also within the mask."""
    half = size // 2
    region = inside(mask)
    if whole:
        region = ndimage.binary_erosion(region, structure=np.ones((size, size)))
    framed = np.zeros_like(region)
    framed[half:region.shape[0] - half, half:region.shape[1] - half] = True
    return np.argwhere(region & framed)


def texture_fidelity(frames, masks, exemplar_frames, exemplar_masks, *, size: int = 5, samples: int = 2000,
                     seed: int = 0) -> float:
    """Mean distance of output patches to their nearest exemplar patch (coherence half of bidirectional
    similarity; 0: made of exemplar patches).

    ``samples`` size×size patches lying wholly inside the output masks are drawn
    uniformly (with the fixed ``seed``) from all frames; each is compared with every
    exemplar patch centred in the exemplar's masks (exact nearest neighbour, brute force).
    The distance is the RMS colour difference over the patch's pixels and channels
    (sRGB in [0, 1]), so it reads as a typical per-pixel error. nan when no output patch
    lies wholly inside the masks or the exemplar has no patch.
    """
    library = np.concatenate([patches(rgb, patch_centres(mask, size, whole=False), size)
                              for rgb, mask in zip(exemplar_frames, exemplar_masks)])
    centres = [patch_centres(mask, size) for mask in masks]
    where = np.concatenate([np.column_stack([np.full(len(c), t), c]) for t, c in enumerate(centres)])
    if not len(where) or not len(library):
        return float("nan")
    rng = np.random.default_rng(seed)
    chosen = where[np.sort(rng.choice(len(where), size=min(samples, len(where)), replace=False))]
    queries = np.concatenate([patches(frames[t], chosen[chosen[:, 0] == t, 1:], size) for t in range(len(frames))])
    library_norms = (library ** 2).sum(axis=1)
    nearest = np.empty(len(queries))
    for start in range(0, len(queries), 128):
        block = queries[start:start + 128]
        squared = (block ** 2).sum(axis=1)[:, None] + library_norms[None, :] - 2.0 * (block @ library.T)
        nearest[start:start + 128] = np.maximum(squared.min(axis=1), 0.0)
    return float(np.sqrt(nearest / library.shape[1]).mean())
