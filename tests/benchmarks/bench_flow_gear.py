"""Measure how the stylized paint of a turning gear follows its rotation: ``flow: masks`` beside ``flow: vector``.

Run: ``NUMBA_CACHE_DIR=.numba-cache .venv/bin/python tests/benchmarks/bench_flow_gear.py
[docs/examples/flow-gear.mp4]``; the video is the one ``docs/examples/make_examples.py
flow-gear`` writes (``examples/gear``: a gear turned a quarter turn in 2 s about
(128, 128), 1.875° a frame, rendered with each flow and with ``carry``; three 256-px panels
under 14-px captions, 4 px apart).

Over the gear's body between the hub and the teeth (radius 30–58 px), for each panel:

* **streaks along the rotation**: the coherence-weighted mean of cos 2(φ − τ), φ the
  texture's streak direction (across the structure tensor's dominant gradient, σ 4 px)
  and τ the tangent of the rotation: 1 when the texture runs along the rotation, −1 when
  radial, 0 for no preference; and the mean coherence;
* **texture motion**: the tangential component of the output's own motion between
  consecutive frames (grid PatchMatch, :func:`fluidymation.engine.motion.estimate_motion`),
  as a share of ω·r (1: the paint turns with the gear; 0: it stays on the paper, the
  paper's behaviour), and the share of pixels that stay still (under 0.1 px/frame).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import imageio.v3 as iio
import numpy as np
from scipy import ndimage

from fluidymation.stages.exemplar_user import motion_flow

ROOT = Path(__file__).resolve().parents[2]
PANEL, CAPTION, GAP = 256, 14, 4
CENTRE, OMEGA = 128.0, np.radians(90 / 48)  # rad/frame
FRAMES = slice(8, 40)


def tangent_alignment(luminance: np.ndarray, tangent: np.ndarray, region: np.ndarray) -> tuple[float, float]:
    gx, gy = ndimage.sobel(luminance, 1), ndimage.sobel(luminance, 0)
    jxx, jyy, jxy = (ndimage.gaussian_filter(product, 4.0) for product in (gx * gx, gy * gy, gx * gy))
    gradient = 0.5 * np.arctan2(2 * jxy, jxx - jyy)
    coherence = np.hypot(jxx - jyy, 2 * jxy) / (jxx + jyy + 1e-9)
    alignment = np.cos(2 * (gradient + np.pi / 2 - tangent))
    return float((alignment * coherence)[region].sum() / coherence[region].sum()), float(coherence[region].mean())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    default = ROOT / "docs" / "examples" / "flow-gear.mp4"
    parser.add_argument("video", nargs="?", type=Path, default=default,
                        help=f"the three-panel video make_examples.py flow-gear writes (default {default.relative_to(ROOT)})")
    video = parser.parse_args().video
    if not video.is_file():
        parser.error(f"{video}: no such video")
    frames = iio.imread(video, plugin="pyav").astype(np.float32) / 255.0
    yy, xx = np.mgrid[:PANEL, :PANEL] + 0.5
    radius = np.hypot(xx - CENTRE, yy - CENTRE)
    tangent = np.arctan2(xx - CENTRE, -(yy - CENTRE))  # clockwise on screen: (−y, x) / r
    unit = np.stack([-(yy - CENTRE), xx - CENTRE], axis=-1) / np.maximum(radius, 1e-6)[..., None]
    body = (radius > 30) & (radius < 58)
    print(f"{video.name}: frames {FRAMES.start}..{FRAMES.stop - 1}, radius 30-58 px")
    print(f"  {'panel':8s} {'streaks along':>14s} {'coherence':>10s} {'texture motion / ωr':>20s} {'still':>6s}")
    for index, name in enumerate(("masks", "vector", "carry")):
        left = index * (PANEL + GAP)
        panel = frames[FRAMES, CAPTION:CAPTION + PANEL, left:left + PANEL]
        alignments = np.array([tangent_alignment(frame.mean(axis=-1), tangent, body) for frame in panel])
        flow = motion_flow(panel)[1:]
        along = (flow * unit).sum(axis=-1)[:, body] / (OMEGA * radius[body])
        still = (np.hypot(flow[..., 0], flow[..., 1])[:, body] < 0.1).mean()
        print(f"  {name:8s} {alignments[:, 0].mean():14.3f} {alignments[:, 1].mean():10.3f} "
              f"{along.mean():20.3f} {still:6.2f}")


if __name__ == "__main__":
    main()
