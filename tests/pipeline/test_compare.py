"""`fluidymation compare`: one layer painted by several stylizers, side by side, with quality figures."""

import json
import math

import av
import imageio.v3 as iio
import numpy as np
import pytest

from fluidymation.pipeline.cli import main
from fluidymation.pipeline.stylizers import stylizer_names

from tests.scenes import write_scene

SIZE = 48
# a still square (a still region) beside a circle drifting 1 px a frame (a moving band), in one layer
SHAPES = (f'<svg xmlns="http://www.w3.org/2000/svg" width="{SIZE}" height="{SIZE}"><g id="shapes">'
          '<rect x="3" y="10" width="18" height="26"/><circle cx="32" cy="24" r="8">'
          '<animate attributeName="cx" from="32" to="44" begin="0s" dur="1s" fill="freeze"/></circle></g></svg>')


def _scene(folder, layer):
    return write_scene(folder, f"input: shapes.svg\nfps: 12\nframes: {{start: 0, end: 4}}\noutput: {{dir: out}}\n"
                               "exemplars:\n  ink: {builtin: watercolor-bloom, size: [32, 32], frames: 6}\n"
                               f"defaults: {{exemplar: ink}}\nlayers:\n  - {layer}\n")


@pytest.fixture(scope="module")
def painted(tmp_path_factory):
    """A scene folder whose layer ``shapes`` is painted from keyframes at frames 0 and 3 (stripes in its masks)."""
    folder = tmp_path_factory.mktemp("compare")
    (folder / "shapes.svg").write_text(SHAPES)
    assert main(["-q", "render", str(_scene(folder, "{name: shapes}")), "--until", "masks"]) == 0
    ys, xs = np.mgrid[:SIZE, :SIZE]
    for frame in (0, 3):
        coverage = iio.imread(folder / "out" / "coverage" / "shapes" / f"{frame:05d}.png").astype(np.float32) / 255
        stripes = 0.5 + 0.4 * np.sin((xs + 2 * ys) / 2.0)
        rgba = np.dstack([0.8 * stripes, 0.3 + 0.2 * stripes, 0.2 + 0.0 * xs, coverage])
        iio.imwrite(folder / f"k{frame}.png", np.rint(rgba * 255).astype(np.uint8))
    _scene(folder, "{name: shapes, stylizer: keyframes, keyframes: {0: k0.png, 3: k3.png}, "
                   "params: {sweeps: 1, em_iterations: 1, levels: 1}}")
    return folder


def test_compare_writes_both_panels_a_contact_sheet_and_finite_figures(painted, cli, tmp_path, monkeypatch):
    monkeypatch.setenv("FLUIDYMATION_CACHE", str(tmp_path / "cache"))
    code, out, err = cli("compare", painted / "scene.yaml", "--layer", "shapes",
                         "--stylizers", "fluidymation,keyframes")
    assert code == 0, err
    folder = painted / "out" / "compare"
    for name in ("fluidymation", "keyframes"):
        assert sorted(path.name for path in (folder / "shapes" / name).glob("*.png")) == [
            f"{k:05d}.png" for k in range(4)]
    with av.open(str(folder / "shapes.mp4")) as container:
        stream = container.streams.video[0]
        assert (stream.codec_context.width, stream.codec_context.height) == (2 * SIZE, SIZE + 14)
        assert sum(1 for _ in container.decode(stream)) == 4
    sheet = iio.imread(folder / "shapes.png")
    assert sheet.shape[1] == 3 * SIZE and sheet.shape[0] > 2 * SIZE  # frames 0, 2 and 3; two rows with captions
    record = json.loads((folder / "shapes.json").read_text())
    rows = {row["name"]: row for row in record["stylizers"]}
    assert rows["keyframes"]["params"] == "layer" and rows["fluidymation"]["params"] == "defaults"
    assert rows["keyframes"]["figures"].pop("fidelity") is None  # no exemplar: n/a
    for row in rows.values():
        assert all(value is not None and math.isfinite(value) for value in row["figures"].values()), row
        assert row["figures"]["iou"] > 0.9
    assert "| keyframes | layer |" in out and "n/a" in out and "fid" in out


def test_an_unknown_stylizer_is_named_with_the_registered_ones(painted, cli):
    code, _, err = cli("compare", painted / "scene.yaml", "--layer", "shapes", "--stylizers", "fluidymation,oils")
    assert code == 2 and "'oils'" in err and ", ".join(stylizer_names()) in err and "Traceback" not in err


def test_the_keyframes_stylizer_needs_the_layers_keyframes(tmp_path, cli):
    (tmp_path / "shapes.svg").write_text(SHAPES)
    code, _, err = cli("compare", _scene(tmp_path, "{name: shapes}"), "--layer", "shapes", "--stylizers", "keyframes")
    assert code == 2 and "layer 'shapes'" in err and "'keyframes' paints from keyframes" in err
    assert not (tmp_path / "out").exists()  # refused before any work
