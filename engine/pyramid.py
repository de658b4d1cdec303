"""Gaussian pyramids: halve the resolution with a 4-tap binomial filter.

Coarse pixel ``k`` covers fine pixels ``2k-1 .. 2k+2`` with weights ``(1, 3, 3, 1)/8``,
so its centre lies at fine coordinate ``2k + 1/2`` (the convention the NNF upscaling
formula assumes). A dimension of size s becomes ``(s + 1) // 2``; edges are clamped.
"""

import numpy as np

from fluidymation.engine._jit import kernel, run_parts

_TAPS = (0.125, 0.375, 0.375, 0.125)


@kernel
def _downsample(image, out, part, parts):
    frames, height, width, channels = image.shape
    out_height = out.shape[1]
    out_width = out.shape[2]
    for row in range(part, frames * out_height, parts):
        t = row // out_height
        y = row % out_height
        column = np.zeros((width, channels), dtype=np.float32)
        for tap in range(4):
            fy = min(max(2 * y - 1 + tap, 0), height - 1)
            weight = np.float32(_TAPS[tap])
            for x in range(width):
                for c in range(channels):
                    column[x, c] += weight * image[t, fy, x, c]
        for x in range(out_width):
            for c in range(channels):
                acc = np.float32(0.0)
                for tap in range(4):
                    fx = min(max(2 * x - 1 + tap, 0), width - 1)
                    acc += np.float32(_TAPS[tap]) * column[fx, c]
                out[t, y, x, c] = acc


def downsample(image):
    """Blur and halve an image or sequence.

    Parameters
    ----------
    image : ndarray, shape (H, W), (H, W, C) or (T, H, W, C), float32

    Returns
    -------
    ndarray, float32, same number of dimensions, each of H and W halved (rounded up).
    """
    image = np.asarray(image, dtype=np.float32)
    ndim = image.ndim
    if ndim not in (2, 3, 4):
        raise ValueError(f"expected (H, W), (H, W, C) or (T, H, W, C), got shape {image.shape}")
    work = image
    if ndim == 2:
        work = image[None, :, :, None]
    elif ndim == 3:
        work = image[None]
    work = np.ascontiguousarray(work)
    frames, height, width, channels = work.shape
    out = np.empty((frames, (height + 1) // 2, (width + 1) // 2, channels), dtype=np.float32)
    run_parts(_downsample, work, out)
    if ndim == 2:
        return out[0, :, :, 0]
    if ndim == 3:
        return out[0]
    return out


def downsample_angles(angles):
    """Halve a field of angles (radians) by averaging unit vectors, shape (..., H, W)."""
    angles = np.asarray(angles, dtype=np.float32)
    unit = np.stack([np.cos(angles), np.sin(angles)], axis=-1)
    if unit.ndim == 3:
        small = downsample(unit)
    else:
        small = downsample(unit.reshape((-1,) + unit.shape[-3:]))
        small = small.reshape(unit.shape[:-3] + small.shape[-3:])
    return np.arctan2(small[..., 1], small[..., 0]).astype(np.float32)


def downsample_labels(labels):
    """Halve a label image (..., H, W) by taking every other pixel (labels do not blend)."""
    labels = np.asarray(labels)
    return np.ascontiguousarray(labels[..., ::2, ::2])


def level_shape(height, width, level):
    """(H, W) after ``level`` halvings."""
    for _ in range(level):
        height, width = (height + 1) // 2, (width + 1) // 2
    return height, width


def levels_that_fit(shapes, *, patch_size):
    """The largest level count whose coarsest level keeps every side ≥ 2·patch_size + 1.

    Parameters
    ----------
    shapes : iterable of (H, W)
        Source and target image sizes.
    patch_size : int

    Returns
    -------
    int, at least 1.
    """
    side = min(min(int(h), int(w)) for h, w in shapes)
    levels = 1
    while (side + 1) // 2 >= 2 * patch_size + 1:
        side = (side + 1) // 2
        levels += 1
    return levels


def gaussian_pyramid(image, levels):
    """List of ``levels`` images, finest (the input, as float32) first."""
    if levels < 1:
        raise ValueError(f"levels must be at least 1, got {levels}")
    pyramid = [np.ascontiguousarray(image, dtype=np.float32)]
    for _ in range(levels - 1):
        pyramid.append(downsample(pyramid[-1]))
    return pyramid
