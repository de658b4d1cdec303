"""`fluidymation render --until ...` on a tiny copy of the blob example."""

from pathlib import Path

import imageio.v3 as iio
import numpy as np

BLOB = Path(__file__).parents[2] / "examples" / "blob" / "blob.svg"


def _scene(tmp_path, params="{border_width: 3, shape_radius: 6, dist_time_sigma: 0.5}"):
    scene = tmp_path / "scene.yaml"
    scene.write_text(
        f"input: {BLOB}\nfps: 24\nsize: [40, 40]\nframes: {{start: 4, end: 7}}\noutput: {{dir: out}}\n"
        "exemplars:\n  ink: {builtin: watercolor-bloom, size: [32, 32], frames: 6}\n"
        f"defaults: {{exemplar: ink, params: {params}}}\n"
        "layers:\n  - {name: blob, params: {opt_iters: '2, 1', pm_iters: 2}}\n")
    return scene


def test_render_until_stylize_writes_rgba_frames(cli, tmp_path, monkeypatch):
    monkeypatch.setenv("FLUIDYMATION_CACHE", str(tmp_path / "cache"))
    scene = _scene(tmp_path)
    code, out, err = cli("-q", "render", scene, "--until", "stylize", "--frames", "5:7", "--nnf")
    assert code == 0, err
    folder = tmp_path / "out" / "stylized" / "blob"
    assert sorted(p.name for p in folder.glob("*.png")) == ["00001.png", "00002.png"]
    rgba = iio.imread(folder / "00002.png")
    mask = iio.imread(tmp_path / "out" / "masks" / "blob" / "00002.png")
    assert rgba.shape == (40, 40, 4) and (rgba[..., 3] > 127).sum() > 0
    assert np.array_equal(rgba[..., 3] > 127, mask > 127)
    assert np.load(folder / "nnf" / "00002.npy").shape == (40, 40, 4)
    assert any((tmp_path / "cache" / "exemplars").iterdir())


def test_unknown_parameter_and_later_stages_are_clear_errors(cli, tmp_path, monkeypatch):
    monkeypatch.setenv("FLUIDYMATION_CACHE", str(tmp_path / "cache"))
    code, _, err = cli("render", _scene(tmp_path, params="{w_tmp: 2}"), "--until", "masks")
    assert code == 2 and "defaults.params.w_tmp" in err and "did you mean 'w_temp'" in err and "scene.yaml" in err
    code, _, err = cli("render", _scene(tmp_path), "--until", "composite")
    assert code == 2 and "does not exist yet" in err
    code, _, err = cli("render", _scene(tmp_path), "--until", "mask")
    assert code == 2 and "masks, guides, stylize" in err
