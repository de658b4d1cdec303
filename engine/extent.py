"""Flow orientation and the motion-extent channels ext+ and ext− (paper 3.2–3.3).

The extent accumulators are 2D: a pixel moved forth and then back returns to zero.
Each frame, the accumulator is reset to (0, 0) wherever the pixel is outside that
frame's mask, so accumulation restarts where material appears again.
"""

from __future__ import annotations

import math

import numpy as np
from fluidymation.engine._jit import kernel


@kernel
def _accumulate(accumulator, flow, mask, extent):
    height, width = mask.shape
    for y in range(height):
        for x in range(width):
            if mask[y, x]:
                acc_x = accumulator[y, x, 0] + flow[y, x, 0]
                acc_y = accumulator[y, x, 1] + flow[y, x, 1]
            else:
                acc_x = np.float32(0.0)
                acc_y = np.float32(0.0)
            accumulator[y, x, 0] = acc_x
            accumulator[y, x, 1] = acc_y
            extent[y, x] = math.sqrt(acc_x * acc_x + acc_y * acc_y)


def accumulate_extent(accumulator: np.ndarray, flow: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """Advance a 2D extent accumulator by one frame and return its length.

    ``accumulator = mask ? accumulator + flow : (0, 0)``, updated in place.

    Parameters
    ----------
    accumulator : (H, W, 2) float32, C-contiguous
        Modified in place.
    flow : (H, W, 2) float32
        The motion added this step, px/frame.
    mask : (H, W) bool
        The frame whose accumulator this becomes.

    Returns
    -------
    (H, W) float32
        ``|accumulator|``, the ext+ (forward pass) or ext− (backward pass) channel.
    """
    if accumulator.dtype != np.float32 or not accumulator.flags.c_contiguous:
        raise TypeError("accumulator must be a C-contiguous float32 array")
    flow = np.ascontiguousarray(flow, dtype=np.float32)
    mask = np.ascontiguousarray(mask, dtype=np.bool_)
    if accumulator.shape != flow.shape or flow.shape != mask.shape + (2,) or mask.ndim != 2:
        raise ValueError(
            f"accumulate_extent: shapes {accumulator.shape}, {flow.shape}, {mask.shape} do not fit"
        )
    extent = np.empty(mask.shape, dtype=np.float32)
    _accumulate(accumulator, flow, mask, extent)
    return extent


def orientation(flow: np.ndarray) -> np.ndarray:
    """``dir = atan2(dy, dx)`` of an ``(H, W, 2)`` flow, float32 radians in [-π, π]."""
    flow = np.asarray(flow, dtype=np.float32)
    if flow.ndim != 3 or flow.shape[2] != 2:
        raise ValueError(f"orientation expects an (H, W, 2) flow, got shape {flow.shape}")
    return np.arctan2(flow[:, :, 1], flow[:, :, 0]).astype(np.float32)
