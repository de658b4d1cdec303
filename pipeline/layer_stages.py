"""The per-layer stages of a render: masks, guides, stylize, colorize (see :mod:`fluidymation.pipeline.stage`).

* ``masks`` rasterizes the layer's vector layers: binary masks, soft coverage and the
  layer's summary record (fill colour, z-order, areas) in its manifest; with ``flow:
  vector`` also each frame's motion read from the geometry (``motion/``, NaN where
  unknown). Its key holds the input files' content, the reader and the renderer.
* ``guides`` writes views of the target guides (only with ``render --until guides``:
  stylize computes the guides itself, so it *repeats* this stage).
* ``stylize`` runs the layer's stylizer (a plugin, :mod:`fluidymation.pipeline.stylizers`)
  over the render's frames, saving its state after every frame for resume.
* ``colorize`` re-renders the stylized paint in the layer's colour.
"""

from __future__ import annotations

import functools
import logging
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from fluidymation.errors import StageError
from fluidymation.pipeline.cache import file_digest
from fluidymation.pipeline.executors import run_jobs
from fluidymation.pipeline.parameters import layer_colorize, layer_guide_params
from fluidymation.pipeline.progress import progress, reporter
from fluidymation.pipeline.resolve import Plan, PlannedLayer
from fluidymation.pipeline.resume import FrameStates
from fluidymation.pipeline.stage import LAYER, Done, Stage
from fluidymation.stages import colorize, guides, motion, rasterize
from fluidymation.stages.colour import parse_hex
from fluidymation.stages.exemplar_store import StoredSource
from fluidymation.stages.files import read_image, write_npy, write_png
from fluidymation.stages.guide_views import VIEWS, write_guide_views
from fluidymation.stages.keyframe_stylizer import painted_frame
from fluidymation.stages.keyframes import read_keyframe
from fluidymation.stages.stylizer import StylizeJob, Stylizer

#: Version of the stylize stage's own work (files, resume); the stylizer's version is in its key too.
STYLIZE_VERSION = 1

log = logging.getLogger(__name__)


# --- masks -----------------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class MaskSettings:
    """What the masks depend on besides the input: the selection, the scene's range, size and frame rate."""

    select: tuple[str, ...]
    start: int
    end: int
    raster: rasterize.Params
    flow: str


def _mask_settings(work) -> MaskSettings:
    plan = work.plan
    return MaskSettings(work.layer.vector_layers, plan.start, plan.end, rasterize.Params(size=plan.size, fps=plan.fps),
                        work.layer.flow)


def _mask_inputs(work) -> dict:
    return work.plan.drawing_record()


def _run_masks(work, key: str) -> Done:
    plan, layer, out = work.plan, work.layer, work.out
    with progress(plan.frame_count, "masks", layer=layer.name, quiet=work.quiet) as bar:
        record = rasterize_layer(plan, layer, range(plan.start, plan.end), out / "masks" / layer.dirname,
                                 coverage_dir=out / "coverage" / layer.dirname,
                                 colour_dir=out / "colour" / layer.dirname, bar=bar)
    files = [out / folder / layer.dirname / f"{k:05d}.png" for folder in ("masks", "coverage", "colour")
             for k in range(plan.frame_count)]
    if layer.flow == "vector":
        with progress(plan.frame_count, "motion", layer=layer.name, quiet=work.quiet) as bar:
            files += write_layer_motion(plan, layer, out / "motion" / layer.dirname, bar=bar)
    return Done(files, manifest={"record": record})


def write_layer_motion(plan: Plan, layer: PlannedLayer, motion_dir: Path, *, bar=None) -> list[Path]:
    """Each scene frame's motion read from the layer's geometry (:mod:`fluidymation.stages.motion`) as .npy.

    What the geometry does not describe is NaN (the guides take the masks' estimate there);
    the elements left to the masks are named in one warning.
    """
    unread: dict[str, None] = {}
    files = []
    for frame in range(plan.start, plan.end):
        if plan.frame_count == 1:
            flow = np.zeros((plan.size[1], plan.size[0], 2), np.float32)  # no second frame, no motion
        else:
            flow, missed = motion.frame_motion(plan.document, layer.vector_layers, frame, plan.fps, plan.size,
                                               first=frame == plan.start)
            unread.update(dict.fromkeys(missed))
        files.append(motion_dir / f"{frame - plan.start:05d}.npy")
        write_npy(files[-1], flow)
        if bar is not None:
            bar.update()
    if unread:
        names = list(unread)
        log.warning("layer '%s': flow: vector does not read %s%s; the masks' motion estimate is used there",
                    layer.name, ", ".join(names[:5]), f" and {len(names) - 5} more" if len(names) > 5 else "")
    return files


