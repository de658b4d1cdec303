"""The still stylizer's method (seed 002): region-restricted matching, per-region budgets, reuse, motion, edge bands."""

import numpy as np
import pytest

from fluidymation import quality
from fluidymation.engine.uniformity import budget_scales
from fluidymation.errors import InputError, ParameterError
from fluidymation.stages import regions as regions_module
from fluidymation.stages import still
from fluidymation.stages.regions import Regions
from fluidymation.stages.still_stylizer import StillStylizer

from tests.scenes import two_region_painting

SIZE = 64
BLUE, GREEN = (0.2, 0.3, 0.8), (0.25, 0.6, 0.25)


def painting() -> still.Painting:
    rgb, labels = two_region_painting(SIZE)
    return still.Painting(rgb, Regions(labels, np.array([[0, 0, 1], [0, 1, 0]], np.float32)))


def target(shift=0.0, size=72):
    """A disk (moved right by ``shift`` px) blue left of x = 30 + shift, green right of it: (colour, coverage)."""
    yy, xx = np.mgrid[:size, :size]
    coverage = (((xx - 34 - shift) ** 2 + (yy - 36) ** 2) < 28 ** 2).astype(np.float32)
    colour = np.where((xx < 30 + shift)[..., None], BLUE, GREEN).astype(np.float32)
    return colour, coverage


def run(frames, params=still.Params(), flow=None, counts=None):
    art = painting()
    layer = still.layer_regions(frames, art.regions, mode="by-color", where="test")
    synthesis = still.StillSynthesis(art, params)
    return list(still.stylize_frames(lambda j: frames[j][1], lambda j: frames[j][0], (0, len(frames)), synthesis,
                                     layer, flow=flow, counts=counts)), art


def source_labels_of(frame, art):
    x = np.clip(np.rint(frame.nnf.coords[..., 0]), 0, SIZE - 1).astype(int)
    y = np.clip(np.rint(frame.nnf.coords[..., 1]), 0, SIZE - 1).astype(int)
    return art.regions.labels[y, x]


def test_fill_colours_map_to_the_nearest_region_and_matches_stay_in_it():
    frames = [target()]
    (frame,), art = run(frames)
    layer = still.layer_regions(frames, art.regions, mode="by-color", where="test")
    assert {tuple(round(float(v), 2) for v in c): int(k) for c, k in zip(layer.palette, layer.labels)} == \
        {(0.2, 0.3, 0.8): 0, (0.25, 0.6, 0.25): 1}
    matched = frame.nnf.frame >= 0
    assert np.array_equal(matched, frame.labels >= 0)
    assert np.array_equal(source_labels_of(frame, art)[matched], frame.labels[matched])


def test_segment_map_overrides_the_nearest_colour_and_names_bad_colours():
    frames = [target()]
    art = painting()
    layer = still.layer_regions(frames, art.regions, mode="by-color", where="layer 'map'",
                                segment_map=(("#334ccc", "#00ff00"),))
    assert list(layer.labels) == [1, 1]
    with pytest.raises(InputError, match="layer 'map': segment_map: #123456 is not one of the layer's fill"):
        still.layer_regions(frames, art.regions, mode="by-color", where="layer 'map'",
                            segment_map=(("#123456", "#00ff00"),))
    with pytest.raises(InputError, match="#ff0000 is not a region colour"):
        still.layer_regions(frames, art.regions, mode="by-color", where="layer 'map'",
                            segment_map=(("#334ccc", "#ff0000"),))
    assert list(still.layer_regions(frames, art.regions, mode="mask", where="x").labels) == [1]  # dominant: green


def test_occurrence_budget_is_per_region_target_over_exemplar_size():
    art = painting()
    _, coverage = target()
    labels = still.layer_regions([target()], art.regions, mode="by-color", where="t").of(target()[0], coverage)
    n, weight = 5, 0.03
    scales = budget_scales(source_segment=art.regions.labels[None], target_segment=labels, patch_size=n,
                           frame_radius=0, weight=weight)
    for k in (0, 1):
        omega_best = (labels == k).sum() / (art.regions.labels == k).sum() * n * n  # the seed: |B_k| / |A_k| · |P|
        assert scales[k] == pytest.approx(weight / (n * n * omega_best), rel=1e-6)


def test_a_still_layer_is_synthesized_once_and_identical_in_every_frame():
    counts = still.Counts()
    frames = [target()] * 4
    out, _ = run(frames, flow=lambda j: np.zeros(frames[0][1].shape + (2,), np.float32), counts=counts)
    assert (counts.synthesized, counts.followed, counts.reused) == (1, 0, 3)
    assert all(np.array_equal(frame.rgba, out[0].rgba) for frame in out)


