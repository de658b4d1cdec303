"""Scene files: defaults, path resolution, and errors naming file, line and key path."""

import textwrap

import pytest

from fluidymation.errors import SceneError
from fluidymation.pipeline.scene import load_scene


def write(tmp_path, text, name="scene.yaml"):
    path = tmp_path / name
    path.write_text(textwrap.dedent(text))
    return path


def error_of(tmp_path, text):
    with pytest.raises(SceneError) as info:
        load_scene(write(tmp_path, text))
    return str(info.value)


def test_minimal_scene_gets_defaults_and_resolved_paths(tmp_path):
    scene = load_scene(write(tmp_path, "input: art/anim.json\n"))
    assert scene.input == (tmp_path / "art" / "anim.json").resolve()
    assert scene.output.dir == (tmp_path / "out" / "scene").resolve()
    assert scene.output.video == "scene.mp4"
    assert scene.layers is None and scene.frames is None and scene.fps is None
    assert scene.defaults.blend == "multiply" and scene.defaults.colorize is None  # the stylizer's default


def test_full_scene(tmp_path):
    scene = load_scene(write(tmp_path, """\
        version: 1
        input: blob.json
        fps: 12.5
        frames: {start: 2, end: 10}
        size: [64, 48]
        seed: 7
        output: {dir: renders, video: b.mp4, frames: true, preview: webp, crf: 23}
        background: {type: solid, color: "#FAFAF0"}
        exemplars:
          bloom: {builtin: watercolor-bloom, seed: 1}
        defaults: {exemplar: bloom, params: {w_temp: 2}}
        layers:
          - name: body
            select: ["body", "arm*"]
            color: "#2a6fdb"
            params: {w_bound: 3}
          - name: sky
            blend: over
            opacity: 0.5
        """))
    assert scene.fps == 12.5 and (scene.frames.start, scene.frames.end) == (2, 10)
    assert scene.size == (64, 48) and scene.seed == 7
    assert (scene.output.frames, scene.output.preview, scene.output.crf) == (True, "webp", 23)
    assert scene.background == {"type": "solid", "color": "#fafaf0"}
    body, sky = scene.layers
    assert body.select == ("body", "arm*") and body.exemplar == "bloom"
    assert body.params == {"w_temp": 2, "w_bound": 3}
    assert sky.select == ("sky",) and sky.blend == "over" and sky.opacity == 0.5


def test_unknown_key_names_line_and_suggests(tmp_path):
    message = error_of(tmp_path, "input: a.json\nlayers:\n  - name: body\n    colour: '#ffffff'\n")
    assert "scene.yaml, line 4" in message
    assert "layers[0].colour" in message and "did you mean 'color'" in message


def test_wrong_type_names_key_path(tmp_path):
    message = error_of(tmp_path, "input: a.json\nlayers:\n  - name: a\n  - name: b\n    opacity: high\n")
    assert "line 5" in message and "layers[1].opacity" in message and "expected a number" in message


@pytest.mark.parametrize("text,expected", [
    ("input: a.json\nsize: [20000, 10]\n", "size[0]: must be at most 16384"),
    ("input: a.json\nframes: {start: 0, end: 100001}\n", "over the limit of 100000"),
    ("input: a.json\nframes: {start: 5, end: 5}\n", "is empty"),
    ("input: a.json\nversion: 9\n", "newer than this fluidymation"),
    ("input: a.json\nsize: [10, 10]\nscale: 2\n", "either size or scale"),
    ("input: a.json\nfps: 0\n", "fps: must be greater than 0"),
    ("input: a.json\nlayers:\n  - name: a\n  - name: a\n", "already defined at layers[0]"),
    ("input: a.json\nlayers:\n  - name: a\n    color: blue\n", '"#rrggbb"'),
    ("input: a.json\nlayers:\n  - name: a\n    blend: screen\n", "not one of multiply, over"),
    ("input: a.json\nexemplars: {x: {builtin: watercolor-bloom}}\nlayers:\n  - {name: a, exemplar: y}\n",
     "no exemplar called 'y'"),
    ("input: a.json\nlayers:\n  - name: ../evil\n", "cannot be a layer name"),
    ("fps: 24\n", "input: is required"),
    ("- just\n- a list\n", "expected a mapping"),
    ("input: a.json\ninput: b.json\n", "duplicate key 'input'"),
])
def test_invalid_values(tmp_path, text, expected):
    assert expected in error_of(tmp_path, text)


def test_malformed_yaml_reports_line(tmp_path):
    message = error_of(tmp_path, "input: a.json\nlayers:\n  - name: [unclosed\n")
    assert "scene.yaml" in message and "malformed YAML" in message and "line" in message


def test_missing_and_empty_scene(tmp_path):
    with pytest.raises(SceneError, match="no such file"):
        load_scene(tmp_path / "nope.yaml")
    assert "empty" in error_of(tmp_path, "# nothing\n")


def test_alias_bomb_is_refused(tmp_path):
    lines = ["a0: &a0 [x, x, x, x, x, x, x, x, x, x]"]
    lines += [f"a{i}: &a{i} [*a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}]"
              for i in range(1, 9)]
    assert "too many YAML values" in error_of(tmp_path, "\n".join(lines) + "\n")
