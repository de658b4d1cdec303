import numpy as np
import pytest

from fluidymation.errors import StageError
from fluidymation.stages.colour import linear_to_srgb, srgb_to_linear
from fluidymation.stages.composite import composite


def _layer(rgb_linear, alpha, shape=(2, 3)):
    rgba = np.empty(shape + (4,), np.float32)
    rgba[..., :3] = linear_to_srgb(np.asarray(rgb_linear, np.float32))
    rgba[..., 3] = alpha
    return rgba


def _background(rgb_linear, shape=(2, 3)):
    return np.broadcast_to(linear_to_srgb(np.asarray(rgb_linear, np.float32)), shape + (3,)).copy()


def test_over_and_multiply_exact_in_linear_light():
    background = _background([0.8, 0.6, 0.4])
    layer = _layer([0.2, 0.5, 1.0], 0.5)
    over = srgb_to_linear(composite(background, [(layer, "over", 1.0)]))
    np.testing.assert_allclose(over, np.broadcast_to([0.5, 0.55, 0.7], over.shape), atol=1e-5)
    multiply = srgb_to_linear(composite(background, [(layer, "multiply", 1.0)]))
    np.testing.assert_allclose(multiply, np.broadcast_to([0.8 * 0.6, 0.6 * 0.75, 0.4], multiply.shape), atol=1e-5)
    assert over.dtype == np.float32 and over.shape == (2, 3, 3)


def test_opacity_scales_alpha():
    background = _background([1.0, 1.0, 1.0])
    layer = _layer([0.0, 0.0, 0.0], 0.8)
    for blend in ("over", "multiply"):
        out = srgb_to_linear(composite(background, [(layer, blend, 0.25)]))
        np.testing.assert_allclose(out, 0.8, atol=1e-5)  # a = 0.8 · 0.25 = 0.2
        full = srgb_to_linear(composite(background, [(layer, blend, 1.0)]))
        np.testing.assert_allclose(full, 0.2, atol=1e-5)


def test_alpha_zero_or_opacity_zero_leaves_the_background():
    rng = np.random.default_rng(0)
    background = rng.random((4, 5, 3)).astype(np.float32)
    visible = np.concatenate([rng.random((4, 5, 3)), np.ones((4, 5, 1))], axis=2).astype(np.float32)
    hidden = visible.copy()
    hidden[..., 3] = 0.0
    layers = [(hidden, "over", 1.0), (hidden, "multiply", 1.0), (visible, "over", 0.0), (visible, "multiply", 0.0)]
    np.testing.assert_allclose(composite(background, layers), background, atol=2e-6)
    np.testing.assert_allclose(composite(background, []), background, atol=2e-6)


def test_order_matters_for_over_not_for_a_multiply_stack():
    rng = np.random.default_rng(1)
    background = rng.random((3, 4, 3)).astype(np.float32)
    first, second = (rng.random((3, 4, 4)).astype(np.float32) for _ in range(2))
    over_ab = composite(background, [(first, "over", 1.0), (second, "over", 0.7)])
    over_ba = composite(background, [(second, "over", 0.7), (first, "over", 1.0)])
    assert np.abs(over_ab - over_ba).max() > 0.05
    multiply_ab = composite(background, [(first, "multiply", 1.0), (second, "multiply", 0.7)])
    multiply_ba = composite(background, [(second, "multiply", 0.7), (first, "multiply", 1.0)])
    np.testing.assert_allclose(multiply_ab, multiply_ba, atol=1e-6)


def test_bad_layers_raise_stage_error():
    background = np.ones((2, 3, 3), np.float32)
    good = np.ones((2, 3, 4), np.float32)
    with pytest.raises(StageError, match="layer 1 has shape"):
        composite(background, [(good, "over", 1.0), (np.ones((3, 2, 4), np.float32), "over", 1.0)])
    with pytest.raises(StageError, match="blend 'screen'"):
        composite(background, [(good, "screen", 1.0)])
    with pytest.raises(StageError, match="opacity"):
        composite(background, [(good, "over", 1.5)])
    with pytest.raises(StageError, match="background"):
        composite(np.ones((2, 3), np.float32), [])
