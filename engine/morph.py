"""Kernels of the keyframe morph (docs/keyframes.md): the windowed search of the motion prior
and the completeness half of the bidirectional-similarity vote.

:func:`window_search` matches every target pixel exhaustively within a square window of
its own radius around its own centre in the source (the advected position: the search
between adjacent frames is restricted to the motion prior's window, seed 003 section 5).
:func:`scatter_vote` is the completeness vote: every source patch adds its pixels to the
target pixels around the position it was matched to. The coherence half is
:func:`fluidymation.engine.vote.vote`.
"""

from __future__ import annotations

import numpy as np

from fluidymation.engine._jit import kernel, run_parts
from fluidymation.engine.nnf import NNF
from fluidymation.engine.patch_cost import _patch_cost


@kernel
def _window_search(cost, source_segment, target_segment, centre, radius, nnf_frame, nnf_coords, error, part, parts):
    height, width = nnf_frame.shape
    source_height, source_width = source_segment.shape[1], source_segment.shape[2]
    for ty in range(part, height, parts):
        for tx in range(width):
            nnf_frame[ty, tx] = -1
            error[ty, tx] = np.inf
            if target_segment[ty, tx] < 0:
                continue
            reach = radius[ty, tx]
            cx = int(np.floor(centre[ty, tx, 0] + 0.5))
            cy = int(np.floor(centre[ty, tx, 1] + 0.5))
            cx = min(max(cx, 0), source_width - 1)
            cy = min(max(cy, 0), source_height - 1)
            best = np.float32(np.inf)
            for y in range(max(cy - reach, 0), min(cy + reach + 1, source_height)):
                for x in range(max(cx - reach, 0), min(cx + reach + 1, source_width)):
                    if source_segment[0, y, x] < 0:
                        continue
                    value = _patch_cost(cost, np.int64(tx), np.int64(ty), np.int64(0), np.float32(x), np.float32(y),
                                        np.float32(0.0), best)
                    if value < best:
                        best = value
                        nnf_frame[ty, tx] = 0
                        nnf_coords[ty, tx, 0] = x
                        nnf_coords[ty, tx, 1] = y
                        nnf_coords[ty, tx, 2] = 0.0
            error[ty, tx] = best


def window_search(cost, centre, radius):
    """The best match of every target pixel within ``radius`` of its ``centre`` in the source.

    Parameters
    ----------
    cost : PatchCost
        Of a one-frame source; its segments say which pixels are searched (target −1:
        none) and which source centres may be matched (−1: never).
    centre : ndarray, shape (H, W, 2), float32
        Per target pixel, the window's centre ``(x, y)`` in source pixels (rounded, clamped).
    radius : ndarray, shape (H, W), int
        Per target pixel, the window's half-width (0: only the centre).

    Returns
    -------
    nnf : NNF
        No match (−1) where the target is not searched or the window holds no source pixel of a segment ≥ 0.
    error : ndarray, shape (H, W), float32
        The match's patch cost, inf without one.
    """
    if cost.source_features.shape[0] != 1:
        raise ValueError("window_search needs a one-frame source")
    height, width = cost.target_features.shape[:2]
    if centre.shape != (height, width, 2) or radius.shape != (height, width):
        raise ValueError(f"centre and radius must be ({height}, {width}, 2) and ({height}, {width})")
    nnf = NNF.empty(height, width)
    error = np.empty((height, width), np.float32)
    run_parts(_window_search, cost.kernel_cost(), cost.source_segment, cost.target_segment,
                   np.ascontiguousarray(centre, np.float32), np.ascontiguousarray(radius, np.int64),
                   nnf.frame, nnf.coords, error)
    return nnf, error


@kernel
def _scatter_vote(source, nnf_frame, nnf_coords, radius, weight, total, weights):
    source_height, source_width, channels = source.shape
    height, width = weights.shape
    for sy in range(source_height):
        for sx in range(source_width):
            if nnf_frame[sy, sx] < 0:
                continue
            tx = int(np.floor(nnf_coords[sy, sx, 0] + 0.5))
            ty = int(np.floor(nnf_coords[sy, sx, 1] + 0.5))
            for dy in range(-radius, radius + 1):
                qy = ty + dy
                if qy < 0 or qy >= height:
                    continue
                py = min(max(sy + dy, 0), source_height - 1)
                for dx in range(-radius, radius + 1):
                    qx = tx + dx
                    if qx < 0 or qx >= width:
                        continue
                    px = min(max(sx + dx, 0), source_width - 1)
                    for c in range(channels):
                        total[qy, qx, c] += weight * source[py, px, c]
                    weights[qy, qx] += weight


def scatter_vote(source, nnf, *, patch_size, weight, total, weights):
    """Add the completeness vote of ``source`` into ``total`` and ``weights``, in place.

    Every source pixel with a match (``nnf``: source → target, the source's shape) adds
    ``weight`` times each pixel of its patch to the target pixel at the same offset from
    its match (rounded; source samples beyond the border repeat the edge).

    Parameters
    ----------
    source : ndarray, shape (Hs, Ws, C), float32
    nnf : NNF
        Of shape (Hs, Ws): target positions per source pixel, frame −1 where unmatched.
    patch_size : int
    weight : float
    total : ndarray, shape (H, W, C), float32
        Sums of the voted values.
    weights : ndarray, shape (H, W), float32
        Sums of the weights.
    """
    if nnf.shape != source.shape[:2]:
        raise ValueError(f"the NNF must have the source's shape {source.shape[:2]}, got {nnf.shape}")
    _scatter_vote(np.ascontiguousarray(source, np.float32), nnf.frame, nnf.coords, patch_size // 2,
                  np.float32(weight), total, weights)
