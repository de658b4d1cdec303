"""Render a scene: the stage table walked in order, per layer and then for the whole scene.

The stages (:mod:`fluidymation.pipeline.layer_stages`, :mod:`fluidymation.pipeline.scene_stages`)
declare what their cache keys depend on (:mod:`fluidymation.pipeline.stage`). Per layer:
``masks``, ``guides`` (only as views, with ``--until guides``), ``stylize``, ``colorize``;
then for the scene: ``background``, ``composite`` (only with ``--until composite``) and
``encode``. Every stage reads its inputs from and writes its products to the output
folder (DESIGN.md's output conventions) and records them in the stage cache
(:mod:`fluidymation.pipeline.cache`), so a later run, or a run of a few layers only,
redoes only the work whose inputs or parameters changed.

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
import time
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

from fluidymation.errors import SceneError
from fluidymation.pipeline import compile_helper
from fluidymation.pipeline.cache import StageCache
from fluidymation.pipeline.exemplars import layer_source, simulated_frame_count, stored_identity
from fluidymation.pipeline.executors import LOCAL, run_jobs
from fluidymation.pipeline.layer_stages import LAYER_STAGES, KeyframePaint
from fluidymation.pipeline.parameters import (
    check_layer_params, layer_guide_params, layer_stylize_params, layer_stylizer,
)
from fluidymation.pipeline.progress import progress
from fluidymation.pipeline.resolve import Plan, PlannedLayer
from fluidymation.pipeline.scene_stages import SCENE_STAGES
from fluidymation.pipeline.stage import LAYER, SCENE, Keys, Stage, stages_to_run
from fluidymation.stages import guides
from fluidymation.stages.exemplar_store import StoredSource
from fluidymation.stages.files import write_text
from fluidymation.stages.stylizer import Stylizer

#: Every stage, in the order they run.
STAGES = LAYER_STAGES + SCENE_STAGES
STAGE_NAMES = tuple(stage.name for stage in STAGES)

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
    jobs: int = 1  # local processes: the layers at once, or one layer's independent tasks (keyframe frames)
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
    if options.until not in STAGE_NAMES:
        raise SceneError(f"--until {options.until!r}: not a stage; choose one of {', '.join(STAGE_NAMES)}")
    for stage in options.force_stages:
        if stage not in STAGE_NAMES:
            raise SceneError(f"--force-stage {stage!r}: not a stage; choose one of {', '.join(STAGE_NAMES)}")
    chosen = [plan.layer(name) for name in options.layers] if options.layers else list(plan.layers)
    for layer in chosen:
        check_layer_params(plan, layer)
    run = _Run(plan, options)
    # workers elsewhere print to their own stderr: keep it quiet
    job_options = options if options.executor == LOCAL else dataclasses.replace(options, quiet=True)
    if options.executor == LOCAL and len(chosen) > 1:
        job_options = dataclasses.replace(job_options, jobs=1)  # the layers take the processes: their tasks run in them
    here = options.executor == LOCAL and (options.jobs <= 1 or len(chosen) <= 1)  # the layers run in this process
    stylizing = any(stage.name == "stylize" for stage in run.stages)
    works = [run.work(layer.name) for layer in chosen] if here and stylizing else []
    warm_ups = [(work.stylizer, work.stylize_params) for work in works]
    with compile_helper.alongside(warm_ups):
        results = run_jobs(render_layer, [(plan, job_options, layer.name) for layer in chosen],
                           executor=options.executor, jobs=options.jobs)
    records = {}
    for layer, (record, entries) in zip(chosen, results):
        records[layer.name] = record
        run.report.entries.extend(entries)
    with run.cache.lock("layers", None):
        write_layers_summary(plan, records, run.out / "masks", range(plan.start, plan.end))
    for stage in run.stages:
        if stage.scope == SCENE:
            run.stage(stage, run.work(None))
    if options.report:
        run.report.write(run.out / "report.json")
    return run.out


def render_layer(plan: Plan, options: Options, name: str) -> tuple[dict, list[dict]]:
    """The per-layer stages of layer ``name`` (a job for the executor): its summary record and report entries."""
    run = _Run(plan, options)
    work = run.work(name)
    for stage in run.stages:
        if stage.scope == LAYER:
            run.stage(stage, work)
    record = dict(run.cache.lookup("masks", name)["record"])
    record["color"] = work.layer.spec.color or record["fill"]
    return record, run.report.entries


class _Run:
    """One render: the plan, options, output folder, cache, keys and report its stages share.

    ``stages`` is the stage table (tests vary it to check the keys).
    """

    def __init__(self, plan: Plan, options: Options, stages: tuple[Stage, ...] = STAGES):
        self.plan, self.options = plan, options
        self.out = output_dir(plan, options)
        self.window = plan.frames(options.window)
        self.cache = StageCache(self.out)
        self.report = Report(plan, options)
        self.stages = stages_to_run(stages, options.until)
        self._works: dict[str | None, Work] = {}
        self.keys = Keys(stages, tuple(layer.name for layer in plan.layers), self.work)

    def work(self, layer: str | None) -> Work:
        """The view of layer ``layer`` (None: the scene) that stages read."""
        if layer not in self._works:
            self._works[layer] = Work(self, None if layer is None else self.plan.layer(layer))
        return self._works[layer]

    def stage(self, stage: Stage, work: Work) -> dict:
        """Run ``stage`` for ``work``'s layer unless the cache holds it under its key; return its manifest.

        Holds the stage's lock from the cache check to the commit, so a concurrent render
        of the scene waits here and then finds the work done.
        """
        layer = None if work.layer is None else work.layer.name
        key = self.keys.key(stage.name, layer)
        where = stage.name if layer is None else f"{stage.name} {layer}"
        frames = stage.frames(work)
        with self.cache.lock(stage.name, layer):
            started = time.perf_counter()
            forced = self.options.force or stage.name in self.options.force_stages
            if not forced and self.cache.hit(stage.name, layer, key):
                log.debug("%s: cached (key %s)", where, key[:12])
                self.report.stage(stage.name, layer, frames, started, cached=True)
                return self.cache.lookup(stage.name, layer)
            log.debug("%s: running (key %s)", where, key[:12])
            self.cache.forget(stage.name, layer)
            done = stage.run(work, key)
            manifest = self.cache.commit(stage.name, layer, key, done.files, **done.manifest)
            self.report.stage(stage.name, layer, frames, started, **done.report)
            log.debug("%s: finished in %.2f s, %d files", where, time.perf_counter() - started, len(done.files))
            return manifest


class Work:
    """What the stages of one layer (or of the scene, ``layer`` None) read: the plan, the options, the
    output folder, the frames, the cache and keys, and the layer's stylizer, parameters and exemplar
    (each worked out on first use)."""

    def __init__(self, run: _Run, layer: PlannedLayer | None):
        self.run, self.layer = run, layer
        self.plan, self.options, self.out, self.window = run.plan, run.options, run.out, run.window
        self.cache, self.keys, self.quiet = run.cache, run.keys, run.options.quiet

    @property
    def frame_span(self) -> tuple[int, int]:
        """The frames rendered, as indices into the scene's range."""
        return self.window.start - self.plan.start, self.window.stop - self.plan.start

    def for_layer(self, layer: PlannedLayer) -> Work:
        """The view of ``layer`` (e.g. the bottom layer with the background's exemplar)."""
        return Work(self.run, layer)

    @cached_property
    def stylizer(self) -> Stylizer:
        return layer_stylizer(self.plan, self.layer)

    @cached_property
    def stylize_params(self):
        return layer_stylize_params(self.plan, self.layer, preview=self.options.preview)

    @cached_property
    def guide_params(self) -> guides.Params:
        return layer_guide_params(self.plan, self.layer)

    @cached_property
    def exemplar_identity(self) -> str:
        return stored_identity(self.plan, self.layer, self.guide_params)

    @cached_property
    def source(self) -> StoredSource:
        """The layer's exemplar with its guides (generated on first use)."""
        return load_layer_source(self.plan, self.layer, self.guide_params, self.quiet)

    @cached_property
    def paint(self):
        """What colorize takes the paper and paint density from: the exemplar, or the painted keyframes."""
        if self.stylizer.uses_keyframes:
            return KeyframePaint(self.plan, self.layer, self.out / "coverage" / self.layer.dirname)
        return self.source

    @property
    def record(self) -> dict:
        """The layer's summary record from its masks stage."""
        return self.cache.lookup("masks", self.layer.name)["record"]


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


def load_layer_source(plan: Plan, layer: PlannedLayer, guide_params, quiet=False) -> StoredSource:
    """The layer's exemplar with its guides on disk (generated on first use), with a progress bar."""
    with progress(simulated_frame_count(plan, layer), "exemplar", layer=layer.name, quiet=quiet) as bar:
        return layer_source(plan, layer, guide_params, progress=bar.update)
