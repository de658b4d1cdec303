"""The moving exemplar of a scene layer, with its guidance channels, from the user cache.

A layer names its exemplar with ``exemplar:`` (its own or the scene defaults'); the
``exemplars:`` section defines it: a built-in preset, or a recording (``video:`` a file,
``images:`` a folder or pattern, ``image:`` one still painting) with masks (``mask:`` an
image sequence or ``auto``) and a flow estimated from the masks (``flow: masks``, the
default) or from the frames (``flow: motion``). A still painting may bring its colour-coded
regions (``segments:``, :mod:`fluidymation.stages.regions`): its mask is then where they are. With no name the built-in ``watercolor-bloom`` with its default
parameters is used. Generated built-in exemplars and all exemplar guides are kept under
:func:`fluidymation.pipeline.paths.cache_dir`; an exemplar's colour is stored beside its
guides, so a stage reads from disk only the exemplar frames it needs
(:class:`fluidymation.stages.exemplar_store.StoredSource`) and a cached exemplar is not loaded whole.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
import shutil
import tempfile
from pathlib import Path

from fluidymation.errors import InputError, SceneError, StageError
from fluidymation.pipeline import paths
from fluidymation.pipeline.presets import resolve_params
from fluidymation.pipeline.resolve import Plan, PlannedLayer
from fluidymation.stages import exemplar_builtin, exemplar_store, exemplar_user, guides
from fluidymation.stages.guide_params import for_exemplar
from fluidymation.stages.files import read_image
from fluidymation.stages.regions import read_regions

DEFAULT_BUILTIN = "watercolor-bloom"
_BUILTIN_OPTIONS = ("kind", "builtin", "seed", "size", "frames", "color", "wetness")
_USER_OPTIONS = ("kind", "path", "mask", "flow", "scale", "step", "frames", "reverse", "seed", "segments")


def exemplar_spec(plan: Plan, layer: PlannedLayer) -> tuple[str, dict]:
    """The name and scene entry of the layer's exemplar (the default built-in when it names none)."""
    name = layer.spec.exemplar
    if name is None:
        return DEFAULT_BUILTIN, {"kind": "builtin", "builtin": DEFAULT_BUILTIN}
    spec = plan.scene.exemplars.get(name)
    if spec is None:
        raise SceneError(f"{plan.scene.path}: layer '{layer.name}' uses exemplar '{name}', which the exemplars "
                         "section does not define")
    return name, spec


def builtin_params(plan: Plan, name: str, spec: dict) -> exemplar_builtin.Params:
    """The built-in exemplar parameters of a ``builtin:`` entry."""
    unsupported = sorted(set(spec) - set(_BUILTIN_OPTIONS))
    if unsupported:
        raise SceneError(f"{plan.scene.path}: exemplars.{name}.{unsupported[0]}: not supported for builtin "
                         f"exemplars; they take seed, size, frames (a count), color and wetness")
    if isinstance(spec.get("frames"), tuple):
        raise SceneError(f"{plan.scene.path}: exemplars.{name}.frames: a builtin exemplar takes a frame count")
    try:
        return resolve_params(spec["builtin"], seed=spec.get("seed"), size=spec.get("size"), frames=spec.get("frames"),
                              color=spec.get("color"), wetness=spec.get("wetness"))
    except (InputError, StageError) as exc:
        raise plan.scene.error(("exemplars", name), str(exc)) from None


def simulated_frame_count(plan: Plan, layer: PlannedLayer) -> int | None:
    """Frames the layer's exemplar simulates when it is a built-in one (for progress bars)."""
    name, spec = exemplar_spec(plan, layer)
    return builtin_params(plan, name, spec).frames if spec["kind"] == "builtin" else None


def user_params(plan: Plan, name: str, spec: dict) -> exemplar_user.Params:
    """How to read a ``video:`` or ``images:`` entry."""
    where = f"{plan.scene.path}: exemplars.{name}"
    unsupported = sorted(set(spec) - set(_USER_OPTIONS))
    if unsupported:
        raise SceneError(f"{where}.{unsupported[0]}: not an option of recorded exemplars; they take mask, flow, "
                         "scale, step, frames, reverse and seed")
    if "segments" in spec and not Path(spec["segments"]).is_file():
        raise SceneError(f"{where}.segments: {spec['segments']} is not a file")
    if spec.get("flow", "masks") == "exact":
        raise SceneError(f"{where}.flow: 'exact' is only known for built-in exemplars; use masks or motion")
    step = spec.get("step", 1)
    if step != int(step):
        raise SceneError(f"{where}.step: must be a whole number of source frames, got {step}")
    frames = spec.get("frames", (0, None))
    if isinstance(frames, int):
        frames = (0, frames)
    try:
        mask = "full" if "segments" in spec else str(spec.get("mask", "auto"))  # the regions are the mask
        return exemplar_user.Params(source=str(spec["path"]), mask=mask,
                                    scale=spec.get("scale", 1.0), step=int(step), start=frames[0], end=frames[1],
                                    reverse=spec.get("reverse", False))
    except StageError as exc:
        raise SceneError(f"{where}: {exc}") from None


