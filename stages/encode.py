"""encode stage: frames to an H.264 MP4 (yuv420p, BT.709 tagged) through imageio-ffmpeg.

The video is written to a temporary file next to the destination and renamed into
place when complete, so an interrupted encode never leaves a truncated MP4 behind.
Odd sizes are padded to even (yuv420p needs even sizes) by repeating the last row or
column.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fluidymation.errors import StageError
from fluidymation.stages.files import atomic_path, to_uint8

NAME = "encode"
VERSION = 1


@dataclass(frozen=True)
class Params:
    fps: float
    crf: int = 18  # H.264 constant rate factor: 0 lossless … 51 worst; 18 is visually lossless
    preset: str = "medium"


def even_size(width: int, height: int) -> tuple[int, int]:
    return width + width % 2, height + height % 2


def pad_to_even(frame: np.ndarray) -> np.ndarray:
    """(H, W, 3) uint8 padded by edge repetition to even height and width."""
    height, width = frame.shape[:2]
    if height % 2 == 0 and width % 2 == 0:
        return frame
    return np.pad(frame, ((0, height % 2), (0, width % 2), (0, 0)), mode="edge")


def encode_mp4(frames: Iterable[np.ndarray], path: str | os.PathLike, *, params: Params) -> int:
    """Write ``frames`` ((H, W, 3) float in [0, 1] or uint8, sRGB) to ``path``; return the count."""
    import imageio_ffmpeg

    try:
        imageio_ffmpeg.get_ffmpeg_exe()
    except RuntimeError as exc:
        raise StageError(f"cannot encode {path}: ffmpeg is not available ({exc})") from None
    frames = iter(frames)
    first = next(frames, None)
    if first is None:
        raise StageError(f"cannot encode {path}: no frames")
    first = pad_to_even(to_uint8(first)[:, :, :3])
    height, width = first.shape[:2]
    count = 0
    with atomic_path(Path(path)) as tmp:
        writer = imageio_ffmpeg.write_frames(
            str(tmp), (width, height), fps=params.fps, codec="libx264", quality=None, macro_block_size=1,
            pix_fmt_in="rgb24", pix_fmt_out="yuv420p", ffmpeg_log_level="error",
            input_params=["-f", "rawvideo"],
            output_params=["-crf", str(params.crf), "-preset", params.preset, "-f", "mp4",
                           "-colorspace", "bt709", "-color_primaries", "bt709", "-color_trc", "bt709",
                           "-color_range", "tv", "-x264-params", "colorprim=bt709:transfer=bt709:colormatrix=bt709",
                           "-movflags", "+faststart"],
        )
        try:
            writer.send(None)
            for frame in _chain(first, frames):
                frame = pad_to_even(to_uint8(frame)[:, :, :3])
                if frame.shape[:2] != (height, width):
                    raise StageError(f"cannot encode {path}: frame {count} is {frame.shape[1]}x{frame.shape[0]}, "
                                     f"the first was {width}x{height}")
                writer.send(np.ascontiguousarray(frame))
                count += 1
            writer.close()
        except (OSError, RuntimeError) as exc:
            raise StageError(f"ffmpeg failed while encoding {path}: {exc}") from None
        finally:
            writer.close()
    return count


def _chain(first, rest):
    yield first
    yield from rest


PREVIEW_WIDTH = 480  # px: animated previews are for quick sharing, not for grading


def preview_frame(frame: np.ndarray, *, width: int = PREVIEW_WIDTH) -> np.ndarray:
    """(H, W, 3) frame as uint8, shrunk by an integer box filter to at most ``width`` px wide."""
    factor = max(1, -(-frame.shape[1] // width))
    height, full_width = (frame.shape[0] // factor) * factor, (frame.shape[1] // factor) * factor
    image = np.asarray(frame[:height, :full_width, :3], np.float32)
    if factor > 1:
        image = image.reshape(height // factor, factor, full_width // factor, factor, 3).mean(axis=(1, 3))
    return to_uint8(image)


def write_animation(frames: list[np.ndarray], path: str | os.PathLike, *, fps: float) -> None:
    """An endlessly looping GIF or WebP (by ``path``'s suffix) of uint8 frames, written atomically."""
    import imageio.v3 as iio

    path = Path(path)
    if not frames:
        raise StageError(f"cannot write {path}: no frames")
    with atomic_path(path) as tmp:
        try:
            iio.imwrite(tmp, np.stack(frames), extension=path.suffix, duration=1000.0 / fps, loop=0)
        except (OSError, ValueError, TypeError) as exc:
            raise StageError(f"cannot write the preview {path}: {exc}") from None
