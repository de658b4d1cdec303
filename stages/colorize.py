"""The ``colorize`` stage: a stylized layer's paint as pigment density, re-rendered in the layer's colour.

The stylized frame shows the exemplar's paint on the exemplar's paper. Dividing the
paper out (in linear light) gives the paint's transmittance T and its optical density
D = −ln T, averaged over the channels; D divided by the exemplar's typical density (the
median over its painted pixels, "density 1") is the pigment density ρ. Beer–Lambert
then re-renders ρ in the layer colour C (linear c): a layer of density ρ transmits c^ρ,
from 1 (paper, ρ = 0) through exactly C (ρ = 1) to darker than C (ρ > 1: watercolor's
dark rims and pools). Mode ``"none"`` keeps the exemplar's own colours instead: the
transmittance is T itself, the paint without the exemplar's paper, so the scene's
background shows through rather than two papers on top of each other.

The output is a straight-alpha RGBA layer that, composited over white paper in linear
light, gives back that transmittance exactly, and multiplied onto any paper multiplies
by it. Its alpha is min(ρ, 1), raised to 1 − min(transmittance) where a channel is
darker than a glaze of that alpha can reach, so paper (ρ = 0) is transparent.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fluidymation.errors import StageError
from fluidymation.stages.colour import as_srgb, linear_to_srgb, srgb_to_linear

NAME = "colorize"
VERSION = 2

MODES = ("layer", "none")

#: Transmittances are clamped to [_MIN_TRANSMITTANCE, 1] before taking −ln (D ≤ 9.2).
_MIN_TRANSMITTANCE = 1e-4
#: Below this share of unpainted exemplar pixels the paper is taken from the brightest ones.
_MIN_PAPER_SHARE = 0.01
#: Statistics over the exemplar use at most this many pixels (evenly spaced, deterministic).
_MAX_SAMPLES = 1 << 18


@dataclass(frozen=True)
class Params:
    """Parameters of the colorize stage.

    Attributes
    ----------
    mode : {"layer", "none"}
        Re-render in ``color``, or keep the exemplar's colours (paper divided out).
    color : tuple of 3 floats, or str, optional
        The layer colour, sRGB in [0, 1] or ``"#rrggbb"`` (stored as a tuple); required
        by mode "layer", ignored by mode "none".
    max_density : float
        Upper bound of ρ, ≥ 1 (density 1 is exactly ``color``).
    """

    mode: str = "layer"
    color: tuple | None = None
    max_density: float = 3.0

    def __post_init__(self):
        if self.mode not in MODES:
            raise StageError(f"colorize: mode must be one of {', '.join(MODES)}, got {self.mode!r}")
        if self.color is not None:
            try:
                colour = as_srgb(self.color)
            except ValueError as exc:
                raise StageError(f"colorize: {exc}") from None
            object.__setattr__(self, "color", tuple(float(v) for v in colour))
        elif self.mode == "layer":
            raise StageError('colorize: mode "layer" needs a colour (the layer\'s "color" or its vector fill)')
        if not (isinstance(self.max_density, (int, float)) and 1.0 <= self.max_density < np.inf):
            raise StageError(f"colorize: max_density must be a number ≥ 1, got {self.max_density!r}")


def estimate_paper(source_rgb: np.ndarray, source_segment: np.ndarray) -> np.ndarray:
    """The exemplar's paper colour: the per-channel median of its unpainted pixels.

    Parameters
    ----------
    source_rgb : (T, Hs, Ws, 3) float32, sRGB
    source_segment : (T, Hs, Ws) int
        -1 where the exemplar is unpainted.

    Returns
    -------
    (3,) float32 sRGB. If fewer than 1 % of the pixels are unpainted, the per-channel
    median of the pixels at or above the 99th percentile of luminance instead.
    """
    pixels, segment = _flatten(source_rgb, source_segment)
    unpainted = np.flatnonzero(segment == -1)
    if unpainted.size >= _MIN_PAPER_SHARE * segment.size:
        return np.median(pixels[_spread(unpainted)], axis=0).astype(np.float32)
    sample = pixels[_spread(np.arange(segment.size))]
    luminance = srgb_to_linear(sample) @ np.array([0.2126, 0.7152, 0.0722], np.float32)
    brightest = luminance >= np.quantile(luminance, 0.99)
    return np.median(sample[brightest], axis=0).astype(np.float32)


def full_density(source_rgb: np.ndarray, source_segment: np.ndarray, paper) -> float:
    """The exemplar's reference optical density, "density 1".

    The median over the painted pixels (segment ≥ 0) of the channel-mean optical density
    ``D = −ln(lin(pixel) / lin(paper))``, the ratio clamped to [1e-4, 1].

    Raises
    ------
    StageError
        If nothing is painted or the paint is not darker than the paper.
    """
    pixels, segment = _flatten(source_rgb, source_segment)
    painted = np.flatnonzero(segment >= 0)
    if painted.size == 0:
        raise StageError("colorize: the exemplar has no painted pixels to measure its paint density")
    density = float(np.median(_optical_density(pixels[_spread(painted)], paper)))
    if not density > 0.0:
        raise StageError("colorize: the exemplar's paint is not darker than its paper, so its density "
                         "cannot be measured; use colorize: none or another exemplar")
    return density


def colorize(rgba: np.ndarray, paper, density_unit: float, params: Params) -> np.ndarray:
    """Re-render a stylized layer frame as pigment of the layer colour (see the module doc).

    Parameters
    ----------
    rgba : (H, W, 4) float32
        Stylized frame: sRGB paint on the exemplar's paper, alpha = the layer's coverage.
    paper : (3,) float
        The exemplar's paper colour, sRGB (:func:`estimate_paper`).
    density_unit : float
        Optical density of density 1 (:func:`full_density`), > 0.
    params : Params

    Returns
    -------
    (H, W, 4) float32 RGBA, sRGB, straight (non-premultiplied) alpha; the paper is
    transparent.
    """
    rgba = np.asarray(rgba, dtype=np.float32)
    if rgba.ndim != 3 or rgba.shape[2] != 4:
        raise StageError(f"colorize: expected an (H, W, 4) RGBA frame, got shape {rgba.shape}")
    if not (np.isfinite(density_unit) and density_unit > 0):
        raise StageError(f"colorize: density_unit must be a positive number, got {density_unit!r}")
    paper = _paper_colour(paper)
    rgb, coverage = rgba[:, :, :3], rgba[:, :, 3]
    density = np.clip(_optical_density(rgb, paper) / np.float32(density_unit), 0.0, params.max_density)
    if params.mode == "layer":
        transmittance = srgb_to_linear(np.asarray(params.color, dtype=np.float32)) ** density[:, :, None]
    else:
        transmittance = _transmittance(rgb, paper, floor=0.0)
    # alpha min(ρ, 1), raised where a channel is darker than a glaze of that alpha can reach (1 − a)
    glaze = np.maximum(np.minimum(density, 1.0)[:, :, None], 1.0 - transmittance.min(axis=2, keepdims=True))
    with np.errstate(divide="ignore", invalid="ignore"):
        linear = np.where(glaze > 0, np.clip((transmittance - (1.0 - glaze)) / glaze, 0.0, 1.0), 0.0)
    out = np.empty_like(rgba)
    out[:, :, :3] = linear_to_srgb(linear)
    out[:, :, 3] = coverage * glaze[:, :, 0]
    return out


def _optical_density(rgb: np.ndarray, paper) -> np.ndarray:
    """Channel-mean optical density −ln(lin(rgb) / lin(paper)) of sRGB pixels (..., 3), float32."""
    return -np.log(_transmittance(rgb, paper, floor=_MIN_TRANSMITTANCE)).mean(axis=-1)


def _transmittance(rgb, paper, *, floor):
    """lin(rgb) / lin(paper) per channel, clamped to [floor, 1]."""
    paper_linear = np.maximum(srgb_to_linear(_paper_colour(paper)), _MIN_TRANSMITTANCE)
    return np.clip(srgb_to_linear(rgb) / paper_linear, floor, 1.0)


def _paper_colour(paper) -> np.ndarray:
    paper = np.asarray(paper, dtype=np.float32)
    if paper.shape != (3,):
        raise StageError(f"colorize: the paper colour must be three sRGB values, got shape {paper.shape}")
    return paper


def _flatten(source_rgb, source_segment):
    """The exemplar as (N, 3) pixels and (N,) labels, checking that the shapes agree."""
    if source_rgb.ndim != 4 or source_rgb.shape[3] != 3 or source_segment.shape != source_rgb.shape[:3]:
        raise StageError(f"colorize: exemplar colour {source_rgb.shape} and segments {source_segment.shape} "
                         "must have shapes (T, H, W, 3) and (T, H, W)")
    return source_rgb.reshape(-1, 3), source_segment.reshape(-1)


def _spread(indices: np.ndarray) -> np.ndarray:
    """At most ``_MAX_SAMPLES`` of ``indices``, evenly spaced (deterministic)."""
    if indices.size <= _MAX_SAMPLES:
        return indices
    return indices[np.linspace(0, indices.size - 1, _MAX_SAMPLES).astype(np.int64)]
