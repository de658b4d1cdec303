import sys
from pathlib import Path

import numba
import numpy as np
from scipy import ndimage

from fluidymation.engine import flow

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import naive  # noqa: E402

SIZE = 72
YY, XX = np.mgrid[:SIZE, :SIZE].astype(np.float64)


def _disk_distance(cx, cy, radius):
    return (radius - np.hypot(XX - cx, YY - cy)).astype(np.float32)


def _inner_boundary(mask):
    padded = np.pad(mask, 1, mode="edge")
    all_inside = padded[:-2, 1:-1] & padded[2:, 1:-1] & padded[1:-1, :-2] & padded[1:-1, 2:]
    return mask & ~all_inside


def test_translating_disk_boundary_flow_points_along_the_motion():
    velocity = np.array([1.5, -0.75])
    centre = np.array([35.3, 36.1])
    before = _disk_distance(*(centre - velocity), 20.0)
    after = _disk_distance(*centre, 20.0)
    result = flow.flow_from_distances(before, after, after > 0)
    ys, xs = np.nonzero(_inner_boundary(after > 0))
    normals = np.stack([xs - centre[0], ys - centre[1]], axis=1)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    along = normals @ (velocity / np.linalg.norm(velocity))
    lead_trail = np.abs(along) >= 0.98
    assert lead_trail.sum() >= 6
    vectors = result[ys, xs][lead_trail]
    cosine = vectors @ velocity / np.linalg.norm(vectors, axis=1) / np.linalg.norm(velocity)
    assert cosine.min() >= 0.95
    speed = np.linalg.norm(vectors, axis=1)
    np.testing.assert_allclose(speed, np.abs(normals[lead_trail] @ velocity), rtol=0.05)


def test_translating_shapes_interior_moves_with_the_shape():
    # the normal boundary motion alone, filled harmonically, reads a disk's centre at
    # half the speed; the fitted motion's tangential part makes it the full velocity
    velocity = np.array([1.5, -0.75])
    centre = np.array([35.3, 36.1])
    square = np.maximum(np.abs(XX - centre[0]), np.abs(YY - centre[1]))
    before = np.maximum(np.abs(XX - centre[0] + velocity[0]), np.abs(YY - centre[1] + velocity[1]))
    for dist_prev, dist_cur in ((_disk_distance(*(centre - velocity), 20.0), _disk_distance(*centre, 20.0)),
                                ((18.0 - before).astype(np.float32), (18.0 - square).astype(np.float32))):
        result = flow.flow_from_distances(dist_prev, dist_cur, dist_cur > 0)
        error = np.linalg.norm(result - velocity, axis=2)[dist_cur > 2] / np.linalg.norm(velocity)
        assert error.mean() < 0.05 and np.percentile(error, 95) < 0.1  # the square's corners err most


def test_two_shapes_moving_apart_each_keep_their_own_motion():
    left, right = np.array([-1.0, 0.0]), np.array([0.5, 1.0])
    dist_prev = np.maximum(_disk_distance(18 - left[0], 36 - left[1], 12.0), _disk_distance(52 - right[0], 36 - right[1], 12.0))
    dist_cur = np.maximum(_disk_distance(18, 36, 12.0), _disk_distance(52, 36, 12.0))
    result = flow.flow_from_distances(dist_prev, dist_cur, dist_cur > 0)
    for velocity, cx in ((left, 18), (right, 52)):
        inside = np.hypot(XX - cx, YY - 36) < 10
        assert np.abs(result[inside] - velocity).max() < 0.1 * np.linalg.norm(velocity) + 0.02


def test_growing_disk_flow_points_outward_and_interior_is_harmonic():
    growth = 1.25
    result = flow.flow_from_distances(_disk_distance(36, 36, 24.0 - growth), _disk_distance(36, 36, 24.0), _disk_distance(36, 36, 24.0) > 0)
    radius = np.hypot(XX - 36, YY - 36)
    outward = np.stack([XX - 36, YY - 36], axis=2) / np.maximum(radius, 1e-9)[:, :, None]
    boundary = _inner_boundary(radius < 24.0)
    speed = np.linalg.norm(result, axis=2)
    np.testing.assert_allclose(speed[boundary], growth, rtol=0.02)
    assert ((result * outward).sum(axis=2)[boundary] > 0.99 * speed[boundary]).all()
    # the harmonic extension of g·n over a disk of radius R is g·r/R·n
    inside = radius < 22.0
    expected = growth * radius / 24.0
    assert np.abs(speed - expected)[inside].max() < 0.05 * growth


