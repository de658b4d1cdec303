"""Benchmark: a folder of animated SVG files (SMIL or CSS) against headless Chromium, and mask rasterization time.

Run: ``.venv/bin/python tests/benchmarks/bench_svg_corpus.py CORPUS [--only smil|css|all]
[--size 96] [--references DIR] [--tree DIR] [--timing-frames 12]``.

Every ``*.svg`` under CORPUS that holds SMIL (``<animate…>``, ``<set>``) or CSS
(``@keyframes``) animation, as ``--only`` selects, is opened as the render opens it. At four
times (0, ¼, ½ and ¾ of its frame range at 24 fps, as the first run reads it) its layers'
coverage ≥ 0.5, all layers unioned and drawn by the document's default renderer at
``--size``², is compared with Chromium's alpha ≥ 0.5 at those times (issue 14: within
IoU 0.9 at all four times). A file the reader refuses (InputError) is *refused*; any other
exception is *crashed*. Chromium's frames and the times are kept in ``--references``
(default ``/tmp/bench-svg-references``), so a second run, e.g. ``--tree /tmp/old`` (another
checkout of this repository, imported instead of the installed one), compares with the same
frames at the same times. Files are known by their folder and name there.

Then each layer of each opened file is rendered alone at 512×512 at ``--timing-frames``
times across its range: the mean wall time per layer-frame is what issue 14 calls mask
rasterization time (the load average is printed beside it).
"""

from __future__ import annotations

import argparse
import importlib.abc
import importlib.util
import json
import os
import re
import sys
import time
from pathlib import Path

import imageio.v3 as iio
import numpy as np

REPOSITORY = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPOSITORY))
from tests.references.chromium import coverage as chromium_coverage  # noqa: E402

IOU_TARGET = 0.9
FRACTIONS = (0.0, 0.25, 0.5, 0.75)
FPS = 24.0
_SMIL = re.compile(r"<(?:\w+:)?(?:animate|animateTransform|animateMotion|animateColor|set)\b")
_CSS = re.compile(r"@keyframes\b")
#: Where each subpackage of ``fluidymation`` lives in a checkout (pyproject.toml's package-dir).
_PACKAGE_DIRS = {"pipeline": "pipeline", "stages": "stages", "engine": "engine", "configs": "configs"}


class _CheckoutFinder(importlib.abc.MetaPathFinder):
    """Imports ``fluidymation`` from another checkout of the repository, laid out as pyproject.toml maps it."""

    def __init__(self, tree: Path):
        self.tree = tree

    def find_spec(self, name, path=None, target=None):
        parts = name.split(".")
        if parts[0] != "fluidymation":
            return None
        if len(parts) == 1:
            location = self.tree / "fluidymation"
        elif parts[1] in _PACKAGE_DIRS:
            location = self.tree.joinpath(_PACKAGE_DIRS[parts[1]], *parts[2:])
        else:
            location = self.tree.joinpath("fluidymation", *parts[1:])
        if (location / "__init__.py").is_file():
            return importlib.util.spec_from_file_location(name, location / "__init__.py",
                                                          submodule_search_locations=[str(location)])
        if location.with_suffix(".py").is_file():
            return importlib.util.spec_from_file_location(name, location.with_suffix(".py"))
        return None


def kind_of(text: str) -> str | None:
    """``smil`` or ``css`` by what the file's text animates with (SMIL first), or None."""
    if _SMIL.search(text):
        return "smil"
    if _CSS.search(text):
        return "css"
    return None


def union_mask(document, renderer, time_seconds: float, size: int) -> np.ndarray:
    """Every layer's coverage ≥ 0.5, drawn together."""
    rgba = renderer.render(document, document.layer_names(), time_seconds, (size, size))
    return rgba[:, :, 3] >= 128


def iou(ours: np.ndarray, reference: np.ndarray) -> float:
    union = (ours | reference).sum()
    return 1.0 if union == 0 else float((ours & reference).sum() / union)


