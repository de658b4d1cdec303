import numpy as np
import pytest

from fluidymation.stages import colour


def test_srgb_curves_are_the_iec_piecewise_ones_and_invert_each_other():
    srgb = np.linspace(0.0, 1.0, 1001, dtype=np.float32)
    linear = colour.srgb_to_linear(srgb)
    expected = np.where(srgb <= 0.04045, srgb / 12.92, ((srgb + 0.055) / 1.055) ** 2.4)
    assert linear.dtype == np.float32
    np.testing.assert_allclose(linear, expected, atol=1e-6)
    np.testing.assert_allclose(colour.linear_to_srgb(linear), srgb, atol=2e-6)
    assert colour.srgb_to_linear(np.float32(0.5)) == pytest.approx(0.2140, abs=1e-4)


def test_parse_hex():
    np.testing.assert_array_equal(colour.parse_hex("#ff8000"), np.array([1.0, 128 / 255, 0.0], np.float32))
    assert colour.parse_hex("#2A6FDB").dtype == np.float32
    for bad in ("ff8000", "#ff80", "#gg0000", 0xFF8000):
        with pytest.raises(ValueError, match="#rrggbb"):
            colour.parse_hex(bad)


def test_as_srgb_takes_hex_or_three_numbers():
    np.testing.assert_array_equal(colour.as_srgb("#000000"), np.zeros(3, np.float32))
    np.testing.assert_array_equal(colour.as_srgb((0.25, 0.5, 1)), np.array([0.25, 0.5, 1.0], np.float32))
    for bad in ((0.1, 0.2), (0.1, 0.2, 1.5), ("a", "b", "c"), None):
        with pytest.raises(ValueError, match="three sRGB values"):
            colour.as_srgb(bad)


def test_srgb_to_lab_reference_values():
    # white, black and sRGB red (CIE 1976, D65; red's published value is 53.24, 80.09, 67.20)
    lab = colour.srgb_to_lab(np.array([[1, 1, 1], [0, 0, 0], [1, 0, 0]], np.float32))
    np.testing.assert_allclose(lab[0], [100, 0, 0], atol=1e-3)
    np.testing.assert_allclose(lab[1], [0, 0, 0], atol=1e-3)
    np.testing.assert_allclose(lab[2], [53.24, 80.09, 67.20], atol=0.1)
    mid_grey = colour.srgb_to_lab(np.full((2, 2, 3), 0.5, np.float32))
    assert mid_grey.shape == (2, 2, 3)
    np.testing.assert_allclose(mid_grey[..., 0], 53.39, atol=0.05)
