"""Generalized PatchMatch over (source frame, x, y, θ), given the patch cost as an object.

:func:`patchmatch_pass` improves a nearest-neighbour field in place: per target pixel,
propagation from the two previous neighbours, then a random search in boxes shrinking by
α around the match. What a candidate's patch costs is the business of a
:class:`~fluidymation.engine.patch_cost.PatchCost`: the search hands it, as one numba
tuple, to the cost kernels of :mod:`fluidymation.engine.patch_cost` and does not know
which features it compares (as EbSynth's search takes its patch-SSD object). To the
patch cost the search adds a per-candidate uniformity penalty looked up in a map over the
source (:mod:`fluidymation.engine.uniformity`), times an optional per-target-pixel
factor; a candidate replaces the match when its total is lower, by an optional
per-pixel relative margin. A target pixel only matches source patches whose centre has
the same segment label; pixels labelled -1 are not synthesized. With ``ROTATION_FLOW``
each random candidate is tried at both flow-aligned angles, θ and θ + π, whose patches share
their bilinear samples (mirrored through the centre), so one pass over them costs both.

Speed: the random search is bound by cache misses on its far candidates, so each
pixel draws all its candidates first (boxes around the match after propagation, as
EbSynth does) and prefetches their data ``PREFETCH_AHEAD`` candidates before comparing
them; unrotated integer candidates of a plain cost go straight to the cost's row-wise
SSD, turned ones (flow-aligned synthesis) to its float32 rotated cost, the pair of
flow-aligned angles to its shared-sample pair cost.

Parallelism: the target is cut into fixed bands of rows (tiles); each thread of
:func:`~fluidymation.engine._jit.run_parts` takes every ``parts``-th tile. Inside a tile,
propagation reads the live field; across a tile border it reads the field as it was at the
start of the pass (one-pass-delayed propagation), so results are the same for any number
of threads.
"""

from __future__ import annotations

import math

import numpy as np
from fluidymation.engine._jit import borrowed, inline_kernel, kernel, prefetch, run_parts
from fluidymation.engine.nnf import ROTATION_FLOW, _flow_rotation
from fluidymation.engine.patch_cost import (
    _flow_pair_cost, _is_plain_window, _patch_cost, _plain_window_cost, _prefetch_window,
)
from fluidymation.engine.random import _key4, _random_below

TILE_ROWS = 16
PREFETCH_AHEAD = 3


@inline_kernel
def _prefetch_candidate(cost, source_segment, penalty, use_penalty, frame, x, y):
    """Start loading the label, the penalty and the patch-cost data of an integer candidate."""
    pixel = (frame * source_segment.shape[1] + y) * source_segment.shape[2] + x
    prefetch(source_segment, pixel)
    if use_penalty:
        prefetch(penalty, pixel)
    _prefetch_window(cost, frame, x, y)


@kernel
def _penalty_at(penalty, use_penalty, scale, frame, x, y):
    if not use_penalty:
        return np.float32(0.0)
    return scale * penalty[frame, int(y + 0.5), int(x + 0.5)]


