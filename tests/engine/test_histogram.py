"""Histogram matching of a vote to the distribution of the source frames its matches use."""

import numpy as np
import pytest

from fluidymation.engine.histogram import QUANTILES, join_tables, match_histograms, quantile_tables
from tests.naive import naive_match_histograms


def _source():
    """Two 8×8 frames: frame 0 uniform over [0, 1), frame 1 uniform over [2, 3); label 0 left half, 1 right."""
    ramp = ((np.arange(64) + 0.5) / 64).reshape(8, 8).astype(np.float32)
    colour = np.stack([ramp, ramp + 2])[..., None]
    segment = np.zeros((2, 8, 8), np.int32)
    segment[:, :, 4:] = 1
    return colour, segment


def test_quantile_tables_per_frame_and_label():
    colour, segment = _source()
    segment[1, :, 4:] = -1  # frame 1 has no label-1 pixel
    tables = quantile_tables(colour, segment, labels=2)
    assert tables.shape == (2, 2, 1, QUANTILES)
    left = colour[0][:, :4, 0]
    np.testing.assert_allclose(tables[0, 0, 0, [0, -1]], np.quantile(left, [0.5 / QUANTILES, 1 - 0.5 / QUANTILES]),
                               rtol=1e-6)
    assert np.isnan(tables[1, 1]).all() and not np.isnan(tables[1, 0]).any()


def test_values_are_ranked_onto_the_used_frames_distribution():
    colour, segment = _source()
    tables = quantile_tables(colour, np.zeros_like(segment), labels=1)
    # a washed-out vote: 100 values squeezed into [0.45, 0.55], all matched in frame 0
    vote = np.linspace(0.45, 0.55, 100, dtype=np.float32).reshape(10, 10, 1)
    frames = np.zeros((10, 10), np.int32)
    out = match_histograms(vote, frames, np.zeros((10, 10), np.int32), tables, strength=1.0)
    flat = out.ravel()
    assert np.all(np.diff(flat) > 0)  # the order is kept
    # spread over frame 0's [0, 1); the tails stop at the outer kept quantiles (1/128 from the ends)
    np.testing.assert_allclose(flat[[0, 49, 99]], [0.005, 0.495, 0.995], atol=0.012)
    half = match_histograms(vote, frames, np.zeros((10, 10), np.int32), tables, strength=0.5)
    np.testing.assert_allclose(half, 0.5 * (vote + out), atol=1e-6)
    np.testing.assert_array_equal(match_histograms(vote, frames, np.zeros((10, 10), np.int32), tables, 0.0), vote)


def test_frames_weighted_by_their_matches_and_unmatched_pixels_kept():
    colour, segment = _source()
    tables = quantile_tables(colour, np.zeros_like(segment), labels=1)
    vote = np.arange(16, dtype=np.float32).reshape(4, 4, 1)
    frames = np.full((4, 4), 1, np.int32)
    frames[0, :3] = 0  # 3 matches in frame 0, 12 in frame 1, one unmatched pixel
    frames[0, 3] = -1
    out = match_histograms(vote, frames, np.zeros((4, 4), np.int32), tables, strength=1.0)
    assert out[0, 3, 0] == vote[0, 3, 0]
    matched = np.sort(out[frames >= 0, 0])
    # the mixture is 1/5 frame 0 ([0, 1)) and 4/5 frame 1 ([2, 3)): the 3 lowest ranks fall in frame 0's range
    assert np.all(matched[:3] < 1.0) and np.all(matched[3:] >= 2.0)


def test_each_segment_matched_on_its_own():
    colour, segment = _source()
    colour[:, :, 4:] += 10  # label 1 lives around 10..13
    tables = quantile_tables(colour, segment, labels=2)
    vote = np.array([[0, 1], [0, 1]], np.float32)[..., None]
    target_segment = np.array([[0, 0], [1, 1]], np.int32)
    out = match_histograms(vote, np.zeros((2, 2), np.int32), target_segment, tables, strength=1.0)
    assert np.all(out[0] < 1.0) and np.all((out[1] >= 10.0) & (out[1] < 11.0))


def test_blended_segments_take_the_weighted_mean_of_both_remappings():
    colour, segment = _source()
    colour[:, :, 4:] += 10
    tables = quantile_tables(colour, segment, labels=2)
    vote = np.array([[0, 1, 2, 3, 0, 1, 2, 3]], np.float32)[..., None]  # the same votes in both segments
    target_segment = np.array([[0, 0, 0, 0, 1, 1, 1, 1]], np.int32)
    frames = np.zeros((1, 8), np.int32)
    own = match_histograms(vote, frames, target_segment, tables, strength=1.0)
    one_hot = np.stack([target_segment == 0, target_segment == 1]).astype(np.float32)
    np.testing.assert_array_equal(match_histograms(vote, frames, target_segment, tables, 1.0, blend=one_hot), own)
    interior_weight = np.array([[0.0, 0.25, 0.5, 1.0, 0.0, 0.25, 0.5, 1.0]], np.float32)
    blended = match_histograms(vote, frames, target_segment, tables, 1.0,
                               blend=np.stack([1 - interior_weight, interior_weight]))
    # a vote v remaps to R0(v) in segment 0 and R1(v) in segment 1 (both read off ``own``)
    expected = (1 - interior_weight) * own[0, :4, 0][[0, 1, 2, 3, 0, 1, 2, 3]] \
        + interior_weight * own[0, 4:, 0][[0, 1, 2, 3, 0, 1, 2, 3]]
    np.testing.assert_allclose(blended[..., 0], expected, rtol=1e-6)


def test_tables_of_frame_ranges_join_into_the_whole():
    colour, segment = _source()
    whole = quantile_tables(colour, segment, labels=2)
    first = quantile_tables(colour[:1], segment[:1], labels=2)
    segment[1] = 0  # the second part has only label 0
    second = quantile_tables(colour[1:], segment[1:], labels=1)
    joined = join_tables([first, second])
    assert joined.shape == whole.shape
    np.testing.assert_array_equal(joined[0], whole[0])
    assert np.isnan(joined[1, 1]).all()


@pytest.mark.parametrize("seed", range(6))
def test_matches_the_naive_remapping(seed):
    """Random votes (distinct beyond 1/65 535 of their range, so the 16-bit ranking is exact), up to three
    segments, unmatched pixels, frames lacking a label, with and without a blend."""
    rng = np.random.default_rng(seed)
    height, width, labels, frames = 7, 9, 1 + seed % 3, 1 + seed % 4
    vote = (rng.permutation(height * width * 3) / (height * width * 3)).astype(np.float32).reshape(height, width, 3)
    nnf_frame = rng.integers(-1, frames, (height, width)).astype(np.int32)
    target_segment = rng.integers(-1, labels, (height, width)).astype(np.int32)
    source_segment = rng.integers(0, labels, (frames, 6, 6))
    source_segment[0] = 0
    tables = quantile_tables(rng.random((frames, 6, 6, 3), dtype=np.float32), source_segment, labels)
    blend = None if seed % 2 else rng.random((labels, height, width)).astype(np.float32)
    out = match_histograms(vote, nnf_frame, target_segment, tables, 0.75, blend)
    expected = naive_match_histograms(vote, nnf_frame, target_segment, tables, 0.75, blend)
    np.testing.assert_allclose(out, expected, atol=2e-6)
