import numba
import numpy as np
import pytest
from scipy.ndimage import gaussian_filter

from fluidymation.engine.nnf import NNF
from fluidymation.engine.synthesis import (
    SynthesisInputs, SynthesisParams, TargetInputs, prepare_source, synthesize, synthesize_prepared,
)


def texture(shape, seed, sigma=1.5):
    image = gaussian_filter(np.random.default_rng(seed).random(shape), (sigma, sigma, 0))
    return ((image - image.min()) / (image.max() - image.min())).astype(np.float32)


def position_guides(height, width):
    ys, xs = np.mgrid[0:height, 0:width]
    return np.stack([xs / width, ys / height], axis=2).astype(np.float32)


def psnr(a, b):
    return 10 * np.log10(1.0 / np.mean((a.astype(np.float64) - b) ** 2))


def identity_inputs(height=40, width=48, **extra):
    colour = texture((height, width, 3), 0)
    guides = position_guides(height, width)
    return colour, SynthesisInputs(
        source_colour=colour[None], source_guides=guides[None], target_guides=guides,
        colour_weights=np.full(3, 1 / 3), guide_weights=np.full(2, 4.0), **extra,
    )


def test_equal_guides_reproduce_the_source():
    colour, inputs = identity_inputs()
    result = synthesize(inputs, SynthesisParams(seed=1, search_vote_iters=(3,), patchmatch_iters=(3,)))
    assert result.image.shape == colour.shape and result.image.dtype == np.float32
    assert psnr(result.image, colour) >= 40
    assert result.mean_error() < 1e-4
    assert result.nnf.frame.dtype == np.int32 and result.nnf.coords.shape == (40, 48, 3)


def test_flow_rotation_reproduces_a_rotated_source():
    colour = texture((32, 40, 3), 2)
    guides = position_guides(32, 40)
    target_colour = np.rot90(colour).copy()  # a quarter turn
    inputs = SynthesisInputs(
        source_colour=colour[None], source_guides=guides[None], target_guides=np.rot90(guides).copy(),
        colour_weights=np.full(3, 1 / 3), guide_weights=np.full(2, 4.0),
        source_angle=np.zeros((1, 32, 40), np.float32), target_angle=np.full((40, 32), np.pi / 2, np.float32),
    )
    rotated = synthesize(inputs, SynthesisParams(seed=0, rotation="flow", search_vote_iters=(3,), patchmatch_iters=(3,)))
    assert psnr(rotated.image, target_colour) >= 35
    thetas = np.mod(rotated.nnf.coords[..., 2], 2 * np.pi)
    assert np.mean(np.isclose(thetas, np.pi / 2, atol=1e-3) | np.isclose(thetas, 3 * np.pi / 2, atol=1e-3)) > 0.99


def _stripe_direction(image):
    """The direction (degrees in (−90, 90]) the image's stripes run along: across its mean structure tensor's gradient."""
    gy, gx = np.gradient(image)
    jxx, jyy, jxy = (gx * gx).mean(), (gy * gy).mean(), (gx * gy).mean()
    return (np.degrees(0.5 * np.arctan2(2 * jxy, jxx - jyy)) + 180.0) % 180.0 - 90.0


@pytest.mark.parametrize("source_degrees, target_degrees", [(0, 45), (30, 80), (-20, 35)])
def test_flow_rotation_lays_the_source_flow_along_the_targets(source_degrees, target_degrees):
    """Stripes along the source flow come out along the target flow at oblique angles too (a quarter turn cannot
    tell an alignment from a mirroring about the source flow)."""
    ys, xs = np.mgrid[0:64, 0:64]
    along = np.radians(source_degrees)
    stripes = 0.5 + 0.5 * np.sin(2 * np.pi * (np.cos(along) * ys - np.sin(along) * xs) / 8)
    inputs = SynthesisInputs(
        source_colour=np.repeat(stripes[None, ..., None], 3, axis=3).astype(np.float32),
        source_guides=np.zeros((1, 64, 64, 1), np.float32), target_guides=np.zeros((48, 48, 1), np.float32),
        colour_weights=np.ones(3, np.float32), guide_weights=np.zeros(1, np.float32),
        source_angle=np.full((1, 64, 64), along, np.float32),
        target_angle=np.full((48, 48), np.radians(target_degrees), np.float32))
    result = synthesize(inputs, SynthesisParams(seed=1, rotation="flow", search_vote_iters=(4,), patchmatch_iters=(4,)))
    assert abs(_stripe_direction(stripes) - source_degrees) < 3.0  # the estimate itself
    turn = np.mod(np.degrees(result.nnf.coords[..., 2]) - (source_degrees - target_degrees), 180.0)
    assert np.all(np.isclose(turn, 0.0, atol=1e-3) | np.isclose(turn, 180.0, atol=1e-3))  # θ = θ_S − θ_T (+ π)
    # the patches' seams bend the stripes a little; a mirroring would put them 70–110° off
    assert abs(_stripe_direction(result.image[6:-6, 6:-6, 0]) - target_degrees) < 10.0


