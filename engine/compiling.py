"""Who hears that a kernel is being compiled, without loading numba to ask.

:mod:`fluidymation.engine._jit` calls every function in :data:`listeners` with
``(kernel_name, started)`` when numba starts (``started`` True) and ends compiling a
kernel, not when it loads one from its disk cache; ``kernel_name`` None means this process
starts or stops waiting for a helper process that compiles kernels for it
(:mod:`fluidymation.pipeline.compile_helper`), which, when done, is reported to :data:`helper_listeners`
as ``(kernels, seconds)``. The CLI listens, to say on a first run why it is slow (docs/performance.md).
"""

from __future__ import annotations

from typing import Callable

listeners: list[Callable[[str | None, bool], None]] = []
helper_listeners: list[Callable[[int, float], None]] = []


def notify(kernel_name: str | None, started: bool) -> None:
    """Tell every listener that ``kernel_name`` (None: the wait for a helper) starts (``started``) or has finished."""
    for listener in listeners:
        listener(kernel_name, started)


def helper_finished(kernels: int, seconds: float) -> None:
    """Tell every helper listener that a helper process compiled ``kernels`` kernels in its ``seconds`` s."""
    for listener in helper_listeners:
        listener(kernels, seconds)
