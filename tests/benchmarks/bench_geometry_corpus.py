"""Benchmark: how much of real vector animations ``flow: vector`` reads, against what players draw.

Run: ``NUMBA_CACHE_DIR=.numba-cache .venv/bin/python tests/benchmarks/bench_geometry_corpus.py CORPUS
[--size 160]`` with CORPUS a folder of Lottie ``.json`` or SVG files (searched recursively), e.g.
rlottie's ``example/resource`` or the svg-spinners collection, fetched for measurement only
(nothing is downloaded or committed).

For each file, at three frames (a quarter, half and three quarters in), the outlines
read from the geometry (:mod:`fluidymation.stages.vector.lottie_geometry`,
:mod:`~fluidymation.stages.vector.svg_geometry`) give the pixels they own; each player
gives its alpha: for Lottie ThorVG through our renderer and rlottie straight from the file,
for SVG our renderer (CairoSVG). Printed per file and player: ``precision``, the share of our pixels the player
draws at all (alpha > 0: a translucent fill counts); ``recall``, the share of the player's
opaque pixels (alpha > 127) our outlines own, low where strokes and the like are left to
the masks. Then the medians and the reasons things were left to the masks, counted over
frames. A file whose reading or drawing fails is printed with its error and counted.
"""

from __future__ import annotations

import argparse
import collections
import re
import statistics
import sys
from pathlib import Path

import numpy as np
from rlottie_python import LottieAnimation

from fluidymation.engine.vector_motion import vector_flow
from fluidymation.errors import InputError
from fluidymation.stages.vector import open_document, renderer_for

PLAYERS = ("thorvg", "rlottie", "cairosvg")


def measure(path: Path, size: int, reasons: collections.Counter) -> dict[str, list[float]]:
    """Per player, the precision and recall at each of three frames, tallying what is not read into ``reasons``."""
    document = open_document(path, fps=24.0)
    renderer = renderer_for(document)
    rlottie = LottieAnimation.from_file(str(path)) if document.kind == "lottie" else None
    fps = document.native_fps or 24.0
    start, end = document.frame_range(fps)
    names = document.layer_names()
    figures = collections.defaultdict(list)
    for frame in np.linspace(start + 1, end - 1, 3).astype(int):
        elements, unread = document.moving_elements(names, (frame - 1) / fps, frame / fps, (size, size))
        reasons.update(re.sub(r"\b[0-9.]+\b", "N", (re.findall(r"\(([^()]*)\)+$", reason) or [reason])[0])
                       for reason in unread)
        _, owned = vector_flow(elements, (size, size))
        drawn = renderer.render(document, names, frame / fps, (size, size))[..., 3]
        if rlottie is None:
            alphas = {"cairosvg": drawn}
        else:
            alphas = {"thorvg": drawn, "rlottie": np.asarray(rlottie.render_pillow_frame(
                frame_num=int(frame - document.in_point), width=size, height=size))[..., 3]}
        for player, alpha in alphas.items():
            if owned.any() and (alpha > 127).any():
                figures[f"{player} precision"].append((owned & (alpha > 0)).sum() / owned.sum())
                figures[f"{player} recall"].append((owned & (alpha > 127)).sum() / (alpha > 127).sum())
        figures["fully read"].append(float(not unread))
    return figures


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("corpus", type=Path)
    parser.add_argument("--size", type=int, default=160)
    args = parser.parse_args()
    reasons: collections.Counter = collections.Counter()
    files, failed = {}, 0
    for path in sorted(p for p in args.corpus.rglob("*") if p.suffix.lower() in (".json", ".svg")):
        try:
            figures = measure(path, args.size, reasons)
        except (InputError, ValueError) as error:
            failed += 1
            print(f"{str(path.relative_to(args.corpus)):48s} failed: {str(error)[:120]}")
            continue
        if not any(key.endswith("precision") for key in figures):
            print(f"{str(path.relative_to(args.corpus)):48s} nothing read to compare")
            continue
        files[str(path)] = {key: float(np.mean(values)) for key, values in figures.items()}
        print(f"{str(path.relative_to(args.corpus)):48s} " + " ".join(f"{key} {files[str(path)][key]:.3f}" for key in
                                           [f"{p} {m}" for p in PLAYERS for m in ("precision", "recall")]
                                           if key in files[str(path)]))
    print(f"\n{len(files)} files compared, {failed} failed; medians (files with precision ≥ 0.99 / recall ≥ 0.99)")
    for subset, chosen in (("all compared", files), ("fully read", {name: f for name, f in files.items()
                                                                    if f["fully read"] == 1.0})):
        print(f"  {subset} ({len(chosen)} files):")
        for key in [f"{p} {m}" for p in PLAYERS for m in ("precision", "recall")]:
            values = [f[key] for f in chosen.values() if key in f]
            if values:
                print(f"    {key:18s} {statistics.median(values):.3f} "
                      f"({sum(v >= 0.99 for v in values)} of {len(values)} ≥ 0.99, lowest {min(values):.3f})")
    print("left to the masks (elements × frames):")
    for reason, count in reasons.most_common(12):
        print(f"  {count:6d} {reason[:100]}")


if __name__ == "__main__":
    sys.exit(main())
