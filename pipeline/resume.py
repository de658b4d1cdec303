"""What an interrupted stylize stage needs to continue: the state after its last finished frame.

After each frame's files are written, the frame's state (the named arrays its stylizer's
:meth:`~fluidymation.stages.stylizer.Stylizer.frame_state` gives) is saved atomically as
``<index>.npz`` and older states are removed. A restarted run continues after the longest
prefix of the processing order whose frames are all finished and whose last state is
saved; the stylizer, given :meth:`~fluidymation.stages.stylizer.Stylizer.resume_from`
of that state, then yields exactly the frames an uninterrupted run would.
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable

import numpy as np

from fluidymation.stages.files import atomic_path
from fluidymation.stages.stylizer import StylizedFrame, Stylizer


class FrameStates:
    """States of a layer's stylized frames in ``folder`` in ``stylizer``'s format, one kept at a time."""

    def __init__(self, folder: Path, stylizer: Stylizer):
        self.folder = Path(folder)
        self.stylizer = stylizer

    def _path(self, index: int) -> Path:
        return self.folder / f"{index:05d}.npz"

    def save(self, frame: StylizedFrame) -> None:
        """Save ``frame``'s state (after its files), then drop the states before it."""
        with atomic_path(self._path(frame.index)) as tmp, open(tmp, "wb") as handle:
            np.savez(handle, **self.stylizer.frame_state(frame))
        for older in self.folder.glob("*.npz"):
            if older != self._path(frame.index):
                older.unlink(missing_ok=True)

    def resume_point(self, order: list[int], finished: Callable[[int], bool]) -> tuple[int, tuple] | None:
        """Where to continue: (frames done, the job's ``resume`` for the stylizer), or None to start afresh.

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
                    return count, self.stylizer.resume_from(index, dict(state))
        return None