def exemplar_identity(plan: Plan, layer: PlannedLayer) -> str:
    """A key that changes whenever the layer's exemplar would: preset parameters, or recording options and file stamps."""
    name, spec = exemplar_spec(plan, layer)
    if spec["kind"] == "builtin":
        return builtin_params(plan, name, spec).cache_key()
    return _recording_identity(user_params(plan, name, spec), spec)


def _stored_record(plan: Plan, layer: PlannedLayer, guide_params: guides.Params) -> str:
    return json.dumps({"exemplar": exemplar_identity(plan, layer), "guides": dataclasses.asdict(guide_params),
                       "version": guides.VERSION, "colour": exemplar_store.StoredSource.COLOUR_FILE}, sort_keys=True)


def stored_identity(plan: Plan, layer: PlannedLayer, guide_params: guides.Params) -> str:
    """A key that changes whenever the layer's stored exemplar would: the exemplar, its guides' parameters and
    version (the name of its folder in the user cache)."""
    record = _stored_record(plan, layer, guide_params)
    return f"{exemplar_identity(plan, layer)}-{hashlib.sha256(record.encode()).hexdigest()[:12]}"


def layer_source(plan: Plan, layer: PlannedLayer, guide_params: guides.Params, *,
                 progress=None) -> exemplar_store.StoredSource:
    """The layer's exemplar and its guides on disk, generated on first use and cached.

    ``progress`` is called with no arguments after each simulated exemplar frame.
    """
    name, spec = exemplar_spec(plan, layer)
    record = _stored_record(plan, layer, guide_params)
    entry = paths.exemplar_guides_cache_dir() / stored_identity(plan, layer, guide_params)
    if not (entry / "done").is_file():
        found = None
        if spec["kind"] == "builtin":
            exemplar = exemplar_builtin.make_builtin_exemplar(builtin_params(plan, name, spec),
                                                              cache_dir=paths.exemplar_cache_dir(), progress=progress)
            rgb, masks, flow = exemplar.rgb, exemplar.mask, exemplar.flow
        else:
            recording = exemplar_user.load_user_exemplar(user_params(plan, name, spec))
            rgb, masks = recording.rgb, recording.mask
            flow = exemplar_user.motion_flow(rgb, seed=spec.get("seed", 0)) if spec.get("flow") == "motion" else None
            if "segments" in spec:
                painted = read_image(spec["path"], channels=3).shape[:2]
                found = read_regions(spec["segments"], painted).resized(rgb.shape[1:3])
                masks = (found.labels >= 0)[None]
        _store_with_guides(entry, record, rgb, masks, flow, guide_params, regions=found)
    return exemplar_store.StoredSource(entry)


def _recording_identity(params: exemplar_user.Params, spec: dict) -> str:
    """A cache key for a recording: its reading options, flow choice and the files' (and segments') sizes and times."""
    files = exemplar_user.image_sequence(params.source) + ([Path(spec["segments"])] if "segments" in spec else [])
    stamps = [(str(p), p.stat().st_size, p.stat().st_mtime_ns) for p in files]
    record = json.dumps({"params": dataclasses.asdict(params), "flow": spec.get("flow", "masks"),
                         "seed": spec.get("seed", 0), "files": stamps}, sort_keys=True, default=str)
    return "recording-" + hashlib.sha256(record.encode()).hexdigest()[:16]


def _store_with_guides(entry: Path, record: str, rgb, masks, flow, guide_params: guides.Params, *,
                       regions=None) -> None:
    """Compute the exemplar's guides (from ``flow``, or the masks) and store them with its colour (and its
    ``regions``, when it has some) in ``entry``, marked done with ``record``."""
    entry.parent.mkdir(parents=True, exist_ok=True)
    staging = tempfile.mkdtemp(prefix=f".{entry.name}.", dir=entry.parent)
    try:
        guides.compute_guides(lambda j: masks[j], len(masks), params=for_exemplar(guide_params), cache_dir=staging,
                              given_flow=None if flow is None else (lambda j: flow[j]))
        exemplar_store.store_colour(rgb, staging)
        if regions is not None:
            exemplar_store.store_regions(regions, staging)
        with open(f"{staging}/done", "w") as handle:
            handle.write(record)
        try:
            os.replace(staging, entry)
        except OSError:
            if not (entry / "done").is_file():  # not a concurrent writer that finished first
                raise
    finally:
        shutil.rmtree(staging, ignore_errors=True)
