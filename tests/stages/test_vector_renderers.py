"""The vector protocol: readers from a table, renderers by document kind, time in seconds, a plugged-in renderer."""

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from fluidymation.errors import InputError
from fluidymation.pipeline.resolve import plan_scene
from fluidymation.pipeline.scene import load_scene
from fluidymation.stages import rasterize
from fluidymation.stages.vector import RENDERERS, Renderer, open_document, renderer_for

DATA = Path(__file__).parent.parent / "data" / "lottie"
EXAMPLES = Path(__file__).parents[2] / "examples"


class Stripes(Renderer):
    """Each layer as an opaque stripe (one per z-order) that grows from the left by a frame width per second."""

    name, version, kinds = "stripes", 1, ("lottie",)

    def render(self, document, layers, time_seconds, size):
        width, height = size
        rgba = np.zeros((height, width, 4), np.uint8)
        stripe = height // len(document.layers)
        reach = min(width, round(width * time_seconds))
        for layer in document.layers:
            if layer.name in layers:
                rgba[layer.z * stripe:(layer.z + 1) * stripe, :reach] = 255
        return rgba


def static_svg(tmp_path):
    path = tmp_path / "still.svg"
    path.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="10" height="10"><g id="a"><rect width="5" '
                    'height="5"/></g></svg>')
    return path


def bar_sequence(tmp_path, count):
    """``count`` SVG files; file k draws a bar k + 1 px wide."""
    for index in range(count):
        (tmp_path / f"f{index}.svg").write_text(
            f'<svg xmlns="http://www.w3.org/2000/svg" width="40" height="10"><g id="bar">'
            f'<rect width="{index + 1}" height="10"/></g></svg>')
    return tmp_path / "f%d.svg"


@pytest.mark.parametrize("path,reader,kind,renderer", [
    (DATA / "parenting.json", "lottie", "lottie", "thorvg"),
    (DATA / "parenting.tgs", "lottie", "tgs", "thorvg"),
    (DATA / "precomp.lottie", "lottie", "dotlottie", "thorvg"),
    (EXAMPLES / "blob" / "blob.svg", "svg", "svg", "cairosvg"),
    ("still.svg", "svg", "svg", "cairosvg"),
    (EXAMPLES / "squiggle" / "frames" / "%04d.svg", "svg-sequence", "svg-sequence", "cairosvg"),
])
def test_reader_and_renderer_per_kind(tmp_path, path, reader, kind, renderer):
    path = static_svg(tmp_path) if path == "still.svg" else path
    document = open_document(path)
    assert (document.reader, document.kind, renderer_for(document).name) == (reader, kind, renderer)
    assert isinstance(document.reader_version, int) and isinstance(renderer_for(document).version, int)


def test_documents_list_every_file_they_read(tmp_path):
    assert open_document(DATA / "precomp.lottie").files == [DATA / "precomp.lottie"]
    pattern = bar_sequence(tmp_path, 3)
    assert open_document(pattern).files == [tmp_path / f"f{index}.svg" for index in range(3)]


def test_unknown_input_type_is_refused(tmp_path):
    with pytest.raises(InputError, match="unknown input type '.gif'"):
        open_document(tmp_path / "a.gif")


def test_a_renderer_added_to_the_table_is_chosen_for_its_kinds(monkeypatch):
    monkeypatch.setattr("fluidymation.stages.vector.RENDERERS", (Stripes(), *RENDERERS))
    assert renderer_for(open_document(DATA / "parenting.json")).name == "stripes"
    assert renderer_for(open_document(DATA / "parenting.tgs")).name == "thorvg"


def test_a_plugged_in_renderer_draws_the_plan(tmp_path):
    scene = tmp_path / "scene.yaml"
    scene.write_text(f"input: {EXAMPLES / 'wave' / 'wave.json'}\nfps: 24\nsize: [48, 20]\n"
                     "layers:\n  - {name: figure, select: ['*']}\n  - {name: arm}\n")
    plan = replace(plan_scene(load_scene(scene)), renderer=Stripes())
    params = rasterize.Params(size=plan.size, fps=plan.fps)
    figure, arm = (rasterize.rasterize_frame(plan.renderer, plan.document, plan.layer(name).vector_layers, 12, params)
                   for name in ("figure", "arm"))
    expected = np.zeros((20, 48), np.float32)
    expected[:, :24] = 1  # frame 12 at 24 fps is 0.5 s: half the width; body is rows 0-9, arm rows 10-19
    assert np.array_equal(figure.coverage, expected)
    expected[:10] = 0
    assert np.array_equal(arm.coverage, expected)


@pytest.mark.parametrize("fps", [12, 24])
def test_sequence_time_picks_the_file_at_the_scenes_fps(tmp_path, fps):
    document = open_document(bar_sequence(tmp_path, 4), fps=fps)
    renderer = renderer_for(document)
    width = [renderer.render(document, ["bar"], k / fps, (40, 10))[:, :, 3].sum() / 2550 for k in range(4)]
    assert width == [1, 2, 3, 4]
    with pytest.raises(InputError, match=r"frame 4 is outside the sequence \(0 to 3\)"):
        renderer.render(document, ["bar"], 4 / fps, (40, 10))


@pytest.mark.parametrize("file_fps,fps", [(12, 10), (12, 24), (12, 25), (12, 30), (25, 25), (25, 50), (30, 30),
                                          (24, 60)])
def test_lottie_time_is_the_files_frame_exactly(tmp_path, file_fps, fps):
    """Scene frame k at ``fps`` is Lottie frame k·fr/fps to the bit ((k / fps) * fr is not: 7/25 s at 25 fps)."""
    data = json.loads((DATA / "shapes_keyframe.json").read_text()) | {"fr": file_fps}
    (tmp_path / "anim.json").write_text(json.dumps(data))
    document = open_document(tmp_path / "anim.json")
    assert [document.lottie_frame(k / fps) for k in range(300)] == [k * float(file_fps) / fps for k in range(300)]


def test_lottie_at_another_fps_shows_the_frame_of_that_time():
    document = open_document(DATA / "shapes_keyframe.json")  # a 12 fps file
    renderer = renderer_for(document)
    for k in range(6):
        at_24 = renderer.render(document, ["square"], (2 * k) / 24, (96, 48))
        at_12 = renderer.render(document, ["square"], k / 12, (96, 48))
        assert np.array_equal(at_24, at_12)
