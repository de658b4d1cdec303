"""Uniformity (Kaspar et al. 2015, extended to space-time and rotation).

The occurrence map Ω* counts, for every source voxel ``(i, y, x)``, how many target
patches cover it: the patch matched at ``(i, x, y, θ)`` covers the rotated n×n
footprint (nearest pixel of ``(x, y) + R(θ) d``) in frames ``i - r .. i + r``. The
penalty of a candidate patch is ``weight · Σ_window Ω* / (n² ω*)`` with the budget
``ω* = n² (2r + 1) |T_seg| / |S_seg|`` of its segment; the window sum is taken over
the unrotated n×n box around the candidate's centre.

An unturned patch's footprint is the n×n box around its nearest pixel, so unturned patches
(all of them in EbSynth-style synthesis) are counted once at that pixel and spread by box
sums, parallel over rows; only turned ones are stamped pixel by pixel.
"""

import math

import numpy as np

from fluidymation.engine._jit import kernel, run_parts


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


@kernel
def _stamp(nnf_frame, nnf_coords, offsets, indices, patch_radius, out, centres, part, parts):
    """Count the footprints of the patches matched in each frame, in that frame only: turned
    patches stamped pixel by pixel into ``out``, unturned ones (whose footprint is the n×n box
    around their nearest pixel) counted once at that pixel in ``centres``. Returns how many
    patches of the frames ``part, part + parts, …`` went to ``centres``."""
    frames, height, width = out.shape
    target_width = nnf_frame.shape[1]
    unturned = 0
    for frame in range(part, frames, parts):
        out[frame] = 0
        centres[frame] = 0
        for k in range(offsets[frame], offsets[frame + 1]):
            ty = indices[k] // target_width
            tx = indices[k] % target_width
            x = nnf_coords[ty, tx, 0]
            y = nnf_coords[ty, tx, 1]
            theta = nnf_coords[ty, tx, 2]
            if theta == 0.0:
                centres[frame, int(math.floor(y + 0.5)), int(math.floor(x + 0.5))] += 1
                unturned += 1
                continue
            cos_t = math.cos(theta)
            sin_t = math.sin(theta)
            for dy in range(-patch_radius, patch_radius + 1):
                for dx in range(-patch_radius, patch_radius + 1):
                    px = int(math.floor(x + cos_t * dx - sin_t * dy + 0.5))
                    py = int(math.floor(y + sin_t * dx + cos_t * dy + 0.5))
                    if 0 <= px < width and 0 <= py < height:
                        out[frame, py, px] += 1
    return unturned


def _add_box_sums(values, radius, out):
    """``out[i, y, x] += Σ values[i, y − r .. y + r, x − r .. x + r]`` (pixels outside count 0),
    parallel over rows: running sums along x, then 2r + 1 rows added along y."""
    rows = np.empty_like(values)
    run_parts(_running_row_sums, values, radius, rows)
    run_parts(_add_row_sums, rows, radius, out)


@kernel
def _running_row_sums(values, radius, rows, part, parts):
    """``rows[i, y, x] = Σ values[i, y, x − r .. x + r]``, for the rows ``part, part + parts, …``."""
    frames, height, width = values.shape
    for index in range(part, frames * height, parts):
        frame = index // height
        y = index % height
        running = 0
        for x in range(-radius, width + radius):
            if x + radius < width:
                running += values[frame, y, x + radius]
            if x - radius - 1 >= 0:
                running -= values[frame, y, x - radius - 1]
            if 0 <= x < width:
                rows[frame, y, x] = running


@kernel
def _add_row_sums(rows, radius, out, part, parts):
    """``out[i, y] += Σ rows[i, y − r .. y + r]``, for the rows ``part, part + parts, …``."""
    frames, height, width = rows.shape
    for index in range(part, frames * height, parts):
        frame = index // height
        y = index % height
        for row in range(max(0, y - radius), min(height, y + radius + 1)):
            for x in range(width):
                out[frame, y, x] += rows[frame, row, x]


@kernel
def _sum_frames(counts, frame_radius, out, part, parts):
    """``out[i] = Σ counts[i − r .. i + r]`` (frames outside the sequence count 0)."""
    frames, height, width = counts.shape
    for y in range(part, height, parts):
        running = np.zeros(width, np.int32)
        for frame in range(-frame_radius, frames + frame_radius):
            for x in range(width):
                if frame + frame_radius < frames:
                    running[x] += counts[frame + frame_radius, y, x]
                if frame - frame_radius - 1 >= 0:
                    running[x] -= counts[frame - frame_radius - 1, y, x]
                if 0 <= frame < frames:
                    out[frame, y, x] = running[x]


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
    centres = np.empty_like(counts)
    offsets, indices = _bucket_by_frame(nnf.frame, frames)
    if sum(run_parts(_stamp, nnf.frame, nnf.coords, offsets, indices, patch_size // 2, counts, centres)):
        _add_box_sums(centres, patch_size // 2, counts)
    if frame_radius == 0:
        return counts
    out = np.empty_like(counts)
    run_parts(_sum_frames, counts, int(frame_radius), out)
    return out


@kernel
def _scale_by_label(window_sums, source_segment, scale_per_label, out, part, parts):
    """``out = window_sums × scale_per_label[label]`` per voxel, 0 where the label is -1."""
    frames, height, width = window_sums.shape
    for index in range(part, frames * height, parts):
        frame = index // height
        y = index % height
        for x in range(width):
            label = source_segment[frame, y, x]
            if 0 <= label < scale_per_label.shape[0]:
                out[frame, y, x] = window_sums[frame, y, x] * scale_per_label[label]
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
    window_sums = np.zeros_like(occurrence)
    _add_box_sums(occurrence, patch_size // 2, window_sums)
    out = np.empty(occurrence.shape, np.float32)
    run_parts(_scale_by_label, window_sums, np.ascontiguousarray(source_segment, np.int32), scales.astype(np.float32), out)
    return out
