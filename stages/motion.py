"""A layer's motion read from its vector geometry (``flow: vector``; docs/guides.md, "Motion from the geometry").

Frame j's flow is the motion from scene frame j − 1 to frame j (times ``(j − 1) / fps`` and
``j / fps``), in px/frame of the output raster, NaN wherever the geometry says nothing
(drawn elements it does not read, pixels outside every element): there the guides fill
in the masks' estimate. The first frame of a range, which has no frame before it, takes
the motion to the next frame, reversed (as the masks' estimate does).
"""

from __future__ import annotations

import numpy as np

from fluidymation.engine.vector_motion import vector_flow
from fluidymation.stages.vector.base import VectorDocument


def frame_motion(document: VectorDocument, names: tuple[str, ...], frame: int, fps: float,
                 size: tuple[int, int], *, first: bool = False) -> tuple[np.ndarray, list[str]]:
    """Scene frame ``frame``'s flow (H, W, 2) float32, NaN where unknown, and the drawn elements not read.

    ``first``: the frame opens the range (its flow is the reversed motion to the next frame).
    """
    other = frame + 1 if first else frame - 1
    elements, unread = document.moving_elements(list(names), other / fps, frame / fps, size)
    flow, owned = vector_flow(elements, (size[1], size[0]))
    if first:
        flow = -flow
    flow[~owned] = np.nan
    return flow, unread
