"""Text captions for comparison videos and contact sheets (Pillow's built-in font)."""

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


def wrapped_caption(parts: list[str], *, width: int, separator: str = " · ") -> np.ndarray:
    """``parts`` joined by ``separator`` and wrapped between parts to fit ``width``: (n · CAPTION_HEIGHT, width, 3)
    float32, one :func:`label_strip` line each (a part wider than the width is clipped)."""
    font = ImageFont.load_default()
    lines = [parts[0]]
    for part in parts[1:]:
        joined = lines[-1] + separator + part
        if font.getlength(joined) + 4 <= width:  # 2 px margin on each side
            lines[-1] = joined
        else:
            lines.append(part)
    return np.concatenate(label_strip(lines, width=width))
