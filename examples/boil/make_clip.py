"""Write examples/boil/clip/0000.png ... 0011.png and boil.svg: a "boiling" pencil outline and a shape to move it.

The clip is a hand-drawn-looking ring of graphite on paper whose line wobbles from frame to
frame (the animator's "line boil"): its radius follows a few low sine harmonics whose phases
drift, its width and darkness vary along the line, and a sparse hatching fills the inside.
boil.svg is a disk gliding across the frame and back (SMIL), which the scene paints with the
clip's drawing and boil (``stylizer: cartoon``). numpy and imageio only, fixed seed.

Run:  python examples/boil/make_clip.py
"""
from pathlib import Path

import imageio.v3 as iio
import numpy as np

FRAMES = 12
SIZE = 96
PAPER = np.array([0.96, 0.94, 0.89])
GRAPHITE = np.array([0.22, 0.22, 0.26])
HERE = Path(__file__).parent


def frame(index: int, rng_phases: np.ndarray) -> np.ndarray:
    """One frame: the wobbly ring, its hatching and the paper, (SIZE, SIZE, 3) in [0, 1]."""
    ys, xs = np.mgrid[:SIZE, :SIZE].astype(np.float64)
    cx = cy = (SIZE - 1) / 2
    angle = np.arctan2(ys - cy, xs - cx)
    r = np.hypot(xs - cx, ys - cy)
    t = 2 * np.pi * index / FRAMES
    radius = 30.0 + sum(1.6 / k * np.sin(k * angle + rng_phases[k] + (k % 3 + 1) * t) for k in range(2, 6))
    width = 2.4 + 0.6 * np.sin(3 * angle + rng_phases[0] + t)
    line = np.clip(1.0 - np.abs(r - radius) / width, 0.0, 1.0)
    hatch_phase = 1.5 * np.sin(t + rng_phases[1])
    hatch = (np.abs(((xs + ys + hatch_phase) % 9.0) - 4.5) < 0.7) & (r < radius - 5)
    ink = np.maximum(line, 0.45 * hatch)
    grain = 0.85 + 0.15 * np.random.default_rng(index).random((SIZE, SIZE))
    ink = np.clip(ink * grain, 0.0, 1.0)
    return PAPER * (1 - ink[..., None]) + GRAPHITE * ink[..., None]


SVG = """<?xml version="1.0" encoding="UTF-8"?>
<svg xmlns="http://www.w3.org/2000/svg" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"
     width="256" height="256" viewBox="0 0 256 256">
  <g inkscape:label="disk" id="disk">
    <circle cx="80" cy="128" r="52" fill="#444444">
      <animate attributeName="cx" values="80;176;80" dur="2s" fill="freeze"/>
    </circle>
  </g>
</svg>
"""


def main() -> None:
    phases = np.random.default_rng(7).uniform(0, 2 * np.pi, 8)
    folder = HERE / "clip"
    folder.mkdir(exist_ok=True)
    for index in range(FRAMES):
        image = frame(index, phases)
        iio.imwrite(folder / f"{index:04d}.png", np.round(image * 255).astype(np.uint8))
    (HERE / "boil.svg").write_text(SVG)


if __name__ == "__main__":
    main()