def test_uniformity_uses_more_of_the_source():
    # every target pixel asks for the same guide value, so without uniformity a few
    # source patches around x = 20 get used over and over (wash-out)
    source = texture((40, 40, 3), 4, sigma=1.0)
    inputs = SynthesisInputs(
        source_colour=source[None], source_guides=position_guides(40, 40)[None, :, :, :1],
        target_guides=np.full((40, 40, 1), 0.5, np.float32), colour_weights=np.full(3, 1 / 3),
        guide_weights=np.ones(1),
    )

    def share(weight):
        result = synthesize(inputs, SynthesisParams(seed=2, uniformity_weight=weight, search_vote_iters=(3,)))
        used = {(f, int(x), int(y)) for f, (x, y, _) in zip(result.nnf.frame.ravel(), result.nnf.coords.reshape(-1, 3))}
        return len(used) / source.shape[0] / source.shape[1]

    without, with_uniformity = share(0.0), share(0.01)
    assert with_uniformity > 2 * without


def full_featured_inputs():
    """A two-frame source with segments, angles, a weight map and an initial field."""
    rng = np.random.default_rng(5)
    colour = np.stack([texture((30, 34, 3), 6), texture((30, 34, 3), 7)])
    guides = np.concatenate([colour[..., :1], rng.random((2, 30, 34, 2)).astype(np.float32)], axis=3)
    segments = np.zeros((2, 30, 34), np.int32)
    segments[:, :, 17:] = 1
    target_segment = np.zeros((28, 26), np.int32)
    target_segment[14:] = 1
    target_segment[:3, :3] = -1
    initial = NNF(np.ones((28, 26), np.int32), np.zeros((28, 26, 3), np.float32))
    initial.coords[..., 0] = 20
    initial.coords[..., 1] = 5
    return SynthesisInputs(
        source_colour=colour, source_guides=guides, target_guides=rng.random((28, 26, 3)).astype(np.float32),
        colour_weights=np.ones(3), guide_weights=np.array([1.0, 0.5, 0.5]),
        weight_maps=rng.random((1, 28, 26)).astype(np.float32), guide_weight_map=np.array([0, -1, -1]),
        opposite_guide=np.array([0, 2, 1]),
        source_angle=rng.uniform(-3, 3, (2, 30, 34)).astype(np.float32),
        target_angle=rng.uniform(-3, 3, (28, 26)).astype(np.float32),
        source_segment=segments, target_segment=target_segment, initial_nnf=initial,
    )


FULL_PARAMS = SynthesisParams(
    seed=4, rotation="flow", uniformity_weight=0.3, uniformity_radius=1, orientation_weight=0.1,
    guided_initialization=True, search_vote_iters=(2, 1), patchmatch_iters=(3, 2), tile_rows=4,
)


def test_same_bytes_for_one_and_two_threads():
    inputs = full_featured_inputs()
    results = []
    previous = numba.get_num_threads()
    try:
        for threads in (1, min(2, numba.config.NUMBA_NUM_THREADS)):
            numba.set_num_threads(threads)
            results.append(synthesize(inputs, FULL_PARAMS))
    finally:
        numba.set_num_threads(previous)
    one, two = results
    assert one.image.tobytes() == two.image.tobytes()
    assert one.nnf.frame.tobytes() == two.nnf.frame.tobytes()
    assert one.nnf.coords.tobytes() == two.nnf.coords.tobytes()
    again = synthesize(inputs, FULL_PARAMS)
    assert again.image.tobytes() == one.image.tobytes()
    other_seed = synthesize(inputs, SynthesisParams(**{**FULL_PARAMS.__dict__, "seed": 5}))
    assert other_seed.image.tobytes() != one.image.tobytes()


def test_segments_are_respected_and_unsynthesized_pixels_have_no_match():
    inputs = full_featured_inputs()
    result = synthesize(inputs, FULL_PARAMS)
    assert np.all(result.nnf.frame[:3, :3] == -1)
    assert np.all(np.isinf(result.error[:3, :3]))
    active = inputs.target_segment >= 0
    frames = result.nnf.frame[active]
    xs = (result.nnf.coords[..., 0][active] + 0.5).astype(int)
    ys = (result.nnf.coords[..., 1][active] + 0.5).astype(int)
    np.testing.assert_array_equal(inputs.source_segment[frames, ys, xs], inputs.target_segment[active])


