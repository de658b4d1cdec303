"""Painted keyframes and the layer's motion between them, as the keyframe morph reads them.

* :func:`read_keyframe`: a keyframe PNG as premultiplied RGBA at the output size (RGB
  images take the layer's coverage as alpha), refused when its paint strays outside the
  layer's mask at that frame.
* :func:`keyframe_weights`: ŵ(m, n) of seed 003 eq. 6.1, the weight of keyframe n in
  frame m (``blend``, ``radius``, ``smooth``; docs/keyframes.md).
* :func:`step_maps`, :class:`KeyMaps`: where each pixel's material is one frame earlier
  and later, and in each keyframe, by following the layer's flow (the motion prior).

Positions are ``(x, y)`` in pixels of the full-resolution frame. ``flow[j]`` is the
motion that brought the material to frame j (docs/guides.md): the material at q in
frame j was at q − flow[j](q) in frame j − 1.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy import ndimage

from fluidymation.errors import InputError
from fluidymation.stages.files import read_image
from fluidymation.stages.keyframe_params import WEIGHTINGS

#: The share of a keyframe's paint that may lie outside the layer's (slightly grown) mask.
STRAY_LIMIT = 0.01
#: How far (px) paint may reach past the mask's edge before it counts as stray.
STRAY_MARGIN = 2


def _resize(image: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """(h, w, C) resampled to ``shape`` bilinearly, low-passed first when shrinking."""
    if image.shape[:2] == tuple(shape):
        return image
    factors = (shape[0] / image.shape[0], shape[1] / image.shape[1])
    sigma = [max(0.0, 0.5 / f - 0.5) for f in factors] + [0.0]
    if max(sigma) > 0:
        image = ndimage.gaussian_filter(image, sigma=sigma, mode="nearest")
    rows = (np.arange(shape[0]) + 0.5) / factors[0] - 0.5
    columns = (np.arange(shape[1]) + 0.5) / factors[1] - 0.5
    grid = np.meshgrid(rows, columns, indexing="ij")
    return np.stack([ndimage.map_coordinates(image[..., c], grid, order=1, mode="nearest")
                     for c in range(image.shape[2])], axis=-1).astype(np.float32)


def read_keyframe(path: str | Path, frame: int, coverage: np.ndarray) -> np.ndarray:
    """Keyframe ``path`` of scene frame ``frame`` as premultiplied RGBA (H, W, 4) float32 at ``coverage``'s size.

    An RGB or grey image is the paint inside the layer: its alpha is ``coverage``. Raises
    InputError naming the file when more than :data:`STRAY_LIMIT` of its paint (alpha ≥ ½)
    lies farther than :data:`STRAY_MARGIN` px outside the layer's mask at that frame.
    """
    path = Path(path)
    image = read_image(path)
    has_alpha = image.shape[2] in (2, 4)
    colour = image[..., :1].repeat(3, axis=2) if image.shape[2] <= 2 else image[..., :3]
    channels = np.concatenate([colour, image[..., -1:]], axis=2) if has_alpha else colour
    channels = _resize(np.clip(channels, 0.0, 1.0), coverage.shape)
    alpha = np.clip(channels[..., 3], 0.0, 1.0) if has_alpha else coverage.astype(np.float32)
    painted = alpha >= 0.5
    if has_alpha and painted.any():
        inside = ndimage.binary_dilation(coverage > 0.01, iterations=STRAY_MARGIN)
        stray = np.count_nonzero(painted & ~inside) / np.count_nonzero(painted)
        if stray > STRAY_LIMIT:
            raise InputError(f"{path}: {stray:.1%} of keyframe {frame}'s paint lies outside the layer's mask at "
                             f"frame {frame} (at most {STRAY_LIMIT:.0%} may); paint inside the layer's shape")
    rgba = np.empty(coverage.shape + (4,), np.float32)
    rgba[..., :3] = np.clip(channels[..., :3], 0.0, 1.0) * alpha[..., None]
    rgba[..., 3] = alpha
    return rgba


def keyframe_weights(frame: int, keys: list[int], weighting: str, radius: int) -> dict[int, float]:
    """ŵ(frame, key) for the keys with a weight above 0, summing to 1.

    ``blend``: the two keys around ``frame``, linearly by its position between them (the
    nearest one alone outside their range or on a key). ``radius`` and ``smooth`` measure
    the distance in keys: u is ``frame``'s fractional rank among the keys; ``radius``
    weighs every key within ``radius`` of u alike, ``smooth`` by the smoothstep of
    1 − |rank − u| / (radius + 1).
    """
    keys = sorted(keys)
    if weighting not in WEIGHTINGS:
        raise ValueError(f"weighting must be one of {WEIGHTINGS}, got {weighting!r}")
    if frame <= keys[0] or frame >= keys[-1]:
        rank = 0.0 if frame <= keys[0] else float(len(keys) - 1)
    else:
        below = int(np.searchsorted(keys, frame, side="right")) - 1
        rank = below + (frame - keys[below]) / (keys[below + 1] - keys[below])
    if weighting == "blend":
        low = int(np.floor(rank))
        share = rank - low
        weights = {keys[low]: 1.0 - share}
        if share > 0:
            weights[keys[low + 1]] = share
    else:
        weights = {}
        for index, key in enumerate(keys):
            distance = abs(index - rank)
            if weighting == "radius":
                value = 1.0 if distance <= radius + 1e-9 else 0.0
            else:
                t = max(0.0, 1.0 - distance / (radius + 1))
                value = t * t * (3.0 - 2.0 * t)
            if value > 0:
                weights[key] = value
    total = sum(weights.values())
    return {key: value / total for key, value in weights.items()}


def sample(values: np.ndarray, positions: np.ndarray) -> np.ndarray:
    """(H, W, C) ``values`` read bilinearly at ``positions`` (..., 2) ``(x, y)``, edges repeated; float32."""
    coords = [positions[..., 1], positions[..., 0]]
    return np.stack([ndimage.map_coordinates(values[..., c], coords, order=1, mode="nearest")
                     for c in range(values.shape[2])], axis=-1).astype(np.float32)


def identity(shape: tuple[int, int]) -> np.ndarray:
    """Every pixel's own position, (H, W, 2) ``(x, y)`` float32."""
    ys, xs = np.mgrid[:shape[0], :shape[1]].astype(np.float32)
    return np.stack([xs, ys], axis=-1)