def reference_frames(path: Path, text: str, times: list[float], size: int, folder: Path) -> list[np.ndarray]:
    """Chromium's alpha ≥ 0.5 at ``times``, from the references folder or drawn now and kept there."""
    frames = []
    shots = [folder / path.parent.name / path.stem / f"{t:.6f}-{size}.png" for t in times]
    if not all(shot.is_file() for shot in shots):
        shots[0].parent.mkdir(parents=True, exist_ok=True)
        for shot, alpha in zip(shots, chromium_coverage(text, times, (size, size))):
            iio.imwrite(shot, np.round(alpha * 255).astype(np.uint8))
    for shot in shots:
        frames.append(iio.imread(shot) >= 128)
    return frames


def sample_times(path: Path, document, folder: Path) -> list[float]:
    """0, ¼, ½, ¾ of the file's frame range, as the first run read it (kept in the references folder)."""
    record = folder / "times.json"
    known = json.loads(record.read_text()) if record.is_file() else {}
    name = f"{path.parent.name}/{path.name}"  # the SMIL and CSS spinner sets share file names
    if name not in known:
        first, end = document.frame_range(FPS)
        known[name] = [round((first + (end - first) * fraction) / FPS, 6) for fraction in FRACTIONS]
        folder.mkdir(parents=True, exist_ok=True)
        record.write_text(json.dumps(known, indent=1, sort_keys=True))
    return known[name]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("corpus", type=Path)
    parser.add_argument("--only", choices=("smil", "css", "all"), default="all")
    parser.add_argument("--size", type=int, default=96)
    parser.add_argument("--references", type=Path, default=Path("/tmp/bench-svg-references"))
    parser.add_argument("--tree", type=Path, help="import fluidymation from this checkout instead")
    parser.add_argument("--timing-frames", type=int, default=12)
    args = parser.parse_args()
    if args.tree:
        sys.meta_path.insert(0, _CheckoutFinder(args.tree.resolve()))
    from fluidymation.errors import InputError
    from fluidymation.stages.vector import open_document, renderer_for

    import fluidymation
    print(f"fluidymation from {Path(fluidymation.__file__).parent.parent}")
    files = [path for path in sorted(args.corpus.rglob("*.svg"))
             if (kind := kind_of(path.read_text(errors="replace"))) and args.only in ("all", kind)]
    matched, refused, crashed, opened = [], [], [], []
    for path in files:
        text = path.read_text()
        try:
            document = open_document(path)
            renderer = renderer_for(document)
            times = sample_times(path, document, args.references)
            scores = [iou(union_mask(document, renderer, t, args.size), reference)
                      for t, reference in zip(times, reference_frames(path, text, times, args.size,
                                                                      args.references))]
        except InputError as exc:
            refused.append(path)
            print(f"refused  {path.name}: {exc}")
            continue
        except Exception as exc:  # noqa: BLE001: a benchmark counts internal errors instead of stopping
            crashed.append(path)
            print(f"crashed  {path.name}: {type(exc).__name__}: {exc}")
            continue
        opened.append((path, document, renderer, times))
        good = min(scores) >= IOU_TARGET
        if good:
            matched.append(path)
        print(f"{'ok      ' if good else 'MISMATCH'} {path.name}: IoU {' '.join(f'{s:.3f}' for s in scores)} "
              f"at {' '.join(f'{t:g}' for t in times)} s")
    total = len(files)
    print(f"\n{len(matched)}/{total} files ({100 * len(matched) / max(total, 1):.1f} %) within IoU {IOU_TARGET} of "
          f"Chromium at 4 times; {len(refused)} refused, {len(crashed)} crashed")
    layer_frames, seconds = 0, 0.0
    for path, document, renderer, times in opened:
        first, end = document.frame_range(FPS)
        span = max(end - first, 1) / FPS
        for layer in document.layer_names():
            for step in range(args.timing_frames):
                start = time.perf_counter()
                renderer.render(document, [layer], span * step / args.timing_frames, (512, 512))
                seconds += time.perf_counter() - start
                layer_frames += 1
    if layer_frames:
        load = " ".join(f"{value:.2f}" for value in os.getloadavg())
        print(f"rasterization at 512x512: {1000 * seconds / layer_frames:.2f} ms per layer-frame "
              f"({layer_frames} layer-frames, {seconds:.1f} s; load average {load})")


if __name__ == "__main__":
    main()
