"""The moving exemplar of a scene layer, with its guidance channels, from the user cache.

A layer names its exemplar with ``exemplar:`` (its own or the scene defaults'); the
``exemplars:`` section defines it. With no name the built-in ``watercolor-bloom`` with
its default parameters is used. Generated built-in exemplars and their guides are kept
under :func:`fluidymation.pipeline.paths.cache_dir`.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
import shutil
import tempfile

from fluidymation.errors import SceneError
from fluidymation.pipeline import paths
from fluidymation.pipeline.commands.exemplar import resolve_params
from fluidymation.pipeline.resolve import Plan, PlannedLayer
from fluidymation.stages import exemplar_builtin, guides, stylize

DEFAULT_BUILTIN = "watercolor-bloom"
_BUILTIN_OPTIONS = ("kind", "builtin", "seed", "size", "frames", "color", "wetness")


def builtin_params(plan: Plan, layer: PlannedLayer) -> exemplar_builtin.Params:
    """The built-in exemplar parameters the layer asks for (SceneError for other kinds)."""
    name = layer.spec.exemplar
    if name is None:
        return resolve_params(DEFAULT_BUILTIN)
    spec = plan.scene.exemplars.get(name)
    if spec is None:
        raise SceneError(f"{plan.scene.path}: layer '{layer.name}' uses exemplar '{name}', which the exemplars "
                         "section does not define")
    if spec["kind"] != "builtin":
        raise SceneError(f"{plan.scene.path}: exemplars.{name}: {spec['kind']} exemplars are not supported by the "
                         "stylize stage yet; use a builtin one (see `fluidymation exemplar list`)")
    unsupported = sorted(set(spec) - set(_BUILTIN_OPTIONS))
    if unsupported:
        raise SceneError(f"{plan.scene.path}: exemplars.{name}.{unsupported[0]}: not supported for builtin "
                         f"exemplars; they take seed, size, frames (a count), color and wetness")
    if isinstance(spec.get("frames"), tuple):
        raise SceneError(f"{plan.scene.path}: exemplars.{name}.frames: a builtin exemplar takes a frame count")
    return resolve_params(spec["builtin"], seed=spec.get("seed"), size=spec.get("size"), frames=spec.get("frames"),
                          color=spec.get("color"), wetness=spec.get("wetness"))


def layer_source(plan: Plan, layer: PlannedLayer, guide_params: guides.Params, *, progress=None) -> stylize.Source:
    """The layer's exemplar and its guides, generated on first use and cached.

    ``progress`` is called with no arguments after each simulated exemplar frame.
    """
    params = builtin_params(plan, layer)
    exemplar = exemplar_builtin.make_builtin_exemplar(params, cache_dir=paths.exemplar_cache_dir(), progress=progress)
    record = json.dumps({"exemplar": params.cache_key(), "guides": dataclasses.asdict(guide_params),
                         "version": guides.VERSION}, sort_keys=True)
    entry = paths.exemplar_guides_cache_dir() / f"{params.cache_key()}-{hashlib.sha256(record.encode()).hexdigest()[:12]}"
    if not (entry / "done").is_file():
        entry.parent.mkdir(parents=True, exist_ok=True)
        staging = tempfile.mkdtemp(prefix=f".{entry.name}.", dir=entry.parent)
        try:
            guides.compute_guides(lambda j: exemplar.mask[j], params.frames, params=guide_params, cache_dir=staging,
                                  given_flow=lambda j: exemplar.flow[j])
            with open(f"{staging}/done", "w") as handle:
                handle.write(record)
            try:
                os.replace(staging, entry)
            except OSError:
                if not (entry / "done").is_file():  # not a concurrent writer that finished first
                    raise
        finally:
            shutil.rmtree(staging, ignore_errors=True)
    return stylize.prepare_source(exemplar.rgb, guides.GuideCache.open(entry))
