"""A tiny made-up stylize job that runs an exemplar stylizer's kernels in well under a second once they are
compiled: a 64×64 ellipse drifting for 3 frames with its motion given (as a vector layer's geometry gives
it), painted from a 32×32×4 blob of smooth colour noise.

:meth:`fluidymation.stages.stylizer.Stylizer.warm_up` stylizes it, so a helper process can compile those
kernels into numba's disk cache while a first render does other work (docs/performance.md). The arrays have
the types a real layer's have, so the kernels compile with the signatures the render then loads.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from fluidymation.stages.guide_params import Params as GuideParams
from fluidymation.stages.guide_params import for_exemplar
from fluidymation.stages.stylizer import StylizeJob

TARGET_SIZE = 64
FRAMES = 3
EXEMPLAR_SIZE = 32
EXEMPLAR_FRAMES = 4


def _ellipse(size: int, centre: tuple[float, float], axes: tuple[float, float]) -> np.ndarray:
    yy, xx = np.mgrid[:size, :size].astype(np.float32) + 0.5
    return ((xx - centre[0]) / axes[0]) ** 2 + ((yy - centre[1]) / axes[1]) ** 2 < 1.0


def _target_mask(j: int) -> np.ndarray:
    return _ellipse(TARGET_SIZE, (32.0 - 2.0 * j, 30.0 + j), (20.0, 14.0)).astype(np.float32)


def _target_flow(j: int) -> np.ndarray:
    """The ellipse's motion, known everywhere, as a vector layer's geometry gives it (no estimate from the masks)."""
    return np.broadcast_to(np.float32([-2.0, 1.0]), (TARGET_SIZE, TARGET_SIZE, 2)).copy()


def _exemplar(cache_dir: Path):
    """The made-up exemplar stored with its guides in ``cache_dir``, as the pipeline keeps exemplars: a blob
    growing by a pixel a frame, filled with smooth noise."""
    from scipy import ndimage

    from fluidymation.stages import exemplar_store, guides

    masks = [_ellipse(EXEMPLAR_SIZE, (16.0, 16.0), (9.0 + j, 8.0 + j)) for j in range(EXEMPLAR_FRAMES)]
    noise = np.random.default_rng(0).random((EXEMPLAR_FRAMES, EXEMPLAR_SIZE, EXEMPLAR_SIZE, 3))
    rgb = ndimage.gaussian_filter(noise, (0, 2, 2, 0)).astype(np.float32)
    still = np.zeros((EXEMPLAR_SIZE, EXEMPLAR_SIZE, 2), np.float32)
    guides.compute_guides(lambda j: masks[j], EXEMPLAR_FRAMES, params=for_exemplar(GuideParams()),
                          cache_dir=cache_dir, given_flow=lambda j: still)
    exemplar_store.store_colour(rgb, cache_dir)
    return exemplar_store.StoredSource(cache_dir)


def tiny_job(folder: Path) -> StylizeJob:
    """The made-up job, its scratch files in ``folder``."""
    return StylizeJob(masks=_target_mask, frame_count=FRAMES, frames=(0, FRAMES), source=_exemplar(folder / "exemplar"),
                      guide_params=GuideParams(), cache_dir=str(folder / "target"), given_flow=_target_flow,
                      layer="warm-up")
