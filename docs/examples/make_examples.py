"""Regenerate the README's example videos and stills in docs/examples/ from the bundled examples.

Run from the repository: ``.venv/bin/python docs/examples/make_examples.py [NAME ...]``
(names: wave, blob, squiggle, puff, map, boil, ablate-blob, flow-gear, compare-boat, boil-resynth; default all). Each example scene is
rendered with the installed ``fluidymation`` into its own ``examples/<name>/out/``; its video
is copied here and five of its frames are laid side by side, 4 px apart, as ``<name>.jpg``.
``ablate-blob`` runs ``fluidymation ablate`` on the blob layer and keeps one frame of its
side-by-side video. ``flow-gear`` renders ``examples/gear`` three times, with its motion from
the masks (``flow: masks``), from the geometry (``flow: vector``, the default) and from the
geometry with the stylizer's ``carry: true``, and sets the videos side by side, labelled
(``flow-gear.mp4``; frame 24 as ``flow-gear.jpg``). ``compare-boat`` runs ``fluidymation compare``
on the boat of ``examples/map`` with the still, lazyfluids and fluidymation stylizers and keeps
its contact sheet (``compare-boat.jpg``). ``boil-resynth`` runs ``fluidymation resynth`` on
``examples/boil/clip`` for 48 frames and lays five of them side by side, over the clip's paper.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import imageio.v3 as iio
import numpy as np

from fluidymation.stages.encode import Params as EncodeParams
from fluidymation.stages.encode import encode_mp4
from fluidymation.stages.labels import label_strip

REPOSITORY = Path(__file__).resolve().parents[2]
HERE = Path(__file__).resolve().parent
#: Which frames of each example's video make its still.
STILL_FRAMES = {"wave": (0, 12, 24, 36, 47), "blob": (0, 12, 24, 36, 47), "squiggle": (2, 8, 14, 20, 23),
                "puff": (0, 6, 12, 18, 23), "map": (0, 6, 12, 18, 23), "boil": (0, 8, 16, 24, 32, 40)}
RESYNTH_FRAMES = (0, 12, 24, 36, 47)
ABLATION_FRAME = 24
GAP = 4


def fluidymation(*arguments: str) -> None:
    subprocess.run([sys.executable, "-m", "fluidymation", *arguments], cwd=REPOSITORY, check=True)


def side_by_side(frames: list[np.ndarray]) -> np.ndarray:
    """Frames in a row, ``GAP`` white pixels apart."""
    height = frames[0].shape[0]
    gap = np.full((height, GAP, 3), 255, np.uint8)
    row = [frames[0]]
    for frame in frames[1:]:
        row += [gap, frame]
    return np.concatenate(row, axis=1)


def make_example(name: str) -> None:
    fluidymation("render", f"examples/{name}/scene.yaml")
    video = REPOSITORY / "examples" / name / "out" / f"{name}.mp4"
    shutil.copyfile(video, HERE / f"{name}.mp4")
    frames = iio.imread(video, plugin="pyav")
    iio.imwrite(HERE / f"{name}.jpg", side_by_side([frames[index] for index in STILL_FRAMES[name]]), quality=90)


def make_ablation() -> None:
    fluidymation("ablate", "examples/blob/scene.yaml", "--layer", "blob")
    video = REPOSITORY / "examples" / "blob" / "out" / "ablate" / "blob.mp4"
    shutil.copyfile(video, HERE / "ablate-blob.mp4")
    iio.imwrite(HERE / "ablate-blob.jpg", iio.imread(video, plugin="pyav", index=ABLATION_FRAME), quality=90)


def make_flow_comparison() -> None:
    gear = REPOSITORY / "examples" / "gear"
    fluidymation("render", str(gear / "scene.yaml"))
    videos = []
    for variant, defaults in (("masks", "{flow: masks}"), ("carry", "{params: {carry: true}}")):
        scene = gear / "out" / variant / "scene.yaml"  # the same scene, the variant's defaults added
        scene.parent.mkdir(parents=True, exist_ok=True)
        scene.write_text((gear / "scene.yaml").read_text().replace("input: gear.svg", "input: ../../gear.svg")
                         .replace("output: {dir: out,", "output: {dir: .,") + f"defaults: {defaults}\n")
        fluidymation("render", str(scene))
        videos.append(iio.imread(scene.parent / "gear.mp4", plugin="pyav"))
    videos.insert(1, iio.imread(gear / "out" / "gear.mp4", plugin="pyav"))
    captions = label_strip(["flow: masks", "flow: vector", "flow: vector, carry: true"], width=videos[0].shape[2])
    frames = [side_by_side([np.concatenate([(caption * 255).astype(np.uint8), video[index]])
                            for caption, video in zip(captions, videos)]) for index in range(len(videos[0]))]
    encode_mp4(frames, HERE / "flow-gear.mp4", params=EncodeParams(fps=24))
    iio.imwrite(HERE / "flow-gear.jpg", frames[ABLATION_FRAME], quality=90)


def make_stylizer_comparison() -> None:
    fluidymation("compare", "examples/map/scene.yaml", "--layer", "boat", "--stylizers", "still,lazyfluids,fluidymation")
    sheet = iio.imread(REPOSITORY / "examples" / "map" / "out" / "compare" / "boat.png")
    iio.imwrite(HERE / "compare-boat.jpg", sheet[..., :3], quality=90)


def make_resynthesis() -> None:
    out = REPOSITORY / "examples" / "boil" / "out" / "resynth"
    fluidymation("resynth", "examples/boil/clip", "-o", str(out), "--frames", "48")
    frames = iio.imread(out / "resynth.mp4", plugin="pyav")
    iio.imwrite(HERE / "boil-resynth.jpg", side_by_side([frames[index] for index in RESYNTH_FRAMES]), quality=90)


SPECIAL = {"ablate-blob": make_ablation, "flow-gear": make_flow_comparison, "compare-boat": make_stylizer_comparison,
           "boil-resynth": make_resynthesis}


def main() -> None:
    names = sys.argv[1:] or [*STILL_FRAMES, *SPECIAL]
    for name in names:
        if name in SPECIAL:
            SPECIAL[name]()
        elif name in STILL_FRAMES:
            make_example(name)
        else:
            sys.exit(f"unknown example {name!r}: choose from {', '.join([*STILL_FRAMES, *SPECIAL])}")


if __name__ == "__main__":
    main()
