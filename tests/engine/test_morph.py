"""The keyframe morph's kernels against naive loops: the windowed search of the motion prior and
the completeness (scatter) vote."""

import numpy as np

from fluidymation.engine.morph import scatter_vote, window_search
from fluidymation.engine.nnf import NNF
from fluidymation.engine.patch_cost import build_patch_cost, patch_errors

from tests.naive import naive_scatter_vote


def _cost(source, target, source_segment, target_segment):
    return build_patch_cost(source_colour=source[None], source_guides=np.zeros(source.shape[:2] + (1,), np.float32)[None],
                            target_colour=target, target_guides=np.zeros(target.shape[:2] + (1,), np.float32),
                            colour_weights=np.ones(source.shape[2]), guide_weights=np.ones(1),
                            source_segment=source_segment[None], target_segment=target_segment, patch_size=3)


def test_window_search_finds_the_best_candidate_of_each_pixels_own_window():
    rng = np.random.default_rng(3)
    source = rng.random((14, 16, 2)).astype(np.float32)
    target = rng.random((10, 12, 2)).astype(np.float32)
    source_segment = np.where(rng.random((14, 16)) < 0.2, -1, 0).astype(np.int32)
    target_segment = np.zeros((10, 12), np.int32)
    target_segment[0, :3] = -1
    centre = (rng.random((10, 12, 2)) * [15, 13]).astype(np.float32)
    radius = rng.integers(0, 3, (10, 12))
    cost = _cost(source, target, source_segment, target_segment)
    nnf, error = window_search(cost, centre, radius)
    for ty in range(10):
        for tx in range(12):
            if target_segment[ty, tx] < 0:
                assert nnf.frame[ty, tx] == -1 and np.isinf(error[ty, tx])
                continue
            cx, cy = int(np.floor(centre[ty, tx, 0] + 0.5)), int(np.floor(centre[ty, tx, 1] + 0.5))
            best = np.inf
            for y in range(max(cy - radius[ty, tx], 0), min(cy + radius[ty, tx] + 1, 14)):
                for x in range(max(cx - radius[ty, tx], 0), min(cx + radius[ty, tx] + 1, 16)):
                    if source_segment[y, x] < 0:
                        continue
                    single = NNF(np.zeros((10, 12), np.int32), np.zeros((10, 12, 3), np.float32))
                    single.coords[ty, tx, :2] = x, y
                    best = min(best, patch_errors(cost, single)[ty, tx])
            assert np.isclose(error[ty, tx], best, rtol=1e-5) or (np.isinf(best) and nnf.frame[ty, tx] == -1)
            if np.isfinite(best):
                x, y = nnf.coords[ty, tx, :2].astype(int)
                assert abs(x - cx) <= radius[ty, tx] and abs(y - cy) <= radius[ty, tx] and source_segment[y, x] == 0


def test_scatter_vote_matches_the_naive_completeness_vote():
    rng = np.random.default_rng(5)
    source = rng.random((9, 11, 3)).astype(np.float32)
    frames = np.where(rng.random((9, 11)) < 0.3, -1, 0).astype(np.int32)
    coords = np.zeros((9, 11, 3), np.float32)
    coords[..., 0] = rng.integers(-1, 14, (9, 11))
    coords[..., 1] = rng.integers(-1, 12, (9, 11))
    total = np.zeros((12, 13, 3), np.float32)
    weights = np.zeros((12, 13), np.float32)
    scatter_vote(source, NNF(frames, coords), patch_size=5, weight=0.25, total=total, weights=weights)
    expected_total, expected_weights = naive_scatter_vote(source, frames, coords, 5, 0.25, (12, 13))
    assert np.allclose(total, expected_total, atol=1e-5) and np.allclose(weights, expected_weights)
