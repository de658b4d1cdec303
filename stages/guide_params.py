"""Parameters of the ``guides`` stage, apart from its kernels.

They are read when a scene is checked (``fluidymation check``), which should not pay for
importing the numerical code of :mod:`fluidymation.stages.guides`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from fluidymation.errors import ParameterError


@dataclass(frozen=True)
class Params:
    """Parameters of the guides stage; lengths in px at full resolution.

    Attributes
    ----------
    blur_sigma : Gaussian blur of the masks before thresholding (thesis 4.1), px.
    exemplar_blur_sigma : the same for an exemplar's masks (:meth:`for_exemplar`), px: they are the
        paint's own edge, which a wide blur moves off the rim (docs/guides.md).
    threshold : blurred coverage at or above which a pixel is inside; below 0.5 so the
        mask includes a little paper.
    dist_time_sigma : Gaussian smoothing of the distance fields along time before the
        flow estimate, frames.
    flow_time_radius : radius of the Gaussian smoothing of the estimated flow along
        time, frames (the kernel spans 3 standard deviations).
    shape_radius : radius ``b`` of the blur that makes the ``shape`` channel, px.
    border_width : signed distance below which an inside pixel is in the border
        segment, px.
    scale : multiplies every px length above (e.g. the exemplar's scale factor).
    relax_sweeps : relaxation sweeps per multigrid level of the interior flow fill.
    """

    blur_sigma: float = 8.0
    exemplar_blur_sigma: float = 2.0
    threshold: float = 0.4
    dist_time_sigma: float = 2.0
    flow_time_radius: int = 3
    shape_radius: float = 30.0
    border_width: float = 10.0
    scale: float = 1.0
    relax_sweeps: int = 8

    def __post_init__(self):
        checks = (
            ("blur_sigma", self.blur_sigma >= 0, "at least 0"),
            ("exemplar_blur_sigma", self.exemplar_blur_sigma >= 0, "at least 0"),
            ("threshold", 0 < self.threshold < 1, "between 0 and 1 (exclusive)"),
            ("dist_time_sigma", self.dist_time_sigma >= 0, "at least 0"),
            ("flow_time_radius", int(self.flow_time_radius) == self.flow_time_radius and self.flow_time_radius >= 0,
             "a whole number of frames, at least 0"),
            ("shape_radius", self.shape_radius >= 0, "at least 0"),
            ("border_width", self.border_width > 0, "positive"),
            ("scale", self.scale > 0, "positive"),
            ("relax_sweeps", int(self.relax_sweeps) == self.relax_sweeps and self.relax_sweeps >= 1,
             "a whole number, at least 1"),
        )
        for name, valid, wanted in checks:
            if not valid:
                raise ParameterError(name, f"guides: parameter {name} must be {wanted}, got {getattr(self, name)!r}")


def for_exemplar(params: Params) -> Params:
    """The parameters of an exemplar's guides: ``params`` with its masks blurred by ``exemplar_blur_sigma``."""
    return replace(params, blur_sigma=params.exemplar_blur_sigma)