def layer_motion(out: Path, layer: PlannedLayer):
    """The masks stage's motion of ``layer`` as ``given_flow(j)`` for the guides, or None with ``flow: masks``."""
    return motion_reader(out / "motion" / layer.dirname) if layer.flow == "vector" else None


def motion_reader(folder: Path):
    """``given_flow(j)`` reading the motion files :func:`write_layer_motion` wrote to ``folder``."""
    return lambda j: np.load(folder / f"{j:05d}.npy")


def rasterize_layer(plan: Plan, layer: PlannedLayer, frames: range, masks_dir: Path, *,
                    coverage_dir: Path | None = None, colour_dir: Path | None = None, bar=None) -> dict:
    """Write the layer's masks (0/255; soft coverage into ``coverage_dir``, its straight colour into
    ``colour_dir``) for scene ``frames``.

    Files are numbered from the scene's start. ``bar`` is advanced once per frame.
    Returns the layer's summary record: selection, colour (the scene's, else the fill), the
    vector file's dominant fill colour, z-order, mask areas.
    """
    raster = rasterize.Params(size=plan.size, fps=plan.fps)
    tally, areas = rasterize.ColorTally(), []
    for frame in frames:
        name = f"{frame - plan.start:05d}.png"
        image = rasterize.rasterize_frame(plan.renderer, plan.document, layer.vector_layers, frame, raster)
        write_png(masks_dir / name, image.mask.astype(np.uint8) * 255)
        if coverage_dir is not None:
            write_png(coverage_dir / name, image.coverage)
        if colour_dir is not None:
            write_png(colour_dir / name, image.straight_rgb)
        tally.add(image.rgba)
        areas.append(int(image.mask.sum()))
        if bar is not None:
            bar.update()
    fill = tally.dominant()
    return {"name": layer.name, "folder": layer.dirname, "select": list(layer.vector_layers),
            "color": layer.spec.color or fill, "fill": fill, "z": layer.z, "area": areas}


def read_coverage(coverage_dir: Path, index: int) -> np.ndarray:
    """Frame ``index``'s soft coverage, (H, W) float32, as written by :func:`rasterize_layer`."""
    return read_image(coverage_dir / f"{index:05d}.png", channels=1)[:, :, 0]


def layer_colour_dir(coverage_dir: Path) -> Path:
    """Where the masks stage wrote the straight colour of the layer whose coverage is in ``coverage_dir``."""
    return coverage_dir.parent.parent / "colour" / coverage_dir.name


def read_colour(colour_dir: Path, index: int) -> np.ndarray:
    """Frame ``index``'s straight colour, (H, W, 3) float32, as written by :func:`rasterize_layer`."""
    return read_image(colour_dir / f"{index:05d}.png", channels=3)


# --- guides ----------------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class GuideSettings:
    """The guides' parameters and the frames whose views are written."""

    guides: guides.Params
    frames: tuple[int, int]


def _guide_settings(work) -> GuideSettings:
    return GuideSettings(work.guide_params, work.frame_span)


def _run_guides(work, key: str) -> Done:
    plan, layer = work.plan, work.layer
    out_dir = work.out / "guides" / layer.dirname
    write_layer_guides(plan, layer, work.window, lambda j: read_coverage(work.out / "coverage" / layer.dirname, j),
                       out_dir, quiet=work.quiet, given_flow=layer_motion(work.out, layer))
    return Done([out_dir / view / f"{frame - plan.start:05d}.png" for view in VIEWS for frame in work.window])


def write_layer_guides(plan: Plan, layer: PlannedLayer, window: range, coverage, out_dir: Path, *, quiet=False,
                       raw=False, given_flow=None) -> None:
    """Guides of ``layer`` over the scene range (masks from ``coverage(index)``), views of ``window`` to ``out_dir``."""
    with progress(1, "guides", layer=layer.name, quiet=quiet, unit="step") as bar:
        write_guide_views(coverage, plan.frame_count, out_dir, params=layer_guide_params(plan, layer), raw=raw,
                          given_flow=given_flow, frames=(window.start - plan.start, window.stop - plan.start),
                          progress=reporter(bar))


