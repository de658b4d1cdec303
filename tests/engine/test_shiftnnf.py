import math

import numpy as np
import pytest

from fluidymation.engine.nnf import NNF
from fluidymation.engine.shiftnnf import shift_nnf, temporal_modulation, transport_nnf
from tests.naive import naive_shift_frames
from tests.scenes import turn_flow


def _single(frame, x, y, theta):
    return NNF(np.array([[frame]], np.int32), np.array([[[x, y, theta]]], np.float32))


def _ramp_source(frames=6, size=4, speed=2.0):
    """Source whose ext+ grows by ``speed`` per frame and ext− shrinks by it; flow along +x."""
    steps = np.arange(frames, dtype=np.float32)[:, None, None] * np.ones((1, size, size), np.float32)
    return speed * steps, speed * (frames - 1 - steps), np.zeros((frames, size, size), np.float32)


def test_forward_shift_matches_the_target_motion_exactly():
    plus, minus, angle = _ramp_source()
    shifted, achieved = shift_nnf(_single(1, 2.0, 1.0, 0.0), target_motion=np.array([[4.0]], np.float32),
                        target_angle=np.zeros((1, 1), np.float32), source_ext_plus=plus,
                        source_ext_minus=minus, source_angle=angle)
    assert shifted.frame[0, 0] == 3  # moved 2 px per source frame: 4 px is 2 frames on
    assert achieved[0, 0] == 4.0
    np.testing.assert_array_equal(shifted.coords, [[[2.0, 1.0, 0.0]]])


def test_opposite_flow_shifts_backward_with_ext_minus():
    plus, minus, angle = _ramp_source()
    # target flows along −x, the unrotated source along +x: roughly opposite
    shifted, achieved = shift_nnf(_single(4, 1.0, 1.0, 0.0), target_motion=np.array([[6.0]], np.float32),
                        target_angle=np.full((1, 1), math.pi, np.float32), source_ext_plus=plus,
                        source_ext_minus=minus, source_angle=angle)
    assert shifted.frame[0, 0] == 1 and achieved[0, 0] == 6.0
    # the same match rotated by π follows the target: forward again, clamped at the last frame
    shifted, achieved = shift_nnf(_single(4, 1.0, 1.0, math.pi), target_motion=np.array([[6.0]], np.float32),
                        target_angle=np.full((1, 1), math.pi, np.float32), source_ext_plus=plus,
                        source_ext_minus=minus, source_angle=angle)
    assert shifted.frame[0, 0] == 5


def test_no_target_motion_and_unmatched_pixels_stay():
    plus, minus, angle = _ramp_source()
    nnf = NNF(np.array([[2, -1]], np.int32), np.array([[[1, 1, 0], [0, 0, 0]]], np.float32))
    shifted, achieved = shift_nnf(nnf, target_motion=np.zeros((1, 2), np.float32), target_angle=np.zeros((1, 2), np.float32),
                        source_ext_plus=plus, source_ext_minus=minus, source_angle=angle)
    np.testing.assert_array_equal(shifted.frame, [[2, -1]])


def test_shift_agrees_with_the_naive_search():
    rng = np.random.default_rng(3)
    frames, height, width = 7, 6, 5
    plus = np.cumsum(rng.uniform(0, 2, (frames, height, width)), axis=0).astype(np.float32)
    minus = np.cumsum(rng.uniform(0, 2, (frames, height, width))[::-1], axis=0)[::-1].astype(np.float32)
    source_angle = rng.uniform(-np.pi, np.pi, (frames, height, width)).astype(np.float32)
    shape = (9, 8)
    frame = rng.integers(-1, frames, shape).astype(np.int32)
    coords = np.stack([rng.uniform(-1, width, shape), rng.uniform(-1, height, shape),
                       rng.uniform(-np.pi, np.pi, shape)], axis=2).astype(np.float32)
    motion = rng.uniform(0, 6, shape).astype(np.float32)
    target_angle = rng.uniform(-np.pi, np.pi, shape).astype(np.float32)
    shifted, achieved = shift_nnf(NNF(frame, coords), target_motion=motion, target_angle=target_angle,
                        source_ext_plus=plus, source_ext_minus=np.ascontiguousarray(minus), source_angle=source_angle)
    expected = naive_shift_frames(frame, coords, motion, target_angle, plus, minus, source_angle)
    np.testing.assert_array_equal(shifted.frame, expected)


