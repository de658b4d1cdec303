"""A flat-coloured map painted from one still exemplar and its regions, end to end: the scene keys, a still
layer synthesized once, a moving one carried along, and the errors naming file and key."""

import imageio.v3 as iio
import numpy as np
import pytest

from fluidymation import quality
from fluidymation.pipeline.cli import main
from fluidymation.stages import still

from tests.scenes import map_svg, two_region_painting, write_scene

QUICK = "{opt_iters: [2], pm_iters: [2], pyramid_levels: 2}"


def _scene(folder, *, map_layer="", exemplar="{image: crayon.png, segments: crayon-seg.png}", frames=4):
    return write_scene(folder, (
        "version: 1\ninput: map.svg\nfps: 12\nsize: [48, 48]\n"
        f"frames: {{start: 0, end: {frames}}}\noutput: {{dir: out, video: film.mp4}}\n"
        'background: {type: solid, color: "#f4efe4"}\n'
        f"exemplars:\n  crayon: {exemplar}\n"
        f"defaults: {{stylizer: still, exemplar: crayon, params: {QUICK}}}\n"
        "layers:\n"
        f"  - {{name: map, select: [map]{map_layer}}}\n"
        "  - {name: boat, select: [boat], segments: mask}\n"))


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """map.svg, a 64² two-region painting (crayon.png) and its segments (crayon-seg.png)."""
    folder = tmp_path_factory.mktemp("map")
    (folder / "map.svg").write_text(map_svg())
    rgb, labels = two_region_painting()
    iio.imwrite(folder / "crayon.png", np.rint(rgb * 255).astype(np.uint8))
    segments = np.where((labels == 0)[..., None], [0, 0, 255], [0, 255, 0]).astype(np.uint8)
    iio.imwrite(folder / "crayon-seg.png", segments)
    return folder


@pytest.fixture(scope="module")
def rendered(folder, monkeypatch_module):
    counts = []
    original = still.stylize_frames

    def counted(*args, **kwargs):
        kwargs["counts"] = still.Counts()
        counts.append(kwargs["counts"])
        yield from original(*args, **kwargs)

    monkeypatch_module.setattr(still, "stylize_frames", counted)
    assert main(["-q", "render", str(_scene(folder))]) == 0
    return folder / "out", counts


@pytest.fixture(scope="module")
def monkeypatch_module():
    with pytest.MonkeyPatch.context() as patch:
        yield patch


def _copy(folder, work):
    """The map scene's files copied to a fresh folder ``work`` (for a scene of its own)."""
    work.mkdir()
    for name in ("map.svg", "crayon.png", "crayon-seg.png"):
        (work / name).write_bytes((folder / name).read_bytes())
    return work


def _frames(out, layer):
    return [iio.imread(path).astype(np.float32) / 255 for path in sorted((out / "stylized" / layer).glob("*.png"))]


def test_the_still_map_is_synthesized_once_and_the_same_in_every_frame(rendered):
    out, counts = rendered
    assert (out / "film.mp4").is_file()
    by_layer = {(c.synthesized, c.followed, c.reused) for c in counts}
    assert (1, 0, 3) in by_layer  # map: one synthesis, three frames reused
    frames = _frames(out, "map")
    assert len(frames) == 4 and all(np.array_equal(frame, frames[0]) for frame in frames)


def test_map_regions_take_the_matching_texture(rendered):
    out, _ = rendered
    frame = _frames(out, "map")[0]
    water, land = frame[10:38, 6:20, :3], frame[10:38, 28:42, :3]
    assert water[..., 2].mean() > water[..., 1].mean() + 0.1  # blue stripes
    assert land[..., 1].mean() > land[..., 2].mean() + 0.2  # green dots


def test_the_boat_carries_its_paint_along(rendered):
    out, counts = rendered
    assert (1, 3, 0) in {(c.synthesized, c.followed, c.reused) for c in counts}
    frames = _frames(out, "boat")
    assert all(np.array_equal(frame[..., 3] > 0.5, frame[..., 3] > 0.5) for frame in frames)
    assert frames[0][..., 3].sum() > 100 and not np.array_equal(frames[0], frames[1])


@pytest.mark.parametrize("layer, exemplar, message", [
    (", segment_map: {'#123456': '#0000ff'}", None, "layer 'map': segment_map: #123456 is not one of the layer's"),
    (", segment_map: {'#334ccc': '#ff0000'}", None, "#ff0000 is not a region colour"),
    ("", "{video: crayon.png, segments: crayon-seg.png}", "exemplars.crayon.segments: only a still image exemplar"),
    ("", "{image: crayon.png, segments: small.png}", "small.png: the segments image is 8x8, the painting 64x64"),
])
def test_bad_regions_are_named(folder, tmp_path, capsys, layer, exemplar, message):
    work = _copy(folder, tmp_path / "scene")
    iio.imwrite(work / "small.png", np.zeros((8, 8, 3), np.uint8))
    scene = _scene(work, map_layer=layer, frames=1, **({"exemplar": exemplar} if exemplar else {}))
    assert main(["-q", "render", str(scene)]) == 2
    assert message in capsys.readouterr().err


def test_lazyfluids_texture_follows_a_translating_disk(tmp_path):
    """A disk moving 3 px a frame, textured from one frame of a built-in exemplar: the texture moves with it."""
    (tmp_path / "disk.svg").write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" width="48" height="48" viewBox="0 0 48 48">\n'
        '  <g id="disk" fill="#2a6fdb"><circle cx="14" cy="24" r="11">\n'
        '    <animate attributeName="cx" from="14" to="50" begin="0s" dur="1s" fill="freeze"/></circle></g>\n'
        '</svg>\n')
    scene = write_scene(tmp_path, (
        "version: 1\ninput: disk.svg\nfps: 12\nsize: [48, 48]\nframes: {start: 0, end: 4}\n"
        'output: {dir: out, video: film.mp4}\nbackground: {type: solid, color: "#f4efe4"}\n'
        "exemplars:\n  ink: {builtin: watercolor-bloom, size: [32, 32], frames: 6}\n"
        "layers:\n  - {name: disk, stylizer: lazyfluids, exemplar: ink,\n"
        "     params: {exemplar_frame: 5, opt_iters: [2, 1], pm_iters: [2]}}\n"))
    assert main(["-q", "render", str(scene)]) == 0
    frames = _frames(tmp_path / "out", "disk")
    masks = [frame[..., 3] for frame in frames]
    shift = np.zeros((48, 48, 2), np.float32)
    shift[..., 0] = 3.0

    def residual(displacement):
        return np.mean([quality.compensated_residual(a[..., :3], b[..., :3], displacement, ma, mb)
                        for a, b, ma, mb in zip(frames, frames[1:], masks, masks[1:])])

    moved, unmoved = residual(shift), residual(np.zeros_like(shift))
    assert moved < 0.6 * unmoved


def test_an_exemplar_painted_to_its_edges_still_paints_a_fluidymation_layer(folder, tmp_path):
    """A painting with no unpainted margin has no border segment: the target's border matches its one segment."""
    work = _copy(folder, tmp_path / "scene")
    scene = _scene(work, map_layer=", stylizer: fluidymation, params: {opt_iters: [1], pm_iters: [1]}", frames=2)
    assert main(["-q", "render", str(scene), "--layer", "map", "--until", "stylize"]) == 0
    frame = _frames(work / "out", "map")[0]
    painted = frame[..., 3] > 0.5
    assert frame[..., :3][painted].mean() > 0.3  # painting's colours, not unmatched black