# --- stylize ---------------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class StylizeSettings:
    """The stylizer (name, version, parameters), the frames it paints, ``nnf``: also write each frame's NNF, and
    the layer's ``segments`` and ``segment_map`` (its regions)."""

    stylizer: str
    stylizer_version: int
    params: Any
    frames: tuple[int, int]
    nnf: bool
    segments: str
    segment_map: tuple


def _stylize_settings(work) -> StylizeSettings:
    stylizer, spec = work.stylizer, work.layer.spec
    return StylizeSettings(stylizer.name, stylizer.version, work.stylize_params, work.frame_span, work.options.nnf,
                           spec.segments, spec.segment_map)


def _stylize_inputs(work) -> dict:
    if work.stylizer.uses_keyframes:
        return {"keyframes": [[frame, file_digest(path)] for frame, path in work.layer.spec.keyframes]}
    return {"exemplar": work.exemplar_identity}


def _run_stylize(work, key: str) -> Done:
    plan, layer, options, stylizer = work.plan, work.layer, work.options, work.stylizer
    if options.nnf and not stylizer.writes_nnf:
        raise StageError(f"layer '{layer.name}': --nnf: the stylizer '{stylizer.name}' has no nearest-neighbour field")
    out_dir = work.out / "stylized" / layer.dirname
    states = FrameStates(work.cache.begin("stylize", layer.name, key), stylizer)
    order = stylizer.processing_order(range(work.window.start - plan.start, work.window.stop - plan.start),
                                      work.stylize_params)
    resume = states.resume_point(order, lambda index: all(
        path.is_file() for path in stylized_files(out_dir, index, nnf=options.nnf)))
    if resume is not None:
        log.debug("stylize %s: resuming after frame %d (%d of %d frames were finished)",
                  layer.name, order[resume[0] - 1], resume[0], len(order))
    source = None if stylizer.uses_keyframes else work.source
    files = stylize_layer(plan, layer, work.window, source, stylizer, work.stylize_params, work.guide_params,
                          coverage_dir=work.out / "coverage" / layer.dirname, out_dir=out_dir, quiet=work.quiet,
                          nnf=options.nnf, states=states, resume=resume, given_flow=layer_motion(work.out, layer),
                          map_tasks=functools.partial(run_jobs, executor=options.executor, jobs=options.jobs))
    return Done(files, report={"resumed": 0 if resume is None else resume[0]})


def stylized_files(out_dir: Path, index: int, *, nnf=False) -> list[Path]:
    """The files of stylized frame ``index`` in ``out_dir``: its PNG, and its NNF with ``nnf``."""
    return [out_dir / f"{index:05d}.png"] + ([out_dir / "nnf" / f"{index:05d}.npy"] if nnf else [])


def stylize_layer(plan: Plan, layer: PlannedLayer, window: range, source: StoredSource | None, stylizer: Stylizer,
                  params, guide_params: guides.Params, *, coverage_dir: Path, out_dir: Path, quiet=False, nnf=False,
                  states: FrameStates | None = None, resume: tuple[int, Any] | None = None,
                  given_flow=None, map_tasks=None) -> list[Path]:
    """Stylize a layer's window of scene frames (coverage read from ``coverage_dir``) into ``out_dir``
    (``given_flow``: the layer's motion from its geometry, :func:`layer_motion`; ``source``: its
    exemplar, None for a stylizer that paints from keyframes).

    Returns the window's files. With ``states``, each frame's state is saved after its
    files; ``resume`` (from :meth:`FrameStates.resume_point`) continues after the frames
    an interrupted run finished, and the stylizer's work folder lives in the states' folder
    (else next to ``out_dir``, like its scratch folder). ``map_tasks`` runs the stylizer's
    independent tasks (default: here, one after the other).
    """
    out_dir.mkdir(parents=True, exist_ok=True)
    finished, after = (0, None) if resume is None else resume
    keyframes = {frame - plan.start: path for frame, path in layer.spec.keyframes}
    with tempfile.TemporaryDirectory(prefix=".guides-", dir=out_dir.parent) as cache_dir, \
            progress(len(window), "stylize", layer=layer.name, quiet=quiet) as bar:
        bar.update(finished)
        work_dir = str(states.folder / "work") if states is not None else str(Path(cache_dir) / "work")
        colour_dir = layer_colour_dir(coverage_dir)
        job = StylizeJob(masks=lambda j: read_coverage(coverage_dir, j), frame_count=plan.frame_count,
                         frames=(window.start - plan.start, window.stop - plan.start), source=source,
                         guide_params=guide_params, cache_dir=cache_dir, resume=after, given_flow=given_flow,
                         keyframes=keyframes, work_dir=work_dir, map_tasks=map_tasks,
                         colours=lambda j: read_colour(colour_dir, j), segments=layer.spec.segments,
                         segment_map=layer.spec.segment_map, layer=layer.name)
        for result in stylizer.stylize(job, params):
            png, *nnf_file = stylized_files(out_dir, result.index, nnf=nnf)
            write_png(png, result.rgba)
            if nnf_file:
                write_npy(nnf_file[0], result.nnf.as_array())
            if states is not None:
                states.save(result)
            bar.update()
    return [path for frame in window for path in stylized_files(out_dir, frame - plan.start, nnf=nnf)]


