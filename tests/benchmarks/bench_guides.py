"""Benchmark: guides of a 1000x800 target, per-frame time; multigrid vs sparse Laplace.

Run: ``.venv/bin/python tests/benchmarks/bench_guides.py [--frames 400] [--laplace]``.
Target (issue 4): under 0.2 s per frame on 2 cores.
"""

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from fluidymation.engine import flow
from fluidymation.stages import guides

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))


def blob_masks(width, height):
    """A wobbling blob of ~150 000 px at 1000×800, moving a few px per frame: ``mask(index)``."""
    yy, xx = np.mgrid[:height, :width].astype(np.float32)

    def mask(index):
        t = index / 24.0
        cx = width / 2 + 180 * np.sin(t)
        cy = height / 2 + 60 * np.cos(1.3 * t)
        angle = np.arctan2(yy - cy, xx - cx)
        radius = 220 + 40 * np.sin(3 * angle + t) + 30 * np.sin(t / 2)
        return np.hypot(xx - cx, yy - cy) < radius

    return mask


def _packed(masks, frames):
    """The masks made before timing (packed 8 to a byte), so only the guides are timed."""
    packed = [np.packbits(masks(index)) for index in range(frames)]
    shape = masks(0).shape
    return lambda index: np.unpackbits(packed[index], count=shape[0] * shape[1]).reshape(shape).view(bool)


def bench_guides(frames, width, height):
    with tempfile.TemporaryDirectory() as cache_dir:
        warm = blob_masks(64, 48)
        guides.compute_guides(warm, 3, params=guides.Params(), cache_dir=cache_dir + "/warm")
        masks = _packed(blob_masks(width, height), frames)
        start = time.perf_counter()
        guides.compute_guides(masks, frames, params=guides.Params(), cache_dir=cache_dir)
        elapsed = time.perf_counter() - start
    print(f"guides {width}x{height}, {frames} frames: {elapsed:.1f} s, {elapsed / frames * 1000:.0f} ms/frame")


def bench_laplace(size):
    import naive

    yy, xx = np.mgrid[:size, :size]
    domain = np.ones((size, size), dtype=bool)
    inside = np.hypot(xx - size / 2, yy - size / 2) < size * 0.4
    padded = np.pad(inside, 1, mode="edge")
    fixed = inside & ~(padded[:-2, 1:-1] & padded[2:, 1:-1] & padded[1:-1, :-2] & padded[1:-1, 2:])
    values = np.stack([np.cos(xx / 50.0), np.sin(yy / 70.0)], axis=2).astype(np.float32)
    flow.harmonic_fill(values, fixed, domain)
    start = time.perf_counter()
    multigrid = flow.harmonic_fill(values, fixed, domain)
    multigrid_time = time.perf_counter() - start
    start = time.perf_counter()
    exact = naive.naive_harmonic_fill(values.astype(np.float64), fixed, domain)
    sparse_time = time.perf_counter() - start
    error = np.abs(multigrid - exact).max() / np.ptp(values[fixed])
    print(
        f"Laplace fill {size}x{size}: multigrid {multigrid_time * 1000:.0f} ms, "
        f"scipy sparse direct (spsolve) {sparse_time * 1000:.0f} ms, max difference {error:.2%} of the range"
    )


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--frames", type=int, default=400)
    parser.add_argument("--width", type=int, default=1000)
    parser.add_argument("--height", type=int, default=800)
    parser.add_argument("--laplace", action="store_true", help="also compare the Laplace solvers at 1000x1000")
    args = parser.parse_args()
    if args.laplace:
        bench_laplace(1000)
    bench_guides(args.frames, args.width, args.height)
