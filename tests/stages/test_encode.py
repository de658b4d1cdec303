"""encode stage: frame count, size, fps and colour tags of the MP4 it writes."""

import re
import subprocess

import imageio_ffmpeg
import numpy as np
import pytest
from PIL import Image

from fluidymation.errors import StageError
from fluidymation.stages.encode import Params, encode_mp4, pad_to_even, preview_frame, write_animation


def probe(path):
    """Stream facts from `ffmpeg -i` (imageio-ffmpeg ships ffmpeg but no ffprobe)."""
    result = subprocess.run([imageio_ffmpeg.get_ffmpeg_exe(), "-hide_banner", "-i", str(path)],
                            capture_output=True, text=True)
    video = next(line for line in result.stderr.splitlines() if "Video:" in line)
    count = imageio_ffmpeg.count_frames_and_secs(str(path))[0]
    return video, count


def frames(count, height, width):
    for index in range(count):
        frame = np.zeros((height, width, 3), np.float32)
        frame[:, : (index + 1) * width // count] = (0.9, 0.5, 0.2)
        yield frame


@pytest.mark.parametrize("fps", [24, 23.976])
def test_mp4_has_the_frames_size_and_fps(tmp_path, fps):
    path = tmp_path / "out.mp4"
    assert encode_mp4(frames(10, 48, 64), path, params=Params(fps=fps)) == 10
    video, count = probe(path)
    assert count == 10
    assert "h264" in video and "yuv420p(tv, bt709, progressive)" in video and "64x48" in video
    assert re.search(rf"\b{round(fps, 2):g} fps", video)


def test_odd_size_is_padded_to_even(tmp_path):
    path = tmp_path / "odd.mp4"
    encode_mp4(frames(3, 33, 21), path, params=Params(fps=12))
    video, count = probe(path)
    assert "22x34" in video and count == 3


def test_pad_repeats_the_edge():
    frame = np.arange(3 * 5 * 3, dtype=np.uint8).reshape(3, 5, 3)
    padded = pad_to_even(frame)
    assert padded.shape == (4, 6, 3)
    assert np.array_equal(padded[3, :5], frame[2]) and np.array_equal(padded[:3, 5], frame[:, 4])


def test_colours_survive_encoding(tmp_path):
    path = tmp_path / "flat.mp4"
    flat = np.full((32, 32, 3), (0.8, 0.3, 0.1), np.float32)
    encode_mp4([flat] * 2, path, params=Params(fps=24, crf=0))
    decoded = subprocess.run([imageio_ffmpeg.get_ffmpeg_exe(), "-v", "error", "-i", str(path), "-frames:v", "1",
                              "-f", "rawvideo", "-pix_fmt", "rgb24", "-"], capture_output=True, check=True).stdout
    rgb = np.frombuffer(decoded, np.uint8).reshape(32, 32, 3).astype(float)
    assert np.abs(rgb.mean(axis=(0, 1)) - np.array([204, 76.5, 25.5])).max() < 4


def test_no_frames_and_mismatched_frames_are_errors(tmp_path):
    with pytest.raises(StageError, match="no frames"):
        encode_mp4([], tmp_path / "none.mp4", params=Params(fps=24))
    with pytest.raises(StageError, match="the first was"):
        encode_mp4([np.zeros((8, 8, 3)), np.zeros((10, 8, 3))], tmp_path / "bad.mp4", params=Params(fps=24))
    assert not list(tmp_path.glob("*.mp4")) and not list(tmp_path.glob(".*part*"))


def test_missing_ffmpeg_is_a_clear_error(tmp_path, monkeypatch):
    def no_ffmpeg():
        raise RuntimeError("No ffmpeg exe could be found")

    monkeypatch.setattr(imageio_ffmpeg, "get_ffmpeg_exe", no_ffmpeg)
    with pytest.raises(StageError, match="ffmpeg is not available"):
        encode_mp4(frames(2, 8, 8), tmp_path / "x.mp4", params=Params(fps=24))


@pytest.mark.parametrize("suffix", [".gif", ".webp"])
def test_animated_preview_loops_at_the_frame_rate(tmp_path, suffix):
    shown = [preview_frame(frame) for frame in frames(4, 20, 1000)]
    assert shown[0].shape == (6, 333, 3) and shown[0].dtype == np.uint8  # 3×3 box filter: at most 480 px wide
    write_animation(shown, tmp_path / f"p{suffix}", fps=10)
    with Image.open(tmp_path / f"p{suffix}") as animation:
        animation.load()
        assert animation.n_frames == 4 and animation.size == (333, 6)
        assert animation.info.get("loop") == 0 and animation.info.get("duration") == 100
