"""Benchmark: motion from the vector geometry (``flow: vector``) against the masks' estimate, per layer-frame.

Run: ``NUMBA_CACHE_DIR=.numba-cache .venv/bin/python tests/benchmarks/bench_vector_flow.py [--size 512]
[--frames 24]``.

Four layers drawn at ``--size``² (issue 16 asks for 512×512: the geometry's motion may
cost at most 2× the estimate's): the bundled ``examples/blob`` (three SMIL-animated
ellipses and circles that grow and slide: affine parts, harmonic fill of nothing), a
gear turned by ``animateTransform`` (a rigid path of 32 vertices), the bundled Lottie
``examples/wave`` (its ``body``: a rotating ellipse layer) and the same gear as a Lottie
layer turned by its rotation keyframes. For each, the time per
frame of :func:`fluidymation.stages.motion.frame_motion` (reading both frames' geometry and
painting the field), and of the guides computed from the masks alone against with that
motion given (``compute_guides``: the estimate's multigrid solves and time smoothing
against the given flow, the rest being the same).
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from fluidymation.stages import guides, motion
from fluidymation.stages.rasterize import Params as RasterParams
from fluidymation.stages.rasterize import rasterize_frame
from fluidymation.stages.vector import open_document, renderer_for

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
from tests.scenes import turning_gear_lottie, turning_gear_svg  # noqa: E402

FPS = 24.0


def measure(path: Path, layer: str, size: int, frames: int, folder: Path) -> dict:
    document = open_document(path, fps=FPS)
    renderer = renderer_for(document)
    raster = RasterParams(size=(size, size), fps=FPS)
    masks = [rasterize_frame(renderer, document, (layer,), j, raster).coverage for j in range(frames)]
    motion.frame_motion(document, (layer,), frames, FPS, (size, size))  # warm-up: compiled kernels loaded
    started = time.perf_counter()
    flows = [motion.frame_motion(document, (layer,), j, FPS, (size, size), first=j == 0)[0] for j in range(frames)]
    geometry = (time.perf_counter() - started) / frames
    params = guides.Params()
    started = time.perf_counter()
    guides.compute_guides(masks, frames, params=params, cache_dir=folder / "estimated")
    estimated = (time.perf_counter() - started) / frames
    started = time.perf_counter()
    guides.compute_guides(masks, frames, params=params, cache_dir=folder / "given", given_flow=flows)
    given = (time.perf_counter() - started) / frames
    return {"geometry": geometry, "estimated": estimated, "given": given}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--frames", type=int, default=24)
    args = parser.parse_args()
    load = os.getloadavg()[0]
    print(f"{args.size}x{args.size}, {args.frames} frames, load average {load:.2f}; seconds per frame")
    print(f"  {'layer':10s} {'geometry':>9s} {'guides (masks)':>15s} {'guides (vector)':>16s} {'vector / masks':>15s}")
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        for name, path, layer in (("blob", ROOT / "examples" / "blob" / "blob.svg", "blob"),
                                  ("gear", turning_gear_svg(folder), "gear"),
                                  ("wave", ROOT / "examples" / "wave" / "wave.json", "body"),
                                  ("gear-lottie", turning_gear_lottie(folder), "gear")):
            times = measure(path, layer, args.size, args.frames, folder / name)
            ratio = (times["geometry"] + times["given"]) / times["estimated"]
            print(f"  {name:10s} {times['geometry']:9.3f} {times['estimated']:15.3f} {times['given']:16.3f} "
                  f"{ratio:15.2f}")
    print("vector / masks: (geometry + guides with it) / guides from the masks alone")


if __name__ == "__main__":
    main()
