"""The source sliding window (``source_window``): bounded exemplar frames, same bytes however the run is split."""

import dataclasses

import numpy as np
import pytest

from fluidymation.engine.nnf import NNF
from fluidymation.engine.synthesis import SynthesisParams, concatenate_prepared, prepare_source
from fluidymation.errors import StageError
from fluidymation.stages import exemplar_store, guides, stylize
from tests.scenes import blob_scene, drifting_disk, spreading_wash, write_scene

SIZE, EXEMPLAR_FRAMES, FRAMES, WINDOW = 32, 12, 6, 5
GUIDES = guides.Params(blur_sigma=1.5, shape_radius=6, border_width=3, dist_time_sigma=0.5, flow_time_radius=1)
PARAMS = stylize.Params(opt_iters=(2, 1), pm_iters=(2,), vote_only_finest=False, cuboid_radius=2, settle_passes=1)


@pytest.fixture(scope="module")
def exemplar(tmp_path_factory):
    """A blotchy blue wash spreading 1 px a frame, 12 frames of 32 px: (in-memory Source, StoredSource)."""
    rgb, mask = spreading_wash(size=SIZE, frames=EXEMPLAR_FRAMES, seed=5, start_radius=4.0, growth=1.0)
    folder = tmp_path_factory.mktemp("exemplar")
    cache = guides.compute_guides(lambda j: mask[j], EXEMPLAR_FRAMES, params=GUIDES, cache_dir=folder)
    exemplar_store.store_colour(rgb, folder)
    return exemplar_store.in_memory(rgb, cache), exemplar_store.StoredSource(folder)


def _run(source, tmp_path, params, **options):
    folder = tmp_path / f"guides-{len(list(tmp_path.iterdir()))}"
    return list(stylize.stylize_sequence(drifting_disk, FRAMES, source, params=params, guide_params=GUIDES,
                                         cache_dir=folder, **options))


def _same(a, b):
    assert [f.index for f in a] == [f.index for f in b]
    for x, y in zip(a, b):
        np.testing.assert_array_equal(x.rgba, y.rgba)
        np.testing.assert_array_equal(x.nnf.frame, y.nnf.frame)
        np.testing.assert_array_equal(x.nnf.coords, y.nnf.coords)
        np.testing.assert_array_equal(x.backlog, y.backlog)


def test_a_window_as_long_as_the_exemplar_is_no_window(exemplar, tmp_path):
    source, stored = exemplar
    whole = _run(source, tmp_path, PARAMS)
    _same(_run(source, tmp_path, dataclasses.replace(PARAMS, source_window=EXEMPLAR_FRAMES)), whole)
    _same(_run(stored, tmp_path, dataclasses.replace(PARAMS, source_window=EXEMPLAR_FRAMES + 7)), whole)
    _same(_run(stored, tmp_path, PARAMS), whole)  # the exemplar read from disk is the one in memory


def test_the_window_slides_from_the_first_frames_to_the_last():
    starts = [stylize.window_start(k, FRAMES, EXEMPLAR_FRAMES, WINDOW) for k in range(FRAMES)]
    assert starts == [0, 1, 3, 4, 6, 7]
    assert stylize.window_start(0, 1, EXEMPLAR_FRAMES, WINDOW) == 0


@pytest.mark.parametrize("reverse", [False, True])
def test_every_match_lies_in_its_steps_window(exemplar, tmp_path, reverse):
    source, stored = exemplar
    params = dataclasses.replace(PARAMS, source_window=WINDOW, reverse=reverse)
    frames = _run(stored, tmp_path, params)
    used = set()
    for k, result in enumerate(frames):
        start = stylize.window_start(k, FRAMES, EXEMPLAR_FRAMES, WINDOW)
        matched = result.nnf.frame[result.nnf.frame >= 0]
        assert matched.size and start <= matched.min() and matched.max() < start + WINDOW
        used.update(matched.tolist())
    assert min(used) < 2 and max(used) >= EXEMPLAR_FRAMES - 2  # the run visits the whole exemplar
    _same(_run(source, tmp_path, params), frames)  # same bytes from memory as from disk, run again
    partial = _run(stored, tmp_path, params, frames=(2, 5))  # a partial run uses the same windows
    for result in partial:
        k = FRAMES - 1 - result.index if reverse else result.index
        start = stylize.window_start(k, FRAMES, EXEMPLAR_FRAMES, WINDOW)
        matched = result.nnf.frame[result.nnf.frame >= 0]
        assert start <= matched.min() and matched.max() < start + WINDOW


