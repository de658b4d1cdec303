"""Parameters and version of the ``stylize`` stage (the ``fluidymation`` stylizer), apart from its kernels.

They are read when a scene is checked (``fluidymation check``), which should not pay for
importing the numerical code of :mod:`fluidymation.stages.stylize`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fluidymation.errors import ParameterError

VERSION = 7  # 7: an exemplar with one segment is matched by the whole target (was unmatched, black)


@dataclass(frozen=True)
class Params:
    """Parameters of the stylize stage (paper Table 1, thesis CLI table).

    Attributes
    ----------
    patch_size : int
        n, odd.
    w_bound, w_edge, w_ext, w_dir, w_temp, w_uni : float
        Weights of the shape, edge-distance, motion-extent, orientation, temporal and
        uniformity terms; any may be 0. The edge guide is the thesis's border channel
        ``df = min(dist / border_width, 1)`` (section 3.4), floored at −1 outside the mask.
    uniformity_lambda : float
        λ: the uniformity penalty at exactly the budget (Ω = ω*) in the units of the
        colour SSD (sRGB in [0, 1]); the penalty weight is ``w_uni · λ``.
    cuboid_radius : int
        r, frames before and after a patch that count as used (uniformity).
    uni_carried : float
        Factor of the uniformity penalty where the temporal term holds (m(q) = 1): the
        penalty is scaled by ``1 − (1 − uni_carried)·m(q)``, so paint carried over from the
        previous frame is not re-spread frame after frame (1: the paper; beyond it, docs/stylize.md).
    histogram_matching : float
        Strength (0–1) of matching each vote's colour histogram to the exemplar frames its
        matches use, against wash-out (beyond the paper; docs/stylize.md).
    m_lower, m_upper : float
        Temporal modulation bounds as fractions of d, the larger target side: m = 1
        where the (border-clamped) distances differ by ≤ m_lower·d, 0 by ≥ m_upper·d.
    ext_unit : float
        Length in px that ext+ and ext− are divided by before comparison.
    dir_clamp : float
        Clamp of ``|tan|`` in the orientation term.
    alpha : float
        Random-search box shrink factor.
    opt_iters, pm_iters : tuple of int
        Search-vote and PatchMatch iterations per level, coarsest first; the last value
        repeats.
    vote_only_finest : bool
        Only vote the finest level from the upscaled field.
    finest_propagation : int
        With ``vote_only_finest``, propagation-only PatchMatch passes on the finest level
        before its vote (they join the upscaled field's 2×2 blocks; docs/stylize.md).
    guided_init : bool
        Refine the first frame's random field with a guides-only pass.
    pyramid_levels : int or None
        None: ``floor(log2(d_min / n))`` capped so the coarsest level fits 2n + 1.
    reverse : bool
        Synthesize from the last frame to the first (material being added).
    carry : bool
        Carry the previous frame's matches along the target's motion before the
        exemplar-time shift, so the texture travels with the shape (a painted wheel
        turning); False: the paper, the paint stays on the paper and flows at moving
        edges (beyond the paper; docs/stylize.md).
    settle_passes : int
        Times a fresh start (the first frame processed) is synthesized again with itself
        as the previous frame, so the next frames do not re-trade its unconverged matches
        (beyond the paper; docs/stylize.md).
    keep_margin : float
        Where the temporal term holds (m(q) = 1), the relative improvement in patch cost a
        match needs to replace the one carried over from the previous frame (scaled by
        m(q); 0: the paper). Settle passes do not use it (beyond the paper; docs/stylize.md).
    still_speed : float
        Motion (px, since the previous frame and not yet followed) under which the target
        counts as still: there, carried-over matches are kept outright (0: never).
    recede_release : float
        Where the target's edge distance fell since the previous frame (the edge moving
        inward past the pixel), m(q) is scaled down linearly, to 0 once it fell by this many
        px: paint laid at the old edge cannot follow it inward (the paper's temporal coherence
        is forward only, section 5), so it is painted afresh. Not with ``carry``. 0: the paper
        (beyond the paper; docs/stylize.md).
    source_window : int or None
        Exemplar frames held and searched at a time (None: all). The window slides evenly
        from the exemplar's first frames at the first processing step to its last frames
        at the last step (:func:`window_start`), so memory follows the window, not the
        exemplar's length (paper section 5; beyond it: docs/stylize.md).
    seed : int
    """

    patch_size: int = 5
    w_bound: float = 4.0
    w_edge: float = 4.0
    w_ext: float = 0.25
    w_dir: float = 0.0
    w_temp: float = 4.0
    w_uni: float = 1.0
    uniformity_lambda: float = 0.3
    cuboid_radius: int = 5
    uni_carried: float = 0.0
    histogram_matching: float = 1.0
    m_lower: float = 0.01
    m_upper: float = 0.1
    ext_unit: float = 10.0
    dir_clamp: float = 10.0
    alpha: float = 0.75
    opt_iters: tuple = (4, 2, 1)
    pm_iters: tuple = (6, 4, 4)
    vote_only_finest: bool = True
    finest_propagation: int = 1
    guided_init: bool = True
    pyramid_levels: int | None = None
    reverse: bool = False
    carry: bool = False
    settle_passes: int = 2
    keep_margin: float = 0.2
    still_speed: float = 0.05
    recede_release: float = 2.0
    source_window: int | None = None
    seed: int = 0

    def __post_init__(self):
        for name in ("opt_iters", "pm_iters"):
            value = getattr(self, name)
            if isinstance(value, (int, np.integer)):
                value = (value,)
            object.__setattr__(self, name, tuple(int(v) for v in value))
        checks = (
            ("patch_size", self.patch_size >= 3 and self.patch_size % 2 == 1, "an odd number ≥ 3"),
            ("w_bound", self.w_bound >= 0, "≥ 0"), ("w_edge", self.w_edge >= 0, "≥ 0"), ("w_ext", self.w_ext >= 0, "≥ 0"),
            ("w_dir", self.w_dir >= 0, "≥ 0"), ("w_temp", self.w_temp >= 0, "≥ 0"),
            ("w_uni", self.w_uni >= 0, "≥ 0"), ("uniformity_lambda", self.uniformity_lambda >= 0, "≥ 0"),
            ("cuboid_radius", self.cuboid_radius >= 0, "≥ 0"),
            ("uni_carried", 0 <= self.uni_carried <= 1, "between 0 and 1"),
            ("histogram_matching", 0 <= self.histogram_matching <= 1, "between 0 and 1"),
            ("m_lower", 0 <= self.m_lower <= self.m_upper, "between 0 and m_upper"),
            ("ext_unit", self.ext_unit > 0, "positive"), ("dir_clamp", self.dir_clamp > 0, "positive"),
            ("alpha", 0 < self.alpha < 1, "between 0 and 1 (exclusive)"),
            ("opt_iters", bool(self.opt_iters) and min(self.opt_iters) >= 0, "a list of counts ≥ 0"),
            ("pm_iters", bool(self.pm_iters) and min(self.pm_iters) >= 0, "a list of counts ≥ 0"),
            ("pyramid_levels", self.pyramid_levels is None or self.pyramid_levels >= 1, "≥ 1"),
            ("settle_passes", self.settle_passes >= 0, "≥ 0"),
            ("finest_propagation", self.finest_propagation >= 0, "≥ 0"),
            ("keep_margin", 0 <= self.keep_margin <= 1, "between 0 and 1"),
            ("still_speed", self.still_speed >= 0, "≥ 0"),
            ("recede_release", self.recede_release >= 0, "≥ 0"),
            ("source_window", self.source_window is None or (
                isinstance(self.source_window, (int, np.integer)) and not isinstance(self.source_window, bool)
                and self.source_window >= self.min_source_window),
             f"null or a whole number of frames ≥ {self.min_source_window} (2·cuboid_radius + 1, at least 2)"),
            ("seed", 0 <= self.seed < 2**31, "between 0 and 2^31 − 1"),
        )
        for name, valid, wanted in checks:
            if not valid:
                raise ParameterError(name, f"stylize: parameter {name} must be {wanted}, got {getattr(self, name)!r}")

    @property
    def min_source_window(self) -> int:
        """The smallest ``source_window``: a patch's uniformity cuboid fits, and SHIFTNNF can move."""
        return max(2, 2 * int(self.cuboid_radius) + 1)
