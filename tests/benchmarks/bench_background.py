"""Benchmark: the synthesized paper background (``background.synthesized``), no files.

Run: ``.venv/bin/python tests/benchmarks/bench_background.py [--size 640 480] [--sample 100] [--runs 3]``.
Target (issue 7): 640x480 from a ~100x100 paper sample in a few seconds on 2 cores. The
sample is a procedural paper (``engine.watercolor.make_paper``). A tiny warm-up run
compiles (or loads) the numba kernels first, so the times are of the synthesis alone.
Also prints the output's mean and contrast next to the sample's.
"""

import argparse
import time

import numpy as np

from fluidymation.engine.watercolor import make_paper
from fluidymation.stages import background


def paper(side, seed=3):
    height, _ = make_paper((side, side), seed=seed)
    return np.clip(np.array([0.95, 0.93, 0.88], np.float32) * (0.94 + 0.06 * height[:, :, None]), 0, 1)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", nargs=2, type=int, default=[640, 480], metavar=("W", "H"))
    parser.add_argument("--sample", type=int, default=100, help="side of the square paper sample")
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    sample = paper(args.sample).astype(np.float32)
    background.synthesized(sample[:32, :32], (48, 40))
    times = []
    for seed in range(args.runs):
        start = time.perf_counter()
        out = background.synthesized(sample, tuple(args.size), seed=seed)
        times.append(time.perf_counter() - start)
    ratio = out.std(axis=(0, 1)).mean() / sample.std(axis=(0, 1)).mean()
    print(f"{args.size[0]}x{args.size[1]} from {args.sample}x{args.sample}: "
          f"min {min(times):.2f} s, median {float(np.median(times)):.2f} s over {args.runs} runs; "
          f"mean colour off by {np.abs(out.mean(axis=(0, 1)) - sample.mean(axis=(0, 1))).max():.4f}, "
          f"contrast (std) ratio {ratio:.2f}")


if __name__ == "__main__":
    main()
