"""A minimal third-party stylizer: each frame painted flat in the exemplar's mean paint colour.

It lives outside the fluidymation package and is found only through the entry point of
the ``flat-stylizer`` test distribution beside it (docs/extending.md quotes it).
"""

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fluidymation.errors import ParameterError
from fluidymation.stages.stylizer import Frame, Stylizer


@dataclass(frozen=True)
class FlatParams:
    shade: float = 0.0  # 0: the exemplar's colour; 1: black

    def __post_init__(self):
        if not 0 <= self.shade <= 1:
            raise ParameterError("shade", f"flat: parameter shade must be between 0 and 1, got {self.shade!r}")


class FlatStylizer(Stylizer):
    name = "flat"
    version = 1
    Params = FlatParams
    defaults = Path(__file__).with_name("flat_stylizer.yaml")
    uses_guides = False

    def stylize(self, job, params):
        first_frame = job.source.window(0, 1)
        paint = first_frame.rgb[0][first_frame.segment[0] >= 0]
        colour = paint.mean(axis=0) * (1 - params.shade)
        first, stop = job.frames
        start = first if job.resume is None else job.resume + 1  # resume_from gives the last finished index
        for index in range(start, stop):
            coverage = job.masks(index)
            rgb = np.broadcast_to(colour, coverage.shape + (3,))
            yield Frame(index, np.dstack([rgb, coverage]).astype(np.float32))