@kernel
def _search_tile(
    cost, source_segment, target_segment, source_angle, target_angle, penalty, use_penalty, penalty_scale, keep_margin,
    nnf_frame, nnf_coords, error, start_frame, start_coords,
    rotation_mode, alpha, seed, salt, reverse, tile_rows, boxes, part, parts,
):
    """The search on the tiles ``part, part + parts, …`` of ``tile_rows`` target rows each: one thread's share
    of a pass (:func:`~fluidymation.engine._jit.run_parts`)."""
    (
        cost, source_segment, target_segment, source_angle, target_angle, penalty, penalty_scale, keep_margin,
        nnf_frame, nnf_coords, error, start_frame, start_coords,
    ) = borrowed((
        cost, source_segment, target_segment, source_angle, target_angle, penalty, penalty_scale, keep_margin,
        nnf_frame, nnf_coords, error, start_frame, start_coords,
    ))
    height, width = nnf_frame.shape
    frames, source_height, source_width = source_segment.shape
    high_x = np.float32(source_width - 1)
    high_y = np.float32(source_height - 1)
    step = -1 if reverse else 1
    draws = np.empty((boxes, 3), np.int64)
    for tile in range(part, (height + tile_rows - 1) // tile_rows, parts):
        y_begin = tile * tile_rows
        y_end = min(height, y_begin + tile_rows)
        for row in range(y_end - y_begin):
            ty = y_end - 1 - row if reverse else y_begin + row
            for column in range(width):
                tx = width - 1 - column if reverse else column
                label = target_segment[ty, tx]
                best_frame = nnf_frame[ty, tx]
                if label < 0 or best_frame < 0:
                    continue
                best_x = nnf_coords[ty, tx, 0]
                best_y = nnf_coords[ty, tx, 1]
                best_theta = nnf_coords[ty, tx, 2]
                best_error = error[ty, tx]
                scale_here = penalty_scale[ty, tx] if use_penalty else np.float32(0.0)
                best_total = best_error + _penalty_at(penalty, use_penalty, scale_here, best_frame, best_x, best_y)
                # a candidate replaces the match only if it is better by the pixel's relative margin
                keep_factor = np.float32(1.0) - keep_margin[ty, tx]
                accept_below = best_total * keep_factor
                # propagation: the neighbour's patch, shifted by the offset turned by its θ
                for direction in range(2):
                    nx = tx - step if direction == 0 else tx
                    ny = ty if direction == 0 else ty - step
                    if nx < 0 or nx >= width or ny < 0 or ny >= height:
                        continue
                    if y_begin <= ny < y_end:
                        cand_frame = nnf_frame[ny, nx]
                        cx = nnf_coords[ny, nx, 0]
                        cy = nnf_coords[ny, nx, 1]
                        cand_theta = nnf_coords[ny, nx, 2]
                    else:
                        cand_frame = start_frame[ny, nx]
                        cx = start_coords[ny, nx, 0]
                        cy = start_coords[ny, nx, 1]
                        cand_theta = start_coords[ny, nx, 2]
                    if cand_frame < 0:
                        continue
                    ex = np.float32(tx - nx)
                    ey = np.float32(ty - ny)
                    if cand_theta != 0.0:
                        cos_t = math.cos(cand_theta)
                        sin_t = math.sin(cand_theta)
                        cx += cos_t * ex - sin_t * ey
                        cy += sin_t * ex + cos_t * ey
                    else:
                        cx += ex
                        cy += ey
                    cx = min(max(cx, np.float32(0.0)), high_x)
                    cy = min(max(cy, np.float32(0.0)), high_y)
                    if cand_frame == best_frame and cx == best_x and cy == best_y and cand_theta == best_theta:
                        continue
                    if source_segment[cand_frame, int(cy + 0.5), int(cx + 0.5)] != label:
                        continue
                    cand_penalty = _penalty_at(penalty, use_penalty, scale_here, cand_frame, cx, cy)
                    if cand_penalty >= accept_below:
                        continue
                    bound = accept_below - cand_penalty
                    if _is_plain_window(cost, tx, ty, cx, cy, cand_theta):
                        cand_error = _plain_window_cost(cost, cand_frame, int(cx), int(cy), tx, ty, bound)
                    else:
                        cand_error = _patch_cost(cost, tx, ty, np.int64(cand_frame), cx, cy, cand_theta, np.float32(bound))
                    if cand_error + cand_penalty < accept_below:
                        best_frame = cand_frame
                        best_x = cx
                        best_y = cy
                        best_theta = cand_theta
                        best_error = cand_error
                        best_total = cand_error + cand_penalty
                        accept_below = best_total * keep_factor
                # (the plain-or-full cost dispatch is written out here and in propagation on purpose:
                # a shared helper, even inlined, made facestyle 25-40 % slower)
                # random search in boxes shrinking by alpha around the match after propagation (as
                # EbSynth): draw every candidate, then try the smallest box first, loading the
                # data of the candidate PREFETCH_AHEAD places later meanwhile (hides cache misses)
                key = _key4(seed, salt, ty, tx)
                centre_x = int(best_x + 0.5)
                centre_y = int(best_y + 0.5)
                centre_frame = best_frame
                scale = 1.0
                for box in range(boxes):
                    half_x = scale * source_width
                    half_y = scale * source_height
                    half_t = int(scale * frames)
                    x_lo = max(0, int(centre_x - half_x))
                    x_hi = min(source_width - 1, int(centre_x + half_x))
                    y_lo = max(0, int(centre_y - half_y))
                    y_hi = min(source_height - 1, int(centre_y + half_y))
                    f_lo = max(0, centre_frame - half_t)
                    f_hi = min(frames - 1, centre_frame + half_t)
                    draws[box, 0] = f_lo + _random_below(key, 3 * box + 2, f_hi - f_lo + 1)
                    draws[box, 1] = x_lo + _random_below(key, 3 * box, x_hi - x_lo + 1)
                    draws[box, 2] = y_lo + _random_below(key, 3 * box + 1, y_hi - y_lo + 1)
                    scale *= alpha
                for box in range(boxes - 1, boxes - 1 - min(PREFETCH_AHEAD, boxes), -1):
                    _prefetch_candidate(cost, source_segment, penalty, use_penalty, draws[box, 0], draws[box, 1],
                                        draws[box, 2])
                for box in range(boxes - 1, -1, -1):
                    if box >= PREFETCH_AHEAD:
                        ahead = box - PREFETCH_AHEAD
                        _prefetch_candidate(cost, source_segment, penalty, use_penalty, draws[ahead, 0],
                                            draws[ahead, 1], draws[ahead, 2])
                    cand_frame = draws[box, 0]
                    cx_int = draws[box, 1]
                    cy_int = draws[box, 2]
                    if source_segment[cand_frame, cy_int, cx_int] != label:
                        continue
                    cx = np.float32(cx_int)
                    cy = np.float32(cy_int)
                    cand_penalty = _penalty_at(penalty, use_penalty, scale_here, cand_frame, cx, cy)
                    if cand_penalty >= accept_below:
                        continue
                    if rotation_mode == ROTATION_FLOW:
                        # both flow-aligned angles, θ and θ + π, in one pass over shared samples
                        theta = np.float32(
                            _flow_rotation(target_angle, source_angle, cand_frame, cx, cy, tx, ty, False)
                        )
                        first_error, second_error = _flow_pair_cost(
                            cost, tx, ty, cand_frame, cx, cy, theta, np.float32(math.cos(theta)),
                            np.float32(math.sin(theta)), accept_below - cand_penalty,
                        )
                        for flip in range(2):
                            cand_error = first_error if flip == 0 else second_error
                            if cand_error + cand_penalty < accept_below:
                                best_frame = cand_frame
                                best_x = cx
                                best_y = cy
                                best_theta = theta if flip == 0 else np.float32(
                                    _flow_rotation(target_angle, source_angle, cand_frame, cx, cy, tx, ty, True)
                                )
                                best_error = cand_error
                                best_total = cand_error + cand_penalty
                                accept_below = best_total * keep_factor
                        continue
                    cand_theta = np.float32(0.0)
                    bound = accept_below - cand_penalty
                    if _is_plain_window(cost, tx, ty, cx, cy, cand_theta):
                        cand_error = _plain_window_cost(cost, cand_frame, cx_int, cy_int, tx, ty, bound)
                    else:
                        cand_error = _patch_cost(cost, tx, ty, np.int64(cand_frame), cx, cy, cand_theta, np.float32(bound))
                    if cand_error + cand_penalty < accept_below:
                        best_frame = cand_frame
                        best_x = cx
                        best_y = cy
                        best_theta = cand_theta
                        best_error = cand_error
                        best_total = cand_error + cand_penalty
                        accept_below = best_total * keep_factor
                nnf_frame[ty, tx] = best_frame
                nnf_coords[ty, tx, 0] = best_x
                nnf_coords[ty, tx, 1] = best_y
                nnf_coords[ty, tx, 2] = best_theta
                error[ty, tx] = best_error

def patchmatch_pass(cost, nnf, error, *, penalty=None, penalty_scale=None, keep_margin=None, rotation_mode=0,
                    alpha=0.75, random_search=True, seed=0, salt=0, reverse=False, tile_rows=TILE_ROWS):
    """One PatchMatch iteration (propagation, then random search unless ``random_search`` is False), in place.

    Parameters
    ----------
    cost : PatchCost
        What a match costs; its segment labels and flow angles also steer the search.
    nnf : NNF
        Modified in place.
    error : ndarray, shape (H, W), float32
        :func:`patch_errors` of ``nnf`` under ``cost``; kept up to date in place.
    penalty : ndarray, shape (T, Hs, Ws), float32, optional
        Uniformity cost of a patch centred at each source voxel.
    penalty_scale : ndarray, shape (H, W), float32, optional
        Per target pixel factor of ``penalty`` (default 1).
    keep_margin : ndarray, shape (H, W), float32, optional
        Per target pixel, the relative improvement (in [0, 1)) of the cost plus penalty a
        candidate needs to replace the current match (default 0: any improvement).
    rotation_mode : int
        ``ROTATION_NONE`` or ``ROTATION_FLOW`` (the two flow-aligned angles).
    alpha : float
        Shrink factor of the random-search box (0 < alpha < 1).
    random_search : bool
        False: propagation only (a few times cheaper; it joins neighbouring matches into coherent ones).
    seed, salt : int
        Random numbers come from ``(seed, salt, y, x)``; give each pass its own salt.
    reverse : bool
        Scan right-to-left, bottom-to-top and propagate from the right/bottom.
    tile_rows : int
        Height of the fixed tiles; the result depends on it, not on the thread count.
    """
    if not 0.0 < alpha < 1.0:
        raise ValueError(f"alpha must lie in (0, 1), got {alpha}")
    use_penalty = penalty is not None
    if penalty is None:
        penalty = np.zeros((1, 1, 1), np.float32)
    if penalty_scale is None:
        penalty_scale = np.ones(nnf.shape if use_penalty else (1, 1), np.float32)
    if keep_margin is None:
        keep_margin = np.zeros(nnf.shape, np.float32)
    run_parts(
        _search_tile,
        cost.kernel_cost(), cost.source_segment, cost.target_segment, cost.source_angle, cost.target_angle,
        penalty, use_penalty,
        np.ascontiguousarray(penalty_scale, np.float32), np.ascontiguousarray(keep_margin, np.float32),
        nnf.frame, nnf.coords, error, nnf.frame.copy(), nnf.coords.copy(),
        int(rotation_mode), float(alpha), int(seed), int(salt), bool(reverse), int(tile_rows),
        _random_boxes(cost.source_segment.shape[1:], alpha) if random_search else 0,
    )


def _random_boxes(source_shape, alpha):
    """How many random-search boxes a pass draws: shrinking by ``alpha`` from the whole source to 1 px."""
    boxes, scale = 0, 1.0
    while scale * max(source_shape) >= 1.0:
        boxes += 1
        scale *= alpha
    return boxes
