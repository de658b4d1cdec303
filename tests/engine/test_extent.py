import sys
from pathlib import Path

import numpy as np
import pytest

from fluidymation.engine import extent

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import naive  # noqa: E402


def _run_passes(flows, masks):
    count = len(flows)
    accumulator = np.zeros(flows[0].shape, dtype=np.float32)
    forward = [extent.accumulate_extent(accumulator, flows[j] if j else np.zeros_like(flows[0]), masks[j]) for j in range(count)]
    accumulator = np.zeros(flows[0].shape, dtype=np.float32)
    backward = [None] * count
    for j in range(count - 1, -1, -1):
        step = flows[j + 1] if j + 1 < count else np.zeros_like(flows[0])
        backward[j] = extent.accumulate_extent(accumulator, step, masks[j])
    return np.array(forward), np.array(backward)


def test_extent_passes_match_the_definition():
    rng = np.random.default_rng(7)
    flows = [rng.normal(size=(6, 8, 2)).astype(np.float32) for _ in range(9)]
    masks = [rng.random((6, 8)) < 0.8 for _ in range(9)]
    forward, backward = _run_passes(flows, masks)
    expected_forward, expected_backward = naive.naive_extent(flows, masks)
    np.testing.assert_allclose(forward, expected_forward, rtol=1e-5, atol=1e-5)
    np.testing.assert_allclose(backward, expected_backward, rtol=1e-5, atol=1e-5)
    assert not forward[0].any() and not backward[-1].any()


def test_accumulation_is_two_dimensional_and_resets_outside_the_mask():
    there = np.full((1, 2, 2), 3.0, dtype=np.float32)
    mask = np.array([[True, False]])
    accumulator = np.zeros((1, 2, 2), dtype=np.float32)
    first = extent.accumulate_extent(accumulator, there, mask)
    assert first[0, 0] == pytest.approx(3.0 * np.sqrt(2)) and first[0, 1] == 0.0
    back = extent.accumulate_extent(accumulator, -there, mask)
    assert back[0, 0] == pytest.approx(0.0)  # moving back undoes the extent
    with pytest.raises(TypeError):
        extent.accumulate_extent(np.zeros((1, 2, 2)), there, mask)


def test_orientation_is_atan2_of_dy_dx():
    field = np.array([[[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -2.0]]], dtype=np.float32)
    np.testing.assert_allclose(extent.orientation(field), [[0.0, np.pi / 2, np.pi, -np.pi / 2]], atol=1e-6)
