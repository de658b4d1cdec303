"""Progress bars on stderr: shown only for work that takes over a second, never with -q."""

from __future__ import annotations

import sys

from tqdm import tqdm


def progress(total: int, description: str, *, quiet: bool = False, unit: str = "frame") -> tqdm:
    return tqdm(total=total, desc=description, unit=unit, file=sys.stderr, disable=True if quiet else None, delay=1.0,
                dynamic_ncols=True, leave=False)


def reporter(bar: tqdm):
    """A ``progress(done, total)`` callback that moves ``bar``, for stages that count their own work."""

    def report(done: int, total: int) -> None:
        bar.total = total
        bar.n = done
        bar.refresh()

    return report