# --- colorize --------------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class ColorizeSettings:
    """``colorize:`` (``layer``, ``none`` or a colour), the layer's own ``color:`` (None: the vector fill,
    which the masks key determines) and the frames."""

    mode: str
    color: str | None
    frames: tuple[int, int]


def _colorize_settings(work) -> ColorizeSettings:
    return ColorizeSettings(layer_colorize(work.plan, work.layer), work.layer.spec.color, work.frame_span)


def _run_colorize(work, key: str) -> Done:
    params = layer_colorize_params(work.plan, work.layer, work.record["fill"])
    return Done(colorize_layer(work.plan, work.layer, work.window, work.paint, params, work.out, quiet=work.quiet))


def layer_colorize_params(plan: Plan, layer: PlannedLayer, fill_color: str | None) -> colorize.Params:
    """How a layer is colorized: ``colorize: layer`` (its colour or the vector fill), a ``#rrggbb``, or ``none``."""
    mode = layer_colorize(plan, layer)
    if mode == "none":
        return colorize.Params(mode="none")
    hex_color = mode if mode != "layer" else (layer.spec.color or fill_color or "#000000")
    return colorize.Params(mode="layer", color=tuple(float(c) for c in parse_hex(hex_color)))


class KeyframePaint:
    """A keyframe layer's paint as colorize reads an exemplar: ``rgb`` (its keyframes over white paper) and
    ``segment`` (0 where painted, −1 on the paper)."""

    def __init__(self, plan: Plan, layer: PlannedLayer, coverage_dir: Path):
        painted = [read_keyframe(path, frame, read_coverage(coverage_dir, frame - plan.start))
                   for frame, path in layer.spec.keyframes]
        self.rgb = np.stack([painted_frame(rgba, rgba[..., 3])[..., :3] for rgba in painted])
        self.segment = np.stack([np.where(rgba[..., 3] >= 0.5, 0, -1) for rgba in painted]).astype(np.int32)


def colorize_layer(plan: Plan, layer: PlannedLayer, window: range, source, params: colorize.Params, out: Path, *,
                   quiet=False) -> list[Path]:
    """Colorize the layer's stylized frames into ``out/layers/<layer>/``; return the files written.

    The paper and paint density are statistics over every frame of the layer's paint
    (``source``: its exemplar, or its :class:`KeyframePaint`): its colour and segments are
    read whole for them (16 bytes a pixel and frame), then released.
    """
    rgb, segment = source.rgb, source.segment
    paper = colorize.estimate_paper(rgb, segment)
    unit = colorize.full_density(rgb, segment, paper) if params.mode == "layer" else 1.0  # only layer colour uses it
    del rgb, segment
    written = []
    with progress(len(window), "colorize", layer=layer.name, quiet=quiet) as bar:
        for frame in window:
            name = f"{frame - plan.start:05d}.png"
            stylized = read_image(out / "stylized" / layer.dirname / name, channels=4)
            write_png(out / "layers" / layer.dirname / name, colorize.colorize(stylized, paper, unit, params))
            written.append(out / "layers" / layer.dirname / name)
            bar.update()
    return written


LAYER_STAGES = (
    Stage("masks", LAYER, rasterize.VERSION, _mask_settings, _run_masks, inputs=_mask_inputs,
          frames=lambda work: work.plan.frame_count),
    Stage("guides", LAYER, guides.VERSION, _guide_settings, _run_guides, upstream=("masks",)),
    Stage("stylize", LAYER, STYLIZE_VERSION, _stylize_settings, _run_stylize, inputs=_stylize_inputs,
          upstream=("masks",), repeats=("guides",)),
    Stage("colorize", LAYER, colorize.VERSION, _colorize_settings, _run_colorize, upstream=("masks", "stylize")),
)
