"""Parameters and version of the keyframe morph (the ``keyframes`` stylizer), apart from its kernels.

They are read when a scene is checked (``fluidymation check``), which should not pay for
importing the numerical code of :mod:`fluidymation.stages.keyframe_morph`.
"""

from __future__ import annotations

from dataclasses import dataclass

from fluidymation.errors import ParameterError

VERSION = 1
SCHEDULES = ("jacobi", "sequential")
#: How a frame weighs the keyframes around it (:func:`fluidymation.stages.keyframes.keyframe_weights`).
WEIGHTINGS = ("blend", "radius", "smooth")


@dataclass(frozen=True)
class Params:
    """Parameters of the keyframe morph (defaults: configs/keyframes.yaml).

    beta : weight β of the terms to the neighbouring frames (temporal coherence).
    prior_size : width p of the motion prior's search window to the neighbours, px of each level.
    gamma : velocity modulation of p (eq. 6.2), 0–1; pass 2 of the two-pass morph (or the one pass).
    weighting : keyframe weights ŵ: ``blend``, ``radius`` or ``smooth`` (pass 2, or the one pass).
    radius : keys weighed by ``radius`` / ``smooth``.
    two_pass : the two-pass morph of section 7 (else one pass with the settings above).
    patch_size : odd patch side.
    levels : pyramid levels of the (first) pass; 0: as many as keep the coarsest side ≥ 32 px.
    sweeps : sweeps per level.
    em_iterations : search–vote iterations per frame and sweep.
    patchmatch_iterations : PatchMatch passes per keyframe term and iteration.
    mask_weight : weight of the coverage guide beside the four colour channels.
    schedule : ``jacobi`` (parallel frames) or ``sequential``.
    seed : random seed.
    """

    beta: float = 1.0
    prior_size: int = 5
    gamma: float = 1.0
    weighting: str = "radius"
    radius: int = 2
    two_pass: bool = True
    patch_size: int = 5
    levels: int = 0
    sweeps: int = 2
    em_iterations: int = 2
    patchmatch_iterations: int = 2
    mask_weight: float = 1.0
    schedule: str = "jacobi"
    seed: int = 0

    def __post_init__(self):
        checks = (
            ("beta", self.beta >= 0, "at least 0"),
            ("prior_size", int(self.prior_size) == self.prior_size and self.prior_size >= 1, "a whole number ≥ 1"),
            ("gamma", 0 <= self.gamma <= 1, "between 0 and 1"),
            ("weighting", self.weighting in WEIGHTINGS, f"one of {', '.join(WEIGHTINGS)}"),
            ("radius", int(self.radius) == self.radius and self.radius >= 1, "a whole number ≥ 1"),
            ("patch_size", int(self.patch_size) == self.patch_size and self.patch_size >= 3 and self.patch_size % 2,
             "an odd whole number ≥ 3"),
            ("levels", int(self.levels) == self.levels and self.levels >= 0, "a whole number ≥ 0 (0: automatic)"),
            ("sweeps", int(self.sweeps) == self.sweeps and self.sweeps >= 1, "a whole number ≥ 1"),
            ("em_iterations", int(self.em_iterations) == self.em_iterations and self.em_iterations >= 1,
             "a whole number ≥ 1"),
            ("patchmatch_iterations", int(self.patchmatch_iterations) == self.patchmatch_iterations
             and self.patchmatch_iterations >= 0, "a whole number ≥ 0"),
            ("mask_weight", self.mask_weight >= 0, "at least 0"),
            ("schedule", self.schedule in SCHEDULES, f"one of {', '.join(SCHEDULES)}"),
            ("seed", int(self.seed) == self.seed and self.seed >= 0, "a whole number ≥ 0"),
        )
        for name, valid, wanted in checks:
            if not valid:
                raise ParameterError(name, f"keyframes: parameter {name} must be {wanted}, got {getattr(self, name)!r}")
