"""Render a scene: every stage in order, per layer and then for the whole scene.

Per layer: ``masks`` (rasterize; binary masks, soft coverage and the fill colour),
``guides`` (only as views, with ``--until guides``), ``stylize``, ``colorize``; then for
the scene: ``background``, ``composite`` and ``encode``. Every stage reads its inputs
from and writes its products to the output folder (DESIGN.md's output conventions) and
records them in the stage cache (:mod:`fluidymation.pipeline.cache`), so a later run, or
a run of a few layers only, redoes only the work whose inputs or parameters changed.

Each stage checks the cache, runs and commits while holding its lock, so renders of one
scene running at once wait for each other's work and reuse it. The stylize stage saves
its state after every frame (:mod:`fluidymation.pipeline.resume`), so a killed render
continues from its last finished frame. The layers are independent jobs that the
executor (:mod:`fluidymation.pipeline.executors`) may run in other processes or on a
Dask cluster; the scene stages run here once they are done.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from fluidymation.errors import SceneError, StageError
from fluidymation.pipeline.cache import StageCache, file_digest, stage_key
from fluidymation.pipeline.exemplars import exemplar_identity, layer_source, simulated_frame_count
from fluidymation.pipeline.executors import LOCAL, run_jobs
from fluidymation.pipeline.parameters import (
    check_layer_params, layer_guide_params, layer_stylize_params, preview_overrides,
)
from fluidymation.pipeline.progress import progress, reporter
from fluidymation.pipeline.resolve import Plan, PlannedLayer
from fluidymation.pipeline.resume import FrameStates
from fluidymation.stages import background, colorize, composite, encode, exemplar_store, rasterize, stylize
from fluidymation.stages.colour import parse_hex
from fluidymation.stages.files import read_image, write_npy, write_png, write_text
from fluidymation.stages.guide_views import write_guide_views

LAYER_STAGES = ("masks", "guides", "stylize", "colorize")
SCENE_STAGES = ("background", "composite", "encode")
STAGES = LAYER_STAGES + SCENE_STAGES

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Options:
    """What ``render`` was asked for: the last stage, layers, frames, quality and what to redo."""

    until: str = "encode"
    layers: tuple[str, ...] | None = None  # None: every layer
    window: tuple[int | None, int | None] | None = None
    preview: bool = False
    nnf: bool = False
    quiet: bool = False
    report: bool = True  # write report.json (commands that only prepare inputs leave the film's report alone)
    force: bool = False  # redo every stage
    force_stages: tuple[str, ...] = ()  # redo these stages
    jobs: int = 1  # layers rendered at once in local processes
    executor: str = LOCAL  # or dask://HOST:PORT


def scaled_plan(plan: Plan, scale: float) -> Plan:
    """The plan at ``scale`` times its output size (at least 8 px a side)."""
    if scale == 1.0:
        return plan
    width, height = (max(8, round(side * scale)) for side in plan.size)
    return dataclasses.replace(plan, size=(width, height))


class Report:
    """Time, frame count and cache hit per stage and layer, written to ``report.json``."""

    def __init__(self, plan: Plan, options: Options):
        self.started = time.perf_counter()
        self.entries: list[dict] = []
        self.header = {"scene": str(plan.scene.path), "size": list(plan.size), "fps": plan.fps,
                       "frames": {"start": plan.start, "end": plan.end}, "preview": options.preview,
                       "until": options.until}

    def stage(self, stage: str, layer: str | None, frames: int, started: float, *, cached: bool = False,
              **details) -> None:
        self.entries.append({"stage": stage, "layer": layer, "frames": frames, "cached": cached,
                             "seconds": round(time.perf_counter() - started, 3), **details})

    def write(self, path: Path) -> None:
        record = self.header | {"seconds": round(time.perf_counter() - self.started, 3),
                                "cache_hits": sum(entry["cached"] for entry in self.entries),
                                "stages": self.entries}
        write_text(path, json.dumps(record, indent=2) + "\n")


def output_dir(plan: Plan, options: Options) -> Path:
    """Where the render goes: ``output.dir``, or its ``preview/`` subfolder for previews."""
    return plan.scene.output.dir / "preview" if options.preview else plan.scene.output.dir


def render(plan: Plan, options: Options) -> Path:
    """Run the stages up to ``options.until`` (skipping work the cache holds); return the output folder."""
    if options.until not in STAGES:
        raise SceneError(f"--until {options.until!r}: not a stage; choose one of {', '.join(STAGES)}")
    for stage in options.force_stages:
        if stage not in STAGES:
            raise SceneError(f"--force-stage {stage!r}: not a stage; choose one of {', '.join(STAGES)}")
    chosen = [plan.layer(name) for name in options.layers] if options.layers else list(plan.layers)
    for layer in chosen:
        check_layer_params(plan, layer)
    run = _Run(plan, options)
    # workers elsewhere print to their own stderr: keep it quiet
    job_options = options if options.executor == LOCAL else dataclasses.replace(options, quiet=True)
    results = run_jobs(render_layer, [(plan, job_options, layer.name) for layer in chosen],
                       executor=options.executor, jobs=options.jobs)
    records = {}
    for layer, (record, entries) in zip(chosen, results):
        records[layer.name] = record
        run.report.entries.extend(entries)
    with run.cache.lock("layers", None):
        write_layers_summary(plan, records, run.out / "masks", range(plan.start, plan.end))
    if run.last >= STAGES.index("background"):
        background_key = run.background()
        if run.last >= STAGES.index("composite"):
            run.composite_and_encode(background_key)
    if options.report:
        run.report.write(run.out / "report.json")
    return run.out


def render_layer(plan: Plan, options: Options, name: str) -> tuple[dict, list[dict]]:
    """The per-layer stages of layer ``name`` (a job for the executor): its summary record and report entries."""
    run = _Run(plan, options)
    record = run.layer(plan.layer(name))
    return record, run.report.entries


@dataclass
class _Done:
    """What a stage run wrote: its files, fields for its manifest and for its ``report.json`` entry."""

    files: list[Path]
    manifest: dict = field(default_factory=dict)
    report: dict = field(default_factory=dict)


class _Run:
    """One render: the plan, options, output folder, cache and report its stages share."""

    def __init__(self, plan: Plan, options: Options):
        self.plan, self.options = plan, options
        self.out = output_dir(plan, options)
        self.window = plan.frames(options.window)
        self.last = STAGES.index(options.until)
        self.cache = StageCache(self.out)
        self.report = Report(plan, options)

    def _fresh(self, stage: str, layer: str | None, key: str) -> bool:
        """Whether the cache holds ``stage`` for ``layer`` under ``key`` (and it is not forced)."""
        forced = self.options.force or stage in self.options.force_stages
        return not forced and self.cache.hit(stage, layer, key)

    def _stage(self, stage: str, layer: str | None, key: str, frames: int, compute: Callable[[], _Done]) -> dict:
        """Run ``compute`` for ``stage`` of ``layer`` unless the cache holds it under ``key``; return its manifest.

        Holds the stage's lock from the cache check to the commit, so a concurrent render
        of the scene waits here and then finds the work done.
        """
        where = stage if layer is None else f"{stage} {layer}"
        with self.cache.lock(stage, layer):
            started = time.perf_counter()
            if self._fresh(stage, layer, key):
                log.debug("%s: cached (key %s)", where, key[:12])
                self.report.stage(stage, layer, frames, started, cached=True)
                return self.cache.lookup(stage, layer)
            log.debug("%s: running (key %s)", where, key[:12])
            self.cache.forget(stage, layer)
            done = compute()
            manifest = self.cache.commit(stage, layer, key, done.files, **done.manifest)
            self.report.stage(stage, layer, frames, started, **done.report)
            log.debug("%s: finished in %.2f s, %d files", where, time.perf_counter() - started, len(done.files))
            return manifest

    def _frame_span(self) -> list[int]:
        return [self.window.start - self.plan.start, self.window.stop - self.plan.start]

    def layer(self, layer: PlannedLayer) -> dict:
        """The per-layer stages; returns the layer's summary record (fill colour, z-order, areas)."""
        plan, out = self.plan, self.out
        masks_key = stage_key("masks", rasterize.VERSION, input=input_digest(plan), select=layer.vector_layers,
                              size=plan.size, fps=plan.fps, start=plan.start, end=plan.end)

        def masks() -> _Done:
            with progress(plan.frame_count, "masks", layer=layer.name, quiet=self.options.quiet) as bar:
                record = rasterize_layer(plan, layer, range(plan.start, plan.end), out / "masks" / layer.dirname,
                                         coverage_dir=out / "coverage" / layer.dirname, bar=bar)
            files = [out / folder / layer.dirname / f"{k:05d}.png" for folder in ("masks", "coverage")
                     for k in range(plan.frame_count)]
            return _Done(files, manifest={"record": record})

        record = self._stage("masks", layer.name, masks_key, plan.frame_count, masks)["record"]
        record["color"] = layer.spec.color or record["fill"]
        if self.options.until == "guides":
            started = time.perf_counter()
            write_layer_guides(plan, layer, self.window, lambda j: read_coverage(out / "coverage" / layer.dirname, j),
                               out / "guides" / layer.dirname, quiet=self.options.quiet)
            self.report.stage("guides", layer.name, len(self.window), started)
        if self.last >= STAGES.index("stylize"):
            self._stylize_and_colorize(layer, masks_key, record)
        return record

    def _stylize_and_colorize(self, layer: PlannedLayer, masks_key: str, record: dict) -> None:
        plan, out, options = self.plan, self.out, self.options
        guide_params = layer_guide_params(plan, layer)
        params = layer_stylize_params(plan, layer, **(preview_overrides() if options.preview else {}))
        stylize_key = stage_key("stylize", stylize.VERSION, masks=masks_key, exemplar=exemplar_identity(plan, layer),
                                guides=dataclasses.asdict(guide_params), params=dataclasses.asdict(params),
                                frames=self._frame_span(), nnf=options.nnf)
        sources = []

        def source() -> exemplar_store.StoredSource:  # opened only when a stage has to run
            if not sources:
                sources.append(load_layer_source(plan, layer, guide_params, options.quiet))
            return sources[0]

        def stylized() -> _Done:
            out_dir = out / "stylized" / layer.dirname
            states = FrameStates(self.cache.begin("stylize", layer.name, stylize_key))
            order = sorted((frame - plan.start for frame in self.window), reverse=params.reverse)
            resume = states.resume_point(order, lambda index: all(
                path.is_file() for path in stylized_files(out_dir, index, nnf=options.nnf)))
            if resume is not None:
                log.debug("stylize %s: resuming after frame %d (%d of %d frames were finished)",
                          layer.name, resume[1][0], resume[0], len(order))
            files = stylize_layer(plan, layer, self.window, source(), params, guide_params,
                                  coverage_dir=out / "coverage" / layer.dirname, out_dir=out_dir, quiet=options.quiet,
                                  nnf=options.nnf, states=states, resume=resume)
            return _Done(files, report={"resumed": 0 if resume is None else resume[0]})

        self._stage("stylize", layer.name, stylize_key, len(self.window), stylized)
        if self.last < STAGES.index("colorize"):
            return
        colorize_params = layer_colorize_params(layer, record["fill"])
        colorize_key = stage_key("colorize", colorize.VERSION, stylize=stylize_key,
                                 params=dataclasses.asdict(colorize_params), frames=self._frame_span())

        def colorized() -> _Done:
            files = colorize_layer(plan, layer, self.window, source(), colorize_params, out, quiet=options.quiet)
            return _Done(files, manifest={"frames": self._frame_span()})

        self._stage("colorize", layer.name, colorize_key, len(self.window), colorized)

    def background(self) -> str:
        """Make (or find in the cache) ``background.png``; return its key."""
        plan, spec = self.plan, self.plan.scene.background
        parts = {"spec": spec, "size": plan.size, "seed": plan.scene.seed}
        if spec.get("path") is not None:
            parts["file"] = file_digest(spec["path"])
        elif spec["type"] == "synthesized":
            parts["exemplar"] = exemplar_identity(plan, _background_layer(plan, spec.get("exemplar")))
        key = stage_key("background", background.VERSION, **parts)

        def paper() -> _Done:
            write_png(self.out / "background.png", make_background(plan, quiet=self.options.quiet))
            return _Done([self.out / "background.png"])

        self._stage("background", None, key, 1, paper)
        return key

    def composite_and_encode(self, background_key: str) -> None:
        """Composite the layers' colorized frames in z-order over the paper; encode unless stopping at composite."""
        plan, out, output = self.plan, self.out, self.plan.scene.output
        ordered = sorted(plan.layers, key=lambda layer: layer.z)
        layer_keys = []
        for layer in ordered:
            manifest = self.cache.lookup("colorize", layer.name)
            if (manifest is None or manifest.get("frames") != self._frame_span()
                    or not self.cache.hit("colorize", layer.name, manifest["key"])):
                raise StageError(f"layer '{layer.name}' has not been colorized for these frames in {out}: render it "
                                 f"(fluidymation render SCENE --layer '{layer.name}') before compositing")
            layer_keys.append([manifest["key"], layer.spec.blend, layer.spec.opacity])
        encode_video = self.last == len(STAGES) - 1
        stage = "composite+encode" if encode_video else "composite"
        key = stage_key(stage, composite.VERSION * 1000 + encode.VERSION, layers=layer_keys, background=background_key,
                        frames=self._frame_span(), fps=plan.fps, output=dataclasses.asdict(output))
        self._stage(stage, None, key, len(self.window), lambda: self._composite(ordered, encode_video))

    def _composite(self, ordered: list[PlannedLayer], encode_video: bool) -> _Done:
        """Composite the window's frames of ``ordered`` layers over the paper; write frames and/or the video."""
        plan, out, output = self.plan, self.out, self.plan.scene.output
        paper = read_image(out / "background.png", channels=3)
        files, previews = [], []

        def frames():
            with progress(len(self.window), "composite", quiet=self.options.quiet) as bar:
                for frame in self.window:
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
        return _Done(files)


