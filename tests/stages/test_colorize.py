import numpy as np
import pytest

from fluidymation.errors import StageError
from fluidymation.stages import colorize as cz
from fluidymation.stages.colour import linear_to_srgb, parse_hex, srgb_to_lab, srgb_to_linear
from fluidymation.stages.composite import composite

PAPER = np.array([0.95, 0.92, 0.85], np.float32)
#: Optical density per channel of the synthetic paint at density 1 (a blue pigment).
PAINT = np.array([1.5, 0.9, 0.3], np.float32)


def _exemplar(frames=3, size=48, radius=14, noise=0.01, seed=0):
    """Paper with ±``noise`` grain around a disk of paint of exactly density 1 (``PAINT``) on
    the clean paper colour; segment -1 outside, 0 at the disk's border, 1 inside."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[:size, :size]
    distance = np.hypot(yy - size / 2, xx - size / 2)
    paper = srgb_to_linear(PAPER) * (1.0 + noise * rng.uniform(-1, 1, (frames, size, size, 1)))
    painted = distance < radius
    linear = np.where(painted[None, :, :, None], srgb_to_linear(PAPER) * np.exp(-PAINT), paper)
    segment = np.where(distance < radius - 2, 1, np.where(painted, 0, -1)).astype(np.int32)
    return linear_to_srgb(np.clip(linear, 0, 1)), np.broadcast_to(segment, (frames, size, size)).copy(), painted


def _over_white(rgba):
    return composite(np.ones(rgba.shape[:2] + (3,), np.float32), [(rgba, "multiply", 1.0)])


def _frame(srgb):
    """An opaque stylized frame from (H, W, 3) sRGB pixels."""
    return np.concatenate([srgb, np.ones(srgb.shape[:2] + (1,), np.float32)], axis=2)


def _with_density(density, paper=PAPER, hue=PAINT):
    """sRGB pixels of the given mean optical densities (relative to ``paper``), shape (1, N, 3)."""
    scale = np.asarray(density, np.float32)[:, None] / hue.mean()
    return linear_to_srgb(srgb_to_linear(paper) * np.exp(-hue * scale))[None]


def test_estimate_paper_is_the_median_of_the_unpainted_pixels():
    rgb, segment, _ = _exemplar()
    np.testing.assert_allclose(cz.estimate_paper(rgb, segment), PAPER, atol=0.003)


def test_estimate_paper_falls_back_to_the_brightest_pixels_when_almost_all_is_painted():
    rgb, segment, _ = _exemplar()
    everything_painted = np.zeros_like(segment)
    estimate = cz.estimate_paper(rgb, everything_painted)
    np.testing.assert_allclose(estimate, PAPER, atol=0.01)
    assert srgb_to_linear(estimate).mean() >= srgb_to_linear(PAPER).mean()


def test_full_density_is_the_median_paint_density():
    rgb, segment, _ = _exemplar()
    paper = cz.estimate_paper(rgb, segment)
    assert cz.full_density(rgb, segment, paper) == pytest.approx(PAINT.mean(), rel=0.02)


@pytest.mark.parametrize("colour", ["#2a6fdb", "#d94f30", "#1b7f3a", "#1a1a1a", "#ffcc00"])
def test_density_one_reproduces_the_layer_colour_on_white(colour):
    rgb, segment, painted = _exemplar()
    paper = cz.estimate_paper(rgb, segment)
    unit = cz.full_density(rgb, segment, paper)
    out = cz.colorize(_frame(rgb[1]), paper, unit, cz.Params(color=colour))
    assert out.shape == (48, 48, 4) and out.dtype == np.float32
    shown = _over_white(out)[painted]
    delta_e = np.linalg.norm(srgb_to_lab(shown) - srgb_to_lab(parse_hex(colour)), axis=-1)
    assert delta_e.max() <= 5.0
    over = composite(np.ones((48, 48, 3), np.float32), [(out, "over", 1.0)])
    np.testing.assert_allclose(over, _over_white(out), atol=1e-5)


def test_paper_is_transparent_and_lighter_densities_are_beer_lambert():
    paper = PAPER
    pixels = _frame(_with_density([0.0, 0.3, 0.6]))
    pixels[0, 0, :3] = paper
    out = cz.colorize(pixels, paper, 0.6, cz.Params(color="#2a6fdb"))
    colour = srgb_to_linear(parse_hex("#2a6fdb"))
    np.testing.assert_allclose(out[0, :, 3], [0.0, max(0.5, 1 - (colour**0.5).min()), 1.0], atol=1e-4)
    shown = srgb_to_linear(_over_white(out))[0]
    np.testing.assert_allclose(shown[0], 1.0, atol=1e-6)
    np.testing.assert_allclose(shown[1], colour**0.5, atol=2e-3)
    np.testing.assert_allclose(shown[2], colour, atol=2e-3)
    lighter_than_paper = _frame(np.minimum(paper + 0.03, 1.0)[None, None])
    assert cz.colorize(lighter_than_paper, paper, 0.6, cz.Params(color="#2a6fdb"))[0, 0, 3] == 0.0


def test_alpha_is_coverage_times_glaze():
    pixels = _frame(_with_density([0.6, 0.6]))
    pixels[0, :, 3] = [0.25, 1.0]
    out = cz.colorize(pixels, PAPER, 1.2, cz.Params(color="#d94f30"))
    glaze = max(0.5, 1 - (srgb_to_linear(parse_hex("#d94f30")) ** 0.5).min())
    np.testing.assert_allclose(out[0, :, 3], [0.25 * glaze, glaze], atol=1e-4)


def test_denser_paint_is_darker_beer_lambert():
    out = cz.colorize(_frame(_with_density([0.8, 1.6, 8.0])), PAPER, 0.8, cz.Params(color="#2a6fdb", max_density=3.0))
    colour = srgb_to_linear(parse_hex("#2a6fdb"))
    shown = srgb_to_linear(_over_white(out))[0]
    np.testing.assert_allclose(shown[0], colour, atol=2e-3)
    np.testing.assert_allclose(shown[1], colour**2, atol=2e-3)
    np.testing.assert_allclose(shown[2], colour**3, atol=2e-3)  # clipped at max_density
    luminance = srgb_to_lab(linear_to_srgb(shown))[:, 0]
    assert luminance[0] > luminance[1] > luminance[2]


def test_mode_none_gives_back_the_paint_without_its_paper():
    rgb, segment, painted = _exemplar()
    paper = cz.estimate_paper(rgb, segment)
    unit = cz.full_density(rgb, segment, paper)
    frame = _frame(np.concatenate([rgb[0], _with_density(np.full(48, 0.5 * unit))], axis=0))
    out = cz.colorize(frame, paper, unit, cz.Params(mode="none"))
    shown = srgb_to_linear(_over_white(out))
    transmittance = srgb_to_linear(frame[:, :, :3]) / srgb_to_linear(paper)
    np.testing.assert_allclose(shown[:48][painted], transmittance[:48][painted], atol=2e-3)
    np.testing.assert_allclose(shown[48], transmittance[48], atol=2e-3)  # a glaze (ρ = 0.5)
    assert out[:48, :, 3][~painted].max() < 0.015  # ±1 % paper grain stays (nearly) transparent
    # the paint's own hue (as on white paper), not the hue it has on the exemplar's cream paper
    lab_paint, lab_out = srgb_to_lab(linear_to_srgb(np.exp(-PAINT))), srgb_to_lab(linear_to_srgb(shown[:48][painted]))
    hue_paint, hue_out = (np.degrees(np.arctan2(lab[..., 2], lab[..., 1])) for lab in (lab_paint, lab_out))
    assert np.abs(hue_out - hue_paint).max() < 1.0


def test_params_validation():
    assert cz.Params(color="#ff0000").color == (1.0, 0.0, 0.0)
    assert cz.Params(color=[0.5, 0.25, 1]).color == (0.5, 0.25, 1.0)
    assert cz.Params(mode="none").color is None
    with pytest.raises(StageError, match="mode must be one of layer, none"):
        cz.Params(mode="tint", color="#ff0000")
    with pytest.raises(StageError, match='mode "layer" needs a colour'):
        cz.Params()
    with pytest.raises(StageError, match="#rrggbb"):
        cz.Params(color="red")
    with pytest.raises(StageError, match="three sRGB values"):
        cz.Params(color=(1.0, 2.0, 0.0))
    with pytest.raises(StageError, match="max_density must be a number ≥ 1"):
        cz.Params(color="#ff0000", max_density=0.5)


def test_bad_inputs_raise_stage_error():
    params = cz.Params(color="#ff0000")
    with pytest.raises(StageError, match=r"\(H, W, 4\)"):
        cz.colorize(np.ones((4, 4, 3), np.float32), PAPER, 1.0, params)
    with pytest.raises(StageError, match="density_unit"):
        cz.colorize(np.ones((4, 4, 4), np.float32), PAPER, 0.0, params)
    rgb, segment, _ = _exemplar(frames=1)
    with pytest.raises(StageError, match="no painted pixels"):
        cz.full_density(rgb, np.full_like(segment, -1), PAPER)
    with pytest.raises(StageError, match="not darker than its paper"):
        cz.full_density(np.ones_like(rgb), segment, PAPER)
