"""Rotated, bilinearly sampled patches of a source sequence.

Coordinates: pixel ``(x, y)`` has its centre at integer ``x, y``; ``x`` runs along the
width, ``y`` down the height. A patch of size n around ``(x, y)`` rotated by ``theta``
samples the source at ``(x, y) + R(theta) (dx, dy)`` for ``dx, dy`` in
``[-n//2, n//2]``, with ``R(theta) = [[cos, -sin], [sin, cos]]``. The same convention
is used by propagation, voting, NNF up/downscaling and the occurrence map. Samples
outside the image are clamped to the nearest edge pixel.
"""

import math

import numpy as np

from fluidymation.engine._jit import kernel


@kernel
def _bilinear_setup(x, y, height, width):
    """Clamped corner indices and weights for sampling at ``(x, y)``."""
    x = min(max(x, 0.0), width - 1.0)
    y = min(max(y, 0.0), height - 1.0)
    x0 = int(math.floor(x))
    y0 = int(math.floor(y))
    x1 = min(x0 + 1, width - 1)
    y1 = min(y0 + 1, height - 1)
    fx = x - x0
    fy = y - y0
    return x0, y0, x1, y1, (1.0 - fx) * (1.0 - fy), fx * (1.0 - fy), (1.0 - fx) * fy, fx * fy


@kernel
def _sample_pixel(source, frame, x, y, out):
    """Bilinear sample of every channel of ``source[frame]`` at ``(x, y)`` into ``out``."""
    height = source.shape[1]
    width = source.shape[2]
    x0, y0, x1, y1, w00, w10, w01, w11 = _bilinear_setup(x, y, height, width)
    for c in range(source.shape[3]):
        out[c] = (
            w00 * source[frame, y0, x0, c]
            + w10 * source[frame, y0, x1, c]
            + w01 * source[frame, y1, x0, c]
            + w11 * source[frame, y1, x1, c]
        )


@kernel
def _sample_patch(source, frame, x, y, theta, radius, out):
    cos_t = math.cos(theta)
    sin_t = math.sin(theta)
    for dy in range(-radius, radius + 1):
        for dx in range(-radius, radius + 1):
            sx = x + cos_t * dx - sin_t * dy
            sy = y + sin_t * dx + cos_t * dy
            _sample_pixel(source, frame, sx, sy, out[dy + radius, dx + radius])


def sample_patch(source, frame, x, y, theta, *, patch_size=5):
    """Sample the rotated n×n patch centred at ``(x, y)`` of ``source[frame]``.

    Parameters
    ----------
    source : ndarray, shape (T, H, W, C), float32
    frame : int
    x, y, theta : float
        Patch centre (pixels) and rotation (radians).
    patch_size : int
        Odd patch side n.

    Returns
    -------
    ndarray, shape (n, n, C), float32
    """
    source = np.ascontiguousarray(source, dtype=np.float32)
    if source.ndim != 4:
        raise ValueError(f"source must have shape (T, H, W, C), got {source.shape}")
    if patch_size < 1 or patch_size % 2 == 0:
        raise ValueError(f"patch_size must be odd and positive, got {patch_size}")
    if not 0 <= frame < source.shape[0]:
        raise ValueError(f"frame {frame} outside the source's {source.shape[0]} frames")
    out = np.empty((patch_size, patch_size, source.shape[3]), dtype=np.float32)
    _sample_patch(source, int(frame), float(x), float(y), float(theta), patch_size // 2, out)
    return out


def sample_back(values: np.ndarray, flow: np.ndarray, *, order: int = 1) -> np.ndarray:
    """``values`` (H, W) or (H, W, C) sampled where each pixel's material came from, q − ``flow``(q) (the motion
    that brought it there), bilinearly (``order`` 1) or at the nearest pixel (0), edges repeated; float64."""
    from scipy import ndimage  # here, not at the top: the synthesis path imports this module and not scipy (0.3 s)

    height, width = flow.shape[:2]
    ys, xs = np.mgrid[:height, :width].astype(np.float64)
    came_from = [ys - flow[..., 1], xs - flow[..., 0]]
    values = np.asarray(values, np.float64)
    if values.ndim == 2:
        return ndimage.map_coordinates(values, came_from, order=order, mode="nearest")
    return np.stack([ndimage.map_coordinates(values[..., c], came_from, order=order, mode="nearest")
                     for c in range(values.shape[2])], axis=-1)
