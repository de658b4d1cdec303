"""The edge band of a real example: is there a seam ring, and is the paint as contrasted as the exemplar's?

Run: ``NUMBA_CACHE_DIR=.numba-cache .venv/bin/python tests/benchmarks/bench_edge_band.py
[--param NAME=VALUE ...] [--crop OUT.png]``.

Renders layer ``blob`` of ``examples/blob`` (frames 0–24, built-in watercolor-bloom at its
default size) through the CLI into a temporary folder and prints, over those frames and
with the layer's alpha as the mask (:mod:`fluidymation.quality`): the edge-gradient
profile's peak/median over bands 5–40 px and the profile of bands 1–20 over that median,
then the local contrast over the exemplar's. ``--crop`` writes frame 24 of the layer over
paper, 3× enlarged around the blob; with ``--before BEFORE.png`` (a crop written the same
way by an older commit) it writes the two side by side, the README's before/after of the
edge band. Run it from a checkout of an older commit to measure the stylizer before a change.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import yaml
from PIL import Image

from bench_quality import over_paper, overrides, profile_curve
from fluidymation import quality
from fluidymation.pipeline import paths
from fluidymation.pipeline.presets import resolve_params
from fluidymation.stages import exemplar_builtin

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "blob"
FRAMES = 25
CROP_FRAME = 24
#: rows and columns of the crop, around the blob at frame 24
CROP = (slice(70, 200), slice(50, 200))
ZOOM = 3
#: white columns between the before and after crops
GAP = 8


def render(workdir: Path, params: dict) -> list[np.ndarray]:
    """The layer's RGBA frames (float, 0–1), rendered by the CLI with ``params`` as the scene's defaults."""
    scene = yaml.safe_load((EXAMPLE / "scene.yaml").read_text())
    scene["layers"] = [layer for layer in scene["layers"] if layer["name"] == "blob"]
    # a scene takes a list parameter as text ("2, 1")
    scene["defaults"] = {"params": {name: ", ".join(map(str, value)) if isinstance(value, tuple) else value
                                    for name, value in params.items()}}
    scene["output"] = {"dir": "out", "video": "blob.mp4"}
    shutil.copy(EXAMPLE / scene["input"], workdir / scene["input"])
    (workdir / "scene.yaml").write_text(yaml.safe_dump(scene))
    subprocess.run([sys.executable, "-m", "fluidymation", "-q", "render", str(workdir / "scene.yaml"),
                    "--frames", f"0:{FRAMES}", "--until", "stylize"], check=True)
    folder = workdir / "out" / "stylized" / "blob"
    return [np.asarray(Image.open(folder / f"{t:05d}.png").convert("RGBA"), np.float32) / 255 for t in range(FRAMES)]


def exemplar_contrast() -> float:
    """Mean local contrast of the built-in watercolor-bloom at its default size, in its masks."""
    made = exemplar_builtin.make_builtin_exemplar(resolve_params("watercolor-bloom"), cache_dir=paths.exemplar_cache_dir())
    return float(np.mean([quality.local_contrast(frame, mask) for frame, mask in zip(made.rgb, made.mask)]))


def crop(frame: np.ndarray) -> Image.Image:
    part = (np.clip(over_paper(frame)[CROP], 0, 1) * 255).astype(np.uint8)
    return Image.fromarray(part).resize((part.shape[1] * ZOOM, part.shape[0] * ZOOM), Image.LANCZOS)


def side_by_side(before: Image.Image, after: Image.Image) -> Image.Image:
    """``before`` and ``after`` in one image, a white gap between them."""
    pair = Image.new("RGB", (before.width + GAP + after.width, max(before.height, after.height)), "white")
    pair.paste(before.convert("RGB"), (0, 0))
    pair.paste(after, (before.width + GAP, 0))
    return pair


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                        help="a stylizer parameter instead of its default (YAML value; repeatable)")
    parser.add_argument("--crop", type=Path, help="write frame 24's crop here")
    parser.add_argument("--before", type=Path, help="with --crop: an older crop to put on the left")
    args = parser.parse_args()
    if args.before and not args.crop:
        parser.error("--before needs --crop")
    params = overrides(args.param)
    with tempfile.TemporaryDirectory() as workdir:
        frames = render(Path(workdir), params)
    rgb, masks = [f[..., :3] for f in frames], [f[..., 3] for f in frames]
    profile, counts = quality.gradient_profile(rgb, masks)
    peak, band = quality.profile_peak_ratio(profile, counts)
    contrast = np.mean([quality.local_contrast(frame, mask) for frame, mask in zip(rgb, masks)])
    print(f"params {params or 'defaults'}")
    print(f"profile peak/median (bands 5-40) {peak:.2f} at band {band}")
    print("bands 1-20 / median:", " ".join(f"{value:.2f}" for value in profile_curve(profile, counts)))
    print(f"local contrast / exemplar's {contrast / exemplar_contrast():.2f}")
    if args.crop:
        after = crop(frames[CROP_FRAME])
        (side_by_side(Image.open(args.before), after) if args.before else after).save(args.crop)
        print(f"wrote {args.crop}")


if __name__ == "__main__":
    main()
