"""Uniformity (Kaspar et al. 2015, extended to space-time and rotation).

The occurrence map Ω* counts, for every source voxel ``(i, y, x)``, how many target
patches cover it: the patch matched at ``(i, x, y, θ)`` covers the rotated n×n
footprint (nearest pixel of ``(x, y) + R(θ) d``) in frames ``i - r .. i + r``. The
penalty of a candidate patch is ``weight · Σ_window Ω* / (n² ω*)`` with the budget
``ω* = n² (2r + 1) |T_seg| / |S_seg|`` of its segment; the window sum is taken over
the unrotated n×n box around the candidate's centre.
"""

import math

import numpy as np
from numba import prange

from fluidymation.engine._jit import kernel, parallel_kernel


@kernel
def _bucket_by_frame(nnf_frame, frames):
    """Target pixel indices (y * W + x) grouped by matched frame: offsets, indices."""
    counts = np.zeros(frames + 1, np.int64)
    flat = nnf_frame.ravel()
    for k in range(flat.shape[0]):
        if 0 <= flat[k] < frames:
            counts[flat[k] + 1] += 1
    offsets = np.cumsum(counts)
    fill = offsets[:-1].copy()
    indices = np.empty(offsets[-1], np.int64)
    for k in range(flat.shape[0]):
        frame = flat[k]
        if 0 <= frame < frames:
            indices[fill[frame]] = k
            fill[frame] += 1
    return offsets, indices


@parallel_kernel
def _stamp(nnf_frame, nnf_coords, offsets, indices, patch_radius, out):
    """Count the footprints of the patches matched in each frame, in that frame only."""
    frames, height, width = out.shape
    target_width = nnf_frame.shape[1]
    for frame in prange(frames):
        out[frame] = 0
        for k in range(offsets[frame], offsets[frame + 1]):
            ty = indices[k] // target_width
            tx = indices[k] % target_width
            x = nnf_coords[ty, tx, 0]
            y = nnf_coords[ty, tx, 1]
            theta = nnf_coords[ty, tx, 2]
            cos_t = math.cos(theta)
            sin_t = math.sin(theta)
            for dy in range(-patch_radius, patch_radius + 1):
                for dx in range(-patch_radius, patch_radius + 1):
                    px = int(math.floor(x + cos_t * dx - sin_t * dy + 0.5))
                    py = int(math.floor(y + sin_t * dx + cos_t * dy + 0.5))
                    if 0 <= px < width and 0 <= py < height:
                        out[frame, py, px] += 1


@parallel_kernel
def _sum_frames(counts, frame_radius, out):
    """``out[i] = Σ counts[i − r .. i + r]`` (frames outside the sequence count 0)."""
    frames, height, width = counts.shape
    for y in prange(height):
        running = np.zeros(width, np.int32)
        for frame in range(-frame_radius, frames + frame_radius):
            if frame + frame_radius < frames:
                running += counts[frame + frame_radius, y]
            if frame - frame_radius - 1 >= 0:
                running -= counts[frame - frame_radius - 1, y]
            if 0 <= frame < frames:
                out[frame, y] = running


def occurrence_map(nnf, *, source_shape, patch_size, frame_radius=0):
    """Count how many target patches cover each source voxel.

    Parameters
    ----------
    nnf : NNF
        Field of shape (H, W); pixels with frame -1 contribute nothing.
    source_shape : (T, Hs, Ws)
    patch_size : int
    frame_radius : int
        r: a patch also covers the r frames before and after its own.

    Returns
    -------
    ndarray, shape (T, Hs, Ws), int32
    """
    frames = int(source_shape[0])
    counts = np.empty(tuple(int(s) for s in source_shape), np.int32)
    offsets, indices = _bucket_by_frame(nnf.frame, frames)
    _stamp(nnf.frame, nnf.coords, offsets, indices, patch_size // 2, counts)
    if frame_radius == 0:
        return counts
    out = np.empty_like(counts)
    _sum_frames(counts, int(frame_radius), out)
    return out


@parallel_kernel
def _penalty(occurrence, source_segment, scale_per_label, radius, out):
    frames, height, width = occurrence.shape
    for frame in prange(frames):
        rows = np.zeros((height, width), np.float32)
        for y in range(height):
            running = 0.0
            for x in range(-radius, width + radius):
                if x + radius < width:
                    running += occurrence[frame, y, x + radius]
                if x - radius - 1 >= 0:
                    running -= occurrence[frame, y, x - radius - 1]
                if 0 <= x < width:
                    rows[y, x] = running
        for x in range(width):
            running = 0.0
            for y in range(-radius, height + radius):
                if y + radius < height:
                    running += rows[y + radius, x]
                if y - radius - 1 >= 0:
                    running -= rows[y - radius - 1, x]
                if 0 <= y < height:
                    label = source_segment[frame, y, x]
                    if 0 <= label < scale_per_label.shape[0]:
                        out[frame, y, x] = running * scale_per_label[label]
                    else:
                        out[frame, y, x] = 0.0


def budget_scales(*, source_segment, target_segment, patch_size, frame_radius, weight):
    """Per-label factor ``weight / (n² ω*)`` turning a window's occurrence sum into cost.

    Parameters
    ----------
    source_segment : ndarray, shape (T, Hs, Ws), int
    target_segment : ndarray, shape (H, W), int
        Labels ≥ 0; -1 is ignored.
    patch_size, frame_radius : int
    weight : float

    Returns
    -------
    ndarray, shape (K,), float32; 0 for labels absent from either side.
    """
    labels = int(max(source_segment.max(initial=-1), target_segment.max(initial=-1))) + 1
    source_counts = np.bincount(source_segment[source_segment >= 0].ravel(), minlength=labels)[:labels]
    target_counts = np.bincount(target_segment[target_segment >= 0].ravel(), minlength=labels)[:labels]
    n2 = float(patch_size * patch_size)
    scales = np.zeros(labels, np.float32)
    for label in range(labels):
        if source_counts[label] and target_counts[label]:
            budget = n2 * (2 * frame_radius + 1) * target_counts[label] / source_counts[label]
            scales[label] = weight / (n2 * budget)
    return scales


def uniformity_penalty(occurrence, *, source_segment, scales, patch_size):
    """The uniformity cost of a patch centred at each source voxel.

    Parameters
    ----------
    occurrence : ndarray, shape (T, Hs, Ws), int32
        From :func:`occurrence_map`.
    source_segment : ndarray, shape (T, Hs, Ws), int32
    scales : ndarray, shape (K,), float32
        From :func:`budget_scales`.
    patch_size : int

    Returns
    -------
    ndarray, shape (T, Hs, Ws), float32
    """
    out = np.empty(occurrence.shape, np.float32)
    _penalty(occurrence, np.ascontiguousarray(source_segment, np.int32), scales.astype(np.float32), patch_size // 2, out)
    return out
