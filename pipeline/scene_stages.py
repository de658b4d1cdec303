"""The scene stages of a render: background, composite, encode (see :mod:`fluidymation.pipeline.stage`).

* ``background`` makes the static paper: a solid colour, an image, or paper grown from
  a paper image or from an exemplar's unpainted paper.
* ``composite`` lays every layer's colorized frames in z-order over the paper and
  writes the frames (``render --until composite``).
* ``encode`` writes the MP4 (and the frames with ``output.frames``, a GIF/WebP with
  ``output.preview``), compositing each frame as it goes: it repeats ``composite``.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from fluidymation.errors import SceneError, StageError
from fluidymation.pipeline.cache import file_digest
from fluidymation.pipeline.parameters import layer_guide_params
from fluidymation.pipeline.progress import progress
from fluidymation.pipeline.resolve import Plan, PlannedLayer
from fluidymation.pipeline.stage import SCENE, Done, Stage
from fluidymation.stages import background, composite, encode
from fluidymation.stages.colour import parse_hex
from fluidymation.stages.files import read_image, write_png


# --- background ------------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class BackgroundSettings:
    """The scene's ``background:`` entry, the output size and the scene's seed."""

    spec: dict
    size: tuple[int, int]
    seed: int


def _background_settings(work) -> BackgroundSettings:
    return BackgroundSettings(work.plan.scene.background, work.plan.size, work.plan.scene.seed)


def _background_inputs(work) -> dict:
    plan, spec = work.plan, work.plan.scene.background
    if spec.get("path") is not None:
        return {"file": file_digest(spec["path"])}
    if spec["type"] == "synthesized":
        return {"exemplar": work.for_layer(background_layer(plan, spec.get("exemplar"))).exemplar_identity}
    return {}


def _run_background(work, key: str) -> Done:
    write_png(work.out / "background.png", make_background(work))
    return Done([work.out / "background.png"])


def make_background(work) -> np.ndarray:
    """The scene's static paper, (H, W, 3) sRGB: a solid colour, an image, or synthesized paper."""
    plan = work.plan
    spec, size = plan.scene.background, plan.size
    if spec["type"] == "solid":
        return background.solid(parse_hex(spec["color"]), size)
    if spec["type"] == "image":
        return background.image(spec["path"], size)
    if spec.get("path") is not None:
        sample = read_image(spec["path"], channels=3)
    else:
        source = work.for_layer(background_layer(plan, spec.get("exemplar"))).source
        sample = background.paper_sample(source.rgb, source.segment)
    with progress(1, "background", quiet=work.quiet, unit="image"):
        return background.synthesized(sample, size, seed=plan.scene.seed)


def background_layer(plan: Plan, exemplar: str | None) -> PlannedLayer:
    """A layer whose exemplar gives the paper: the named exemplar, or the bottom layer's."""
    bottom = min(plan.layers, key=lambda layer: layer.z)
    if exemplar is None:
        return bottom
    if exemplar not in plan.scene.exemplars:
        raise SceneError(f"{plan.scene.path}: background.exemplar: no exemplar called '{exemplar}' "
                         f"(defined: {', '.join(plan.scene.exemplars) or 'none'})")
    layer = dataclasses.replace(bottom, spec=dataclasses.replace(bottom.spec, exemplar=exemplar))
    layer_guide_params(plan, layer)  # its guides parameters are valid
    return layer


# --- composite and encode ----------------------------------------------------------------------------------------

@dataclass(frozen=True)
class CompositeSettings:
    """The layers bottom to top, each (name, blend, opacity), and the frames."""

    layers: tuple[tuple[str, str, float], ...]
    frames: tuple[int, int]


def _composite_settings(work) -> CompositeSettings:
    return CompositeSettings(tuple((layer.name, layer.spec.blend, layer.spec.opacity) for layer in _bottom_up(work)),
                             work.frame_span)


@dataclass(frozen=True)
class EncodeSettings:
    """The scene's ``output:`` entry, the frame rate and the frames."""

    output: dict
    fps: float
    frames: tuple[int, int]


def _encode_settings(work) -> EncodeSettings:
    return EncodeSettings(dataclasses.asdict(work.plan.scene.output), work.plan.fps, work.frame_span)


def _bottom_up(work) -> list[PlannedLayer]:
    return sorted(work.plan.layers, key=lambda layer: layer.z)


def _run_composite(work, key: str) -> Done:
    return _composite(work, encode_video=False)


def _run_encode(work, key: str) -> Done:
    return _composite(work, encode_video=True)


def _composite(work, *, encode_video: bool) -> Done:
    """Composite the window's frames of every layer over the paper; write the frames and/or the video."""
    plan, out, output = work.plan, work.out, work.plan.scene.output
    ordered = _bottom_up(work)
    for layer in ordered:
        if not work.cache.hit("colorize", layer.name, work.keys.key("colorize", layer.name)):
            raise StageError(f"layer '{layer.name}' has not been colorized for these frames in {out}: render it "
                             f"(fluidymation render SCENE --layer '{layer.name}') before compositing")
    paper = read_image(out / "background.png", channels=3)
    files, previews = [], []

    def frames():
        with progress(len(work.window), "composite", quiet=work.quiet) as bar:
            for frame in work.window:
                name = f"{frame - plan.start:05d}.png"
                image = composite.composite(paper, [
                    (read_image(out / "layers" / layer.dirname / name, channels=4), layer.spec.blend,
                     layer.spec.opacity) for layer in ordered])
                if output.frames or not encode_video:
                    write_png(out / "frames" / name, image)
                    files.append(out / "frames" / name)
                if output.preview and encode_video:
                    previews.append(encode.preview_frame(image))
                bar.update()
                yield image

    if encode_video:
        video = out / output.video
        encode.encode_mp4(frames(), video, params=encode.Params(fps=plan.fps, crf=output.crf))
        files.append(video)
        if output.preview:
            encode.write_animation(previews, video.with_suffix(f".{output.preview}"), fps=plan.fps)
            files.append(video.with_suffix(f".{output.preview}"))
    else:
        for _ in frames():
            pass
    return Done(files)


SCENE_STAGES = (
    Stage("background", SCENE, background.VERSION, _background_settings, _run_background, inputs=_background_inputs,
          frames=lambda work: 1),
    Stage("composite", SCENE, composite.VERSION, _composite_settings, _run_composite,
          upstream=("colorize", "background")),
    Stage("encode", SCENE, encode.VERSION, _encode_settings, _run_encode, repeats=("composite",)),
)
