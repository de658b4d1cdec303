"""A layer painted from keyframes, end to end: the scene key, its errors, colorize none, the cache,
resume after a kill, and the same bytes from local processes and a Dask cluster."""

import json
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest

from fluidymation.pipeline.cli import main
from fluidymation.stages import keyframe_morph
from fluidymation.stages.colour import linear_to_srgb, srgb_to_linear

from tests.scenes import blob_scene, write_scene

QUICK = "{sweeps: 1, em_iterations: 1, levels: 1}"


def _scene(folder, keyframes="{0: k0.png, 3: k3.png}", stylizer="keyframes", params=QUICK):
    layer = f'  - {{name: blob, stylizer: {stylizer}, keyframes: {keyframes}, params: {params}}}\n'
    return write_scene(folder, blob_scene(layers=layer, params="{}"))


@pytest.fixture(scope="module")
def painted(tmp_path_factory):
    """A scene folder with keyframes painted (a striped texture) inside the blob's masks of frames 0 and 3."""
    folder = tmp_path_factory.mktemp("painted")
    masks_only = write_scene(folder, blob_scene())
    assert main(["-q", "render", str(masks_only), "--until", "masks"]) == 0
    ys, xs = np.mgrid[:40, :40]
    for frame in (0, 3):
        coverage = iio.imread(folder / "out" / "coverage" / "blob" / f"{frame:05d}.png").astype(np.float32) / 255
        stripes = 0.5 + 0.4 * np.sin((xs + 2 * ys + 3 * frame) / 2.0)
        rgba = np.dstack([0.8 * stripes, 0.3 + 0.2 * stripes, 0.2 + 0.0 * xs, coverage])
        iio.imwrite(folder / f"k{frame}.png", np.rint(rgba * 255).astype(np.uint8))
    (folder / "scene.yaml").unlink()
    return folder


def _stylized(out):
    return {path.name: path.read_bytes() for path in sorted((out / "stylized" / "blob").glob("*.png"))}


@pytest.fixture(scope="module")
def rendered(painted):
    scene = _scene(painted)
    assert main(["-q", "render", str(scene)]) == 0
    return painted / "out"


def test_keyframes_render_with_their_own_colours(rendered, painted):
    assert (rendered / "film.mp4").is_file() and len(_stylized(rendered)) == 4
    key = iio.imread(painted / "k0.png").astype(np.float32) / 255
    stylized = iio.imread(rendered / "stylized" / "blob" / "00000.png").astype(np.float32) / 255
    layer = iio.imread(rendered / "layers" / "blob" / "00000.png").astype(np.float32) / 255
    inside = key[..., 3] > 0.99
    # the approximating morph keeps the keyframe's colours (its stripes a little softened) ...
    assert np.abs(stylized[..., :3] - key[..., :3])[inside].mean() < 0.05
    # ... and colorize none keeps the stylized colours: the layer over white in linear light gives them back
    shown = srgb_to_linear(layer[..., :3]) * layer[..., 3:] + (1 - layer[..., 3:])
    assert np.abs(linear_to_srgb(shown) - stylized[..., :3])[inside].max() < 0.02


def test_an_unchanged_keyframe_scene_is_cached_and_a_new_keyframe_restylizes(rendered, painted, cli):
    scene = _scene(painted)
    code, _, _ = cli("-q", "render", scene)
    report = json.loads((rendered / "report.json").read_text())
    assert code == 0 and all(entry["cached"] for entry in report["stages"] if entry["stage"] == "stylize")
    image = iio.imread(painted / "k3.png")
    image[..., 0] = 255 - image[..., 0]
    iio.imwrite(painted / "k3b.png", image)
    code, _, _ = cli("-q", "render", _scene(painted, "{0: k0.png, 3: k3b.png}"), "--until", "stylize")
    report = json.loads((rendered / "report.json").read_text())
    assert code == 0 and not any(entry["cached"] for entry in report["stages"] if entry["stage"] == "stylize")
    assert main(["-q", "render", str(_scene(painted))]) == 0  # back to the fixture's render


@pytest.mark.parametrize("keyframes, stylizer, message", [
    ("{0: k0.png, 9: k3.png}", "keyframes", "k3.png: keyframe 9 is outside the scene's frames 0:4"),
    ("{0: k0.png, 3: missing.png}", "keyframes", "missing.png: no such image"),
    ("{zero: k0.png}", "keyframes", "the keys are whole frame numbers"),
    ("{0: k0.png}", "fluidymation", "does not use keyframes"),
])
def test_bad_keyframes_are_named(painted, cli, keyframes, stylizer, message):
    code, _, err = cli("render", _scene(painted, keyframes, stylizer, "{}"))
    assert code == 2 and message in err and "Traceback" not in err


