"""The ``guides`` stage: guidance channels of a mask sequence, streamed frame by frame.

For every frame ``j`` of a mask sequence it produces (ALGORITHM.md, "Guidance
channels"): the smoothed mask, the signed distance ``dist``, the ``shape`` channel,
the border/interior ``segments``, the ``flow`` (estimated from the masks or given), its
orientation and the motion extents ``ext+`` and ``ext−``.

Frame conventions: ``flow[j]`` is the motion that brought the material to frame ``j``
(from ``j − 1``; for the first frame, the motion to the second). The accumulators are
``acc+[j] = mask[j] · (acc+[j−1] + flow[j])`` from ``acc+[0] = 0`` and
``acc−[j] = mask[j] · (acc−[j+1] + flow[j+1])`` from ``acc−[T−1] = 0``, so reversing a
sequence negates its flows and swaps ext+ and ext−. An estimated flow is defined
everywhere: outside the mask it is the smooth extension of the boundary motion (so
ext− sees the motion of a boundary that recedes past a pixel).

Memory does not grow with the number of frames: the forward quantities are computed in
one pass with a fixed window of frames in memory and written to an on-disk cache of
memory-mapped files (one mapping per frame access, released at once); ext− is then
computed by a backward pass over that cache.
"""

from __future__ import annotations

import json
import os
from dataclasses import asdict
from pathlib import Path
from typing import Any, Callable, NamedTuple, Sequence, Union

import numpy as np
from scipy import ndimage

from fluidymation.engine import distance, extent, flow as flow_kernels
from fluidymation.errors import StageError
from fluidymation.stages.guide_params import Params
from fluidymation.stages.flow_io import read_flow

NAME = "guides"
VERSION = 1

#: One mask per frame index: a callable ``masks(j)`` or a sequence ``masks[j]``.
MaskSource = Union[Callable[[int], np.ndarray], Sequence[np.ndarray]]
#: One flow per frame index, as an (H, W, 2) array or the path of a .npy/.flo file.
FlowSource = Union[Callable[[int], Any], Sequence[Any]]
#: ``progress(done, total)``, called after each unit of work.
Progress = Callable[[int, int], None]


def map_frames(path: str | os.PathLike, start: int, stop: int, frame_shape: tuple, mode: str = "r") -> np.memmap:
    """Frames ``start..stop−1`` of a raw float32 file of equally shaped frames stored back to back, mapped.

    Delete the mapping once done with it: the pages it touched then leave the process's
    resident memory, so reading a long file piece by piece keeps memory bounded.
    """
    frame_bytes = int(np.prod(frame_shape)) * 4
    return np.memmap(path, dtype=np.float32, mode=mode, offset=start * frame_bytes,
                     shape=(stop - start,) + tuple(frame_shape))


class FrameGuides(NamedTuple):
    """The guidance channels of one frame; ``(H, W)`` unless noted."""

    mask: np.ndarray  #: bool, the smoothed mask
    dist: np.ndarray  #: float32 signed distance, positive inside
    shape: np.ndarray  #: float32 in [0, 1]
    segments: np.ndarray  #: uint8, distance.OUTSIDE / BORDER / INTERIOR
    flow: np.ndarray  #: (H, W, 2) float32 (dx, dy) px/frame
    direction: np.ndarray  #: float32 radians, atan2(dy, dx)
    ext_plus: np.ndarray  #: float32
    ext_minus: np.ndarray  #: float32


