"""The PatchMatch search: exact matches of tiny sources, the uniformity penalty, the keep margin, segments."""

import numpy as np

from fluidymation.engine.nnf import NNF, fill_random
from fluidymation.engine.patch_cost import patch_errors
from fluidymation.engine.patchmatch import patchmatch_pass
from tests.engine.test_patch_cost import make_cost
from tests.naive import naive_exact_nnf


def test_patchmatch_finds_the_exact_nearest_neighbours_of_a_tiny_source():
    rng = np.random.default_rng(9)
    cost, source, target, _ = make_cost(rng, frames=2, source=(6, 6), target=(4, 5))
    field = NNF.empty(4, 5)
    fill_random(field, target_segment=cost.target_segment, source_segment=cost.source_segment, seed=3)
    error = patch_errors(cost, field)
    for iteration in range(600):  # random target, so no coherence: enough passes to sample all 72 patches
        patchmatch_pass(cost, field, error, alpha=0.5, seed=3, salt=iteration, reverse=iteration % 2 == 1, tile_rows=2)
    np.testing.assert_allclose(error, patch_errors(cost, field), rtol=1e-6)
    exact = naive_exact_nnf(source, target, np.array([1.0, 0.5, 0.25, 2.0, 3.0]), 5)
    np.testing.assert_allclose(error, exact, rtol=1e-4)


def test_penalty_scaled_per_target_pixel():
    # frame 0 costs 100 per patch, frame 1 nothing; target row 0 does not pay the penalty
    rng = np.random.default_rng(9)
    cost, source, target, _ = make_cost(rng, frames=2, source=(6, 6), target=(4, 5))
    penalty = np.zeros((2, 6, 6), np.float32)
    penalty[0] = 100.0
    scale = np.ones((4, 5), np.float32)
    scale[0] = 0.0
    field = NNF.empty(4, 5)
    fill_random(field, target_segment=cost.target_segment, source_segment=cost.source_segment, seed=3)
    error = patch_errors(cost, field)
    for iteration in range(600):
        patchmatch_pass(cost, field, error, penalty=penalty, penalty_scale=scale, alpha=0.5, seed=3, salt=iteration,
                        reverse=iteration % 2 == 1, tile_rows=2)
    assert np.all(field.frame[1:] == 1)
    exact = naive_exact_nnf(source, target, np.array([1.0, 0.5, 0.25, 2.0, 3.0]), 5)
    np.testing.assert_allclose(error[0], exact[0], rtol=1e-4)


def test_keep_margin_refuses_small_improvements():
    rng = np.random.default_rng(9)
    cost, source, target, _ = make_cost(rng, frames=2, source=(6, 6), target=(4, 5))
    start = NNF.empty(4, 5)
    fill_random(start, target_segment=cost.target_segment, source_segment=cost.source_segment, seed=3)

    def search(margin, passes=40):
        field = NNF(start.frame.copy(), start.coords.copy())
        error = patch_errors(cost, field)
        for iteration in range(passes):
            patchmatch_pass(cost, field, error, keep_margin=margin, alpha=0.5, seed=3, salt=iteration,
                            reverse=iteration % 2 == 1, tile_rows=2)
        return field, error

    free, free_error = search(None)
    zero, zero_error = search(np.zeros((4, 5), np.float32))
    np.testing.assert_array_equal(zero.coords, free.coords)
    np.testing.assert_array_equal(zero_error, free_error)
    # margin 1 on row 0: nothing there is ever good enough; the other rows search as before
    margin = np.zeros((4, 5), np.float32)
    margin[0] = 1.0
    held, held_error = search(margin)
    np.testing.assert_array_equal(held.frame[0], start.frame[0])
    np.testing.assert_array_equal(held.coords[0], start.coords[0])
    assert held_error[1:].mean() < patch_errors(cost, start)[1:].mean()
    # margin 0.5: every accepted change at least halved the cost of the match it replaced
    half, half_error = search(np.full((4, 5), 0.5, np.float32), passes=1)
    initial = patch_errors(cost, start)
    changed = (half.frame != start.frame) | np.any(half.coords != start.coords, axis=2)
    assert changed.any()
    assert np.all(half_error[changed] < 0.5 * initial[changed])


def test_matches_stay_in_their_segment():
    rng = np.random.default_rng(10)
    source_segment = np.zeros((2, 9, 10), np.int32)
    source_segment[:, :, 5:] = 1
    target_segment = np.zeros((7, 8), np.int32)
    target_segment[3:] = 1
    target_segment[0, :2] = -1
    cost, *_ = make_cost(rng, source_segment=source_segment, target_segment=target_segment)
    field = NNF.empty(7, 8)
    fill_random(field, target_segment=target_segment, source_segment=source_segment, seed=0)
    error = patch_errors(cost, field)
    before = error.copy()
    for iteration in range(6):
        patchmatch_pass(cost, field, error, seed=0, salt=iteration, reverse=iteration % 2 == 1)
    assert np.all(field.frame[0, :2] == -1)
    active = target_segment >= 0
    assert error[active].sum() < before[active].sum()
    for ty, tx in zip(*np.nonzero(active)):
        x, y, _ = field.coords[ty, tx]
        assert source_segment[field.frame[ty, tx], int(y + 0.5), int(x + 0.5)] == target_segment[ty, tx]


def test_propagation_only_takes_shifted_neighbour_matches_and_never_gets_worse():
    rng = np.random.default_rng(9)
    cost, _, _, _ = make_cost(rng, frames=2, source=(6, 6), target=(4, 5))
    field = NNF.empty(4, 5)
    fill_random(field, target_segment=cost.target_segment, source_segment=cost.source_segment, seed=3)
    before = NNF(field.frame.copy(), field.coords.copy())
    error = patch_errors(cost, field)
    start_error = error.copy()
    patchmatch_pass(cost, field, error, random_search=False, seed=3, tile_rows=4)
    assert np.all(error <= start_error)
    np.testing.assert_allclose(error, patch_errors(cost, field), rtol=1e-6)
    changed = np.argwhere((field.frame != before.frame) | np.any(field.coords != before.coords, axis=2))
    assert len(changed) > 0
    for ty, tx in changed:  # θ = 0 here: the left or upper neighbour's new match, one pixel on (clamped)
        offers = [(field.frame[ny, nx], min(field.coords[ny, nx, 0] + tx - nx, 5), min(field.coords[ny, nx, 1] + ty - ny, 5))
                  for ny, nx in ((ty, tx - 1), (ty - 1, tx)) if ny >= 0 and nx >= 0]
        assert (field.frame[ty, tx], field.coords[ty, tx, 0], field.coords[ty, tx, 1]) in offers
