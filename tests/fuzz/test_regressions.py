"""What the readers' fuzzing found (tests/fuzz/harness.py), one small case each: exit code 2 with a message naming
the file and the key or element, where each used to be an internal error (exit 1)."""

import json

import pytest

from tests.scenes import ROOT, blob_scene, write_scene

LOTTIE = ROOT / "examples/wave/wave.json"


def refused(cli, scene, *fragments):
    code, out, err = cli("-q", "check", scene)
    assert code == 2, err
    assert err.startswith("error:") and "Traceback" not in err, err
    for fragment in fragments:
        assert fragment in err, err
    return err


@pytest.mark.parametrize("text", ["x: " + "[" * 5000 + "1" + "]" * 5000 + "\n",
                                  "x: " + "[" * 150 + "1" + "]" * 150 + "\n"])
def test_scene_nested_too_deeply(cli, tmp_path, text):  # was RecursionError in pipeline/yaml_lines.py
    refused(cli, write_scene(tmp_path, blob_scene() + text), "scene.yaml", "nested")


def test_required_value_written_as_null(cli, tmp_path):  # was TypeError in pipeline/scene.py (layer name None)
    scene = blob_scene(layers="  - {name: null}\n")
    refused(cli, write_scene(tmp_path, scene), "scene.yaml", "layers[0].name", "is required")


def test_null_takes_the_default(cli, tmp_path):  # frames.start: null was TypeError comparing None with an int
    scene = blob_scene(size=32).replace("frames: {start: 0, end: 4}", "frames: {start: null, end: 2}")
    code, out, err = cli("-q", "check", write_scene(tmp_path, scene))
    assert code == 0, err
    assert "frames:  0:2" in out


@pytest.mark.parametrize("value,fragment", [('"a\\0b.png"', "NUL character"), ("x" * 5000 + ".png", "too long")])
def test_unusable_file_names(cli, tmp_path, value, fragment):  # were ValueError / OSError from pathlib
    scene = blob_scene(layers="  - {name: blob, stylizer: keyframes, keyframes: {0: %s}}\n" % value)
    refused(cli, write_scene(tmp_path, scene), "scene.yaml", "layers[0].keyframes", fragment)


def test_lottie_nested_too_deeply(cli, tmp_path):  # was RecursionError in json.loads
    (tmp_path / "deep.json").write_text('{"layers": ' + "[" * 100000 + "]" * 100000 + "}")
    write_scene(tmp_path, "input: deep.json\n")
    refused(cli, tmp_path / "scene.yaml", "deep.json", "nested too deeply")


@pytest.mark.parametrize("where", ["shape type", "font name"])
def test_lottie_unhashable_values(cli, tmp_path, where):  # was TypeError: unhashable type (lottie_reader.py)
    data = json.loads(LOTTIE.read_text())
    if where == "shape type":
        data["layers"][0]["shapes"][0]["ty"] = ["gr"]
    else:
        data["fonts"] = {"list": [{"fName": ["Sans"], "fFamily": {"a": 1}}]}
        data["chars"] = [{"fFamily": ["Sans"]}]
    (tmp_path / "anim.json").write_text(json.dumps(data))
    write_scene(tmp_path, "input: anim.json\nsize: [32, 32]\nframes: {start: 0, end: 2}\n")
    code, out, err = cli("-q", "check", tmp_path / "scene.yaml")
    assert code in (0, 2) and "internal error" not in err, err


def test_svg_nan_length(cli, tmp_path):  # was cairocffi.CairoError (invalid matrix) from cairosvg's ellipse
    (tmp_path / "nan.svg").write_text('<svg xmlns="http://www.w3.org/2000/svg" width="32" height="32">'
                                      '<ellipse id="e" cx="16" cy="16" rx="8" ry="nan"/></svg>')
    write_scene(tmp_path, "input: nan.svg\n")
    refused(cli, tmp_path / "scene.yaml", "nan.svg", "cannot be rendered as SVG")


@pytest.mark.parametrize("key", ["ind", "tp", "refId"])
def test_lottie_reference_that_is_a_list(cli, tmp_path, key):  # was TypeError: unhashable (lottie_reader.py)
    data = json.loads(LOTTIE.read_text())
    data["layers"][0][key] = [1]
    (tmp_path / "anim.json").write_text(json.dumps(data))
    write_scene(tmp_path, "input: anim.json\nsize: [32, 32]\nframes: {start: 0, end: 2}\n")
    refused(cli, tmp_path / "scene.yaml", "anim.json", f"layers[0].{key} must be a number or text")


@pytest.mark.parametrize("name,where,path", [
    ("matte.json", ["layers", 0, "shapes", 0, "it", 0, "p", "k", 0], "layers[0].shapes[0].it[0].p.k[0]"),  # a point
    ("parenting.json", ["layers", 2, "ks", "p", "k", 0], "layers[2].ks.p.k[0]"),  # a keyframe
])
def test_lottie_null_in_a_list(cli, tmp_path, name, where, path):  # ThorVG 1.0 hung loading them: exit 2 after 120 s
    data = json.loads((ROOT / "tests/data/lottie" / name).read_text())
    parent = data
    for key in where[:-1]:
        parent = parent[key]
    parent[where[-1]] = None
    (tmp_path / "anim.json").write_text(json.dumps(data))
    write_scene(tmp_path, "input: anim.json\nsize: [32, 32]\nframes: {start: 0, end: 2}\n")
    refused(cli, tmp_path / "scene.yaml", "anim.json", f"{path} is null")


def test_svg_endless_css_animation(cli, tmp_path):  # was OverflowError in frames_in (stages/vector/base.py)
    (tmp_path / "long.svg").write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" width="32" height="32"><style>@keyframes a { to { opacity: 0 } }'
        " rect { animation: a 1s; animation-iteration-count: 1e308 }</style>"
        '<g id="g"><rect width="8" height="8"/></g></svg>')
    write_scene(tmp_path, "input: long.svg\n")
    refused(cli, tmp_path / "scene.yaml", "long.svg", "too long to count its frames")


@pytest.mark.parametrize("svg", ['<ellipse cx="16" cy="16" rx="8" ry="1e308"/>',
                                 '<ellipse cx="16" cy="16" rx="8" ry="32"><animate attributeName="ry" from="-1e308" '
                                 'to="46" dur="1s" fill="freeze"/></ellipse>'])
def test_svg_radius_beyond_reason(tmp_path, svg):  # cairo's arc looped for ever (a subprocess: a hang is a failure)
    import subprocess
    import sys

    (tmp_path / "huge.svg").write_text(f'<svg xmlns="http://www.w3.org/2000/svg" width="32" height="32">{svg}</svg>')
    write_scene(tmp_path, "input: huge.svg\nframes: {start: 0, end: 2}\n")
    done = subprocess.run([sys.executable, "-m", "fluidymation", "-q", "check", str(tmp_path / "scene.yaml")],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 2, done.stderr
    assert "huge.svg" in done.stderr and 'ry="' in done.stderr and "radius beyond" in done.stderr, done.stderr
