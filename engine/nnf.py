"""Nearest-neighbour fields: layout, random initialisation, upscaling, downscaling, merging.

An NNF maps every target pixel ``(x̂, ŷ)`` to a source patch ``(i, x, y, θ)``:
``frame[ŷ, x̂] = i`` (int32, -1 where the pixel has no match, e.g. outside the target
mask) and ``coords[ŷ, x̂] = (x, y, θ)`` (float32; positions in source pixels, θ in
radians, the rotation convention of :mod:`fluidymation.engine.sampling`). Patch centres
may lie anywhere in the source; window samples beyond its border repeat the edge pixels.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fluidymation.engine._jit import kernel, run_parts
from fluidymation.engine.random import _key4, _random_below
from fluidymation.engine.sorting import argsort_prefix

ROTATION_NONE = 0
ROTATION_FLOW = 1


@dataclass(frozen=True)
class NNF:
    """A nearest-neighbour field.

    Attributes
    ----------
    frame : ndarray, shape (H, W), int32
        Source frame index per target pixel, -1 for no match.
    coords : ndarray, shape (H, W, 3), float32
        Source ``x, y`` (pixels) and rotation ``θ`` (radians) per target pixel.
    """

    frame: np.ndarray
    coords: np.ndarray

    def __post_init__(self):
        if self.frame.ndim != 2 or self.frame.dtype != np.int32:
            raise TypeError(f"NNF.frame must be an (H, W) int32 array, got {self.frame.dtype} {self.frame.shape}")
        if self.coords.shape != self.frame.shape + (3,) or self.coords.dtype != np.float32:
            raise TypeError(f"NNF.coords must be an (H, W, 3) float32 array, got {self.coords.dtype} {self.coords.shape}")

    @property
    def shape(self):
        return self.frame.shape

    @classmethod
    def empty(cls, height, width):
        """An NNF of the given size with no matches."""
        return cls(np.full((height, width), -1, np.int32), np.zeros((height, width, 3), np.float32))

    def copy(self):
        return NNF(self.frame.copy(), self.coords.copy())

    def as_array(self):
        """(H, W, 4) float32 array ``(i, x, y, θ)`` for saving (``i = -1``: no match)."""
        return np.concatenate([self.frame[:, :, None].astype(np.float32), self.coords], axis=2)


@kernel
def _clamp(value, low, high):
    return min(max(value, low), high)


@kernel
def _match_is_valid(frame, x, y, label, source_segment):
    frames, height, width = source_segment.shape
    if frame < 0 or frame >= frames:
        return False
    if x < 0 or y < 0 or x > width - 1 or y > height - 1:
        return False
    return source_segment[frame, int(y + 0.5), int(x + 0.5)] == label


@kernel
def _flow_rotation(target_angle, source_angle, frame, x, y, tx, ty, flip):
    """The flow-aligned rotation θ_S(p) − θ_T(q), plus π when ``flip``.

    A patch turned by θ samples the source at ``R(θ)`` times its target offsets, so a source
    direction α shows in the target at α − θ: this θ lays the source flow onto the target's.
    """
    theta = source_angle[frame, int(y + 0.5), int(x + 0.5)] - target_angle[ty, tx]
    if flip:
        theta += math.pi
    return theta


@kernel
def _fill_random(
    nnf_frame, nnf_coords, target_segment, source_segment, segment_offsets, segment_pixels,
    rotation_mode, target_angle, source_angle, seed, salt, replace_all,
    part, parts,
):
    height, width = target_segment.shape
    source_height = source_segment.shape[1]
    source_width = source_segment.shape[2]
    labels = segment_offsets.shape[0] - 1
    for ty in range(part, height, parts):
        for tx in range(width):
            label = target_segment[ty, tx]
            if label < 0:
                nnf_frame[ty, tx] = -1
                continue
            if not replace_all and _match_is_valid(
                nnf_frame[ty, tx], nnf_coords[ty, tx, 0], nnf_coords[ty, tx, 1], label, source_segment
            ):
                continue
            if label >= labels or segment_offsets[label + 1] == segment_offsets[label]:
                nnf_frame[ty, tx] = -1
                continue
            key = _key4(seed, salt, ty, tx)
            count = segment_offsets[label + 1] - segment_offsets[label]
            flat = segment_pixels[segment_offsets[label] + _random_below(key, np.int64(0), count)]
            frame = flat // (source_height * source_width)
            rest = flat % (source_height * source_width)
            sy = rest // source_width
            sx = rest % source_width
            theta = 0.0
            if rotation_mode == ROTATION_FLOW:
                flip = _random_below(key, np.int64(1), np.int64(2)) == 1  # int64s: no literal counter to compile for
                theta = _flow_rotation(target_angle, source_angle, frame, sx, sy, tx, ty, flip)
            nnf_frame[ty, tx] = frame
            nnf_coords[ty, tx, 0] = sx
            nnf_coords[ty, tx, 1] = sy
            nnf_coords[ty, tx, 2] = theta


def segment_index(source_segment):
    """Source patch centres grouped by segment label, for uniform random sampling.

    Parameters
    ----------
    source_segment : ndarray, shape (T, H, W), int32
        Label per source pixel (≥ 0), -1 where no patch may be centred.

    Returns
    -------
    offsets : ndarray, shape (K + 1,), int64
        Centres with label k are ``pixels[offsets[k]:offsets[k + 1]]``.
    pixels : ndarray, int64
        Flat indices ``(i * H + y) * W + x``, ascending within each label.
    """
    flat = np.asarray(source_segment).ravel().astype(np.int64)
    usable = np.flatnonzero(flat >= 0)
    order = np.argsort(flat[usable], kind="stable")
    pixels = usable[order].astype(np.int64)
    count = int(flat.max()) + 1 if flat.size and flat.max() >= 0 else 0
    offsets = np.zeros(count + 1, np.int64)
    np.cumsum(np.bincount(flat[usable], minlength=count), out=offsets[1:])
    return offsets, pixels


def _empty_angles(shape):
    return np.zeros(shape, np.float32)


def fill_random(nnf, *, target_segment, source_segment, seed, salt=0, replace_all=True,
                rotation_mode=ROTATION_NONE, target_angle=None, source_angle=None, index=None):
    """Give target pixels uniformly random source matches of their own segment, in place.

    Parameters
    ----------
    nnf : NNF
        Field of the target's size; modified in place.
    target_segment : ndarray, shape (H, W), int32
        Label per target pixel; -1 pixels get no match.
    source_segment : ndarray, shape (T, Hs, Ws), int32
    seed, salt : int
        Random numbers come from ``(seed, salt, y, x)``.
    replace_all : bool
        False keeps every match that is already valid (in range, same segment).
    rotation_mode : int
        ``ROTATION_NONE`` (θ = 0) or ``ROTATION_FLOW`` (θ = θ_S − θ_T or that + π,
        from ``target_angle`` (H, W) and ``source_angle`` (T, Hs, Ws)).
    index : tuple, optional
        A precomputed :func:`segment_index` of ``source_segment``.
    """
    offsets, pixels = index if index is not None else segment_index(source_segment)
    if target_angle is None:
        target_angle = _empty_angles((1, 1))
        source_angle = _empty_angles((1, 1, 1))
    run_parts(
        _fill_random,
        nnf.frame, nnf.coords, np.ascontiguousarray(target_segment, np.int32), np.ascontiguousarray(source_segment, np.int32),
        offsets, pixels, int(rotation_mode), target_angle, source_angle, int(seed), int(salt),
        bool(replace_all),
    )


@kernel
def _upscale(coarse_frame, coarse_coords, fine_frame, fine_coords, source_height, source_width, part, parts):
    height, width = fine_frame.shape
    coarse_height, coarse_width = coarse_frame.shape
    for ty in range(part, height, parts):
        cy = min(ty // 2, coarse_height - 1)
        oy = (ty - 2 * cy) - 0.5
        for tx in range(width):
            cx = min(tx // 2, coarse_width - 1)
            frame = coarse_frame[cy, cx]
            fine_frame[ty, tx] = frame
            if frame < 0:
                continue
            ox = (tx - 2 * cx) - 0.5
            theta = coarse_coords[cy, cx, 2]
            cos_t = math.cos(theta)
            sin_t = math.sin(theta)
            x = 2.0 * coarse_coords[cy, cx, 0] + 0.5 + cos_t * ox - sin_t * oy
            y = 2.0 * coarse_coords[cy, cx, 1] + 0.5 + sin_t * ox + cos_t * oy
            fine_coords[ty, tx, 0] = _clamp(x, 0.0, source_width - 1.0)
            fine_coords[ty, tx, 1] = _clamp(y, 0.0, source_height - 1.0)
            fine_coords[ty, tx, 2] = theta


def upscale_nnf(nnf, *, target_shape, source_shape):
    """Upscale an NNF by one pyramid level, offsets turned by each match's rotation.

    ``(x↑, y↑) = 2 (x', y') + c + R(θ) ((x̂ mod 2, ŷ mod 2) − c)`` with ``c = (½, ½)``,
    then clamped to the source.

    Parameters
    ----------
    nnf : NNF
        Coarse field.
    target_shape : (H, W)
        Size of the finer target level.
    source_shape : (Hs, Ws)
        Size of the finer source level.

    Returns
    -------
    NNF of size ``target_shape``.
    """
    fine = NNF.empty(*target_shape)
    run_parts(_upscale, nnf.frame, nnf.coords, fine.frame, fine.coords, int(source_shape[0]), int(source_shape[1]))
    return fine


@kernel
def _downscale(fine_frame, fine_coords, steps, coarse_frame, coarse_coords, source_height, source_width, part, parts):
    height, width = coarse_frame.shape
    fine_height, fine_width = fine_frame.shape
    block = 1 << steps
    for cy in range(part, height, parts):
        keys = np.empty(block * block, np.int64)
        order = np.empty(block * block, np.int64)
        thetas = np.empty(block * block, np.float32)
        for cx in range(width):
            count = np.int64(0)  # not a literal 0: the sort would be compiled for it too
            for by in range(block):
                ty = cy * block + by
                if ty >= fine_height:
                    break
                for bx in range(block):
                    tx = cx * block + bx
                    if tx >= fine_width:
                        break
                    frame = fine_frame[ty, tx]
                    if frame < 0:
                        continue
                    theta = fine_coords[ty, tx, 2]
                    cos_t = math.cos(theta)
                    sin_t = math.sin(theta)
                    x = np.float64(fine_coords[ty, tx, 0])
                    y = np.float64(fine_coords[ty, tx, 1])
                    qx = tx
                    qy = ty
                    for _ in range(steps):
                        ox = (qx % 2) - 0.5
                        oy = (qy % 2) - 0.5
                        x = (x - 0.5 - (cos_t * ox - sin_t * oy)) * 0.5
                        y = (y - 0.5 - (sin_t * ox + cos_t * oy)) * 0.5
                        qx //= 2
                        qy //= 2
                    ix = int(_clamp(round(x), 0, source_width - 1))
                    iy = int(_clamp(round(y), 0, source_height - 1))
                    keys[count] = (np.int64(frame) << 40) | (np.int64(iy) << 20) | np.int64(ix)
                    thetas[count] = theta
                    count += 1
            if count == 0:
                coarse_frame[cy, cx] = -1
                continue
            argsort_prefix(keys, count, order)
            best_key = keys[order[0]]
            best_run = 0
            run = 0
            for k in range(count):
                if k > 0 and keys[order[k]] == keys[order[k - 1]]:
                    run += 1
                else:
                    run = 1
                if run > best_run:
                    best_run = run
                    best_key = keys[order[k]]
            for k in range(count):
                if keys[k] == best_key:
                    coarse_coords[cy, cx, 2] = thetas[k]
                    break
            coarse_frame[cy, cx] = np.int32(best_key >> 40)
            coarse_coords[cy, cx, 1] = (best_key >> 20) & 0xFFFFF
            coarse_coords[cy, cx, 0] = best_key & 0xFFFFF


def downscale_nnf(nnf, *, steps, target_shape, source_shape):
    """Downscale an NNF by ``steps`` pyramid levels, by the mode of the block's matches.

    Each fine match in the ``2^steps × 2^steps`` block of a coarse pixel is mapped back
    through the inverse of :func:`upscale_nnf` and rounded; the most frequent
    ``(i, x, y)`` wins (ties: the smallest ``(i, y, x)``), with the θ of its first
    occurrence in row-major order.

    Parameters
    ----------
    nnf : NNF
        Fine field.
    steps : int
        Number of halvings (≥ 0).
    target_shape, source_shape : (H, W)
        Sizes of the coarse target and source levels.

    Returns
    -------
    NNF of size ``target_shape`` with integer positions (``steps`` = 0: a copy of ``nnf``,
    positions untouched, so a field carried over at full resolution keeps its sub-pixel matches).
    """
    if steps < 0:
        raise ValueError(f"steps must be non-negative, got {steps}")
    if steps == 0:
        if nnf.shape != tuple(target_shape):
            raise ValueError(f"steps=0 keeps the size: nnf is {nnf.shape}, target_shape {tuple(target_shape)}")
        return NNF(nnf.frame.copy(), nnf.coords.copy())
    coarse = NNF.empty(*target_shape)
    run_parts(_downscale, nnf.frame, nnf.coords, int(steps), coarse.frame, coarse.coords,
               int(source_shape[0]), int(source_shape[1]))
    return coarse


def merge_nnf(first, second, first_error, second_error):
    """Per pixel, the match with the lower error (ties and -1 errors keep ``first``).

    Parameters
    ----------
    first, second : NNF
        Fields of the same size.
    first_error, second_error : ndarray, shape (H, W), float32
        Patch errors; pixels where ``second`` has no match always keep ``first``.

    Returns
    -------
    merged : NNF
    took_second : ndarray, shape (H, W), bool
        Where ``merged`` holds ``second``'s match.
    """
    take_second = (second.frame >= 0) & ((first.frame < 0) | (second_error < first_error))
    frame = np.where(take_second, second.frame, first.frame).astype(np.int32)
    coords = np.where(take_second[:, :, None], second.coords, first.coords).astype(np.float32)
    return NNF(frame, coords), take_second
