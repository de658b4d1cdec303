import math

import numpy as np
import pytest

from fluidymation.engine.vector_motion import (
    Clip, ClipPart, MovingElement, affine_fit, coverage, stroke_rings, vector_flow,
)
from tests.naive import naive_inside


def _circle(centre, radius, points=256):
    angles = np.arange(points) * (2 * math.pi / points)
    return np.column_stack([centre[0] + radius * np.cos(angles), centre[1] + radius * np.sin(angles)])


def _turned(points, centre, angle):
    c, s = math.cos(angle), math.sin(angle)
    offset = points - centre
    return np.column_stack([c * offset[:, 0] - s * offset[:, 1], s * offset[:, 0] + c * offset[:, 1]]) + centre


def _element(now, before, *rings):
    starts = np.cumsum([0] + [len(ring) for ring in rings]) if rings else [0, len(now)]
    return MovingElement(now=now, before=before, ring_starts=starts)


def test_coverage_matches_the_winding_number_of_every_pixel_centre():
    star = [(20.0, 2.0), (26.0, 36.0), (3.0, 14.0), (37.0, 14.0), (14.0, 36.0)]  # self-crossing
    hole = [(18.0, 16.0), (18.0, 20.0), (22.0, 20.0), (22.0, 16.0)]  # clockwise in the image
    points = np.array(star + hole, np.float32)
    for even_odd in (False, True):
        element = MovingElement(now=points, before=points, ring_starts=[0, 5, 9], even_odd=even_odd)
        got = coverage(element, (40, 41))
        expected = np.array([[naive_inside([star, hole], x + 0.5, y + 0.5, even_odd) for x in range(41)]
                             for y in range(40)])
        np.testing.assert_array_equal(got, expected)


def test_a_turning_disk_reads_its_tangential_motion_everywhere_inside():
    centre, omega = np.array([32.0, 30.0]), 0.05  # rad/frame; the mask of this disk never changes
    now = _circle(centre, 24.0)
    flow, owned = vector_flow([_element(now, _turned(now, centre, -omega))], (64, 64))
    yy, xx = np.nonzero(owned)
    offset = np.column_stack([xx + 0.5, yy + 0.5]) - centre
    radius = np.hypot(offset[:, 0], offset[:, 1])
    away = radius > 2.0
    speed = np.hypot(*flow[yy, xx].T)
    np.testing.assert_allclose(speed[away], omega * radius[away], rtol=0.05)
    tangent = np.arctan2(offset[:, 0], -offset[:, 1])  # (−y, x): counter-clockwise in x right, y down
    turn = np.angle(np.exp(1j * (np.arctan2(flow[yy, xx, 1], flow[yy, xx, 0]) - tangent)))
    assert np.degrees(np.abs(turn[away])).max() < 5.0
    assert not owned[0, 0] and np.all(flow[~owned] == 0.0)


def test_a_scaling_square_reads_the_analytic_field():
    square = np.array([(10.0, 12.0), (50.0, 12.0), (50.0, 52.0), (10.0, 52.0)])
    centre, growth = np.array([30.0, 32.0]), 1.06
    before = centre + (square - centre) / growth
    flow, owned = vector_flow([_element(square, before)], (64, 64))
    yy, xx = np.nonzero(owned)
    expected = (np.column_stack([xx + 0.5, yy + 0.5]) - centre) * (1.0 - 1.0 / growth)
    np.testing.assert_allclose(flow[yy, xx], expected, atol=1e-4)


def test_a_deforming_outline_is_interpolated_smoothly_inside():
    # a disk whose right half bulges out: no affine motion explains it
    centre = np.array([32.0, 32.0])
    angles = np.arange(256) * (2 * math.pi / 256)
    bulge = 3.0 * np.clip(np.cos(angles), 0.0, None) ** 2
    now = _circle(centre, 20.0) + np.column_stack([np.cos(angles), np.sin(angles)]) * bulge[:, None]
    before = _circle(centre, 20.0)
    flow, owned = vector_flow([_element(now, before)], (64, 64))
    assert affine_fit(_element(now, before)).shape == (2, 3)
    # right edge moves out by 3 px, left edge not at all; the interior lies between
    assert flow[32, 53, 0] == pytest.approx(3.0, abs=0.3)
    assert abs(flow[32, 12, 0]) < 0.3
    assert 0.3 < flow[32, 32, 0] < 2.7
    gradient = np.abs(np.diff(flow[owned.nonzero()[0].min():owned.nonzero()[0].max(), 32, 0]))
    assert gradient.max() < 0.5


