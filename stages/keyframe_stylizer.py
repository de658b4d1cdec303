"""The ``keyframes`` stylizer: an artist's painted keyframes in-betweened along the layer's motion (seed 003).

Parameters are :class:`fluidymation.stages.keyframe_params.Params`, their defaults
``configs/keyframes.yaml``; the method is :mod:`fluidymation.stages.keyframe_morph`
(docs/keyframes.md). The motion is the layer's guides' flow (from the geometry with
``flow: vector``, else estimated from the masks). The morph's sweeps are checkpointed in
the job's work folder, so a killed render continues from the tasks it finished; its frames
are yielded once the last pass is done.
"""

from __future__ import annotations

import logging
from importlib import resources
from pathlib import Path

import numpy as np

from fluidymation.stages import keyframe_params
from fluidymation.stages.stylizer import Frame, StylizeJob, Stylizer

log = logging.getLogger(__name__)


def painted_frame(rgba: np.ndarray, coverage: np.ndarray) -> np.ndarray:
    """A morphed frame (premultiplied RGBA) as a stylized frame: its paint over white paper, the coverage as alpha."""
    out = np.empty(rgba.shape, np.float32)
    out[..., :3] = np.clip(rgba[..., :3] + (1.0 - np.clip(rgba[..., 3:], 0.0, 1.0)), 0.0, 1.0)
    out[..., 3] = coverage
    return out


def read_keyframes(job: StylizeJob) -> dict[int, np.ndarray]:
    """The job's keyframes as premultiplied RGBA at the output size (errors name the file)."""
    from fluidymation.stages.keyframes import read_keyframe  # on use: check loads no numerical code

    return {frame: read_keyframe(path, frame, job.masks(frame)) for frame, path in sorted(job.keyframes.items())}


class KeyframeStylizer(Stylizer):
    """Painted keyframes in-betweened by the flow-guided regenerative morph (seed 003, sections 4–7)."""

    name = "keyframes"
    version = keyframe_params.VERSION
    Params = keyframe_params.Params
    defaults = resources.files("fluidymation.configs").joinpath("keyframes.yaml")
    uses_keyframes = True
    default_colorize = "none"
    ablation = (("two-pass", ()), ("no neighbours", ("beta",)), ("no velocity modulation", ("gamma",)))

    def stylize(self, job: StylizeJob, params: keyframe_params.Params):
        from fluidymation.stages import keyframe_morph  # on use: check loads no numerical code

        root = Path(job.work_dir or job.cache_dir) / "morph"
        keyframes = read_keyframes(job)
        keyframe_morph.prepare(root, job.masks, job.motion(), job.frame_count, keyframes)
        shape = next(iter(keyframes.values())).shape[:2]
        map_tasks = job.map_tasks or keyframe_morph.serial_map
        total = keyframe_morph.sweep_count(params, shape)
        done = 0

        def swept():
            nonlocal done
            done += 1
            log.info("keyframes: sweep %d of %d done", done, total)

        contexts = keyframe_morph.morph(root, params, list(keyframes), job.frame_count, shape, map_tasks=map_tasks,
                                        progress=swept)
        first, stop = job.frames
        start = first if job.resume is None else job.resume + 1
        for index, rgba in keyframe_morph.frames_out(contexts):
            if start <= index < stop:
                yield Frame(index, painted_frame(rgba, job.masks(index)))
