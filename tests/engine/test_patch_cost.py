"""The patch cost: its kernels against the naive float64 cost of tests/naive.py."""

import numpy as np
import pytest

from fluidymation.engine.nnf import NNF
from fluidymation.engine.patch_cost import (
    _flow_pair_cost, _is_plain_window, _plain_window_cost, _rotated_cost, build_patch_cost, patch_errors,
)
from tests.naive import naive_bilinear, naive_patch_cost, naive_rotate


def make_cost(rng, *, frames=2, source=(9, 10), target=(7, 8), weight_map=False, guide_weights=(2.0, 3.0), **options):
    source_colour = rng.random((frames,) + source + (3,)).astype(np.float32)
    source_guides = rng.random((frames,) + source + (2,)).astype(np.float32)
    target_colour = rng.random(target + (3,)).astype(np.float32)
    target_guides = rng.random(target + (2,)).astype(np.float32)
    extra = {}
    if weight_map:
        extra = dict(guide_weight_map=np.array([0, -1]), weight_maps=rng.random((1,) + target).astype(np.float32))
    cost = build_patch_cost(
        source_colour=source_colour, source_guides=source_guides, target_colour=target_colour,
        target_guides=target_guides, colour_weights=[1.0, 0.5, 0.25], guide_weights=guide_weights, **extra, **options,
    )
    source = np.concatenate([source_colour, source_guides], axis=3)
    target = np.concatenate([target_colour, target_guides], axis=2)
    return cost, source, target, extra


@pytest.mark.parametrize("weight_map", [False, True])
def test_patch_errors_match_naive_cost(weight_map):
    rng = np.random.default_rng(6)
    cost, source, target, extra = make_cost(rng, weight_map=weight_map)
    field = NNF(rng.integers(0, 2, (7, 8)).astype(np.int32), np.zeros((7, 8, 3), np.float32))
    field.coords[..., 0] = rng.integers(0, 10, (7, 8))
    field.coords[..., 1] = rng.integers(0, 9, (7, 8))
    field.coords[::2, :, 2] = rng.uniform(-3, 3, (4, 8))
    field.coords[:, ::3, 0] += 0.3
    field.frame[4, 4] = -1
    errors = patch_errors(cost, field)
    weights = np.array([1.0, 0.5, 0.25, 2.0, 3.0])
    for ty, tx in np.ndindex(7, 8):
        frame = field.frame[ty, tx]
        if frame < 0:
            assert errors[ty, tx] == np.inf
            continue
        x, y, theta = field.coords[ty, tx]
        if weight_map:
            # guide 0 is scaled by the map at each window pixel: compare term by term
            expected = 0.0
            maps = extra["weight_maps"][0]
            for dy in range(-2, 3):
                for dx in range(-2, 3):
                    qx, qy = tx + dx, ty + dy
                    if 0 <= qx < 8 and 0 <= qy < 7:
                        w = weights.copy()
                        w[3] *= maps[qy, qx]
                        one = np.zeros_like(target)
                        one[qy, qx] = target[qy, qx]
                        expected += naive_patch_cost(source, one, w, frame, x, y, theta, tx, ty, 5) - \
                            naive_patch_cost(source, one, w * 0, frame, x, y, theta, tx, ty, 5) - \
                            _others(source, one, w, frame, x, y, theta, tx, ty, qx, qy)
        else:
            expected = naive_patch_cost(source, target, weights, frame, x, y, theta, tx, ty, 5)
        assert errors[ty, tx] == pytest.approx(expected, rel=1e-4, abs=1e-5)


def _others(source, one, w, frame, x, y, theta, tx, ty, qx, qy):
    """Cost of the window pixels other than (qx, qy) when the target is zero there."""
    total = naive_patch_cost(source, one, w, frame, x, y, theta, tx, ty, 5)
    ox, oy = naive_rotate(theta, qx - tx, qy - ty)
    value = naive_bilinear(source[frame], x + ox, y + oy)
    single = float(np.sum(w * (value - one[qy, qx]) ** 2))
    return total - single