class GuideCache:
    """Per-frame guides on disk: one raw float32 file per channel, frames back to back.

    Every access maps only the one frame it touches and releases the mapping, so the
    resident memory does not grow with the number of frames.
    """

    CHANNELS = {"dist": 1, "shape": 1, "flow": 2, "ext_plus": 1, "ext_minus": 1}
    _META = "guides.json"

    def __init__(self, directory: str | os.PathLike, meta: dict):
        self.directory = Path(directory)
        self.meta = meta
        self.frame_count = int(meta["frame_count"])
        self.height = int(meta["height"])
        self.width = int(meta["width"])
        self.border_width = float(meta["border_width"])

    @classmethod
    def create(cls, directory, *, frame_count: int, height: int, width: int, border_width: float) -> GuideCache:
        """Make an empty cache in ``directory`` (created if missing)."""
        directory = Path(directory)
        directory.mkdir(parents=True, exist_ok=True)
        meta = {"frame_count": frame_count, "height": height, "width": width, "border_width": border_width}
        cache = cls(directory, meta)
        for channel, depth in cls.CHANNELS.items():
            with open(cache._path(channel), "wb") as handle:
                handle.truncate(frame_count * height * width * depth * 4)
        cache.save_meta()
        return cache

    @classmethod
    def open(cls, directory: str | os.PathLike) -> GuideCache:
        """Open a cache written by :func:`compute_guides`."""
        directory = Path(directory)
        try:
            meta = json.loads((directory / cls._META).read_text())
        except (OSError, ValueError) as exc:
            raise StageError(f"{directory}: not a guides cache ({exc})") from None
        return cls(directory, meta)

    def save_meta(self) -> None:
        (self.directory / self._META).write_text(json.dumps(self.meta, indent=1))

    def _path(self, channel: str) -> Path:
        return self.directory / f"{channel}.f32"

    def _frame_shape(self, channel: str) -> tuple:
        depth = self.CHANNELS[channel]
        return (self.height, self.width, depth) if depth > 1 else (self.height, self.width)

    def _offset(self, channel: str, index: int) -> int:
        if not 0 <= index < self.frame_count:
            raise IndexError(f"frame {index} outside 0..{self.frame_count - 1}")
        return index * int(np.prod(self._frame_shape(channel))) * 4

    def write(self, channel: str, index: int, array: np.ndarray) -> None:
        """Store frame ``index`` of ``channel`` (written through the page cache: four times faster than
        through a fresh mapping, whose every page faults first)."""
        data = np.ascontiguousarray(np.broadcast_to(array, self._frame_shape(channel)), np.float32)
        offset = self._offset(channel, index)
        with open(self._path(channel), "r+b") as handle:
            view = memoryview(data).cast("B")
            while view:
                written = os.pwrite(handle.fileno(), view, offset)
                view, offset = view[written:], offset + written

    def read(self, channel: str, index: int) -> np.ndarray:
        array = np.empty(self._frame_shape(channel), np.float32)
        offset = self._offset(channel, index)
        with open(self._path(channel), "rb") as handle:
            view = memoryview(array).cast("B")
            while view:
                got = os.preadv(handle.fileno(), [view], offset)
                if got == 0:
                    raise StageError(f"{self._path(channel)}: frame {index} is cut short")
                view, offset = view[got:], offset + got
        return array

    def frame(self, index: int) -> FrameGuides:
        """All channels of frame ``index``."""
        dist = self.read("dist", index)
        flow = self.read("flow", index)
        return FrameGuides(
            mask=dist > 0,
            dist=dist,
            shape=self.read("shape", index),
            segments=distance.segments(dist, border_width=self.border_width),
            flow=flow,
            direction=extent.orientation(flow),
            ext_plus=self.read("ext_plus", index),
            ext_minus=self.read("ext_minus", index),
        )


class _Window:
    """A per-frame quantity produced in increasing frame order and kept in a ring of
    ``depth`` frames.

    Temporal filters read frames beyond the sequence's ends as clamped to the end frame
    (``extrapolate=False``: constant) or linearly extrapolated by odd reflection about
    it (``extrapolate=True``: ``f(−k) = 2·f(0) − f(k)``, likewise after the last frame),
    which keeps a steady motion steady up to the ends.
    """

    def __init__(self, frame_count: int, depth: int, produce: Callable[[int], np.ndarray], *, extrapolate: bool):
        self.frame_count = frame_count
        self.depth = depth
        self.produce = produce
        self.extrapolate = extrapolate
        self.ring: np.ndarray | None = None
        self.produced = 0

    def _clamp(self, index: int) -> int:
        return min(max(index, 0), self.frame_count - 1)

    def get(self, index: int) -> np.ndarray:
        """Frame ``index`` (clamped); valid until ``depth`` newer frames are produced."""
        index = self._clamp(index)
        while self.produced <= index:
            value = self.produce(self.produced)
            if self.ring is None:
                self.ring = np.empty((self.depth,) + value.shape, dtype=np.float32)
            self.ring[self.produced % self.depth] = value
            self.produced += 1
        if index < self.produced - self.depth:
            raise RuntimeError(f"frame {index} already left the window (depth {self.depth})")
        return self.ring[index % self.depth]

    def _terms(self, index: int) -> list[tuple[int, float]]:
        """Frame ``index`` as ``(frame, factor)`` terms of frames inside the sequence."""
        end = self._clamp(index)
        if end == index or not self.extrapolate:
            return [(end, 1.0)]
        return [(end, 2.0), (self._clamp(2 * end - index), -1.0)]

    def slot_weights(self, center: int, taps: np.ndarray) -> np.ndarray:
        """Weights of the ring's slots that make ``sum_k taps[k] · frame[center + k − r]``
        (frames beyond the ends as the window reads them); valid until the ring moves on."""
        radius = taps.shape[0] // 2
        self.get(center + radius)
        weights = np.zeros(self.depth, dtype=np.float32)
        for offset in range(-radius, radius + 1):
            for index, factor in self._terms(center + offset):
                self.get(index)
                weights[index % self.depth] += factor * taps[offset + radius]
        return weights

    def smoothed(self, center: int, taps: np.ndarray) -> np.ndarray:
        """``sum_k taps[k] · frame[center + k − r]``, frames beyond the ends as the window reads them."""
        weights = self.slot_weights(center, taps)
        return flow_kernels.weighted_sum(self.ring, weights)


