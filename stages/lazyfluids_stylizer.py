"""The ``lazyfluids`` stylizer: the Fluidymation paper's baseline, LazyFluids (Jamriška et al. 2015).

One exemplar frame (a still image, or ``exemplar_frame`` of a moving exemplar) textures every
frame; the previous output carried along the target's motion is the temporal guide; the
mask (its blurred shape, LazyFluids' alpha) guides the boundary; uniformity spreads the
exemplar's patches. It runs the project's synthesis (:mod:`fluidymation.stages.stylize`)
with the terms LazyFluids has and without those it has not — no edge distance, motion
extent, exemplar time or histogram matching (configs/lazyfluids.yaml; docs/still.md says
where it differs from the original).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from importlib import resources

from fluidymation.errors import ParameterError
from fluidymation.stages import stylize_params
from fluidymation.stages.fluidymation_stylizer import FluidymationStylizer
from fluidymation.stages.stylizer import StylizeJob


@dataclass(frozen=True)
class Params(stylize_params.Params):
    """:class:`fluidymation.stages.stylize_params.Params` and ``exemplar_frame``: the exemplar frame that is the
    still."""

    exemplar_frame: int = 0

    def synthesis(self) -> stylize_params.Params:
        """The parameters of the synthesis itself."""
        synthesis = stylize_params.Params
        return synthesis(**{field.name: getattr(self, field.name) for field in dataclasses.fields(synthesis)})


class OneFrame:
    """Frame ``index`` of a stored exemplar, seen as an exemplar of one frame (what the synthesis reads of it)."""

    def __init__(self, source, index: int):
        if not 0 <= index < source.frame_count:
            raise ParameterError("exemplar_frame", f"exemplar_frame {index}: the exemplar has {source.frame_count} frames")
        self.source, self.index = source, index
        self.frame_count = 1
        self.ext_max = source.ext_max

    def window(self, start: int, stop: int):
        return self.source.window(self.index + start, self.index + stop)


class LazyFluidsStylizer(FluidymationStylizer):
    """One still exemplar, the previous frame advected as the temporal guide, the mask and uniformity."""

    name = "lazyfluids"
    version = 1
    Params = Params
    defaults = resources.files("fluidymation.configs").joinpath("lazyfluids.yaml")
    ablation = (("full", ()), ("no temp", ("w_temp",)), ("no uni", ("w_uni",)), ("no bound", ("w_bound",)))

    def stylize(self, job: StylizeJob, params: Params):
        return super().stylize(dataclasses.replace(job, source=OneFrame(job.source, params.exemplar_frame)),
                               params.synthesis())