def test_a_keyframes_layer_needs_keyframes_and_refuses_stray_paint(painted, cli, tmp_path):
    scene = write_scene(tmp_path, blob_scene(layers="  - {name: blob, stylizer: keyframes}\n", params="{}"))
    code, _, err = cli("render", scene)
    assert code == 2 and "paints from keyframes" in err
    stray = np.zeros((40, 40, 4), np.uint8)
    stray[..., 3] = 255  # paint over the whole frame
    iio.imwrite(painted / "stray.png", stray)
    code, _, err = cli("render", _scene(painted, "{0: stray.png}"))
    assert code == 2 and "stray.png" in err and "outside the layer's mask at frame 0" in err


def test_a_killed_render_resumes_to_the_same_frames(rendered, painted, tmp_path, monkeypatch):
    folder = tmp_path / "killed"
    folder.mkdir()
    for name in ("k0.png", "k3.png"):
        (folder / name).write_bytes((painted / name).read_bytes())
    scene = _scene(folder)
    real, calls = keyframe_morph.morph_frame, []

    def dies(context, task):
        if len(calls) == 6:
            raise KeyboardInterrupt
        calls.append(task.frame)
        real(context, task)

    monkeypatch.setattr(keyframe_morph, "morph_frame", dies)
    assert main(["-q", "render", str(scene)]) != 0  # "interrupted; finished frames are kept"
    resumed = []

    def counts(context, task):
        if not Path(task.out).is_file():  # a task an earlier run finished is skipped
            resumed.append(task.frame)
        real(context, task)

    monkeypatch.setattr(keyframe_morph, "morph_frame", counts)
    assert main(["-q", "render", str(scene)]) == 0
    assert _stylized(folder / "out") == _stylized(rendered)
    assert len(resumed) == 2 * 2 * 4 - 6  # two passes of an initialization and a sweep over 4 frames, 6 were done


def test_local_processes_and_a_dask_cluster_give_the_same_frames(rendered, painted, tmp_path):
    distributed = pytest.importorskip("distributed")
    for name in ("jobs", "dask"):
        (tmp_path / name).mkdir()
        for key in ("k0.png", "k3.png"):
            (tmp_path / name / key).write_bytes((painted / key).read_bytes())
    assert main(["-q", "render", str(_scene(tmp_path / "jobs")), "--jobs", "2"]) == 0
    assert _stylized(tmp_path / "jobs" / "out") == _stylized(rendered)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        address = cluster.scheduler_address.removeprefix("tcp://")
        assert main(["-q", "render", str(_scene(tmp_path / "dask")), "--executor", f"dask://{address}"]) == 0
    assert _stylized(tmp_path / "dask" / "out") == _stylized(rendered)


def test_ablate_compares_the_keyframe_variants(painted, cli):
    code, out, err = cli("ablate", _scene(painted), "--layer", "blob")
    assert code == 0, err
    variants = sorted(path.name for path in (painted / "out" / "ablate" / "blob").iterdir() if path.is_dir())
    assert variants == ["no-neighbours", "no-velocity-modulation", "two-pass"]
    assert (painted / "out" / "ablate" / "blob.mp4").is_file() and "wrote 3 versions" in out


def test_colorize_a_colour_repaints_the_keyframe_paint_in_it(painted, tmp_path):
    folder = tmp_path / "tinted"
    folder.mkdir()
    for name in ("k0.png", "k3.png"):
        (folder / name).write_bytes((painted / name).read_bytes())
    scene = _scene(folder)
    scene.write_text(scene.read_text().replace("stylizer: keyframes,", 'stylizer: keyframes, colorize: "#1f7a3a",'))
    assert main(["-q", "render", str(scene), "--until", "colorize"]) == 0
    layer = iio.imread(folder / "out" / "layers" / "blob" / "00000.png").astype(np.float32) / 255
    painted_pixels = layer[..., 3] > 0.5
    red, green, blue = (layer[..., c][painted_pixels].mean() for c in range(3))
    assert green > red and green > blue  # the keyframes' red-brown paint now in the layer's green