def test_modulation_is_one_when_distances_agree_and_zero_outside_the_previous_mask():
    source_dist = np.array([[[0.0, 5.0, 10.0, 3.0]]], np.float32)
    nnf = NNF(np.zeros((1, 4), np.int32), np.array([[[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0]]], np.float32))
    target_dist = np.array([[0.5, 5.0, 4.0, 3.0]], np.float32)
    previous = np.array([[True, True, True, False]])
    m = temporal_modulation(nnf, target_dist=target_dist, source_dist=source_dist, previous_mask=previous,
                            lower=1.0, upper=4.0)
    np.testing.assert_allclose(m, [[1.0, 1.0, 0.0, 0.0]])
    halfway = temporal_modulation(nnf, target_dist=np.array([[2.5, 5, 10, 3]], np.float32), source_dist=source_dist,
                                  previous_mask=previous, lower=1.0, upper=4.0)
    assert halfway[0, 0] == pytest.approx(0.5)


def test_bad_shapes_are_refused():
    plus, minus, angle = _ramp_source()
    with pytest.raises(ValueError):
        shift_nnf(_single(0, 0, 0, 0), target_motion=np.zeros((2, 2), np.float32), target_angle=np.zeros((1, 1), np.float32),
                  source_ext_plus=plus, source_ext_minus=minus, source_angle=angle)


def _identity_field(height, width, frame=2):
    """Every target pixel matched to the same source pixel, unturned."""
    ys, xs = np.mgrid[0:height, 0:width].astype(np.float32)
    return NNF(np.full((height, width), frame, np.int32), np.stack([xs, ys, np.zeros_like(xs)], axis=2))


def test_transport_carries_matches_along_a_rigid_turn_and_turns_them_with_it():
    size, omega = 33, math.radians(3.0)
    ys, xs = np.mgrid[0:size, 0:size].astype(np.float64)
    flow = turn_flow(size, 3.0)  # about (16, 16)
    before_x, before_y = xs - flow[..., 0], ys - flow[..., 1]  # where each point was a frame ago
    carried, origin = transport_nnf(_identity_field(size, size), flow)
    inner = slice(2, -2)
    np.testing.assert_allclose(carried.coords[inner, inner, 0], before_x[inner, inner], atol=1e-4)
    np.testing.assert_allclose(carried.coords[inner, inner, 1], before_y[inner, inner], atol=1e-4)
    np.testing.assert_allclose(carried.coords[inner, inner, 2], -omega, atol=1e-4)  # a vote turns it back by ω
    came_in = (np.floor(before_x + 0.5) >= 0) & (np.floor(before_x + 0.5) < size) & \
        (np.floor(before_y + 0.5) >= 0) & (np.floor(before_y + 0.5) < size)
    np.testing.assert_array_equal(carried.frame, np.where(came_in, 2, -1))  # the corners came from outside
    np.testing.assert_array_equal(origin, np.where(came_in, np.floor(before_y + 0.5) * size + np.floor(before_x + 0.5),
                                                   -1))


def test_transport_leaves_unmatched_what_came_from_outside_or_from_no_match():
    field = _identity_field(6, 8)
    field.frame[:, 0] = -1
    flow = np.zeros((6, 8, 2), np.float32)
    flow[..., 0] = 1.0  # everything moved one pixel right: column 0 came from outside, column 1 from no match
    carried, origin = transport_nnf(field, flow)
    assert np.all(carried.frame[:, :2] == -1) and np.all(origin[:, :2] == -1)
    np.testing.assert_array_equal(carried.coords[:, 2:, 0], field.coords[:, 1:-1, 0])
    with pytest.raises(ValueError, match="flow must have shape"):
        transport_nnf(field, flow[:, :4])