def input_digest(plan: Plan) -> list[str]:
    """Content hashes of the scene's vector input (every file of a numbered sequence)."""
    return [file_digest(path) for path in plan.document.files]


def rasterize_layer(plan: Plan, layer: PlannedLayer, frames: range, masks_dir: Path, *,
                    coverage_dir: Path | None = None, bar=None) -> dict:
    """Write the layer's masks (0/255; and soft coverage into ``coverage_dir``) for scene ``frames``.

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
        tally.add(image.rgba)
        areas.append(int(image.mask.sum()))
        if bar is not None:
            bar.update()
    fill = tally.dominant()
    return {"name": layer.name, "folder": layer.dirname, "select": list(layer.vector_layers),
            "color": layer.spec.color or fill, "fill": fill, "z": layer.z, "area": areas}


def write_layers_summary(plan: Plan, records: dict, masks_dir: Path, frames: range) -> None:
    """``masks/layers.json``: the layers rasterized (records of other layers from earlier runs kept), in z-order."""
    path = masks_dir / "layers.json"
    known = {}
    if path.is_file():
        try:
            known = {item["name"]: item for item in json.loads(path.read_text())["layers"]}
        except (ValueError, KeyError, TypeError):
            known = {}
    names = {layer.name for layer in plan.layers}
    merged = {name: item for name, item in (known | records).items() if name in names}
    summary = {"input": str(plan.scene.input), "size": list(plan.size), "fps": plan.fps,
               "frames": {"start": frames.start, "end": frames.stop, "scene_start": plan.start},
               "layers": sorted(merged.values(), key=lambda item: item["z"])}
    write_text(path, json.dumps(summary, indent=2) + "\n")


def write_layer_guides(plan: Plan, layer: PlannedLayer, window: range, coverage, out_dir: Path, *, quiet=False,
                       raw=False, given_flow=None) -> None:
    """Guides of ``layer`` over the scene range (masks from ``coverage(index)``), views of ``window`` to ``out_dir``."""
    with progress(1, "guides", layer=layer.name, quiet=quiet, unit="step") as bar:
        write_guide_views(coverage, plan.frame_count, out_dir, params=layer_guide_params(plan, layer), raw=raw,
                          given_flow=given_flow, frames=(window.start - plan.start, window.stop - plan.start),
                          progress=reporter(bar))


def read_coverage(coverage_dir: Path, index: int) -> np.ndarray:
    """Frame ``index``'s soft coverage, (H, W) float32, as written by :func:`rasterize_layer`."""
    return read_image(coverage_dir / f"{index:05d}.png", channels=1)[:, :, 0]


