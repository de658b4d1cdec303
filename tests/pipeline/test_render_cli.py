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


def _recording(folder, frames=5, size=32):
    """A blue disk growing on cream paper, as a numbered PNG sequence."""
    folder.mkdir()
    yy, xx = np.mgrid[:size, :size]
    rng = np.random.default_rng(0)
    for k in range(frames):
        image = np.ones((size, size, 3)) * (0.95, 0.93, 0.88)
        inside = (yy - size / 2) ** 2 + (xx - size / 2) ** 2 < (5 + 1.5 * k) ** 2
        image[inside] = (0.2, 0.35, 0.8) + 0.1 * rng.random((inside.sum(), 3))
        iio.imwrite(folder / f"{k:02d}.png", (image * 255).astype(np.uint8))


def test_render_with_a_recorded_exemplar_and_motion_flow(cli, tmp_path, monkeypatch):
    monkeypatch.setenv("FLUIDYMATION_CACHE", str(tmp_path / "cache"))
    _recording(tmp_path / "rec")
    scene = tmp_path / "scene.yaml"
    scene.write_text(
        f"input: {BLOB}\nfps: 24\nsize: [40, 40]\nframes: {{start: 4, end: 6}}\noutput: {{dir: out}}\n"
        "exemplars:\n  rec: {images: 'rec/%02d.png', mask: auto, flow: motion}\n"
        "defaults: {exemplar: rec, params: {border_width: 3, shape_radius: 6}}\n"
        "layers:\n  - {name: blob, params: {opt_iters: '2, 1', pm_iters: 2}}\n")
    code, _, err = cli("-q", "render", scene, "--until", "stylize")
    assert code == 0, err
    rgba = iio.imread(tmp_path / "out" / "stylized" / "blob" / "00001.png")
    painted = rgba[rgba[..., 3] > 127][:, :3].astype(float)
    assert painted.size and painted[:, 2].mean() > painted[:, 0].mean() + 40  # blue paint from the recording
    assert any(p.name.startswith("recording-") for p in (tmp_path / "cache" / "exemplar-guides").iterdir())


def test_recorded_exemplar_errors_name_the_key(cli, tmp_path, monkeypatch):
    monkeypatch.setenv("FLUIDYMATION_CACHE", str(tmp_path / "cache"))
    _recording(tmp_path / "rec")
    scene = tmp_path / "scene.yaml"
    scene.write_text(f"input: {BLOB}\nsize: [40, 40]\nframes: {{start: 4, end: 5}}\n"
                     "exemplars:\n  rec: {images: 'rec/%02d.png', flow: exact}\ndefaults: {exemplar: rec}\n")
    code, _, err = cli("render", scene, "--until", "stylize")
    assert code == 2 and "exemplars.rec.flow" in err and "built-in" in err