def test_vote_only_finest_level_keeps_the_upscaled_field():
    source = texture((40, 40, 3), 8)
    inputs = SynthesisInputs(
        source_colour=source[None], source_guides=position_guides(40, 40)[None, :, :, :1],
        target_guides=np.full((40, 40, 1), 0.5, np.float32), colour_weights=np.full(3, 1 / 3),
        guide_weights=np.ones(1),
    )

    def upscaled_share(vote_only):
        params = SynthesisParams(seed=1, search_vote_iters=(2,), patchmatch_iters=(2,), vote_only_finest=vote_only)
        nnf = synthesize(inputs, params).nnf
        # an unrotated upscaled field maps each 2×2 block to 2·(x', y') + (x̂ mod 2, ŷ mod 2)
        ys, xs = np.mgrid[0:40, 0:40]
        base_x = nnf.coords[..., 0] - xs % 2
        base_y = nnf.coords[..., 1] - ys % 2
        same = np.ones((20, 20), bool)
        for dy in range(2):
            for dx in range(2):
                same &= (base_x[dy::2, dx::2] == base_x[::2, ::2]) & (base_y[dy::2, dx::2] == base_y[::2, ::2])
                same &= nnf.frame[dy::2, dx::2] == nnf.frame[::2, ::2]
        return same.mean()

    assert upscaled_share(True) == 1.0
    assert upscaled_share(False) < 0.9


def test_initial_field_is_used_when_it_is_better():
    colour, inputs = identity_inputs(height=24, width=24)
    ys, xs = np.mgrid[0:24, 0:24]
    identity = NNF(np.zeros((24, 24), np.int32), np.stack([xs, ys, np.zeros_like(xs)], 2).astype(np.float32))
    seeded = SynthesisInputs(**{**inputs.__dict__, "initial_nnf": identity})
    result = synthesize(seeded, SynthesisParams(seed=0, search_vote_iters=(0,), patchmatch_iters=(0,)))
    np.testing.assert_array_equal(result.nnf.coords, identity.coords)


def prepared_and_target(inputs, params, guide_range=None):
    source = prepare_source(
        inputs.source_colour, inputs.source_guides, guide_weight_map=inputs.guide_weight_map,
        opposite_guide=inputs.opposite_guide, source_angle=inputs.source_angle, source_segment=inputs.source_segment,
        guide_range=guide_range, params=params,
    )
    target = TargetInputs(
        target_guides=inputs.target_guides, colour_weights=inputs.colour_weights, guide_weights=inputs.guide_weights,
        weight_maps=inputs.weight_maps, target_angle=inputs.target_angle, target_segment=inputs.target_segment,
        initial_nnf=inputs.initial_nnf,
    )
    return source, target


def test_a_prepared_source_gives_the_same_result_over_the_same_ranges():
    # one level: synthesize quantizes over the source's and this target's ranges, which the prepared source is given
    inputs = full_featured_inputs()
    params = SynthesisParams(**{**FULL_PARAMS.__dict__, "pyramid_levels": 1})
    guides = inputs.target_guides.reshape(-1, 3)
    source, target = prepared_and_target(inputs, params, guide_range=(guides.min(axis=0), guides.max(axis=0)))
    expected = synthesize(inputs, params)
    for _ in range(2):  # the prepared source is not consumed
        result = synthesize_prepared(source, target, params)
        assert result.image.tobytes() == expected.image.tobytes()
        assert result.nnf.coords.tobytes() == expected.nnf.coords.tobytes()
        assert result.error.tobytes() == expected.error.tobytes()


def test_a_prepared_source_serves_targets_of_other_sizes_and_refuses_too_few_levels():
    inputs = full_featured_inputs()
    source, target = prepared_and_target(inputs, FULL_PARAMS)
    assert len(source.levels) == 2  # 30×34 px with 5 px patches
    smaller = TargetInputs(**{**target.__dict__, "target_guides": inputs.target_guides[:20, :22],
                              "weight_maps": inputs.weight_maps[:, :20, :22], "target_angle": inputs.target_angle[:20, :22],
                              "target_segment": inputs.target_segment[:20, :22], "initial_nnf": None})
    result = synthesize_prepared(source, smaller, FULL_PARAMS)
    assert result.image.shape == (20, 22, 3) and (result.nnf.frame[3:, 3:] >= 0).all()
    one_level, _ = prepared_and_target(inputs, SynthesisParams(pyramid_levels=1))
    with pytest.raises(ValueError, match="prepared with 1 levels"):
        synthesize_prepared(one_level, target, FULL_PARAMS)


@pytest.mark.parametrize("bad", [dict(patch_size=4), dict(alpha=1.0), dict(rotation="spin"), dict(search_vote_iters=())])
def test_bad_params_are_rejected(bad):
    with pytest.raises(ValueError):
        SynthesisParams(**bad)