def test_texture_follows_a_translating_layer_and_only_uncovered_area_is_new():
    frames = [target(0.0), target(3.0)]
    counts = still.Counts()
    flow = np.zeros(frames[0][1].shape + (2,), np.float32)
    flow[..., 0] = 3.0
    out, _ = run(frames, flow=lambda j: flow, counts=counts)
    assert (counts.synthesized, counts.followed) == (1, 1)
    before, after = out[0].rgba[..., :3], out[1].rgba[..., :3]
    moved = np.zeros_like(before)
    moved[:, 3:] = before[:, :-3]
    interior = quality.inside(frames[0][1]) & quality.inside(frames[1][1])
    interior[:, 3:] &= interior[:, :-3]
    from scipy import ndimage
    interior = ndimage.binary_erosion(interior, iterations=4)
    residual = np.abs(after - moved)[interior].mean()
    unmoved = np.abs(after - before)[interior].mean()
    assert residual < 0.15 * unmoved


def test_edge_band_synthesis_keeps_full_synthesis_quality_and_synthesizes_less():
    frames = [target(size=96)]
    art = painting()
    full, _ = run(frames)
    band, _ = run(frames, params=still.Params(edge_band=6))
    masks = [frames[0][1]]
    fidelity = {name: quality.texture_fidelity([out[0].rgba], masks, [art.rgb], [art.regions.labels >= 0],
                                               samples=600) for name, out in (("full", full), ("band", band))}
    assert fidelity["band"] <= 1.15 * fidelity["full"]
    assert quality.blockiness([band[0].rgba], masks)[0] <= 1.05
    matched = band[0].nnf.frame >= 0
    assert np.array_equal(source_labels_of(band[0], art)[matched], band[0].labels[matched])


def test_read_regions_takes_flat_colours_and_refuses_a_size_mismatch(tmp_path):
    from fluidymation.stages.files import write_png

    image = np.zeros((20, 30, 4), np.float32)
    image[:, :10] = (0, 0, 1, 1)
    image[:, 10:] = (0, 1, 0, 1)
    image[:, 10] = (0, 0.5, 0.5, 1)  # an anti-aliased seam goes to a neighbour
    image[:5, 25:, 3] = 0  # transparent: no region
    write_png(tmp_path / "seg.png", image)
    found = regions_module.read_regions(tmp_path / "seg.png", (20, 30))
    assert len(found.colours) == 2 and (found.labels[:5, 25:] == -1).all()
    assert set(np.unique(found.labels[:, 10])) <= {0, 1}
    with pytest.raises(InputError, match="seg.png: the segments image is 30x20, the painting 40x20"):
        regions_module.read_regions(tmp_path / "seg.png", (20, 40))


def test_a_run_resumed_from_a_finished_frames_state_continues_with_the_same_frames():
    frames = [target(2.0 * j) for j in range(4)]
    flow = np.zeros(frames[0][1].shape + (2,), np.float32)
    flow[..., 0] = 2.0
    whole, art = run(frames, flow=lambda j: flow)
    stylizer = StillStylizer()
    index, nnf, rgb = stylizer.resume_from(1, stylizer.frame_state(whole[1]))
    previous = still.resumed(index, nnf, rgb, frames[1][1], whole[1].labels)
    layer = still.layer_regions(frames, art.regions, mode="by-color", where="test")
    rest = list(still.stylize_frames(lambda j: frames[j][1], lambda j: frames[j][0], (2, 4),
                                     still.StillSynthesis(art, still.Params()), layer, flow=lambda j: flow,
                                     previous=previous))
    assert [frame.index for frame in rest] == [2, 3]
    assert all(np.array_equal(a.rgba, b.rgba) for a, b in zip(rest, whole[2:]))


@pytest.mark.parametrize("values, name", [({"w_style": -1.0}, "w_style"), ({"w_style": 0.0}, "w_style"),
                                          ({"edge_band": -2.0}, "edge_band"), ({"exemplar_frame": -1}, "exemplar_frame")])
def test_bad_parameters_are_refused_naming_them(values, name):
    with pytest.raises(ParameterError, match=name) as caught:
        still.Params(**values)
    assert caught.value.name == name


def test_an_exemplar_frame_past_the_exemplar_is_refused_naming_it():
    from fluidymation.stages.lazyfluids_stylizer import OneFrame

    class TwoFrames:
        frame_count, ext_max = 2, 1.0

    with pytest.raises(ParameterError, match="exemplar_frame 2: the exemplar has 2 frames"):
        OneFrame(TwoFrames(), 2)
