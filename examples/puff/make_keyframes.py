"""Write examples/puff/puff.svg and its painted keyframes paint/puff-000.png, -012.png, -023.png.

The animation is one SMIL-animated ellipse (layer "puff") drifting right and swelling over
1 s (24 frames at 24 fps). Each keyframe is "painted" here without regard to the others, as
an artist would: dabs of a dry brush in two blues, laid at random inside the ellipse of that
frame, over a pale wash, with a darker rim. Plain numpy and imageio; deterministic.

Run:  python examples/puff/make_keyframes.py
"""
from pathlib import Path

import imageio.v3 as iio
import numpy as np

HERE = Path(__file__).parent
SIZE = 256
FRAMES = 24
KEYS = (0, 12, 23)
# ellipse (cx, cy, rx, ry) at the first and last frame; SMIL interpolates linearly
START = (84.0, 140.0, 44.0, 32.0)
END = (168.0, 112.0, 60.0, 46.0)

SVG = f"""<?xml version="1.0" encoding="UTF-8"?>
<svg xmlns="http://www.w3.org/2000/svg" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"
     width="{SIZE}" height="{SIZE}" viewBox="0 0 {SIZE} {SIZE}">
  <!-- Fluidymation example: a puff that drifts and swells over 1 s; painted keyframes in paint/
       (written with this file by make_keyframes.py). -->
  <g id="puff" inkscape:label="puff" fill="#3b6fb6">
    <ellipse cx="{START[0]:g}" cy="{START[1]:g}" rx="{START[2]:g}" ry="{START[3]:g}">
      <animate attributeName="cx" from="{START[0]:g}" to="{END[0]:g}" begin="0s" dur="{FRAMES / 24:g}s" fill="freeze"/>
      <animate attributeName="cy" from="{START[1]:g}" to="{END[1]:g}" begin="0s" dur="{FRAMES / 24:g}s" fill="freeze"/>
      <animate attributeName="rx" from="{START[2]:g}" to="{END[2]:g}" begin="0s" dur="{FRAMES / 24:g}s" fill="freeze"/>
      <animate attributeName="ry" from="{START[3]:g}" to="{END[3]:g}" begin="0s" dur="{FRAMES / 24:g}s" fill="freeze"/>
    </ellipse>
  </g>
</svg>
"""


def ellipse_at(frame):
    t = frame / FRAMES
    return [a + (b - a) * t for a, b in zip(START, END)]


def paint(frame, rng):
    """A keyframe: RGBA float in [0, 1], the paint inside the ellipse of ``frame``."""
    cx, cy, rx, ry = ellipse_at(frame)
    ys, xs = np.mgrid[:SIZE, :SIZE] + 0.5
    radial = np.sqrt(((xs - cx) / rx) ** 2 + ((ys - cy) / ry) ** 2)
    alpha = np.clip((1.0 - radial) * min(rx, ry), 0.0, 1.0)  # 1 inside, a 1-px soft edge
    wash = np.array([0.78, 0.86, 0.95])
    colour = np.broadcast_to(wash, (SIZE, SIZE, 3)).copy()
    for _ in range(140):  # dabs of a dry brush: short oriented strokes, two blues
        angle = rng.uniform(-0.6, 0.6)
        length, width = rng.uniform(10, 22), rng.uniform(2.5, 5)
        r = np.sqrt(rng.uniform(0, 1))
        phi = rng.uniform(0, 2 * np.pi)
        px, py = cx + r * rx * np.cos(phi), cy + r * ry * np.sin(phi)
        u = (xs - px) * np.cos(angle) + (ys - py) * np.sin(angle)
        v = -(xs - px) * np.sin(angle) + (ys - py) * np.cos(angle)
        bristles = 0.65 + 0.35 * np.sin(v * 2.7 + rng.uniform(0, 6))
        dab = np.exp(-(u / length) ** 4 - (v / width) ** 2) * bristles
        tint = np.array([0.16, 0.33, 0.66]) if rng.random() < 0.6 else np.array([0.35, 0.55, 0.82])
        colour = colour * (1 - 0.8 * dab[..., None]) + tint * 0.8 * dab[..., None]
    rim = np.clip((radial - 0.82) / 0.18, 0.0, 1.0) ** 2
    colour = colour * (1 - 0.5 * rim[..., None]) + np.array([0.12, 0.22, 0.48]) * 0.5 * rim[..., None]
    return np.dstack([colour, alpha])


def main():
    (HERE / "puff.svg").write_text(SVG)
    (HERE / "paint").mkdir(exist_ok=True)
    for frame in KEYS:
        rgba = paint(frame, np.random.default_rng(1000 + frame))
        iio.imwrite(HERE / "paint" / f"puff-{frame:03d}.png", np.rint(np.clip(rgba, 0, 1) * 255).astype(np.uint8))


if __name__ == "__main__":
    main()
