"""The ``still`` stylizer: flat-coloured layers painted from one still exemplar and its regions (seed 002).

Parameters are :class:`fluidymation.stages.still_params.Params`, their defaults ``configs/still.yaml``;
the method is :mod:`fluidymation.stages.still` (docs/still.md). The layer's regions come from
its fill colours (``segments: by-color``) or its mask (``segments: mask``), matched to the
exemplar's regions by nearest colour or the layer's ``segment_map:``. The state kept per
finished frame is its NNF and colour, so a resumed run carries the texture on as before.
"""

from __future__ import annotations

import logging
from importlib import resources

from typing import TYPE_CHECKING

import numpy as np

from fluidymation.stages import still_params
from fluidymation.stages.stylizer import StylizeJob, Stylizer

if TYPE_CHECKING:
    from fluidymation.stages.still import StillFrame

log = logging.getLogger(__name__)


class StillStylizer(Stylizer):
    """One painting, matched region to region, carried along the layer's motion (seed 002 and docs/still.md)."""

    name = "still"
    version = still_params.VERSION
    Params = still_params.Params
    defaults = resources.files("fluidymation.configs").joinpath("still.yaml")
    default_colorize = "none"
    writes_nnf = True
    ablation = (("full", ()), ("no uniformity", ("uniformity",)), ("no guide", ("w_guide",)))

    def stylize(self, job: StylizeJob, params: still_params.Params):
        from fluidymation.stages import still  # on use: check loads no numerical code

        painting = still.painting_from(job.source, params.exemplar_frame)
        regions = still.layer_regions(((job.colours(j), job.masks(j)) for j in range(job.frame_count)),
                                      painting.regions, mode=job.segments, segment_map=job.segment_map,
                                      where=f"layer '{job.layer}'")
        flow = job.motion() if params.follow_motion and job.frame_count > 1 else None
        first, stop = job.frames
        previous = None
        if job.resume is not None:
            index, nnf, rgb = job.resume
            coverage = job.masks(index)
            previous = still.resumed(index, nnf, rgb, coverage, regions.of(job.colours(index), coverage))
            first = index + 1
        counts = still.Counts()
        yield from still.stylize_frames(job.masks, job.colours, (first, stop), still.StillSynthesis(painting, params),
                                        regions, flow=flow, previous=previous, counts=counts)
        log.info("still %s: %d frames synthesized, %d carried along the motion, %d reused unchanged",
                 job.layer, counts.synthesized, counts.followed, counts.reused)

    def frame_state(self, frame: StillFrame) -> dict[str, np.ndarray]:
        return {"frame": frame.nnf.frame, "coords": frame.nnf.coords, "rgb": frame.rgba[..., :3]}

    def resume_from(self, index: int, state: dict[str, np.ndarray]):
        from fluidymation.engine.nnf import NNF  # on use: check loads no numerical code

        return index, NNF(state["frame"], state["coords"]), state["rgb"]
