"""Benchmark: mask rasterization time of animated SVG files, with their timeline against drawn still.

Run: ``.venv/bin/python tests/benchmarks/bench_svg_raster.py CORPUS [--only smil|css|all]
[--times 12] [--rounds 3]``.

Every SMIL or CSS animated ``*.svg`` under CORPUS is opened as the render opens it, and
each of its layers is drawn alone at 512×512 at ``--times`` times across its frame range,
under three variants interleaved file by file (so load changes hit all three alike):

- ``timeline``: as shipped (the file's animations applied at each time);
- ``still``: the same layers with no animation applied (what a reader without the
  timelines drew), with today's pixel conversion;
- ``still, old conversion``: as ``still`` with cairo's BGRA turned into RGBA by fancy
  indexing as before issue 14's speed fix (the code a user had before the timelines).

Printed: mean ms per layer-frame of each variant and the load average.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

REPOSITORY = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPOSITORY))
from tests.benchmarks.bench_svg_corpus import kind_of  # noqa: E402

from fluidymation.stages.vector import open_document, raster, renderer_for  # noqa: E402

SIZE = (512, 512)


def _old_conversion(bgra: np.ndarray) -> np.ndarray:
    return bgra[:, :, [2, 1, 0, 3]].copy()


def _draw_all(document, times: list[float]) -> float:
    """Seconds to draw each layer alone at each of ``times``."""
    renderer = renderer_for(document)
    start = time.perf_counter()
    for layer in document.layer_names():
        for seconds in times:
            renderer.render(document, [layer], seconds, SIZE)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("corpus", type=Path)
    parser.add_argument("--only", choices=("smil", "css", "all"), default="all")
    parser.add_argument("--times", type=int, default=12)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    files = [path for path in sorted(args.corpus.rglob("*.svg"))
             if (kind := kind_of(path.read_text(errors="replace"))) and args.only in ("all", kind)]
    totals = {"timeline": 0.0, "still": 0.0, "still, old conversion": 0.0}
    layer_frames = 0
    shipped_conversion = raster._bgra_to_rgba
    for _ in range(args.rounds):
        for path in files:
            document = open_document(path)
            first, end = document.frame_range(24.0)
            span = max(end - first, 1) / 24.0
            times = [span * step / args.times for step in range(args.times)]
            animations = document.animations
            totals["timeline"] += _draw_all(document, times)
            document.animations = ()
            totals["still"] += _draw_all(document, times)
            raster._bgra_to_rgba = _old_conversion
            try:
                totals["still, old conversion"] += _draw_all(document, times)
            finally:
                raster._bgra_to_rgba = shipped_conversion
                document.animations = animations
            layer_frames += len(document.layer_names()) * len(times)
    load = " ".join(f"{value:.2f}" for value in os.getloadavg())
    print(f"{len(files)} files, {layer_frames} layer-frames per variant at {SIZE[0]}x{SIZE[1]} (load average {load})")
    for variant, seconds in totals.items():
        print(f"  {variant:<22} {1000 * seconds / max(layer_frames, 1):6.2f} ms per layer-frame")


if __name__ == "__main__":
    main()