def _item_getter(source, what: str) -> Callable[[int], Any]:
    if callable(source):
        return source
    if hasattr(source, "__getitem__"):
        return source.__getitem__
    raise TypeError(f"{what} must be a callable taking a frame index or a sequence, got {type(source).__name__}")


def _coverage(mask: Any, index: int, shape: tuple[int, int] | None) -> np.ndarray:
    """A mask as float32 coverage in [0, 1]: bool as is, uint8 divided by 255, floats as is."""
    mask = np.asarray(mask)
    if mask.ndim != 2:
        raise StageError(f"guides: mask of frame {index} must be (H, W), got shape {mask.shape}")
    if shape is not None and mask.shape != shape:
        raise StageError(f"guides: mask of frame {index} has shape {mask.shape}, frame 0 has {shape}")
    if mask.dtype == np.bool_:
        return mask.astype(np.float32)
    if mask.dtype == np.uint8:
        return mask.astype(np.float32) / np.float32(255.0)
    if np.issubdtype(mask.dtype, np.floating):
        return np.clip(mask, 0.0, 1.0).astype(np.float32)
    raise StageError(f"guides: mask of frame {index} has dtype {mask.dtype}; use bool, uint8 or float coverage")


def _given_flow(item: Any, index: int, shape: tuple[int, int]) -> np.ndarray:
    if isinstance(item, (str, os.PathLike)):
        return read_flow(item, shape=shape)
    flow = np.asarray(item)
    if flow.shape != shape + (2,):
        raise StageError(f"guides: given flow of frame {index} has shape {flow.shape}, expected {shape + (2,)}")
    return np.array(flow, dtype=np.float32, order="C", copy=True)


def _fill_unknown(flow: np.ndarray, inside: np.ndarray, reach: float, estimate: Callable[[], np.ndarray]) -> np.ndarray:
    """``flow`` with its NaN pixels filled. Up to ``reach`` px from known pixels (where a
    geometry's coverage and the guides' blurred mask disagree: a rim, the gaps between a
    gear's teeth) by the nearest known value. Further away by the masks' ``estimate()``
    when some of those pixels lie inside the mask (so a layer the geometry says nothing
    about gets exactly the estimate), else by 0 (outside the mask the flow is not used)."""
    unknown = ~np.isfinite(flow).all(axis=2)
    if not unknown.any():
        return flow
    far = unknown.copy()
    known = ~unknown
    if known.any():
        rows, columns = np.nonzero(inside | known)
        margin = int(np.ceil(reach)) + 1
        window = (slice(max(rows.min() - margin, 0), rows.max() + margin + 1),
                  slice(max(columns.min() - margin, 0), columns.max() + margin + 1))
        distance, (near_rows, near_columns) = ndimage.distance_transform_edt(unknown[window], return_indices=True)
        near = unknown[window] & (distance <= reach)
        local = flow[window]
        local[near] = local[near_rows[near], near_columns[near]]
        far[window] &= ~near
    flow[far] = estimate()[far] if (far & inside).any() else 0.0
    return flow