def load_layer_source(plan: Plan, layer: PlannedLayer, guide_params, quiet=False) -> exemplar_store.StoredSource:
    """The layer's exemplar with its guides on disk (generated on first use), with a progress bar."""
    with progress(simulated_frame_count(plan, layer), "exemplar", layer=layer.name, quiet=quiet) as bar:
        return layer_source(plan, layer, guide_params, progress=bar.update)


def stylized_files(out_dir: Path, index: int, *, nnf=False) -> list[Path]:
    """The files of stylized frame ``index`` in ``out_dir``: its PNG, and its NNF with ``nnf``."""
    return [out_dir / f"{index:05d}.png"] + ([out_dir / "nnf" / f"{index:05d}.npy"] if nnf else [])


def stylize_layer(plan: Plan, layer: PlannedLayer, window: range, source: exemplar_store.StoredSource, params: stylize.Params,
                  guide_params, *, coverage_dir: Path, out_dir: Path, quiet=False, nnf=False,
                  states: FrameStates | None = None, resume: tuple[int, tuple] | None = None) -> list[Path]:
    """Stylize a layer's window of scene frames (coverage read from ``coverage_dir``) into ``out_dir``.

    Returns the window's files. With ``states``, each frame's state is saved after its
    files; ``resume`` (from :meth:`FrameStates.resume_point`) continues after the frames
    an interrupted run finished. The target guides live in a temporary folder next to ``out_dir``.
    """
    out_dir.mkdir(parents=True, exist_ok=True)
    finished, after = (0, None) if resume is None else resume
    with tempfile.TemporaryDirectory(prefix=".guides-", dir=out_dir.parent) as cache_dir, \
            progress(len(window), "stylize", layer=layer.name, quiet=quiet) as bar:
        bar.update(finished)
        frames = stylize.stylize_sequence(
            lambda j: read_coverage(coverage_dir, j), plan.frame_count, source,
            params=params, guide_params=guide_params, cache_dir=cache_dir,
            frames=(window.start - plan.start, window.stop - plan.start), resume=after)
        for result in frames:
            png, *nnf_file = stylized_files(out_dir, result.index, nnf=nnf)
            write_png(png, result.rgba)
            if nnf_file:
                write_npy(nnf_file[0], result.nnf.as_array())
            if states is not None:
                states.save(result)
            bar.update()
    return [path for frame in window for path in stylized_files(out_dir, frame - plan.start, nnf=nnf)]


