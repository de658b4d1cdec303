"""``stylize_sequence(resume=...)`` continues a sequence exactly as an uninterrupted run."""

import dataclasses

import numpy as np
import pytest

from fluidymation.engine.nnf import NNF
from fluidymation.errors import StageError
from fluidymation.stages import exemplar_store, guides, stylize
from tests.scenes import drifting_disk, spreading_wash

SIZE = 32
GUIDES = guides.Params(blur_sigma=1.5, shape_radius=6, border_width=3, dist_time_sigma=0.5, flow_time_radius=1)
PARAMS = stylize.Params(opt_iters=(2, 1), pm_iters=(2,), vote_only_finest=False)


@pytest.fixture(scope="module")
def source(tmp_path_factory):
    """A blotchy blue wash spreading 1.5 px a frame, 6 frames of 32 px."""
    rgb, mask = spreading_wash(size=SIZE, frames=6, seed=3, start_radius=6.0, growth=1.5)
    cache = guides.compute_guides(lambda j: mask[j], 6, params=GUIDES, cache_dir=tmp_path_factory.mktemp("source"))
    return exemplar_store.in_memory(rgb, cache)


def _run(source, tmp_path, params, **options):
    folder = tmp_path / f"guides-{len(list(tmp_path.iterdir()))}"
    return list(stylize.stylize_sequence(drifting_disk, 5, source, params=params, guide_params=GUIDES,
                                         cache_dir=folder, **options))


@pytest.mark.parametrize("reverse", [False, True])
def test_resuming_from_a_frames_state_gives_the_remaining_frames_bit_for_bit(source, tmp_path, reverse):
    params = dataclasses.replace(PARAMS, reverse=reverse)
    whole = _run(source, tmp_path, params)
    done = whole[1]
    saved = NNF(done.nnf.frame.copy(), done.nnf.coords.copy())  # as the pipeline stores and reloads it
    rest = _run(source, tmp_path, params, resume=(done.index, saved, done.backlog.copy(),
                                                  done.rgba[..., :3].copy()))
    assert [f.index for f in rest] == [f.index for f in whole[2:]]
    assert np.abs(done.backlog).max() > 0  # the carried motion matters here
    for resumed, uninterrupted in zip(rest, whole[2:]):
        np.testing.assert_array_equal(resumed.rgba, uninterrupted.rgba)
        np.testing.assert_array_equal(resumed.nnf.coords, uninterrupted.nnf.coords)


def test_resuming_after_a_frame_outside_the_window_is_refused(source, tmp_path):
    with pytest.raises(StageError, match="cannot resume after frame 4"):
        _run(source, tmp_path, PARAMS, frames=(1, 3), resume=(4, NNF.empty(SIZE, SIZE), np.zeros((SIZE, SIZE)),
                                                                np.zeros((SIZE, SIZE, 3))))
