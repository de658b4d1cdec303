"""``fluidymation resynth``: a drawn clip re-synthesized to PNGs and an MP4, resumed where it stopped, and its
bad input refused with exit 2 naming the clip, the option or the frame."""

import av
import imageio.v3 as iio
import numpy as np
import pytest

from fluidymation.pipeline.cli import main

from tests.stages.test_cartoon import sprite_clip

QUICK = ["--param", "patch_size=5", "--param", "pyramid_levels=1", "--param", "motion_iterations=20",
         "--param", "block_size=9", "--param", "opt_iters=[2]", "--param", "fresh_iters=[4]"]


@pytest.fixture(scope="module")
def clip(tmp_path_factory):
    folder = tmp_path_factory.mktemp("clip")
    rgb, _ = sprite_clip(frames=5)
    for index, frame in enumerate(rgb):
        iio.imwrite(folder / f"{index:04d}.png", np.rint(frame * 255).astype(np.uint8))
    return folder


def _frames(out, count):
    return [iio.imread(out / "frames" / f"{index:04d}.png") for index in range(count)]


def test_resynth_writes_rgba_frames_and_a_video_and_resumes(clip, tmp_path):
    whole = tmp_path / "whole"
    assert main(["-q", "resynth", str(clip), "-o", str(whole), "--frames", "8", *QUICK]) == 0
    frames = _frames(whole, 8)
    assert frames[0].shape == (36, 52, 4) and all(0 < (frame[..., 3] > 127).mean() < 0.2 for frame in frames)
    with av.open(str(whole / "resynth.mp4")) as container:
        assert sum(1 for _ in container.decode(container.streams.video[0])) == 8
    parts = tmp_path / "parts"
    assert main(["-q", "resynth", str(clip), "-o", str(parts), "--frames", "3", *QUICK]) == 0
    assert main(["-q", "resynth", str(clip), "-o", str(parts), "--frames", "8", *QUICK]) == 0
    assert all(np.array_equal(a, b) for a, b in zip(_frames(parts, 8), frames))
    assert main(["-q", "resynth", str(clip), "-o", str(parts), "--frames", "8", *QUICK, "--seed", "3"]) == 0
    assert not all(np.array_equal(a, b) for a, b in zip(_frames(parts, 8), frames))  # another seed: afresh


@pytest.mark.parametrize("argv, message", [
    (["--frames", "0"], "--frames must be between 1 and"),
    (["--frames", "2", "--param", "nope=1"], "--param nope=1: give NAME=VALUE with NAME one of"),
    (["--frames", "2", "--param", "patch_size=4"], "patch_size must be an odd number"),
])
def test_bad_options_are_refused(clip, tmp_path, capsys, argv, message):
    assert main(["resynth", str(clip), "-o", str(tmp_path / "out"), *argv]) == 2
    assert message in capsys.readouterr().err


def test_a_clip_with_a_moving_background_is_refused_naming_it(tmp_path, capsys):
    rgb, mask = sprite_clip(frames=3)
    paper = 0.8 + 0.2 * np.random.default_rng(5).random((36, 60))
    for index in range(3):  # the grey-noise paper pans by 2 px a frame under the sprite
        rgb[index][~mask[index]] = paper[:, 2 * index:2 * index + 52, None].repeat(3, -1)[~mask[index]]
    for index, frame in enumerate(rgb):
        iio.imwrite(tmp_path / f"{index:04d}.png", np.rint(frame * 255).astype(np.uint8))
    assert main(["resynth", str(tmp_path), "-o", str(tmp_path / "out"), "--frames", "2", *QUICK]) == 2
    assert f"{tmp_path}: frame 1: the background moves" in capsys.readouterr().err


def test_a_missing_clip_is_refused(tmp_path, capsys):
    assert main(["resynth", str(tmp_path / "nothing"), "-o", str(tmp_path / "out"), "--frames", "2"]) == 2
    assert f"{tmp_path / 'nothing'}: no such video" in capsys.readouterr().err


def test_a_clip_may_be_a_pattern_or_a_video(clip, tmp_path):
    from fluidymation.stages.encode import Params, encode_mp4

    folder = tmp_path / "folder"
    assert main(["-q", "resynth", str(clip), "-o", str(folder), "--frames", "3", *QUICK]) == 0
    pattern = tmp_path / "pattern"
    assert main(["-q", "resynth", str(clip / "%04d.png"), "-o", str(pattern), "--frames", "3", *QUICK]) == 0
    assert all(np.array_equal(a, b) for a, b in zip(_frames(pattern, 3), _frames(folder, 3)))
    rgb, _ = sprite_clip(frames=5)
    encode_mp4(list(rgb), tmp_path / "clip.mp4", params=Params(fps=12, crf=12))
    video = tmp_path / "video"
    assert main(["-q", "resynth", str(tmp_path / "clip.mp4"), "-o", str(video), "--frames", "3", *QUICK]) == 0
    assert all(0.05 < (frame[..., 3] > 127).mean() < 0.2 for frame in _frames(video, 3))
