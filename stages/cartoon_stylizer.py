"""The ``cartoon`` stylizer: a drawn clip's detail and motion pattern carried onto a scene layer (seed 004's
motion transfer; docs/cartoon.md).

The layer's exemplar is the clip (a recording: ``video:`` or ``images:``, its subject's
masks ``auto`` or given). Its analysis (:func:`fluidymation.stages.cartoon_clip.analyse_clip`:
grid-PatchMatch motion and geometry samples) is kept in the stage's work folder. Each frame
is synthesized by :class:`fluidymation.stages.cartoon.CartoonSynthesis` with the layer's
coverage as the subject, positions in the layer's own rectangle and the layer's own motion as
the global constraint; the frame's colour is the clip's, its alpha the layer's coverage. The
state kept per finished frame is its NNF and the frames its successor compares, so a resumed
run goes on as an uninterrupted one.
"""

from __future__ import annotations

import hashlib
import json
import logging
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from fluidymation.stages import cartoon_params
from fluidymation.stages.files import atomic_path
from fluidymation.stages.stylizer import StylizeJob, Stylizer

if TYPE_CHECKING:
    from fluidymation.engine.nnf import NNF
    from fluidymation.stages.cartoon import CartoonFrame
    from fluidymation.stages.cartoon_clip import Clip

log = logging.getLogger(__name__)


class CartoonStylizer(Stylizer):
    """The clip's drawn detail, moving with the clip's local motion, on the layer's shape and motion."""

    name = "cartoon"
    version = cartoon_params.VERSION
    Params = cartoon_params.Params
    defaults = resources.files("fluidymation.configs").joinpath("cartoon.yaml")
    uses_guides = False
    default_colorize = "none"
    writes_nnf = True
    ablation = (("full", ()), ("no temporal", ("w_temporal",)), ("no position", ("w_position",)))

    def stylize(self, job: StylizeJob, params: cartoon_params.Params):
        from fluidymation.stages import cartoon  # on use: check loads no numerical code

        clip = layer_clip(job, params)
        synthesis = cartoon.CartoonSynthesis(clip, params)
        flow = job.motion() if job.frame_count > 1 else None
        first, stop = job.frames
        previous = None
        if job.resume is not None:
            previous = job.resume
            first = previous.index + 1
        elif first > 0:  # a later part of the layer on its own: the frame before it is synthesized first
            previous = synthesis.frame(first - 1, cartoon.layer_target(job.masks(first - 1), None), None)
        for index in range(first, stop):
            coverage = job.masks(index)
            target = cartoon.layer_target(coverage, None if previous is None else flow(index))
            previous = synthesis.frame(index, target, previous)
            rgb = cartoon.straight(previous.rgba)[..., :3]
            yield _Output(index, np.concatenate([rgb, coverage[..., None]], axis=-1).astype(np.float32), previous.nnf,
                          previous)

    def frame_state(self, frame) -> dict[str, np.ndarray]:
        state = frame.state
        return {"frame": state.nnf.frame, "coords": state.nnf.coords, "rgba": state.rgba, "history": state.history}

    def resume_from(self, index: int, state: dict[str, np.ndarray]):
        from fluidymation.engine.nnf import NNF  # on use: check loads no numerical code
        from fluidymation.stages.cartoon import CartoonFrame

        return CartoonFrame(index, state["rgba"], NNF(state["frame"], state["coords"]), state["history"])


class _Output(NamedTuple):
    """A yielded frame: ``index``, ``rgba`` (straight colour, the coverage as alpha), ``nnf``, and the synthesis
    ``state`` the next frame continues from."""

    index: int
    rgba: np.ndarray
    nnf: NNF
    state: CartoonFrame


def layer_clip(job: StylizeJob, params: cartoon_params.Params) -> Clip:
    """The layer's exemplar analysed as a clip, from the stage's work folder when an earlier run analysed it."""
    from fluidymation.stages.cartoon_clip import Clip, analyse_clip  # on use: check loads no numerical code

    source = job.source
    key = hashlib.sha256(json.dumps([str(source.cache.directory), repr(params.motion), params.seed]).encode())
    path = Path(job.work_dir or job.cache_dir) / f"clip-{key.hexdigest()[:16]}.npz"
    if path.is_file():
        return Clip.load(path)
    masks = np.stack([source.cache.read("dist", index) > 0 for index in range(source.frame_count)])
    clip = analyse_clip(source.rgb, masks, name=f"layer '{job.layer}': its exemplar clip", motion=params.motion,
                        seed=params.seed)
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as handle:
            clip.save(handle)
    log.info("cartoon %s: clip of %d frames analysed", job.layer, clip.frame_count)
    return clip
