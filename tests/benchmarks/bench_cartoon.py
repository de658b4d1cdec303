"""Benchmark: cartoon re-synthesis (issue 19) beside seed 004's Table 1 ("Green Fish": 60 frames at 400×250,
spatial size 0.25, temporal size 5, 5 levels; matching 13.3 s, total 310 s on a 2.3 GHz dual-core i5).

Run: ``NUMBA_CACHE_DIR=.numba-cache .venv/bin/python tests/benchmarks/bench_cartoon.py [--frames 60]
[--temporal-size 5] [--size 400 250]``.

The clip is drawn here: a fish (an ellipse body, a tail that beats, an eye and scale
hatching, dark outline) swimming across paper for ``--frames`` frames at ``--size``. Printed,
with the load average: the seconds of the clip's analysis (grid-PatchMatch motion and geometry
samples: the seed's "Matching"), of synthesizing as many output frames, and their sum (the
seed's "Total Time"), and the pyramid levels used. The kernels are compiled before timing.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import time

import numpy as np

from fluidymation.pipeline.parameters import default_params
from fluidymation.stages import cartoon
from fluidymation.stages.cartoon_clip import analyse_clip
from fluidymation.stages.cartoon_stylizer import CartoonStylizer

PAPER = np.array([0.95, 0.93, 0.88])
INK = np.array([0.15, 0.2, 0.15])
SCALES = np.array([0.35, 0.6, 0.3])


def fish_clip(frames: int, width: int, height: int):
    """(rgb (T, H, W, 3), mask (T, H, W)) of a drawn fish swimming to the right."""
    ys, xs = np.mgrid[:height, :width].astype(np.float64)
    rgb = np.empty((frames, height, width, 3))
    mask = np.empty((frames, height, width), bool)
    length = 0.4 * width
    for index in range(frames):
        cx = 0.3 * width + 0.3 * width * index / max(frames - 1, 1)
        cy = height / 2 + 0.05 * height * np.sin(2 * np.pi * index / 20)
        u, v = (xs - cx) / (length / 2), (ys - cy) / (0.22 * height)
        body = u ** 2 + v ** 2 <= 1
        beat = 0.35 * np.sin(2 * np.pi * index / 12)
        tu = (xs - (cx - length / 2)) / (0.25 * length)  # 0 at the body's end, 1 at the tail's tip (leftwards)
        tail = (tu < 0) & (tu > -1) & (np.abs((ys - cy) / (0.22 * height) - beat * tu ** 2) < -tu * 0.9)
        shape = body | tail
        edge = shape & ~np.roll(shape, 2, 0) | shape & ~np.roll(shape, -2, 0) | shape & ~np.roll(shape, 2, 1) \
            | shape & ~np.roll(shape, -2, 1)
        hatch = (np.abs(((xs - cx) * 0.7 + (ys - cy) + 3 * index % 7) % 8 - 4) < 1) & body
        eye = (xs - (cx + 0.3 * length)) ** 2 + (ys - cy + 0.05 * height) ** 2 < (0.03 * height) ** 2
        image = np.where(shape[..., None], SCALES, PAPER)
        image = np.where((hatch | edge | eye)[..., None], INK, image)
        rgb[index], mask[index] = image, shape
    return rgb.astype(np.float32), mask


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=60)
    parser.add_argument("--size", type=int, nargs=2, default=(400, 250), metavar=("W", "H"))
    parser.add_argument("--temporal-size", type=int, default=5)
    args = parser.parse_args()
    params = dataclasses.replace(default_params(CartoonStylizer), temporal_size=args.temporal_size)
    rgb, mask = fish_clip(args.frames, *args.size)
    small_rgb, small_mask = fish_clip(3, 120, 80)  # compile the kernels on a small clip first
    small = analyse_clip(small_rgb, small_mask, name="warm-up", motion=params.motion)
    list(cartoon.synthesize_frames(cartoon.CartoonSynthesis(small, params),
                                   ((i, cartoon.ResynthPath(small, 3).target(i)) for i in range(3))))
    start = time.perf_counter()
    clip = analyse_clip(rgb, mask, name="fish", motion=params.motion, seed=params.seed)
    matching = time.perf_counter() - start
    start = time.perf_counter()
    synthesis = cartoon.CartoonSynthesis(clip, params)
    path = cartoon.ResynthPath(clip, args.frames)
    for _ in cartoon.synthesize_frames(synthesis, ((i, path.target(i)) for i in range(args.frames))):
        pass
    synthesized = time.perf_counter() - start
    load = os.getloadavg()
    print(f"fish clip, {args.frames} frames at {args.size[0]}x{args.size[1]}, temporal size {args.temporal_size}, "
          f"spatial size {params.spatial_size}, {synthesis.synthesis.pyramid_levels} levels, patch "
          f"{params.patch_size}, {os.cpu_count()} cores, load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")
    print(f"{'':24s}{'matching':>10s}{'synthesis':>11s}{'total':>9s}{'s/frame':>9s}")
    print(f"{'fluidymation':24s}{matching:9.1f}s{synthesized:10.1f}s{matching + synthesized:8.1f}s"
          f"{(matching + synthesized) / args.frames:8.2f}s")
    print(f"{'seed 004, Green Fish':24s}{13.3:9.1f}s{310 - 13.3:10.1f}s{310.0:8.1f}s{310 / 60:8.2f}s")


if __name__ == "__main__":
    main()