def step_maps(flow_here: np.ndarray, flow_next: np.ndarray | None, *, iterations: int = 4):
    """Where the material of each pixel of frame j is in frames j − 1 and j + 1, and its speed.

    ``flow_here`` is flow[j]: frame j − 1 holds q's material at q − flow[j](q).
    ``flow_next`` is flow[j + 1] (None for the last frame): q's material moves to the y
    with y − flow[j+1](y) = q, found by fixed-point iteration from q + flow[j+1](q).

    Returns
    -------
    back, forward : ndarray, (H, W, 2) float32
        Positions in frames j − 1 and j + 1 (forward: ``q + flow[j]`` past the last frame).
    speed : ndarray, (H, W) float32
        |flow[j]|, px/frame.
    """
    here = identity(flow_here.shape[:2])
    back = here - flow_here
    step = flow_here if flow_next is None else flow_next
    forward = here + step
    if flow_next is not None:
        for _ in range(iterations):
            forward = here + sample(flow_next, forward)
    speed = np.sqrt(flow_here[..., 0] ** 2 + flow_here[..., 1] ** 2).astype(np.float32)
    return back.astype(np.float32), forward.astype(np.float32), speed


def follow(map_there: np.ndarray, step: np.ndarray) -> np.ndarray:
    """The position in a keyframe of each pixel, given ``map_there`` (the positions in that keyframe of
    the pixels of the neighbouring frame) and ``step`` (each pixel's position in that neighbouring frame)."""
    return sample(map_there, step)
