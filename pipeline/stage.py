"""The stage contract: what each render stage declares, and the cache keys derived from it.

A :class:`Stage` declares its name, whether it runs per layer or once for the scene, its
version, its frozen parameters, the outside inputs its products depend on (content
hashes of files, an exemplar's identity), the stages whose products it reads
(``upstream``) and the stages whose work it does again itself instead of reading their
products (``repeats``: stylize computes the target guides, encode composites the frames
as it encodes them), and how it runs. Its cache key (:meth:`Keys.key`) is the hash of
all of that, with the *keys* of its upstream and repeated stages in place of their
products; so a change to any stage's version, parameters or inputs changes its key and
the key of every stage after it, and nothing else. A scene stage that depends on a layer
stage depends on it for every layer.

A stage whose work a later stage of the same render repeats is not run on its own
(:func:`stages_to_run`): ``render --until guides`` writes the guide views, a full render
does not.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

from fluidymation.pipeline.cache import stage_key

LAYER, SCENE = "layer", "scene"


@dataclass
class Done:
    """What a stage run wrote: its files, fields for its manifest and for its ``report.json`` entry."""

    files: list[Path]
    manifest: dict = field(default_factory=dict)
    report: dict = field(default_factory=dict)


def _no_inputs(work) -> dict:
    return {}


def _window_frames(work) -> int:
    return len(work.window)


@dataclass(frozen=True)
class Stage:
    """One stage of a render (see the module docstring).

    ``params(work)`` returns a frozen dataclass; ``inputs(work)`` a JSON-able mapping;
    ``run(work, key)`` does the work and returns :class:`Done`; ``frames(work)`` is the
    number of frames it makes (for the report; default: the frames rendered). ``work`` is
    the render's view of one layer (or of the scene, for scene stages).
    """

    name: str
    scope: str
    version: int
    params: Callable[[Any], Any]
    run: Callable[[Any, str], Done]
    inputs: Callable[[Any], dict] = _no_inputs
    upstream: tuple[str, ...] = ()
    repeats: tuple[str, ...] = ()
    frames: Callable[[Any], int] = _window_frames

    @property
    def depends_on(self) -> tuple[str, ...]:
        return self.upstream + self.repeats


class Keys:
    """The cache key of every (stage, layer) of a render, from the stages' declarations.

    ``work_for(layer)`` gives the work view a stage's ``params`` and ``inputs`` read
    (layer None: the scene's). Keys are computed once and remembered.
    """

    def __init__(self, stages: tuple[Stage, ...], layers: tuple[str, ...], work_for: Callable[[str | None], Any]):
        self.stages = {stage.name: stage for stage in stages}
        self.layers = layers
        self.work_for = work_for
        self._keys: dict[tuple[str, str | None], str] = {}

    def key(self, name: str, layer: str | None = None) -> str:
        """The key of stage ``name`` for ``layer`` (None for a scene stage)."""
        if (name, layer) not in self._keys:
            stage = self.stages[name]
            work = self.work_for(layer)
            parts = {"params": dataclasses.asdict(stage.params(work)), "inputs": stage.inputs(work)}
            for other in stage.depends_on:
                if self.stages[other].scope == LAYER and layer is None:
                    parts[other] = {each: self.key(other, each) for each in self.layers}
                else:
                    parts[other] = self.key(other, layer)
            self._keys[(name, layer)] = stage_key(name, stage.version, **parts)
        return self._keys[(name, layer)]

    def all(self) -> dict[tuple[str, str | None], str]:
        """Every key: each layer stage for each layer, each scene stage once."""
        return {(stage.name, layer): self.key(stage.name, layer) for stage in self.stages.values()
                for layer in (self.layers if stage.scope == LAYER else (None,))}


def stages_to_run(stages: tuple[Stage, ...], until: str) -> tuple[Stage, ...]:
    """The stages up to ``until`` (in table order), without those whose work a later one of them repeats."""
    names = [stage.name for stage in stages]
    chosen = stages[:names.index(until) + 1]
    repeated = {name for stage in chosen for name in stage.repeats}
    return tuple(stage for stage in chosen if stage.name not in repeated)
