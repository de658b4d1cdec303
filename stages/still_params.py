"""Parameters and version of the ``still`` stylizer, apart from its synthesis.

They are read when a scene is checked (``fluidymation check``), which should not pay for
importing the numerical code of :mod:`fluidymation.stages.still`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from fluidymation.errors import ParameterError

if TYPE_CHECKING:
    from fluidymation.engine.synthesis import SynthesisParams

VERSION = 1


@dataclass(frozen=True)
class Params:
    """Parameters of the ``still`` stylizer (defaults: configs/still.yaml).

    Attributes
    ----------
    patch_size : int
    w_style, w_guide : float
        α and β of the seed's patch distance α·SSD(style) + β·SSD(guide); the guide is the
        region colour and whether there is paint (RGBA).
    uniformity : float
        λ of the occurrence penalty, in units of the style SSD at the budget ω_best (0: off).
    opt_iters, pm_iters : tuple of int
        Search-vote iterations and PatchMatch passes per level, coarsest first (the seed: 5 per level).
    pyramid_levels : int or None
        The seed's 3; None: as many as fit.
    alpha : float
        Random-search shrink factor.
    edge_band : float
        0: every fresh frame fully synthesized; else only this many px along region edges at
        full resolution (half that at each coarser level) over pre-synthesized region textures.
    follow_motion : bool
        Carry the previous frame's texture along the layer's motion and synthesize only what it uncovers.
    exemplar_frame : int
        Which frame of the exemplar is the painting (0 for a still image).
    seed : int
    """

    patch_size: int = 5
    w_style: float = 0.3
    w_guide: float = 0.7
    uniformity: float = 0.1
    opt_iters: tuple = (5,)
    pm_iters: tuple = (4,)
    pyramid_levels: int | None = 3
    alpha: float = 0.75
    edge_band: float = 0.0
    follow_motion: bool = True
    exemplar_frame: int = 0
    seed: int = 0

    def __post_init__(self):
        for name in ("w_style", "w_guide", "uniformity", "edge_band"):
            if getattr(self, name) < 0:
                raise ParameterError(name, f"{name} must be ≥ 0, got {getattr(self, name)}")
        if self.w_style == 0:
            raise ParameterError("w_style", "w_style must be above 0: without it nothing looks like the painting")
        if self.exemplar_frame < 0:
            raise ParameterError("exemplar_frame", f"exemplar_frame must be ≥ 0, got {self.exemplar_frame}")

    def synthesis(self) -> SynthesisParams:
        from fluidymation.engine.synthesis import SynthesisParams  # the engine, only when synthesizing

        return SynthesisParams(patch_size=self.patch_size, pyramid_levels=self.pyramid_levels,
                               search_vote_iters=tuple(self.opt_iters), patchmatch_iters=tuple(self.pm_iters),
                               alpha=self.alpha, uniformity_weight=self.uniformity * self.w_style, seed=self.seed)
