"""Colour helpers shared by the stages: sRGB transfer curves, ``#rrggbb`` colours, CIELAB.

The sRGB curves are the exact piecewise ones of IEC 61966-2-1; they live in
:mod:`fluidymation.engine.watercolor` (the Kubelka–Munk renderer works in linear light)
and are re-exported here so that stages import every colour helper from one place.
CIELAB uses the D65 white of sRGB, so that sRGB white maps to L* = 100, a* = b* = 0.
"""

from __future__ import annotations

import re

import numpy as np

from fluidymation.engine.watercolor import linear_to_srgb, srgb_to_linear

__all__ = ["as_srgb", "linear_to_srgb", "parse_hex", "srgb_to_lab", "srgb_to_linear"]

_HEX = re.compile(r"^#[0-9a-fA-F]{6}$")

#: Linear sRGB to CIE XYZ (D65), IEC 61966-2-1.
_RGB_TO_XYZ = np.array([
    [0.4124, 0.3576, 0.1805],
    [0.2126, 0.7152, 0.0722],
    [0.0193, 0.1192, 0.9505],
])
_WHITE = _RGB_TO_XYZ.sum(axis=1)


def parse_hex(colour: str) -> np.ndarray:
    """``"#rrggbb"`` to a (3,) float32 sRGB colour in [0, 1]."""
    if not isinstance(colour, str) or not _HEX.match(colour):
        raise ValueError(f"a colour must look like #rrggbb, got {colour!r}")
    return np.array([int(colour[i : i + 2], 16) for i in (1, 3, 5)], dtype=np.float32) / np.float32(255.0)


def as_srgb(colour) -> np.ndarray:
    """A ``"#rrggbb"`` string or three numbers in [0, 1] as a (3,) float32 sRGB colour."""
    if isinstance(colour, str):
        return parse_hex(colour)
    try:
        values = np.asarray(colour, dtype=np.float32)
    except (TypeError, ValueError):
        values = None
    if values is None or values.shape != (3,) or not np.all((values >= 0.0) & (values <= 1.0)):
        raise ValueError(f"a colour must be #rrggbb or three sRGB values in [0, 1], got {colour!r}")
    return values


def srgb_to_lab(rgb) -> np.ndarray:
    """sRGB values in [0, 1], shape (..., 3), to CIELAB (L*, a*, b*), D65, float32."""
    xyz = srgb_to_linear(rgb).astype(np.float64) @ _RGB_TO_XYZ.T / _WHITE
    edge = (6.0 / 29.0) ** 3
    f = np.where(xyz > edge, np.cbrt(xyz), xyz / (3.0 * (6.0 / 29.0) ** 2) + 4.0 / 29.0)
    lab = np.stack([116.0 * f[..., 1] - 16.0, 500.0 * (f[..., 0] - f[..., 1]), 200.0 * (f[..., 1] - f[..., 2])], axis=-1)
    return lab.astype(np.float32)