def layer_colorize_params(layer: PlannedLayer, fill_color: str | None) -> colorize.Params:
    """How a layer is colorized: ``colorize: layer`` (its colour or the vector fill), a ``#rrggbb``, or ``none``."""
    mode = layer.spec.colorize
    if mode == "none":
        return colorize.Params(mode="none")
    hex_color = mode if mode != "layer" else (layer.spec.color or fill_color or "#000000")
    return colorize.Params(mode="layer", color=tuple(float(c) for c in parse_hex(hex_color)))


def colorize_layer(plan: Plan, layer: PlannedLayer, window: range, source: exemplar_store.StoredSource,
                   params: colorize.Params, out: Path, *, quiet=False) -> list[Path]:
    """Colorize the layer's stylized frames into ``out/layers/<layer>/``; return the files written.

    The paper and paint density are statistics over every exemplar frame: its colour and
    segments are read whole for them (16 bytes a pixel and frame), then released.
    """
    rgb, segment = source.rgb, source.segment
    paper = colorize.estimate_paper(rgb, segment)
    unit = colorize.full_density(rgb, segment, paper)
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


def make_background(plan: Plan, *, quiet=False) -> np.ndarray:
    """The scene's static paper, (H, W, 3) sRGB: a solid colour, an image, or synthesized paper."""
    spec, size = plan.scene.background, plan.size
    if spec["type"] == "solid":
        return background.solid(parse_hex(spec["color"]), size)
    if spec["type"] == "image":
        return background.image(spec["path"], size)
    if spec.get("path") is not None:
        sample = read_image(spec["path"], channels=3)
    else:
        layer = _background_layer(plan, spec.get("exemplar"))
        source = load_layer_source(plan, layer, layer_guide_params(plan, layer), quiet)
        sample = background.paper_sample(source.rgb, source.segment)
    with progress(1, "background", quiet=quiet, unit="image"):
        return background.synthesized(sample, size, seed=plan.scene.seed)


def _background_layer(plan: Plan, exemplar: str | None) -> PlannedLayer:
    """A layer whose exemplar gives the paper: the named exemplar, or the bottom layer's."""
    bottom = min(plan.layers, key=lambda layer: layer.z)
    if exemplar is None:
        return bottom
    if exemplar not in plan.scene.exemplars:
        raise SceneError(f"{plan.scene.path}: background.exemplar: no exemplar called '{exemplar}' "
                         f"(defined: {', '.join(plan.scene.exemplars) or 'none'})")
    return dataclasses.replace(bottom, spec=dataclasses.replace(bottom.spec, exemplar=exemplar))
