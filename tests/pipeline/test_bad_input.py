"""Every kind of bad input: a clear message naming the file, exit code 2, no traceback,
no read of files the scene does not name, no network access."""

import gzip
import io
import json
import shutil
import socket
import sys
import zipfile
from pathlib import Path

import pytest

DATA = Path(__file__).parent.parent / "data" / "lottie"
SECRET = "/etc/hostname"

_opened = []


def _audit(event, args):
    if event == "open" and _opened is not None and isinstance(args[0], str):
        _opened.append(args[0])


sys.addaudithook(_audit)


@pytest.fixture(autouse=True)
def no_network_and_record_opens(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("network access attempted")

    monkeypatch.setattr(socket.socket, "connect", refuse)
    monkeypatch.setattr(socket, "create_connection", refuse)
    _opened.clear()
    yield
    assert not [path for path in _opened if path.startswith(SECRET)], "read a file the scene does not name"


def scene_for(tmp_path, input_name, extra=""):
    path = tmp_path / "scene.yaml"
    path.write_text(f"input: {input_name}\n{extra}")
    return path


def assert_refused(cli, scene, *fragments, command="masks"):
    code, out, err = cli(command, scene)
    assert code == 2, err
    assert "Traceback" not in err
    for fragment in fragments:
        assert fragment in err, err
    return err


def test_missing_scene_file(cli, tmp_path):
    assert_refused(cli, tmp_path / "nope.yaml", "nope.yaml", "no such file")


def test_missing_input_file(cli, tmp_path):
    assert_refused(cli, scene_for(tmp_path, "gone.json"), "gone.json", "no such file")


def test_malformed_yaml(cli, tmp_path):
    path = tmp_path / "scene.yaml"
    path.write_text("input: a.json\nlayers: [\n")
    assert_refused(cli, path, "scene.yaml", "malformed YAML")


def test_malformed_svg(cli, tmp_path):
    (tmp_path / "bad.svg").write_text('<svg xmlns="http://www.w3.org/2000/svg"><g id="a"></svg>')
    assert_refused(cli, scene_for(tmp_path, "bad.svg"), "bad.svg, line 1", "malformed XML")


def test_svg_root_must_be_svg(cli, tmp_path):
    (tmp_path / "html.svg").write_text("<html><body/></html>")
    assert_refused(cli, scene_for(tmp_path, "html.svg"), "html.svg", "<html>, not <svg>")


@pytest.mark.parametrize("text,fragment", [
    ("{ not json", "malformed JSON"),
    ("[1, 2, 3]", "got a JSON list"),
    ('{"w": 64, "h": 64, "fr": 24, "ip": 0, "op": 10}', "'layers' must be a list"),
    ('{"w": "wide", "h": 64, "fr": 24, "ip": 0, "op": 10, "layers": []}', "'w' must be a number"),
    ('{"w": 64, "h": 64, "fr": 24, "ip": 0, "op": 10, "layers": [{"nm": "x"}]}', "layers[0] is not a Lottie layer"),
])
def test_invalid_lottie(cli, tmp_path, text, fragment):
    (tmp_path / "anim.json").write_text(text)
    assert_refused(cli, scene_for(tmp_path, "anim.json"), "anim.json", fragment)


def test_dotlottie_with_escaping_paths(cli, tmp_path):
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as archive:
        archive.writestr("manifest.json", json.dumps({"animations": [{"id": "a"}]}))
        archive.writestr("animations/a.json", (DATA / "matte.json").read_text())
        archive.writestr("../../escape.txt", "x")
    (tmp_path / "evil.lottie").write_bytes(buffer.getvalue())
    assert_refused(cli, scene_for(tmp_path, "evil.lottie"), "evil.lottie", "points outside the archive")


def test_dotlottie_that_is_not_a_zip(cli, tmp_path):
    (tmp_path / "plain.lottie").write_text("{}")
    assert_refused(cli, scene_for(tmp_path, "plain.lottie"), "plain.lottie", "not a zip archive")


def test_gzip_bomb_tgs(cli, tmp_path):
    (tmp_path / "bomb.tgs").write_bytes(gzip.compress(b" " * (80 * 2**20), compresslevel=9))
    assert_refused(cli, scene_for(tmp_path, "bomb.tgs"), "bomb.tgs", "gzip bomb")


def test_svg_with_external_entity(cli, tmp_path):
    (tmp_path / "xxe.svg").write_text(
        f'<?xml version="1.0"?><!DOCTYPE svg [<!ENTITY secret SYSTEM "file://{SECRET}">]>'
        '<svg xmlns="http://www.w3.org/2000/svg" width="10" height="10"><g id="a"><text>&secret;</text></g></svg>')
    assert_refused(cli, scene_for(tmp_path, "xxe.svg"), "xxe.svg", "DTD or XML entities")


@pytest.mark.parametrize("element", [
    f'<image href="file://{SECRET}" width="5" height="5"/>',
    '<image xmlns:xlink="http://www.w3.org/1999/xlink" xlink:href="http://example.com/a.png" width="5" height="5"/>',
    f'<image href="{SECRET}" width="5" height="5"/>',
    '<rect width="5" height="5" style="fill: url(http://example.com/p.svg#x)"/>',
    '<rect width="5" height="5" fill="url(other.svg#grad)"/>',
    '<use href="other.svg#shape"/>',
])
def test_svg_with_external_reference(cli, tmp_path, element):
    (tmp_path / "ext.svg").write_text(
        f'<svg xmlns="http://www.w3.org/2000/svg" width="10" height="10"><g id="a">{element}</g></svg>')
    assert_refused(cli, scene_for(tmp_path, "ext.svg"), "ext.svg", "external resource")


def test_svg_style_import_is_refused(cli, tmp_path):
    (tmp_path / "imp.svg").write_text('<svg xmlns="http://www.w3.org/2000/svg" width="10" height="10">'
                                      '<style>@import url(x.css);</style><g id="a"/></svg>')
    assert_refused(cli, scene_for(tmp_path, "imp.svg"), "imp.svg", "@import")


def test_lottie_with_external_image(cli, tmp_path):
    data = json.loads((DATA / "matte.json").read_text())
    data["assets"] = [{"id": "img", "w": 4, "h": 4, "u": "/etc/", "p": "hostname", "e": 0}]
    (tmp_path / "img.json").write_text(json.dumps(data))
    assert_refused(cli, scene_for(tmp_path, "img.json"), "img.json", "external image '/etc/hostname'")


@pytest.mark.parametrize("extra,fragment", [
    ("size: [16385, 100]\n", "must be at most 16384"),
    ("scale: 400\n", "must be at most 64"),
    ("frames: {start: 0, end: 100001}\n", "over the limit of 100000"),
    ("frames: {start: 3, end: 3}\n", "is empty"),
])
def test_impossible_sizes_and_ranges(cli, tmp_path, extra, fragment):
    shutil.copy(DATA / "matte.json", tmp_path / "m.json")
    assert_refused(cli, scene_for(tmp_path, "m.json", extra), "scene.yaml", fragment)


@pytest.mark.parametrize("extra,fragment", [
    ("animation: second\n", "picks an animation or theme of a dotLottie archive"),
    ("theme: [dark]\n", "theme: expected text"),
    ("theme: ''\n", "theme: expected text, got empty text"),
])
def test_dotlottie_choices_on_other_inputs(cli, tmp_path, extra, fragment):
    shutil.copy(DATA / "matte.json", tmp_path / "m.json")
    assert_refused(cli, scene_for(tmp_path, "m.json", extra), fragment, command="check")


def test_output_size_from_scale_over_limit(cli, tmp_path):
    data = json.loads((DATA / "matte.json").read_text())
    data["w"] = 2000  # 2000 px * 10 > 16384
    (tmp_path / "m.json").write_text(json.dumps(data))
    assert_refused(cli, scene_for(tmp_path, "m.json", "scale: 10\n"), "over the limit of 16384")


def test_unknown_layer_lists_available_names(cli, tmp_path):
    shutil.copy(DATA / "precomp.json", tmp_path / "p.json")
    scene = scene_for(tmp_path, "p.json", "layers:\n  - name: tree\n")
    assert_refused(cli, scene, "'tree' matches no layer", "ground, leaves", command="check")


def test_unknown_layer_on_command_line(cli, tmp_path):
    shutil.copy(DATA / "precomp.json", tmp_path / "p.json")
    code, _, err = cli("masks", scene_for(tmp_path, "p.json"), "--layer", "tree")
    assert code == 2 and "no layer called 'tree'" in err and "ground, leaves" in err


def test_frames_window_outside_the_range(cli, tmp_path):
    shutil.copy(DATA / "precomp.json", tmp_path / "p.json")
    code, _, err = cli("masks", scene_for(tmp_path, "p.json"), "--frames", "5:40")
    assert code == 2 and "--frames 5:40" in err and "0:12" in err


def test_unknown_input_type(cli, tmp_path):
    (tmp_path / "a.gif").write_bytes(b"GIF89a")
    assert_refused(cli, scene_for(tmp_path, "a.gif"), "a.gif", "unknown input type")


def test_debug_shows_the_traceback(cli, tmp_path):
    code, _, err = cli("--debug", "masks", scene_for(tmp_path, "gone.json"))
    assert code == 2 and "Traceback" in err


def test_usage_errors_exit_2(cli):
    code, _, err = cli("masks")
    assert code == 2 and "scene" in err