def test_static_mask_has_zero_flow():
    dist = _disk_distance(30, 40, 15.0)
    assert not flow.flow_from_distances(dist, dist, dist > 0).any()


def test_harmonic_fill_matches_a_sparse_direct_solve():
    domain = (np.hypot(XX[:40, :40] - 18, YY[:40, :40] - 20) < 16) | (np.abs(XX[:40, :40] - 30) + np.abs(YY[:40, :40] - 10) < 8)
    fixed = _inner_boundary(domain)
    fixed[20, 18] = True  # an interior Dirichlet point too
    values = np.stack([np.cos(XX[:40, :40] / 6.0) + YY[:40, :40] / 20.0, np.sin(YY[:40, :40] / 5.0)], axis=2).astype(np.float32)
    expected = naive.naive_harmonic_fill(values.astype(np.float64), fixed, domain)
    result = flow.harmonic_fill(values, fixed, domain, sweeps=8)
    spread = np.ptp(values[fixed])
    assert np.abs(result - expected).max() < 0.02 * spread
    assert not result[~domain].any()


def test_weighted_sum_matches_numpy():
    rng = np.random.default_rng(3)
    stack = rng.random((5, 7, 9, 2)).astype(np.float32)
    weights = np.array([0.1, 0.0, 0.5, 0.25, 0.15], dtype=np.float32)
    np.testing.assert_allclose(flow.weighted_sum(stack, weights), np.tensordot(weights, stack, axes=1), rtol=1e-5)


def test_runs_near_fixed_cover_a_square_dilation_in_whole_tiles():
    rng = np.random.default_rng(5)
    state = np.where(rng.random((37, 53)) < 0.005, flow._FIXED, flow._UNKNOWN).astype(np.int8)
    counts = np.empty(37, dtype=np.int64)
    starts, stops = np.empty((2, 37 * 53), dtype=np.int64)
    total = flow._runs_near_fixed(state, 4, counts, starts, stops)
    covered = np.zeros(state.shape, dtype=bool)
    row_of_run = np.repeat(np.arange(37), counts)
    for y, start, stop in zip(row_of_run, starts[:total], stops[:total]):
        covered[y, start:stop] = True
    fixed = state == flow._FIXED
    tile = flow._TILE
    assert (covered | ~ndimage.maximum_filter(fixed, size=9, mode="constant")).all()
    # reach 4 rounds up to one tile, beyond the fixed cell's own tile
    assert not (covered & ~ndimage.maximum_filter(fixed, size=2 * (2 * tile - 1) + 1, mode="constant")).any()
    tiles = covered[: 37 // tile * tile, : 53 // tile * tile].reshape(37 // tile, tile, 53 // tile, tile)
    assert (tiles.all(axis=(1, 3)) | ~tiles.any(axis=(1, 3))).all()


def test_harmonic_fill_far_from_the_fixed_pixels_matches_a_sparse_direct_solve():
    # the finest grids relax only near the fixed pixels: check a domain much wider than that reach
    size = 160
    yy, xx = np.mgrid[:size, :size].astype(np.float64)
    fixed = _inner_boundary(np.hypot(xx - 50, yy - 60) < 25) | _inner_boundary(np.abs(xx - 125) + np.abs(yy - 110) < 12)
    domain = np.ones((size, size), dtype=bool)
    values = np.stack([np.cos(xx / 9.0), np.sin(yy / 13.0) + xx / 80.0], axis=2).astype(np.float32)
    expected = naive.naive_harmonic_fill(values.astype(np.float64), fixed, domain)
    result = flow.harmonic_fill(values, fixed, domain, sweeps=8)
    assert np.abs(result - expected).max() < 0.035 * np.ptp(values[fixed])  # 2.7 %; relaxing everywhere: 2.6 %


def test_harmonic_fill_does_not_depend_on_the_thread_count():
    yy, xx = np.mgrid[:90, :70].astype(np.float64)
    domain = np.ones((90, 70), dtype=bool)
    fixed = _inner_boundary(np.hypot(xx - 30, yy - 40) < 20)
    values = np.stack([xx / 10.0, np.cos(yy / 7.0)], axis=2).astype(np.float32)
    results = []
    for threads in (1, numba.config.NUMBA_NUM_THREADS):
        numba.set_num_threads(threads)
        results.append(flow.harmonic_fill(values, fixed, domain))
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    np.testing.assert_array_equal(results[0], results[1])
