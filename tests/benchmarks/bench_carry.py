"""Benchmark: ``carry: true`` moves the painting with the shape, for every built-in medium (issue 16, item 5).

Run: ``NUMBA_CACHE_DIR=.numba-cache .venv/bin/python tests/benchmarks/bench_carry.py [--scale K]
[--exemplar-size N] [--media watercolor-bloom ...]``.

Two scenes of bench_quality.py's kind (12 frames on a 128-px canvas, K times larger), each
given its own motion as ``flow: vector`` gives a vector input: a textured disk (radius
40 px) turning 4° a frame about its centre, whose outline never moves, and the tilted
ellipse translating (2.5, 1) px a frame. Each is stylized three times with the stylizer's
defaults: as the paper does (``carry: false``), with ``carry: true``, and with frames made
independently (``w_temp: 0``). Printed per medium and scene: the motion-compensated
residual (:func:`fluidymation.quality.compensated_residual`, frame j against frame j − 1
moved by the known motion, averaged over the frame pairs, ×10³) of each, and the ratios
to the independent frames'. The issue asks carry/independent ≤ 0.5 (P/F); the paper's
ratio is printed beside it: its paint stays on the paper, so it is higher.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_quality as bench  # noqa: E402

from fluidymation import quality  # noqa: E402
from fluidymation.pipeline.parameters import default_params  # noqa: E402
from fluidymation.pipeline.stylizers import get_stylizer  # noqa: E402
from fluidymation.stages import guides  # noqa: E402

LIMIT = 0.5


def carry_scenes(c: bench.Canvas) -> tuple[bench.Scene, ...]:
    translation = next(scene for scene in bench.make_scenes(c) if scene.name == "translation")
    return (bench.Scene("turning disk", "disk r 40 px turning 4°/frame about its centre",
                        lambda t: c.ellipse(64, 64, 40, 40), lambda t: c.rotation(64, 64, np.radians(4))),
            translation)


def residual(frames: np.ndarray, scene: bench.Scene) -> float:
    return float(np.mean([quality.compensated_residual(frames[t - 1], frames[t], scene.displacement(t),
                                                       scene.coverage(t - 1), scene.coverage(t))
                          for t in range(1, bench.FRAMES)]))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scale", type=float, default=1.0)
    parser.add_argument("--exemplar-size", type=int, default=bench.EXEMPLAR_SIZE)
    parser.add_argument("--media", nargs="+", default=list(bench.MEDIA), choices=bench.MEDIA)
    args = parser.parse_args()
    canvas = bench.Canvas(args.scale)
    params = default_params(get_stylizer("fluidymation"))
    guide_params = guides.Params()
    print(f"{canvas.size}-px scenes, {args.exemplar_size}-px exemplars, load average {os.getloadavg()[0]:.2f}; "
          "compensated residual ×10³ (carry/indep. ≤ 0.5 asked)")
    print(f"  {'medium':20s} {'scene':14s} {'paper':>7s} {'carry':>7s} {'indep.':>7s} {'paper/indep.':>13s} "
          f"{'carry/indep.':>13s}")
    failed = 0
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        for medium in args.media:
            exemplar = bench.load_exemplar(medium, args.exemplar_size, folder, guide_params)
            for scene in carry_scenes(canvas):
                figures = {}
                for label, changes in (("paper", {}), ("carry", {"carry": True}), ("indep.", {"w_temp": 0.0})):
                    frames = bench.render(scene, exemplar, dataclasses.replace(params, **changes), guide_params,
                                          folder / medium / scene.name / label, true_motion=True)
                    figures[label] = residual(frames, scene)
                ratio = figures["carry"] / figures["indep."]
                failed += ratio > LIMIT
                print(f"  {medium:20s} {scene.name:14s} {1e3 * figures['paper']:7.2f} {1e3 * figures['carry']:7.2f} "
                      f"{1e3 * figures['indep.']:7.2f} {figures['paper'] / figures['indep.']:13.2f} "
                      f"{ratio:11.2f} {'P' if ratio <= LIMIT else 'F'}")
    print(f"{failed} of {2 * len(args.media)} above {LIMIT}")


if __name__ == "__main__":
    main()
