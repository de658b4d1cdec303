"""The ``composite`` stage: the scene's layers over its paper, in linear light.

Layers are straight-alpha sRGB RGBA images stacked bottom to top, each with a blend mode
and an opacity; with a = alpha · opacity and everything in linear light:

* ``"over"``: out = a·rgb + (1 − a)·out, opaque paint covering what is below;
* ``"multiply"``: out = out · ((1 − a) + a·rgb), transparent watercolor glazes whose
  transmittances multiply, so a stack of them does not depend on its order.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from fluidymation.errors import StageError
from fluidymation.stages.colour import linear_to_srgb, srgb_to_linear

NAME = "composite"
VERSION = 1

BLENDS = ("multiply", "over")


def composite(background: np.ndarray, layers: Sequence[tuple[np.ndarray, str, float]]) -> np.ndarray:
    """Blend ``layers`` (bottom to top) over ``background``.

    Parameters
    ----------
    background : (H, W, 3) float32, sRGB
    layers : sequence of (rgba, blend, opacity)
        ``rgba`` (H, W, 4) float32 sRGB with straight alpha, ``blend`` one of
        :data:`BLENDS`, ``opacity`` in [0, 1].

    Returns
    -------
    (H, W, 3) float32, sRGB.
    """
    background = np.asarray(background, dtype=np.float32)
    if background.ndim != 3 or background.shape[2] != 3:
        raise StageError(f"composite: the background must be an (H, W, 3) image, got shape {background.shape}")
    out = srgb_to_linear(background)
    for index, (rgba, blend, opacity) in enumerate(layers):
        rgba = np.asarray(rgba, dtype=np.float32)
        if rgba.shape != background.shape[:2] + (4,):
            raise StageError(f"composite: layer {index} has shape {rgba.shape}, expected "
                             f"{background.shape[:2] + (4,)} to match the background")
        if blend not in BLENDS:
            raise StageError(f"composite: layer {index} has blend {blend!r}; valid: {', '.join(BLENDS)}")
        if not 0.0 <= opacity <= 1.0:
            raise StageError(f"composite: layer {index} has opacity {opacity!r}, expected a number in [0, 1]")
        alpha = rgba[:, :, 3:] * np.float32(opacity)
        colour = srgb_to_linear(rgba[:, :, :3])
        if blend == "over":
            out = alpha * colour + (1.0 - alpha) * out
        else:
            out = out * ((1.0 - alpha) + alpha * colour)
    return linear_to_srgb(out)
