"""`fluidymation masks` and `fluidymation check` on the bundled examples."""

import json
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest

EXAMPLES = Path(__file__).parents[2] / "examples"


@pytest.mark.parametrize("example,layers", [("blob", ["blob", "drop"]), ("wave", ["body", "arm"]),
                                            ("squiggle", ["squiggle"])])
def test_masks_on_examples(cli, tmp_path, example, layers):
    code, out, err = cli("-q", "masks", EXAMPLES / example / "scene.yaml", "-o", tmp_path, "--frames", "2:5")
    assert code == 0, err
    summary = json.loads((tmp_path / "layers.json").read_text())
    assert [record["name"] for record in summary["layers"]] == layers
    assert summary["frames"] == {"start": 2, "end": 5, "scene_start": 0}
    for record in summary["layers"]:
        files = sorted((tmp_path / record["folder"]).glob("*.png"))
        assert [f.name for f in files] == ["00002.png", "00003.png", "00004.png"]
        masks = [iio.imread(f) for f in files]
        assert all(m.dtype == np.uint8 and set(np.unique(m)) <= {0, 255} for m in masks)
        assert record["area"] == [int((m == 255).sum()) for m in masks]
        assert record["color"].startswith("#") and len(record["color"]) == 7
        assert max(record["area"]) > 0


def test_squiggle_is_drawn_on(cli, tmp_path):
    assert cli("-q", "masks", EXAMPLES / "squiggle" / "scene.yaml", "-o", tmp_path)[0] == 0
    area = json.loads((tmp_path / "layers.json").read_text())["layers"][0]["area"]
    assert len(area) == 24 and all(b > a for a, b in zip(area, area[1:]))


def test_default_output_dir_and_z_order(cli, tmp_path):
    scene = tmp_path / "scene.yaml"
    scene.write_text(f"input: {EXAMPLES / 'wave' / 'wave.json'}\nframes: {{start: 0, end: 2}}\nsize: [32, 32]\n")
    assert cli("-q", "masks", scene)[0] == 0
    summary = json.loads((tmp_path / "out" / "scene" / "masks" / "layers.json").read_text())
    assert {r["name"]: r["z"] for r in summary["layers"]} == {"body": 0, "arm": 1}
    assert iio.imread(tmp_path / "out" / "scene" / "masks" / "arm" / "00001.png").shape == (32, 32)


def test_layers_merge_and_scene_colour_wins(cli, tmp_path):
    scene = tmp_path / "scene.yaml"
    scene.write_text(f"input: {EXAMPLES / 'wave' / 'wave.json'}\nframes: {{start: 0, end: 1}}\n"
                     "layers:\n  - {name: figure, select: ['*'], color: '#010203'}\n  - {name: arm}\n")
    assert cli("-q", "masks", scene, "-o", tmp_path / "m")[0] == 0
    records = {r["name"]: r for r in json.loads((tmp_path / "m" / "layers.json").read_text())["layers"]}
    assert records["figure"]["select"] == ["body", "arm"] and records["figure"]["color"] == "#010203"
    assert records["figure"]["area"][0] > records["arm"]["area"][0]


def test_check_prints_the_resolved_scene(cli):
    code, out, err = cli("check", EXAMPLES / "wave" / "scene.yaml")
    assert code == 0, err
    assert "size:    256x256 px" in out and "fps:     24" in out and "frames:  0:48 (48 frames)" in out
    assert "body: z=0, selects body, colour #" in out and "arm: z=1, selects arm" in out
    assert "reader:  lottie v2, renderer thorvg v1" in out


@pytest.mark.parametrize("example,line", [("blob", "reader:  svg v4, renderer cairosvg v1"),
                                          ("squiggle", "reader:  svg-sequence v3, renderer cairosvg v1")])
def test_check_names_the_reader_and_renderer(cli, example, line):
    code, out, err = cli("check", EXAMPLES / example / "scene.yaml")
    assert code == 0, err
    assert line in out
