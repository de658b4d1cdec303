"""What an interrupted stylize stage needs to continue: the state after its last finished frame.

After each frame's files are written, the frame's state (its NNF, the motion not yet
followed and its colour, see :class:`fluidymation.stages.stylize.StylizedFrame`) is saved atomically as
``<index>.npz`` and older states are removed. A restarted run continues after the longest
prefix of the processing order whose frames are all finished and whose last state is
saved; :func:`~fluidymation.stages.stylize.stylize_sequence` then yields exactly the
frames an uninterrupted run would.
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable

import numpy as np

from fluidymation.engine.nnf import NNF
from fluidymation.stages.files import atomic_path
from fluidymation.stages.stylize import StylizedFrame


class FrameStates:
    """States of a layer's stylized frames in ``folder``, one kept at a time."""

    def __init__(self, folder: Path):
        self.folder = Path(folder)

    def _path(self, index: int) -> Path:
        return self.folder / f"{index:05d}.npz"

    def save(self, frame: StylizedFrame) -> None:
        """Save ``frame``'s state (after its files), then drop the states before it."""
        with atomic_path(self._path(frame.index)) as tmp, open(tmp, "wb") as handle:
            np.savez(handle, frame=frame.nnf.frame, coords=frame.nnf.coords, backlog=frame.backlog,
                     rgb=frame.rgba[..., :3])
        for older in self.folder.glob("*.npz"):
            if older != self._path(frame.index):
                older.unlink(missing_ok=True)

    def resume_point(self, order: list[int], finished: Callable[[int], bool]) -> tuple[int, tuple] | None:
        """Where to continue: (frames done, ``resume`` argument of ``stylize_sequence``), or None to start afresh.

        ``order`` lists the frame indices in processing order; ``finished(index)`` tells
        whether a frame's files are all written.
        """
        saved = {int(path.stem) for path in self.folder.glob("*.npz") if path.stem.isdigit()}
        done = 0
        while done < len(order) and finished(order[done]):
            done += 1
        for count in range(done, 0, -1):
            index = order[count - 1]
            if index in saved:
                with np.load(self._path(index)) as state:
                    return count, (index, NNF(state["frame"], state["coords"]), state["backlog"], state["rgb"])
        return None
