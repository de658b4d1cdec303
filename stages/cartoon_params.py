"""Parameters and version of cartoon synthesis, apart from its kernels.

They are read when a scene is checked (``fluidymation check``), which should not pay for
importing the numerical code of :mod:`fluidymation.stages.cartoon`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from fluidymation.errors import ParameterError

if TYPE_CHECKING:
    from fluidymation.stages.cartoon_clip import Clip, MotionParams

VERSION = 2


@dataclass(frozen=True)
class Params:
    """Parameters of cartoon synthesis (defaults: configs/cartoon.yaml; the seed's values where it gives them).

    Attributes
    ----------
    grid_spacing, search_radius, motion_iterations, block_size : int
        The seed's d, r, n, w (3, 8, 70, 16): the clip's grid-PatchMatch motion (blocks odd:
        17 for the seed's 16).
    patch_size : int
        Odd patch side of the synthesis (the seed gives none; 9 copies the sprites of the tests
        closer than 17 does, at a third of the time: docs/cartoon.md).
    spatial_size : float
        The seed's spatial neighbourhood size Ω, relative to the subject rectangle's longer
        side: the pyramid has as many levels as bring Ω down to one patch (Table 1: 0.15–0.3).
    pyramid_levels : int or None
        Levels given outright (None: from ``spatial_size``).
    temporal_size : int
        The seed's temporal size Δt: frames in a neighbourhood (1: spatial only; Table 1: 1–5).
    opt_iters, pm_iters : tuple of int
        Search-vote iterations and PatchMatch passes per level, coarsest first.
    fresh_iters : tuple of int
        Search-vote iterations per level of a frame started from random matches (the first).
    w_colour, w_shape, w_position, w_temporal : float
        Weights of the colour, the shape, the position and the temporal neighbourhood.
    seed : int
    """

    grid_spacing: int = 3
    search_radius: int = 8
    motion_iterations: int = 70
    block_size: int = 17
    patch_size: int = 9
    spatial_size: float = 0.25
    pyramid_levels: int | None = None
    temporal_size: int = 3
    opt_iters: tuple = (4,)
    pm_iters: tuple = (2,)
    fresh_iters: tuple = (12,)
    w_colour: float = 1.0
    w_shape: float = 2.0
    w_position: float = 4.0
    w_temporal: float = 1.0
    seed: int = 0

    def __post_init__(self):
        whole = (("grid_spacing", 1), ("search_radius", 1), ("motion_iterations", 1), ("temporal_size", 1))
        for name, low in whole:
            value = getattr(self, name)
            if int(value) != value or value < low:
                raise ParameterError(name, f"cartoon: {name} must be a whole number ≥ {low}, got {value!r}")
        for name in ("block_size", "patch_size"):
            value = getattr(self, name)
            if int(value) != value or value < 3 or value % 2 == 0:
                raise ParameterError(name, f"cartoon: {name} must be an odd number ≥ 3, got {value!r}")
        if not 0.0 < self.spatial_size <= 1.0:
            raise ParameterError("spatial_size", f"cartoon: spatial_size must lie in (0, 1], got {self.spatial_size}")
        if self.pyramid_levels is not None and self.pyramid_levels < 1:
            raise ParameterError("pyramid_levels", f"cartoon: pyramid_levels must be ≥ 1, got {self.pyramid_levels}")
        for name in ("w_colour", "w_shape", "w_position", "w_temporal"):
            if getattr(self, name) < 0:
                raise ParameterError(name, f"cartoon: {name} must be ≥ 0, got {getattr(self, name)}")
        if self.w_colour == 0:
            raise ParameterError("w_colour", "cartoon: w_colour must be above 0: without it nothing looks like the clip")

    @property
    def motion(self) -> MotionParams:
        from fluidymation.stages.cartoon_clip import MotionParams  # the clip's kernels, only when analysing

        return MotionParams(spacing=self.grid_spacing, search_radius=self.search_radius,
                            iterations=self.motion_iterations, patch_size=self.block_size)

    def levels_for(self, clip: Clip) -> int:
        """The pyramid levels: given, or enough that Ω of the subject's longer side shrinks to one patch."""
        if self.pyramid_levels is not None:
            return self.pyramid_levels
        sizes = np.maximum(clip.boxes[:, 2] - clip.boxes[:, 0], clip.boxes[:, 3] - clip.boxes[:, 1])
        span = self.spatial_size * float(np.median(sizes))
        return 1 + max(0, round(math.log2(max(span, 1.0) / self.patch_size)))