def test_orientation_term_and_opposite_swap():
    rng = np.random.default_rng(7)
    source_angle = rng.uniform(-3, 3, (2, 9, 10)).astype(np.float32)
    target_angle = rng.uniform(-3, 3, (7, 8)).astype(np.float32)
    equal = (2.0, 2.0)
    plain, source, target, _ = make_cost(np.random.default_rng(8), guide_weights=equal)
    swapped, *_ = make_cost(np.random.default_rng(8), guide_weights=equal, opposite_guide=[1, 0],
                            source_angle=source_angle, target_angle=target_angle)
    oriented, *_ = make_cost(np.random.default_rng(8), guide_weights=equal, source_angle=source_angle,
                             target_angle=target_angle, orientation_weight=0.5, orientation_clamp=3.0)
    with pytest.raises(ValueError, match="equal weights"):
        make_cost(np.random.default_rng(8), opposite_guide=[1, 0], source_angle=source_angle, target_angle=target_angle)
    field = NNF(np.ones((7, 8), np.int32), np.zeros((7, 8, 3), np.float32))
    field.coords[..., 0] = 5
    field.coords[..., 1] = 4
    field.coords[..., 2] = 0.3
    base, swap, orient = (patch_errors(c, field) for c in (plain, swapped, oriented))
    weights = np.array([1.0, 0.5, 0.25, 2.0, 2.0])
    source_swapped = source[..., [0, 1, 2, 4, 3]]
    for ty, tx in [(3, 3), (0, 7), (6, 1)]:
        opposite = np.cos(source_angle[1, 4, 5] - 0.3 - target_angle[ty, tx]) < 0
        reference = source_swapped if opposite else source
        assert swap[ty, tx] == pytest.approx(naive_patch_cost(reference, target, weights, 1, 5, 4, 0.3, tx, ty, 5), rel=1e-4)
        extra = 0.0
        for dy in range(-2, 3):
            for dx in range(-2, 3):
                qx, qy = tx + dx, ty + dy
                if 0 <= qx < 8 and 0 <= qy < 7:
                    px = 5 + np.cos(0.3) * dx - np.sin(0.3) * dy
                    py = 4 + np.sin(0.3) * dx + np.cos(0.3) * dy
                    sa = source_angle[1, int(min(max(py + 0.5, 0), 8)), int(min(max(px + 0.5, 0), 9))]
                    extra += 0.5 * min(abs(np.tan(sa - 0.3 - target_angle[qy, qx])), 3.0)
        assert orient[ty, tx] == pytest.approx(base[ty, tx] + extra, rel=1e-4)


def test_plain_window_cost_matches_naive_cost_inside_both_images():
    rng = np.random.default_rng(11)
    cost, source, target, _ = make_cost(rng, source=(9, 10), target=(7, 8))
    kernel_cost = cost.kernel_cost()
    assert kernel_cost.plain
    weights = np.array([1.0, 0.5, 0.25, 2.0, 3.0])
    for frame, sx, sy, tx, ty in [(0, 2, 2, 2, 2), (1, 7, 6, 5, 4), (1, 4, 3, 3, 2)]:
        assert _is_plain_window(kernel_cost, tx, ty, np.float32(sx), np.float32(sy), np.float32(0.0))
        expected = naive_patch_cost(source, target, weights, frame, sx, sy, 0.0, tx, ty, 5)
        got = _plain_window_cost(kernel_cost, frame, sx, sy, tx, ty, np.float32(np.inf))
        assert got == pytest.approx(expected, rel=1e-4)
        stopped = _plain_window_cost(kernel_cost, frame, sx, sy, tx, ty, np.float32(0.0))
        assert stopped < expected  # early termination after the first row
    # the target window over the border
    assert not _is_plain_window(kernel_cost, 1, 2, np.float32(2), np.float32(2), np.float32(0.0))


def test_opposite_guide_must_be_a_swap():
    with pytest.raises(ValueError, match="swap"):
        make_cost(np.random.default_rng(8), guide_weights=(2.0, 2.0), opposite_guide=[1, 1])


def test_flow_pair_cost_is_both_flow_aligned_angles():
    """One pass over shared samples gives θ's cost unswapped and θ + π's swapped, with the
    orientation term, as two rotated costs would."""
    rng = np.random.default_rng(12)
    source_angle = rng.uniform(-3, 3, (2, 9, 10)).astype(np.float32)
    target_angle = rng.uniform(-3, 3, (7, 8)).astype(np.float32)
    cost, *_ = make_cost(rng, guide_weights=(2.0, 2.0), opposite_guide=[1, 0], source_angle=source_angle,
                         target_angle=target_angle, orientation_weight=0.5, orientation_clamp=3.0)
    kernel_cost = cost.kernel_cost()
    for frame, x, y, theta, tx, ty in [(1, 5.0, 4.0, 0.7, 3, 3), (0, 2.0, 6.0, -2.1, 0, 6), (1, 8.0, 1.0, 3.0, 7, 0)]:
        cos_t, sin_t = np.float32(np.cos(theta)), np.float32(np.sin(theta))
        first, second = _flow_pair_cost(kernel_cost, tx, ty, frame, np.float32(x), np.float32(y), np.float32(theta),
                                        cos_t, sin_t, np.float32(np.inf))
        unswapped = _rotated_cost(kernel_cost, tx, ty, frame, np.float32(x), np.float32(y), np.float32(theta),
                                  cos_t, sin_t, False, np.float32(np.inf))
        swapped = _rotated_cost(kernel_cost, tx, ty, frame, np.float32(x), np.float32(y), np.float32(theta + np.pi),
                                -cos_t, -sin_t, True, np.float32(np.inf))
        assert first == pytest.approx(unswapped, rel=1e-5)
        assert second == pytest.approx(swapped, rel=1e-5)
        assert first != pytest.approx(second, rel=1e-3)
        stopped_first, stopped_second = _flow_pair_cost(kernel_cost, tx, ty, frame, np.float32(x), np.float32(y),
                                                        np.float32(theta), cos_t, sin_t, np.float32(0.0))
        assert 0.0 < stopped_first < first and 0.0 < stopped_second < second  # both stop early
