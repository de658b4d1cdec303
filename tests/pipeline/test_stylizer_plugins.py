"""Stylizers are plugins: a distribution outside this repository adds one through its entry point."""

import json
import os
import subprocess
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest

from fluidymation.pipeline import stylizers

from tests.scenes import blob_scene, write_scene

PLUGIN = Path(__file__).parents[1] / "data" / "stylizer_plugin"
FLAT_LAYER = '  - {name: blob, stylizer: flat, params: {shade: 0.5}}\n'


@pytest.fixture
def flat_installed(monkeypatch):
    """The ``flat-stylizer`` test distribution on the path (its dist-info registers ``flat``)."""
    monkeypatch.syspath_prepend(str(PLUGIN))
    stylizers.forget_installed()
    yield
    monkeypatch.undo()
    stylizers.forget_installed()


def _ran(out):
    report = json.loads((out / "report.json").read_text())
    return {(entry["stage"], entry["layer"]) for entry in report["stages"] if not entry["cached"]}


def test_a_stylizer_from_another_distribution_renders_a_layer(cli, tmp_path, monkeypatch, flat_installed):
    monkeypatch.setenv("FLUIDYMATION_CACHE", str(tmp_path / "cache"))
    assert stylizers.stylizer_names() == ("cartoon", "flat", "fluidymation", "keyframes", "lazyfluids", "still")
    scene = write_scene(tmp_path, blob_scene(layers=FLAT_LAYER, params="{}"))
    code, out, _ = cli("check", scene)
    assert code == 0 and "blob: z=" in out and "stylizer flat v1" in out
    code, _, err = cli("-q", "render", scene)
    assert code == 0, err
    out = tmp_path / "out"
    assert (out / "film.mp4").stat().st_size > 0
    rgba = iio.imread(out / "stylized" / "blob" / "00002.png").astype(np.float32) / 255
    coverage = iio.imread(out / "coverage" / "blob" / "00002.png").astype(np.float32) / 255
    assert np.allclose(rgba[..., 3], coverage, atol=1 / 255)
    inside = rgba[..., 3] > 0.5
    flat_colour = rgba[inside][:, :3]
    assert np.ptp(flat_colour, axis=0).max() <= 1 / 255  # one colour: the exemplar's mean paint, half shaded
    assert 0.05 < flat_colour.mean() < 0.5
    assert ("stylize", "blob") in _ran(out)


def test_its_version_is_part_of_the_stylize_key(cli, tmp_path, monkeypatch, flat_installed):
    monkeypatch.setenv("FLUIDYMATION_CACHE", str(tmp_path / "cache"))
    scene = write_scene(tmp_path, blob_scene(layers=FLAT_LAYER, params="{}"))
    assert cli("-q", "render", scene, "--until", "colorize")[0] == 0
    assert cli("-q", "render", scene, "--until", "colorize")[0] == 0
    assert _ran(tmp_path / "out") == set()
    monkeypatch.setattr(stylizers.get_stylizer("flat"), "version", 2)
    assert cli("-q", "render", scene, "--until", "colorize")[0] == 0
    assert _ran(tmp_path / "out") == {("stylize", "blob"), ("colorize", "blob")}


def test_its_parameters_are_checked_against_its_own_params(cli, tmp_path, monkeypatch, flat_installed):
    monkeypatch.setenv("FLUIDYMATION_CACHE", str(tmp_path / "cache"))
    scene = write_scene(tmp_path, blob_scene(layers='  - {name: blob, stylizer: flat, params: {w_temp: 2}}\n',
                                             params="{}"))
    code, _, err = cli("render", scene, "--until", "masks")
    assert code == 2 and "line 13: layers[0].params.w_temp: unknown parameter 'w_temp' of stylizer 'flat'" in err
    scene.write_text(scene.read_text().replace("w_temp: 2", "border_width: 2"))  # flat uses no guides
    code, _, err = cli("render", scene, "--until", "masks")
    assert code == 2 and "layers[0].params.border_width: unknown parameter" in err
    scene.write_text(scene.read_text().replace("border_width: 2", "shade: 3"))
    code, _, err = cli("render", scene, "--until", "stylize")
    assert code == 2 and "line 13: layers[0].params.shade: flat: parameter shade must be between 0 and 1" in err


def test_an_unknown_stylizer_is_a_scene_error_listing_the_installed_ones(cli, tmp_path, flat_installed):
    scene = write_scene(tmp_path, blob_scene(layers='  - {name: blob, stylizer: flatt}\n'))
    code, _, err = cli("check", scene)
    assert code == 2 and "layers[0].stylizer: 'flatt' is not one of cartoon, flat, fluidymation, keyframes, lazyfluids, still (did you mean 'flat'?)" in err


def test_a_fresh_process_finds_the_stylizer_on_its_path(tmp_path, command_line):
    scene = write_scene(tmp_path, blob_scene(layers=FLAT_LAYER, params="{}"))
    command, env = command_line("-q", "render", scene, "--until", "stylize")
    env = env | {"PYTHONPATH": os.pathsep.join(filter(None, [str(PLUGIN), env.get("PYTHONPATH")]))}
    result = subprocess.run(command, env=env, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert len(list((tmp_path / "out" / "stylized" / "blob").glob("*.png"))) == 4