def test_resuming_a_windowed_run_gives_the_remaining_frames_bit_for_bit(exemplar, tmp_path):
    _, stored = exemplar
    params = dataclasses.replace(PARAMS, source_window=WINDOW)
    whole = _run(stored, tmp_path, params)
    done = whole[2]
    saved = NNF(done.nnf.frame.copy(), done.nnf.coords.copy())
    # the resumed run prepares its first window afresh; the uninterrupted one slid into it
    resume = (done.index, saved, done.backlog.copy(), done.rgba[..., :3].copy())
    _same(_run(stored, tmp_path, params, resume=resume), whole[3:])


def test_frames_prepared_apart_and_joined_equal_the_window_prepared_at_once(exemplar):
    source, _ = exemplar
    window = source.window(2, 9)
    guides_of = np.concatenate([window.shape[..., None], window.ext_plus[..., None] * 0.1,
                                window.ext_minus[..., None] * 0.1, window.rgb], axis=3)
    ranges = {"guide_range": ([-0.01] * 6, [1.01] * 6), "colour_range": ([-0.01] * 3, [1.01] * 3)}
    options = dict(source_angle=window.angle, source_segment=window.segment, params=SynthesisParams(), **ranges)

    def prepared(a, b):
        return prepare_source(window.rgb[a:b], guides_of[a:b], **options | {
            "source_angle": window.angle[a:b], "source_segment": window.segment[a:b]})

    whole = prepared(0, 7)
    joined = concatenate_prepared([prepared(0, 5).frames(1, 5), prepared(5, 7)])
    expected = whole.frames(1, 7)
    for a, b in zip(joined.levels, expected.levels):
        np.testing.assert_array_equal(a.colour, b.colour)
        np.testing.assert_array_equal(a.features.codes, b.features.codes)
        np.testing.assert_array_equal(a.angle, b.angle)
        np.testing.assert_array_equal(a.index[1], b.index[1])
    unfixed = prepare_source(window.rgb[:2] * 0.5, guides_of[:2], source_segment=window.segment[:2])
    with pytest.raises(ValueError, match="quantization"):
        concatenate_prepared([unfixed, prepare_source(window.rgb[2:4], guides_of[2:4],
                                                      source_segment=window.segment[2:4])])


@pytest.mark.parametrize("value", [4, 0, 2.5, True, "10"])
def test_a_window_too_short_or_not_a_frame_count_is_refused(value):
    with pytest.raises(StageError, match=r"source_window must be null or a whole number of frames ≥ 11"):
        stylize.Params(source_window=value)
    assert stylize.Params(source_window=3, cuboid_radius=1).source_window == 3


def test_a_scene_sets_the_window_and_a_bad_one_is_a_clear_error(cli, tmp_path, monkeypatch):
    monkeypatch.setenv("FLUIDYMATION_CACHE", str(tmp_path / "cache"))
    layers = '  - {name: blob, params: {source_window: 3, cuboid_radius: 1}}\n'
    scene = write_scene(tmp_path / "good", blob_scene(layers=layers))
    code, _, err = cli("-q", "render", scene, "--until", "stylize", "--nnf")
    assert code == 0, err
    nnf_dir = tmp_path / "good" / "out" / "stylized" / "blob" / "nnf"
    for k in range(4):
        start = stylize.window_start(k, 4, 6, 3)
        frames = np.load(nnf_dir / f"{k:05d}.npy")[..., 0]
        assert start <= frames[frames >= 0].min() and frames.max() < start + 3
    bad = write_scene(tmp_path / "bad", blob_scene(layers='  - {name: blob, params: {source_window: 4}}\n'))
    code, _, err = cli("render", bad, "--until", "stylize")
    assert code == 2 and "source_window" in err and "≥ 11" in err and "scene.yaml" in err
