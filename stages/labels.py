"""Text captions for comparison videos (Pillow's built-in bitmap font)."""

from __future__ import annotations

import numpy as np
from PIL import Image, ImageDraw, ImageFont

CAPTION_HEIGHT = 14  # px


def label_strip(labels: list[str], *, width: int) -> list[np.ndarray]:
    """One (CAPTION_HEIGHT, width, 3) float32 caption per label: dark text on white, clipped to the width."""
    font = ImageFont.load_default()
    strips = []
    for label in labels:
        image = Image.new("RGB", (width, CAPTION_HEIGHT), "white")
        ImageDraw.Draw(image).text((2, 1), label, fill=(20, 20, 20), font=font)
        strips.append(np.asarray(image, np.float32) / np.float32(255.0))
    return strips