def test_the_topmost_element_owns_its_pixels():
    disk = _circle(np.array([20.0, 20.0]), 10.0)
    square = np.array([(15.0, 15.0), (40.0, 15.0), (40.0, 40.0), (15.0, 40.0)])
    below = _element(disk, disk - (1.0, 0.0))
    above = _element(square, square - (0.0, 2.0))
    flow, owned = vector_flow([below, above], (48, 48))
    np.testing.assert_allclose(flow[20, 20], (0.0, 2.0), atol=1e-5)  # under both: the square's
    np.testing.assert_allclose(flow[20, 12], (1.0, 0.0), atol=1e-5)  # the disk alone
    assert owned[20, 12] and owned[30, 30] and not owned[45, 45]


def test_elements_check_their_points():
    with pytest.raises(ValueError, match="ring_starts"):
        MovingElement(now=np.zeros((3, 2)), before=np.zeros((3, 2)), ring_starts=[0, 2])
    with pytest.raises(ValueError, match="both be"):
        MovingElement(now=np.zeros((3, 2)), before=np.zeros((4, 2)), ring_starts=[0, 3])


def _square(x0, y0, x1, y1):
    points = np.array([(x0, y0), (x1, y0), (x1, y1), (x0, y1)], np.float32)
    return MovingElement(now=points, before=points, ring_starts=[0, 4])


@pytest.mark.parametrize("modes, inverted, expected", [
    (("add",), (False,), lambda a, b: a),
    (("add",), (True,), lambda a, b: ~a),
    (("subtract",), (False,), lambda a, b: ~a),
    (("intersect",), (False,), lambda a, b: a),
    (("add", "add"), (False, False), lambda a, b: a | b),
    (("add", "subtract"), (False, False), lambda a, b: a & ~b),
    (("add", "intersect"), (False, True), lambda a, b: a & ~b),
    (("add", "difference"), (False, False), lambda a, b: a ^ b),
    (("subtract", "subtract"), (False, False), lambda a, b: ~a & ~b)])
def test_clips_combine_their_parts_in_order(modes, inverted, expected):
    shape = (20, 20)
    a_element, b_element = _square(2, 2, 12, 12), _square(8, 8, 18, 18)
    a, b = coverage(a_element, shape), coverage(b_element, shape)
    clip = Clip(tuple(ClipPart((element,), mode, flip)
                      for element, mode, flip in zip((a_element, b_element), modes, inverted)))
    np.testing.assert_array_equal(clip.region(shape), expected(a, b))
    whole = _square(0, 0, 20, 20)
    clipped = MovingElement(now=whole.now, before=whole.before, ring_starts=whole.ring_starts, clips=(clip,))
    np.testing.assert_array_equal(coverage(clipped, shape), expected(a, b))
    flow, owned = vector_flow([clipped], shape)
    np.testing.assert_array_equal(owned, expected(a, b))


def test_clip_parts_check_their_mode():
    with pytest.raises(ValueError, match="clip mode"):
        ClipPart((), "multiply")


def _band(rings):
    points = np.concatenate(rings).astype(np.float32)
    return MovingElement(now=points, before=points, ring_starts=np.cumsum([0] + [len(ring) for ring in rings]))


def test_a_stroke_band_covers_what_lies_within_half_its_width():
    line = np.column_stack([np.linspace(4, 36, 17), np.full(17, 20.0)])
    got = coverage(_band(stroke_rings(line, 3.0, closed=False)), (40, 40))
    expected = np.zeros((40, 40), bool)
    expected[17:23, 4:36] = True  # pixel centres within 3 px of y = 20, between the flat ends
    np.testing.assert_array_equal(got, expected)
    centre = np.array([20.0, 20.0])
    ring = _circle(centre, 12.0)
    yy, xx = np.mgrid[:40, :40] + 0.5
    radius = np.hypot(xx - 20, yy - 20)
    got = coverage(_band(stroke_rings(ring, 2.5, closed=True)), (40, 40))
    sure = (radius > 9.7) & (radius < 14.3)
    assert got[sure].all() and not got[(radius < 9.3) | (radius > 14.7)].any()  # the annulus, chords aside
