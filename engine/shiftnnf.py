"""Reuse of the previous frame's field: SHIFTNNF, the temporal modulation m(q) and transport (``carry``).

:func:`shift_nnf` moves every match ``(i, x, y, θ)`` of frame ``j − 1`` forward (or, where
the rotated source flow opposes the target flow, backward) in source time by the ``Δi``
whose source motion amount best matches the target's motion amount between frames
``j − 1`` and ``j`` (paper section 3.4; ALGORITHM.md, "Multi-scale and reuse between
frames"). :func:`temporal_modulation` is the per-pixel factor m(q) of the temporal term:
0 where q was outside the previous mask, else 1 when the target and source distances
differ by at most ``lower`` and 0 when by ``upper`` or more, smooth in between.
:func:`transport_nnf` moves the field along the target's motion, turning each match with
the motion's local rotation, so that the texture travels with the shape (``carry``, beyond
the paper; docs/stylize.md).
"""

from __future__ import annotations

import math

import numpy as np

from fluidymation.engine._jit import kernel, run_parts
from fluidymation.engine.nnf import NNF


@kernel
def _shift(frame_in, coords_in, target_motion, target_angle, source_ext_plus, source_ext_minus, source_angle, frame_out,
           achieved, part, parts):
    height, width = frame_in.shape
    frames, source_height, source_width = source_ext_plus.shape
    for ty in range(part, height, parts):
        for tx in range(width):
            frame = frame_in[ty, tx]
            if frame < 0:
                frame_out[ty, tx] = -1
                achieved[ty, tx] = 0.0
                continue
            sx = min(max(int(coords_in[ty, tx, 0] + 0.5), 0), source_width - 1)
            sy = min(max(int(coords_in[ty, tx, 1] + 0.5), 0), source_height - 1)
            theta = coords_in[ty, tx, 2]
            opposite = math.cos(source_angle[frame, sy, sx] - theta - target_angle[ty, tx]) < 0.0
            wanted = target_motion[ty, tx]
            best_frame = frame
            best_gap = abs(wanted)
            best_amount = 0.0
            # forward along ext+, or backward along ext− where the flows are opposite
            extent = source_ext_minus if opposite else source_ext_plus
            step = -1 if opposite else 1
            stop = -1 if opposite else frames
            start = extent[frame, sy, sx]
            for candidate in range(frame + step, stop, step):
                amount = extent[candidate, sy, sx] - start
                gap = abs(wanted - amount)
                if gap < best_gap:
                    best_gap = gap
                    best_frame = candidate
                    best_amount = amount
            frame_out[ty, tx] = best_frame
            achieved[ty, tx] = best_amount


def shift_nnf(nnf, *, target_motion, target_angle, source_ext_plus, source_ext_minus, source_angle):
    """SHIFTNNF: the previous frame's field moved along source time to match the target motion.

    For each match ``(i, x, y, θ)`` at target pixel q (source values read at the nearest
    pixel to ``(x, y)``): if ``cos(S_dir(i, p) − θ − T_dir(q)) ≥ 0`` find ``Δi ≥ 0``
    minimising ``|target_motion(q) − (S_ext+(i + Δi, p) − S_ext+(i, p))|``, otherwise
    ``Δi ≤ 0`` minimising ``|target_motion(q) − (S_ext−(i + Δi, p) − S_ext−(i, p))|``;
    ties go to the smallest ``|Δi|``. ``x, y, θ`` are kept.

    Parameters
    ----------
    nnf : NNF
        The previous frame's field (H, W).
    target_motion : ndarray, shape (H, W), float32
        ``T_ext+(j) − T_ext+(j − 1)``: how far the target moved at each pixel.
    target_angle : ndarray, shape (H, W), float32
        Target flow orientation (radians) of frame j.
    source_ext_plus, source_ext_minus, source_angle : ndarray, shape (T, Hs, Ws), float32

    Returns
    -------
    shifted : NNF
        A new field; unmatched pixels (frame -1) stay unmatched.
    achieved : ndarray, shape (H, W), float32
        The source motion amount of the chosen shift (0 where unmatched); the caller may
        carry ``target_motion − achieved`` over to the next frame.
    """
    height, width = nnf.shape
    source_shape = np.shape(source_ext_plus)
    for name, value, shape in (
        ("target_motion", target_motion, (height, width)), ("target_angle", target_angle, (height, width)),
        ("source_ext_minus", source_ext_minus, source_shape), ("source_angle", source_angle, source_shape),
    ):
        if np.shape(value) != shape:
            raise ValueError(f"{name} must have shape {shape}, got {np.shape(value)}")
    if len(source_shape) != 3:
        raise ValueError(f"source_ext_plus must have shape (T, Hs, Ws), got {source_shape}")
    frame_out = np.empty((height, width), np.int32)
    achieved = np.empty((height, width), np.float32)
    run_parts(
        _shift,
        nnf.frame, nnf.coords, np.ascontiguousarray(target_motion, np.float32),
        np.ascontiguousarray(target_angle, np.float32), np.ascontiguousarray(source_ext_plus, np.float32),
        np.ascontiguousarray(source_ext_minus, np.float32), np.ascontiguousarray(source_angle, np.float32), frame_out,
        achieved,
    )
    return NNF(frame_out, nnf.coords.copy()), achieved


