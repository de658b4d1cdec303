"""The ``fluidymation`` stylizer: the paper's method (:mod:`fluidymation.stages.stylize`) as a plugin.

Parameters are :class:`fluidymation.stages.stylize_params.Params`, their defaults
``configs/fluidymation.yaml``. The state kept per finished frame for resume is its NNF
(source frame and coordinates per pixel), the motion not yet followed and its colour:
exactly what :func:`~fluidymation.stages.stylize.stylize_sequence` needs to continue.
"""

from __future__ import annotations

from importlib import resources

from typing import TYPE_CHECKING

import numpy as np

from fluidymation.stages import stylize_params
from fluidymation.stages.stylizer import StylizeJob, Stylizer

if TYPE_CHECKING:
    from fluidymation.stages.stylize import StylizedFrame


class FluidymationStylizer(Stylizer):
    """Moving-exemplar synthesis with the full Fluidymation energy (paper section 3, appendix B)."""

    name = "fluidymation"
    version = stylize_params.VERSION
    Params = stylize_params.Params
    defaults = resources.files("fluidymation.configs").joinpath("fluidymation.yaml")
    writes_nnf = True
    warm_up_modules = tuple(f"fluidymation.engine.{name}" for name in (
        "histogram", "nnf", "patch_cost", "patchmatch", "pyramid", "shiftnnf", "uniformity", "vote"))
    ablation = (
        ("full", ()),
        ("no bound", ("w_bound",)),
        ("no edge", ("w_edge",)),
        ("no dir", ("w_dir",)),
        ("no ext", ("w_ext",)),
        ("no temp", ("w_temp",)),
        ("no uni", ("w_uni",)),
        ("no dir+bound", ("w_dir", "w_bound")),
    )

    def processing_order(self, frames: range, params: stylize_params.Params) -> list[int]:
        return sorted(frames, reverse=params.reverse)

    def stylize(self, job: StylizeJob, params: stylize_params.Params):
        from fluidymation.stages import stylize  # on use: check loads no numerical code

        return stylize.stylize_sequence(job.masks, job.frame_count, job.source, params=params,
                                        guide_params=job.guide_params, cache_dir=job.cache_dir, frames=job.frames,
                                        resume=job.resume, given_flow=job.given_flow)

    def frame_state(self, frame: StylizedFrame) -> dict[str, np.ndarray]:
        return {"frame": frame.nnf.frame, "coords": frame.nnf.coords, "backlog": frame.backlog,
                "rgb": frame.rgba[..., :3]}

    def resume_from(self, index: int, state: dict[str, np.ndarray]):
        from fluidymation.engine.nnf import NNF  # on use: check loads no numerical code

        return index, NNF(state["frame"], state["coords"]), state["backlog"], state["rgb"]
