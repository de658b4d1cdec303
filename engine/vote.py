"""Voting: each target pixel becomes the average of the collocated pixels of every
source patch (rotated, bilinearly sampled) that overlaps it according to the NNF."""

import math

import numpy as np

from fluidymation.engine._jit import kernel, run_parts
from fluidymation.engine.sampling import _bilinear_setup


@kernel
def _turns(nnf_coords, box, out, part, parts):
    """cos θ and sin θ of every match in the box (a pixel is voted by n² patches: one sine each, not n²)."""
    y_begin, y_end, x_begin, x_end = box
    for ty in range(y_begin + part, y_end, parts):
        for tx in range(x_begin, x_end):
            theta = nnf_coords[ty, tx, 2]
            out[ty, tx, 0] = math.cos(theta)
            out[ty, tx, 1] = math.sin(theta)


@kernel
def _vote(source, nnf_frame, nnf_coords, turns, radius, box, out, coverage, part, parts):
    height, width = nnf_frame.shape
    source_height = source.shape[1]
    source_width = source.shape[2]
    channels = source.shape[3]
    y_begin, y_end, x_begin, x_end = box
    for ty in range(y_begin + part, y_end, parts):
        total = np.zeros(channels, np.float32)
        for tx in range(x_begin, x_end):
            total[:] = 0.0
            count = 0
            for dy in range(-radius, radius + 1):
                ny = ty - dy
                if ny < 0 or ny >= height:
                    continue
                for dx in range(-radius, radius + 1):
                    nx = tx - dx
                    if nx < 0 or nx >= width:
                        continue
                    frame = nnf_frame[ny, nx]
                    if frame < 0:
                        continue
                    x = nnf_coords[ny, nx, 0]
                    y = nnf_coords[ny, nx, 1]
                    theta = nnf_coords[ny, nx, 2]
                    sx = int(x) + dx
                    sy = int(y) + dy
                    if theta == 0.0 and x == int(x) and y == int(y) and 0 <= sx < source_width and 0 <= sy < source_height:
                        for c in range(channels):
                            total[c] += source[frame, sy, sx, c]
                    else:
                        cos_t = turns[ny, nx, 0]
                        sin_t = turns[ny, nx, 1]
                        x0, y0, x1, y1, w00, w10, w01, w11 = _bilinear_setup(
                            x + cos_t * dx - sin_t * dy, y + sin_t * dx + cos_t * dy, source_height, source_width
                        )
                        for c in range(channels):
                            total[c] += (
                                w00 * source[frame, y0, x0, c]
                                + w10 * source[frame, y0, x1, c]
                                + w01 * source[frame, y1, x0, c]
                                + w11 * source[frame, y1, x1, c]
                            )
                    count += 1
            coverage[ty, tx] = count
            scale = np.float32(1.0 / count) if count > 0 else np.float32(0.0)
            for c in range(channels):
                out[ty, tx, c] = total[c] * scale


def vote(source, nnf, *, patch_size):
    """Average the overlapping source patches the NNF assigns.

    Parameters
    ----------
    source : ndarray, shape (T, Hs, Ws, C), float32
        What to vote (usually the source colour).
    nnf : NNF
        Field of shape (H, W).
    patch_size : int

    Returns
    -------
    image : ndarray, shape (H, W, C), float32
        Zero where no patch covers the pixel.
    coverage : ndarray, shape (H, W), int32
        How many patches covered each pixel.
    """
    source = np.ascontiguousarray(source, dtype=np.float32)
    if source.ndim != 4:
        raise ValueError(f"source must have shape (T, H, W, C), got {source.shape}")
    height, width = nnf.shape
    out = np.zeros((height, width, source.shape[3]), np.float32)
    coverage = np.zeros((height, width), np.int32)
    matched = nnf.frame >= 0
    rows = np.flatnonzero(matched.any(axis=1))
    if rows.size == 0:
        return out, coverage
    columns = np.flatnonzero(matched.any(axis=0))
    radius = patch_size // 2
    # only pixels a patch can reach: the matches' bounding box grown by the patch radius
    box = (max(rows[0] - radius, 0), min(rows[-1] + radius + 1, height),
           max(columns[0] - radius, 0), min(columns[-1] + radius + 1, width))
    turns = np.empty((height, width, 2), np.float32)
    run_parts(_turns, nnf.coords, np.array(box, np.int64), turns)
    run_parts(_vote, source, nnf.frame, nnf.coords, turns, radius, np.array(box, np.int64), out, coverage)
    return out, coverage