@kernel
def _modulation(frame_in, coords_in, target_dist, source_dist, previous_mask, lower, upper, out, part, parts):
    height, width = frame_in.shape
    source_height = source_dist.shape[1]
    source_width = source_dist.shape[2]
    span = upper - lower
    for ty in range(part, height, parts):
        for tx in range(width):
            frame = frame_in[ty, tx]
            if frame < 0 or not previous_mask[ty, tx]:
                out[ty, tx] = 0.0
                continue
            sx = min(max(int(coords_in[ty, tx, 0] + 0.5), 0), source_width - 1)
            sy = min(max(int(coords_in[ty, tx, 1] + 0.5), 0), source_height - 1)
            gap = abs(target_dist[ty, tx] - source_dist[frame, sy, sx])
            if gap <= lower:
                out[ty, tx] = 1.0
            elif gap >= upper or span <= 0.0:
                out[ty, tx] = 0.0
            else:
                t = (gap - lower) / span
                out[ty, tx] = 1.0 - t * t * (3.0 - 2.0 * t)


def temporal_modulation(nnf, *, target_dist, source_dist, previous_mask, lower, upper):
    """m(q): how much to trust the temporal guide at each target pixel.

    Parameters
    ----------
    nnf : NNF
        The shifted field NNF_prev (H, W).
    target_dist : ndarray, shape (H, W), float32
        Target distance of frame j (e.g. signed distance clamped at the border width).
    source_dist : ndarray, shape (T, Hs, Ws), float32
        Source distance in the same units, read at the nearest pixel of each match.
    previous_mask : ndarray of bool, shape (H, W)
        Where the target was in frame j − 1.
    lower, upper : float
        m = 1 for ``|T_dist − S_dist| ≤ lower``, 0 for ``≥ upper``, smoothstep between.

    Returns
    -------
    ndarray, shape (H, W), float32 in [0, 1]
    """
    if lower < 0 or upper < lower:
        raise ValueError(f"need 0 ≤ lower ≤ upper, got lower={lower}, upper={upper}")
    height, width = nnf.shape
    if np.shape(target_dist) != (height, width) or np.shape(previous_mask) != (height, width):
        raise ValueError(f"target_dist and previous_mask must have shape {(height, width)}")
    if np.ndim(source_dist) != 3:
        raise ValueError(f"source_dist must have shape (T, Hs, Ws), got {np.shape(source_dist)}")
    out = np.empty((height, width), np.float32)
    run_parts(
        _modulation,
        nnf.frame, nnf.coords, np.ascontiguousarray(target_dist, np.float32),
        np.ascontiguousarray(source_dist, np.float32), np.ascontiguousarray(previous_mask, np.bool_),
        np.float32(lower), np.float32(upper), out,
    )
    return out


@kernel
def _transport(frame_in, coords_in, flow, turn, frame_out, coords_out, origin, part, parts):
    height, width = frame_in.shape
    for ty in range(part, height, parts):
        for tx in range(width):
            # where the material now at (tx, ty) was in the previous frame
            px = tx - flow[ty, tx, 0]
            py = ty - flow[ty, tx, 1]
            nx = int(math.floor(px + 0.5))
            ny = int(math.floor(py + 0.5))
            if not (0 <= nx < width and 0 <= ny < height) or frame_in[ny, nx] < 0:
                frame_out[ty, tx] = -1
                coords_out[ty, tx, 0] = 0.0
                coords_out[ty, tx, 1] = 0.0
                coords_out[ty, tx, 2] = 0.0
                origin[ty, tx] = -1
                continue
            dx = px - nx
            dy = py - ny
            theta = coords_in[ny, nx, 2]
            c = math.cos(theta)
            s = math.sin(theta)
            frame_out[ty, tx] = frame_in[ny, nx]
            coords_out[ty, tx, 0] = coords_in[ny, nx, 0] + c * dx - s * dy
            coords_out[ty, tx, 1] = coords_in[ny, nx, 1] + s * dx + c * dy
            coords_out[ty, tx, 2] = theta + turn[ty, tx]
            origin[ty, tx] = ny * width + nx


def transport_nnf(nnf, flow):
    """The previous frame's field carried along the target's motion ``flow`` (H, W, 2; frame j's: the motion that
    brought the material to frame j).

    Each target pixel q takes the match of the point it came from, p = q − flow(q): the
    match of p's nearest pixel moved by the sub-pixel rest (through its rotation, as a vote
    samples it) and turned by the rotation of the backward map q ↦ p there (from the
    flow's derivatives), so a rigidly moving target votes the same texture, moved.

    Returns
    -------
    carried : NNF
        Unmatched where p leaves the image or its pixel had no match.
    origin : ndarray, shape (H, W), int64
        The flat index of p's nearest pixel (−1 where unmatched): other per-pixel state of
        the previous frame is carried with ``previous.ravel()[origin]``.
    """
    height, width = nnf.shape
    flow = np.ascontiguousarray(flow, np.float32)
    if flow.shape != (height, width, 2):
        raise ValueError(f"flow must have shape {(height, width, 2)}, got {flow.shape}")
    d_fx_dy, d_fx_dx = np.gradient(flow[..., 0])
    d_fy_dy, d_fy_dx = np.gradient(flow[..., 1])
    # the backward map's Jacobian I − ∇flow, and the angle of its rotation part
    turn = np.arctan2(d_fx_dy - d_fy_dx, 2.0 - d_fx_dx - d_fy_dy).astype(np.float32)
    frame_out = np.empty((height, width), np.int32)
    coords_out = np.empty((height, width, 3), np.float32)
    origin = np.empty((height, width), np.int64)
    run_parts(_transport, nnf.frame, nnf.coords, flow, turn, frame_out, coords_out, origin)
    return NNF(frame_out, coords_out), origin
