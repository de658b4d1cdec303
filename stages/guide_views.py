"""Per-frame PNG views (and optionally raw arrays) of the guides of a mask sequence.

Layout under the output directory, files numbered by frame index in the sequence::

    flow/00000.png       hue = direction, brightness = |flow| (paper fig. 4b)
    ext_plus/00000.png   grey ramp, 0 .. largest ext± of the sequence
    ext_minus/00000.png
    shape/00000.png      grey, the shape channel itself
    dist/00000.png       grey ramp, mid-grey on the boundary, white inside
    segments/00000.png   black outside, grey border, white interior

With ``raw=True`` also ``flow/00000.npy`` (H, W, 2) float32 (dx, dy) px/frame with y
down, and ``ext_plus/``, ``ext_minus/``, ``dist/``, ``shape/`` ``.npy`` (H, W) float32.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

import numpy as np

from fluidymation.engine import distance
from fluidymation.errors import StageError
from fluidymation.stages.files import write_npy, write_png
from fluidymation.stages.guides import FlowSource, FrameGuides, MaskSource, Params, Progress, compute_guides

RAW_CHANNELS = ("flow", "ext_plus", "ext_minus", "dist", "shape")

_SEGMENT_GREY = np.zeros(3, dtype=np.float32)
_SEGMENT_GREY[distance.BORDER] = 0.5
_SEGMENT_GREY[distance.INTERIOR] = 1.0


def flow_colour(flow: np.ndarray, *, max_speed: float) -> np.ndarray:
    """Flow as colour: hue = direction (0 = +x, turning towards +y), value = speed.

    Parameters
    ----------
    flow : (H, W, 2) float32
    max_speed : float
        Speed shown at full brightness; larger speeds are clipped.

    Returns
    -------
    (H, W, 3) float32 RGB in [0, 1]
    """
    angle = np.arctan2(flow[:, :, 1], flow[:, :, 0])
    hue = np.mod(angle / (2.0 * np.pi), 1.0) * 6.0
    speed = np.hypot(flow[:, :, 0], flow[:, :, 1])
    value = np.clip(speed / max_speed, 0.0, 1.0) if max_speed > 0 else np.zeros_like(speed)
    sector = np.floor(hue).astype(np.int64) % 6
    fraction = hue - np.floor(hue)
    rising, falling = value * fraction, value * (1.0 - fraction)
    zero = np.zeros_like(value)
    # HSV with full saturation: per sector, (r, g, b) from value, rising, falling, 0
    choices_r = [value, falling, zero, zero, rising, value]
    choices_g = [rising, value, value, falling, zero, zero]
    choices_b = [zero, zero, rising, value, value, falling]
    rgb = np.stack([np.choose(sector, c) for c in (choices_r, choices_g, choices_b)], axis=2)
    return rgb.astype(np.float32)


def _grey_ramp(values: np.ndarray, top: float) -> np.ndarray:
    return np.clip(values / top, 0.0, 1.0) if top > 0 else np.zeros_like(values)


def _frame_range(frames, frame_count: int) -> range:
    if frames is None:
        return range(frame_count)
    start, stop = (frames.start, frames.stop) if isinstance(frames, range) else frames
    if not 0 <= start < stop <= frame_count:
        raise StageError(
            f"guides: frames {start}:{stop} are not inside the sequence 0:{frame_count} (end exclusive)"
        )
    return range(start, stop)


#: The folders of the views, one PNG per frame in each (:func:`_write_frame`).
VIEWS = ("flow", "ext_plus", "ext_minus", "shape", "dist", "segments")


def _write_frame(out_dir: Path, number: int, guides: FrameGuides, meta: dict, raw: bool) -> None:
    name = f"{number:05d}"
    extent_top = max(meta["ext_plus_max"], meta["ext_minus_max"])
    write_png(out_dir / "flow" / f"{name}.png", flow_colour(guides.flow, max_speed=meta["flow_max"]))
    write_png(out_dir / "ext_plus" / f"{name}.png", _grey_ramp(guides.ext_plus, extent_top))
    write_png(out_dir / "ext_minus" / f"{name}.png", _grey_ramp(guides.ext_minus, extent_top))
    write_png(out_dir / "shape" / f"{name}.png", guides.shape)
    dist_top = meta["dist_max"]
    write_png(out_dir / "dist" / f"{name}.png", 0.5 + 0.5 * np.clip(guides.dist / dist_top, -1.0, 1.0))
    write_png(out_dir / "segments" / f"{name}.png", _SEGMENT_GREY[guides.segments])
    if raw:
        for channel in RAW_CHANNELS:
            write_npy(out_dir / channel / f"{name}.npy", getattr(guides, channel).astype(np.float32))


def write_guide_views(
    masks: MaskSource,
    frame_count: int,
    out_dir: str | os.PathLike,
    *,
    params: Params,
    frames=None,
    raw: bool = False,
    given_flow: FlowSource | None = None,
    progress: Progress | None = None,
    cache_dir: str | os.PathLike | None = None,
) -> dict:
    """Compute the guides of a mask sequence and write views of the requested frames.

    The guides are always computed over the whole sequence (ext+ starts at its first
    frame, ext− at its last), then frames ``frames`` are written, each file numbered by its frame index
    (as the masks are), so a partial write lines up with a full one.

    Parameters
    ----------
    masks, frame_count, params, given_flow
        As for :func:`fluidymation.stages.guides.compute_guides`.
    out_dir : path
        Receives ``flow/``, ``ext_plus/``, ``ext_minus/``, ``shape/``, ``dist/`` and
        ``segments/``.
    frames : (start, stop) or range, optional
        Frames to write, stop exclusive; default all.
    raw : bool
        Also write the arrays as ``.npy``.
    progress : callable, optional
        ``progress(done, total)``; ``total`` = 2·frame_count + frames written.
    cache_dir : path, optional
        Where to keep the guide cache; by default a temporary folder in ``out_dir``
        that is removed afterwards.

    Returns
    -------
    dict
        The cache metadata (size, frame count, largest |flow|, ext±, |dist|) and
        ``frames`` written as ``[start, stop]``.
    """
    out_dir = Path(out_dir)
    selected = _frame_range(frames, frame_count)
    total = 2 * frame_count + len(selected)

    def report(done: int, _total: int) -> None:
        if progress is not None:
            progress(done, total)

    out_dir.mkdir(parents=True, exist_ok=True)
    with contextlib.ExitStack() as stack:
        if cache_dir is None:
            cache_dir = stack.enter_context(tempfile.TemporaryDirectory(dir=out_dir, prefix=".guides-cache-"))
        cache = compute_guides(
            masks,
            frame_count,
            params=params,
            cache_dir=cache_dir,
            given_flow=given_flow,
            progress=report,
        )
        for done, index in enumerate(selected, start=1):
            _write_frame(out_dir, index, cache.frame(index), cache.meta, raw)
            report(2 * frame_count + done, total)
        return dict(cache.meta, frames=[selected.start, selected.stop])
