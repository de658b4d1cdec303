"""Benchmark: the still stylizer at 1024×1024 (issue 18): full vs edge-band synthesis, and a still layer's later frames.

Run: ``NUMBA_CACHE_DIR=.numba-cache .venv/bin/python tests/benchmarks/bench_still.py [--size 1024]
[--band 8]``.

The target is the map layer of examples/map/map.svg (water, land and a road in one layer)
drawn at ``--size``², the exemplar examples/map/style/crayon.png (256², three regions) with
its segments, the stylizer's defaults (configs/still.yaml). Printed, with the load average:
the seconds of one full synthesis; of the edge-band start (the region textures synthesized
once at the frame's size, then the frame with only ``--band`` px along region edges
synthesized); of a later frame of a still layer (the previous frame unchanged: compared and
reused). Beside the times, the quality module's figures of the full and the edge-band frame
(texture fidelity to the painting, blockiness, local contrast), so the speed option's
quality can be judged against full synthesis. The seed (Texler 2019, table 5.1) reports
NNF times only, on a phone GPU, so the figures compare with our own full synthesis.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

from fluidymation import quality
from fluidymation.stages import rasterize, still
from fluidymation.stages.files import read_image
from fluidymation.stages.regions import read_regions
from fluidymation.stages.vector import open_document, renderer_for

ROOT = Path(__file__).parents[2]
MAP = ROOT / "examples" / "map"


def target(size: int):
    """The map layer at ``size``²: (straight colour, coverage)."""
    document = open_document(MAP / "map.svg")
    raster = rasterize.rasterize_frame(renderer_for(document), document, ("map",), 0,
                                       rasterize.Params(size=(size, size), fps=24.0))
    return raster.straight_rgb, raster.coverage


def painting() -> still.Painting:
    rgb = read_image(MAP / "style" / "crayon.png", channels=3)
    return still.Painting(rgb, read_regions(MAP / "style" / "crayon-segments.png", rgb.shape[:2]))


def timed(function):
    started = time.perf_counter()
    result = function()
    return result, time.perf_counter() - started


def figures(rgba, coverage, art) -> str:
    fidelity = quality.texture_fidelity([rgba], [coverage], [art.rgb], [art.regions.labels >= 0], samples=1500)
    blocks, _ = quality.blockiness([rgba], [coverage])
    contrast = quality.local_contrast(rgba[..., :3], quality.inside(coverage))
    return f"fidelity {fidelity:.4f}  blockiness {blocks:.3f}  local contrast {contrast:.4f}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=1024)
    parser.add_argument("--band", type=float, default=8.0, help="edge band in px at full resolution")
    args = parser.parse_args()
    load = os.getloadavg()[0]
    colour, coverage = target(args.size)
    art = painting()
    regions = still.layer_regions([(colour, coverage)], art.regions, mode="by-color", where="map")
    labels = regions.of(colour, coverage)
    print(f"still stylizer, {args.size}x{args.size} target ({int((labels >= 0).sum())} px painted, "
          f"{len(regions.palette)} fills), 256x256 painting; load average {load:.2f} (2 cores)")

    warm = still.StillSynthesis(art, still.Params(opt_iters=(1,), pm_iters=(1,)))
    warm.synthesize(labels[:64, :64], coverage[:64, :64])  # compile the kernels outside the timings

    full = still.StillSynthesis(art, still.Params())
    (_, full_rgb), full_seconds = timed(lambda: full.synthesize(labels, coverage))
    print(f"full synthesis:            {full_seconds:7.1f} s/frame")

    banded = still.StillSynthesis(art, still.Params(edge_band=args.band))
    (start, keep), texture_seconds = timed(lambda: banded.band_start(labels))
    (_, band_rgb), band_seconds = timed(lambda: banded.synthesize(labels, coverage, initial=start, keep=keep))
    print(f"edge band {args.band:g} px:           {band_seconds:7.1f} s/frame "
          f"({full_seconds / band_seconds:.2f}x faster; region textures once: {texture_seconds:.1f} s)")

    frames = [(colour, coverage)] * 3
    counts = still.Counts()
    stamps = []
    for _ in still.stylize_frames(lambda j: frames[j][1], lambda j: frames[j][0], (0, 3), full, regions, flow=None,
                                  counts=counts):
        stamps.append(time.perf_counter())
    later = (stamps[2] - stamps[1])
    print(f"still layer, later frames: {later:7.3f} s/frame ({counts.reused} of 3 frames reused)")
    with_alpha = [np.concatenate([rgb, coverage[..., None]], axis=2) for rgb in (full_rgb, band_rgb)]
    print(f"quality, full:      {figures(with_alpha[0], coverage, art)}")
    print(f"quality, edge band: {figures(with_alpha[1], coverage, art)}")
    difference = np.abs(full_rgb - band_rgb)[quality.inside(coverage)].mean()
    print(f"mean |full - edge band| inside: {difference:.4f}; load average at the end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
