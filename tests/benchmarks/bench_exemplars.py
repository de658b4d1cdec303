"""Benchmark: generating each built-in exemplar (simulation and rendering, no cache, no files).

Run: ``.venv/bin/python tests/benchmarks/bench_exemplars.py [--size 256 256] [--frames 40]``.
Target (issue 5): a 256x256x40 preset in under 60 s on 2 cores. A tiny warm-up run
compiles (or loads) the numba kernels first, so the times are of the generation alone.
"""

import argparse
import time

from fluidymation.stages import exemplar_builtin


def bench(size, frames):
    results = {}
    for name in sorted(exemplar_builtin.PRESETS):
        warm = exemplar_builtin.Params(preset=name, seed=0, size=(32, 32), frames=2, color="#2a6fdb", wetness=0.5)
        exemplar_builtin.generate(warm)
        params = exemplar_builtin.Params(preset=name, seed=0, size=tuple(size), frames=frames, color="#2a6fdb",
                                         wetness=0.5)
        start = time.perf_counter()
        exemplar_builtin.generate(params)
        results[name] = time.perf_counter() - start
    return results


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", nargs=2, type=int, default=[256, 256], metavar=("W", "H"))
    parser.add_argument("--frames", type=int, default=40)
    args = parser.parse_args()
    for name, seconds in bench(args.size, args.frames).items():
        verdict = "ok" if seconds < 60 else "SLOW"
        print(f"{name:20s} {args.size[0]}x{args.size[1]}x{args.frames}: {seconds:6.2f} s  {verdict}")


if __name__ == "__main__":
    main()
