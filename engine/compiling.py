"""Who hears that a kernel is being compiled, without loading numba to ask.

:mod:`fluidymation.engine._jit` calls every function in :data:`listeners` with
``(kernel_name, started)`` when numba starts (``started`` True) and ends compiling a
kernel, not when it loads one from its disk cache. The CLI listens, to say on a first run
why it is slow (docs/performance.md).
"""

from __future__ import annotations

from typing import Callable

listeners: list[Callable[[str, bool], None]] = []


def notify(kernel_name: str, started: bool) -> None:
    """Tell every listener that ``kernel_name`` starts (``started``) or has finished compiling."""
    for listener in listeners:
        listener(kernel_name, started)
