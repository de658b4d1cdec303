"""Every bundled example renders to an MP4 whose frames, size and fps are the scene's."""

import shutil
from fractions import Fraction
from pathlib import Path

import av
import pytest

from fluidymation.pipeline.resolve import plan_scene
from fluidymation.pipeline.scene import load_scene

EXAMPLES = Path(__file__).parents[2] / "examples"


@pytest.mark.parametrize("name", ["blob", "squiggle", "wave"])
def test_example_renders_to_a_video_of_the_scene(cli, tmp_path, monkeypatch, name):
    monkeypatch.setenv("FLUIDYMATION_CACHE", str(tmp_path / "cache"))
    folder = tmp_path / name
    shutil.copytree(EXAMPLES / name, folder, ignore=shutil.ignore_patterns("out"))
    scene = folder / "scene.yaml"
    plan = plan_scene(load_scene(scene))
    code, _, err = cli("-q", "render", scene)
    assert code == 0, err
    video = plan.scene.output.dir / plan.scene.output.video
    with av.open(str(video)) as container:
        stream = container.streams.video[0]
        frames = sum(1 for _ in container.decode(stream))
        size = (stream.codec_context.width, stream.codec_context.height)
        assert stream.codec_context.name == "h264" and stream.codec_context.pix_fmt == "yuv420p"
        assert stream.average_rate == Fraction(plan.fps).limit_denominator(1001)
    assert frames == plan.frame_count and size == plan.size