def compute_guides(
    masks: MaskSource,
    frame_count: int,
    *,
    params: Params,
    cache_dir: str | os.PathLike,
    given_flow: FlowSource | None = None,
    progress: Progress | None = None,
) -> GuideCache:
    """Compute the guides of a whole mask sequence into an on-disk cache.

    Parameters
    ----------
    masks : callable or sequence
        ``masks(j)`` / ``masks[j]`` gives frame ``j``'s (H, W) mask: bool, uint8
        (0..255) or float coverage in [0, 1]. Each frame is requested once, in order.
    frame_count : int
        Number of frames ``T``.
    params : Params
    cache_dir : path
        Directory for the memory-mapped cache (about 24 bytes per pixel and frame).
    given_flow : callable or sequence, optional
        Flow of frame ``j`` as an (H, W, 2) float32 array (dx, dy) px/frame or a
        ``.npy``/``.flo`` path; used as is in place of the estimate from the masks, except
        where it is NaN (nothing known there, e.g. what the vector geometry does not
        describe): within ``blur_sigma`` (at least 2 px) of known pixels the nearest known
        value fills in, further away the estimate (0 when none of those pixels is inside
        the mask).
    progress : callable, optional
        ``progress(done, total)`` after each frame of each pass; ``total = 2·T``.

    Returns
    -------
    GuideCache
        Read frames with ``cache.frame(j)``; ``cache.meta`` also holds the largest
        ``|flow|``, ext+, ext− and ``|dist|`` of the sequence.
    """
    if frame_count < 1:
        raise StageError(f"guides: need at least one frame, got frame_count={frame_count}")
    get_mask = _item_getter(masks, "masks")
    get_flow = None if given_flow is None else _item_getter(given_flow, "given_flow")
    scale = params.scale
    border_width = params.border_width * scale
    dist_taps = distance.gaussian_weights(params.dist_time_sigma)
    flow_taps = distance.gaussian_weights(params.flow_time_radius / 3.0)
    dist_radius = dist_taps.shape[0] // 2
    flow_radius = flow_taps.shape[0] // 2

    first = _coverage(get_mask(0), 0, None)
    shape = first.shape
    pending = {0: first}

    def produce_dist(index: int) -> np.ndarray:
        coverage = pending.pop(index) if index in pending else _coverage(get_mask(index), index, shape)
        blurred = distance.gaussian_blur(coverage, sigma=params.blur_sigma * scale)
        return distance.signed_distance(blurred, threshold=params.threshold)

    # distances extrapolated linearly past the ends, so the ends' motion is not damped;
    # flows held constant past the ends (a steady motion again)
    dists = _Window(frame_count, 2 * dist_radius + flow_radius + 3, produce_dist, extrapolate=True)

    def produce_raw_flow(index: int) -> np.ndarray:
        mask = dists.get(index) > 0
        # between the distances smoothed along time around two frames; the first frame
        # takes the motion to the next one, seen on its own boundary
        prev_frame, cur_frame = (1, 0) if index == 0 else (index - 1, index)
        motion = flow_kernels.flow_from_distance_stack(
            dists.ring,
            dists.slot_weights(prev_frame, dist_taps),
            dists.slot_weights(cur_frame, dist_taps),
            mask,
            sweeps=params.relax_sweeps,
        )
        return -motion if index == 0 else motion

    raw_flows = _Window(frame_count, 2 * flow_radius + 1, produce_raw_flow, extrapolate=False)

    cache = GuideCache.create(
        cache_dir, frame_count=frame_count, height=shape[0], width=shape[1], border_width=border_width
    )
    total = 2 * frame_count
    accumulator = np.zeros(shape + (2,), dtype=np.float32)
    zero_flow = np.zeros(shape + (2,), dtype=np.float32)
    flow_max = ext_plus_max = dist_max = 0.0
    for index in range(frame_count):
        if get_flow is None:
            frame_flow = raw_flows.smoothed(index, flow_taps)
        else:
            frame_flow = _fill_unknown(_given_flow(get_flow(index), index, shape), dists.get(index) > 0,
                                       max(2.0, params.blur_sigma * scale), lambda: raw_flows.smoothed(index, flow_taps))
        frame_dist = dists.get(index)
        mask = frame_dist > 0
        ext_plus = extent.accumulate_extent(accumulator, frame_flow if index > 0 else zero_flow, mask)
        cache.write("dist", index, frame_dist)
        cache.write("shape", index, distance.shape_channel(mask, radius=params.shape_radius * scale))
        cache.write("flow", index, frame_flow)
        cache.write("ext_plus", index, ext_plus)
        flow_max = max(flow_max, float(np.sqrt(np.max(frame_flow[:, :, 0] ** 2 + frame_flow[:, :, 1] ** 2))))
        ext_plus_max = max(ext_plus_max, float(ext_plus.max()))
        dist_max = max(dist_max, float(frame_dist.max()), -float(frame_dist.min()))
        if progress is not None:
            progress(index + 1, total)

    accumulator[...] = 0.0
    ext_minus_max = 0.0
    for index in range(frame_count - 1, -1, -1):
        mask = cache.read("dist", index) > 0
        step = cache.read("flow", index + 1) if index + 1 < frame_count else zero_flow
        ext_minus = extent.accumulate_extent(accumulator, step, mask)
        cache.write("ext_minus", index, ext_minus)
        ext_minus_max = max(ext_minus_max, float(ext_minus.max()))
        if progress is not None:
            progress(2 * frame_count - index, total)

    cache.meta.update(
        flow_max=flow_max,
        ext_plus_max=ext_plus_max,
        ext_minus_max=ext_minus_max,
        dist_max=dist_max,
        params=asdict(params),
        flow_given=given_flow is not None,
    )
    cache.save_meta()
    return cache

