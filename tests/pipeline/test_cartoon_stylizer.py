"""``stylizer: cartoon`` end to end: a drawn clip's texture carried onto a vector disk follows the disk's motion,
and a resumed render continues as an uninterrupted one."""

import imageio.v3 as iio
import numpy as np
import pytest

from fluidymation.pipeline.cli import main

from tests.naive import naive_shift
from tests.scenes import disk, write_scene

SVG = """<svg xmlns="http://www.w3.org/2000/svg" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"
     width="48" height="48"><g inkscape:label="disk"><circle cx="14" cy="24" r="10" fill="#333">
  <animate attributeName="cx" values="14;34" dur="1s" fill="freeze"/></circle></g></svg>"""
QUICK = "{patch_size: 5, pyramid_levels: 1, motion_iterations: 10, block_size: 9, opt_iters: [2], fresh_iters: [4]}"


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    """The disk moving 2 px a frame, painted from a clip of a still hatched disk (no boil: its motion is the disk's)."""
    folder = tmp_path_factory.mktemp("cartoon")
    (folder / "disk.svg").write_text(SVG)
    (folder / "clip").mkdir()
    alpha = disk(32, 11.0)[..., None]
    hatch = np.kron(np.random.default_rng(2).random((16, 16, 3)), np.ones((2, 2, 1)))
    for index in range(3):
        iio.imwrite(folder / "clip" / f"{index:04d}.png", np.rint((hatch * alpha + 1 - alpha) * 255).astype(np.uint8))
    scene = write_scene(folder, (
        "version: 1\ninput: disk.svg\nfps: 10\nsize: [48, 48]\nframes: {start: 0, end: 6}\n"
        "output: {dir: out, video: film.mp4}\nbackground: {type: solid, color: '#ffffff'}\n"
        "exemplars:\n  pencil: {images: clip, mask: auto}\n"
        f"layers:\n  - {{name: disk, stylizer: cartoon, exemplar: pencil, params: {QUICK}}}\n"))
    assert main(["-q", "render", str(scene)]) == 0
    return scene, [iio.imread(folder / "out" / "stylized" / "disk" / f"{index:05d}.png") / 255.0 for index in range(6)]


def test_the_clip_texture_follows_the_disk(rendered):
    _, frames = rendered
    for before, after in zip(frames[1:], frames[2:]):
        interior = after[..., 3] >= 0.99
        shift = naive_shift(before[..., :3], after[..., :3], interior.astype(np.float64))
        assert np.allclose(shift, [2.0, 0.0], atol=0.5), shift


def test_the_colour_is_the_clip_s_and_the_alpha_the_layer_s(rendered):
    _, frames = rendered
    inside = frames[3][..., 3] >= 0.99
    assert frames[3][..., :3][inside].std() > 0.1  # the clip's random hatching, not one flat colour
    assert 250 < inside.sum() < 330  # the disk of radius 10


def test_a_resumed_cartoon_render_matches_an_uninterrupted_one(rendered, tmp_path):
    scene, frames = rendered
    from fluidymation.stages import cartoon_stylizer

    original = cartoon_stylizer.CartoonStylizer.stylize
    calls = []

    def interrupted(self, job, params):
        for frame in original(self, job, params):
            calls.append(frame.index)
            yield frame
            if frame.index == 2 and job.resume is None:
                raise KeyboardInterrupt

    copy = tmp_path / "scene"
    copy.mkdir()
    for path in scene.parent.iterdir():
        if path.is_file() or path.name == "clip":
            target = copy / path.name
            if path.is_dir():
                target.mkdir()
                for file in path.iterdir():
                    (target / file.name).write_bytes(file.read_bytes())
            else:
                target.write_bytes(path.read_bytes())
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(cartoon_stylizer.CartoonStylizer, "stylize", interrupted)
        assert main(["-q", "render", str(copy / scene.name)]) != 0
        assert main(["-q", "render", str(copy / scene.name)]) == 0
    assert calls == [0, 1, 2, 3, 4, 5]
    again = [iio.imread(copy / "out" / "stylized" / "disk" / f"{index:05d}.png") / 255.0 for index in range(6)]
    assert all(np.array_equal(a, b) for a, b in zip(again, frames))
