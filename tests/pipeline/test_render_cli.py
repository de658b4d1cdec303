"""`fluidymation render --until ...` on a tiny copy of the blob example."""

import json
from pathlib import Path

import av
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


def test_unknown_parameter_and_stage_are_clear_errors(cli, tmp_path, monkeypatch):
    monkeypatch.setenv("FLUIDYMATION_CACHE", str(tmp_path / "cache"))
    code, _, err = cli("render", _scene(tmp_path, params="{w_tmp: 2}"), "--until", "masks")
    assert code == 2 and "defaults.params.w_tmp" in err and "did you mean 'w_temp'" in err and "scene.yaml" in err
    code, _, err = cli("render", _scene(tmp_path), "--until", "mask")
    assert code == 2 and "masks, guides, stylize, colorize, background, composite, encode" in err
    code, _, err = cli("render", _scene(tmp_path), "--scale", "0")
    assert code == 2 and "--scale" in err


def test_full_render_writes_layers_frames_video_and_report(cli, tmp_path, monkeypatch):
    monkeypatch.setenv("FLUIDYMATION_CACHE", str(tmp_path / "cache"))
    scene = _scene(tmp_path)
    scene.write_text(scene.read_text().replace("output: {dir: out}", "output: {dir: out, preview: gif}")
                     + "background: {type: solid, color: '#ffffff'}\n")
    code, out, err = cli("render", scene)
    assert code == 0, err
    root = tmp_path / "out"
    assert "scene.mp4" in out and (root / "scene.mp4").stat().st_size > 0
    assert iio.imread(root / "scene.gif").shape == (3, 40, 40, 3)
    layer = iio.imread(root / "layers" / "blob" / "00002.png")
    assert layer.shape == (40, 40, 4) and layer[..., 3].max() > 0
    assert (layer[..., 3] == 0).sum() > 0  # outside the blob and on its unpainted paper: transparent
    report = json.loads((root / "report.json").read_text())
    stages = [(entry["stage"], entry["layer"]) for entry in report["stages"]]
    assert stages == [("masks", "blob"), ("stylize", "blob"), ("colorize", "blob"), ("background", None),
                      ("encode", None)]
    assert report["frames"] == {"start": 4, "end": 7} and all(e["seconds"] >= 0 for e in report["stages"])


def test_preview_renders_half_size_into_its_own_folder(cli, tmp_path, monkeypatch):
    monkeypatch.setenv("FLUIDYMATION_CACHE", str(tmp_path / "cache"))
    scene = _scene(tmp_path)
    scene.write_text(scene.read_text() + "background: {type: solid}\n")
    code, _, err = cli("-q", "render", scene, "--preview", "--until", "composite")
    assert code == 0, err
    frames = sorted((tmp_path / "out" / "preview" / "frames").glob("*.png"))
    assert len(frames) == 3 and iio.imread(frames[0]).shape == (20, 20, 3)
    assert not (tmp_path / "out" / "frames").exists()


def test_one_layer_cannot_be_composited_before_the_others_exist(cli, tmp_path, monkeypatch):
    monkeypatch.setenv("FLUIDYMATION_CACHE", str(tmp_path / "cache"))
    scene = _scene(tmp_path)
    scene.write_text(scene.read_text() + "  - {name: drop}\nbackground: {type: solid}\n")
    code, _, err = cli("-q", "render", scene, "--layer", "blob")
    assert code == 2 and "layer 'drop'" in err and "--layer 'drop'" in err


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


def test_ablate_renders_each_term_switched_off_side_by_side(cli, tmp_path, monkeypatch):
    monkeypatch.setenv("FLUIDYMATION_CACHE", str(tmp_path / "cache"))
    scene = _scene(tmp_path)
    code, out, err = cli("ablate", scene, "--layer", "blob", "--frames", "4:6")
    assert code == 0, err
    folder = tmp_path / "out" / "ablate" / "blob"
    variants = sorted(p.name for p in folder.iterdir() if p.is_dir())
    # w_dir is 0 by default, so "no dir" equals "full" and gets no panel of its own
    assert variants == ["full", "no-bound", "no-dir-bound", "no-edge", "no-ext", "no-temp", "no-uni"]
    assert "no dir: the weight is already 0" in out
    assert not (tmp_path / "out" / "report.json").exists()  # a film's report is not overwritten by ablate
    full, no_temp = (iio.imread(folder / name / "00001.png") for name in ("full", "no-temp"))
    assert not np.array_equal(full, no_temp)
    with av.open(str(tmp_path / "out" / "ablate" / "blob.mp4")) as container:
        stream = container.streams.video[0]
        assert (stream.codec_context.width, stream.codec_context.height) == (7 * 40, 40 + 14)
        assert sum(1 for _ in container.decode(stream)) == 2
