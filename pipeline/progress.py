"""Progress on stderr: bars shown only for work that takes over a second, or JSON lines; never with -q.

With :func:`use_json_lines` (``--json``) every step of work prints one line
``{"stage": ..., "layer": ..., "done": n, "total": m}`` instead of a bar, for programs
that watch a render.
"""

from __future__ import annotations

import json
import sys
import time


_json_lines = False


def use_json_lines(enabled: bool) -> None:
    """Report progress as JSON lines (True) or bars (False) from now on, in this process."""
    global _json_lines
    _json_lines = enabled


def json_lines() -> bool:
    """Whether progress is reported as JSON lines."""
    return _json_lines


def progress(total: int | None, description: str, *, layer: str | None = None, quiet: bool = False,
             unit: str = "frame"):
    """A progress counter for ``total`` steps of ``description`` (a stage), optionally of a ``layer``.

    Use it as a context manager; ``update(n=1)`` counts steps done.
    """
    if _json_lines and not quiet:
        return JsonProgress(total, description, layer)
    label = description if layer is None else f"{description} {layer}"
    from tqdm import tqdm  # here, not at import: it costs the CLI's start-up a tenth of a second

    return tqdm(total=total, desc=label, unit=unit, file=sys.stderr, disable=True if quiet else None, delay=1.0,
                dynamic_ncols=True, leave=False)


class JsonProgress:
    """A progress counter that prints ``{"stage", "layer", "done", "total"}`` as a JSON line at every change."""

    def __init__(self, total: int | None, stage: str, layer: str | None):
        self.total, self.stage, self.layer, self.n = total, stage, layer, 0

    def __enter__(self):
        self.refresh()
        return self

    def __exit__(self, *exc) -> None:
        return None

    def update(self, n: int = 1) -> None:
        self.n += n
        self.refresh()

    def refresh(self) -> None:
        line = json.dumps({"stage": self.stage, "layer": self.layer, "done": self.n, "total": self.total})
        print(line, file=sys.stderr, flush=True)


def reporter(bar):
    """A ``progress(done, total)`` callback that moves ``bar``, for stages that count their own work."""

    def report(done: int, total: int) -> None:
        bar.total = total
        bar.n = done
        bar.refresh()

    return report


class CompileNotice:
    """Says once, when numba starts compiling kernels (a first run, or after an upgrade), why the run is slow,
    and counts the kernels on a progress line; later runs load them from numba's disk cache and hear nothing.

    Listen with :meth:`listen` (it does not load numba) and :meth:`close` when the command ends, which says
    how many kernels were compiled and how long compiling took (numba compiles one kernel at a time, the
    kernels it calls inside it), and how many a helper process compiled for it (pipeline/compile_helper.py).
    """

    def __init__(self, *, quiet: bool = False):
        self.quiet, self.bar, self.compiled = quiet, None, 0
        self.depth, self.since, self.seconds = 0, 0.0, 0.0
        self.helper_compiled, self.helper_seconds = 0, 0.0

    def listen(self) -> CompileNotice:
        from fluidymation.engine import compiling

        compiling.listeners.append(self.heard)
        compiling.helper_listeners.append(self.heard_helper)
        return self

    def heard_helper(self, kernels: int, seconds: float) -> None:
        """A helper process compiled ``kernels`` kernels for this one in ``seconds`` (pipeline/compile_helper.py)."""
        self.helper_compiled += kernels
        self.helper_seconds += seconds

    def heard(self, kernel: str | None, started: bool) -> None:
        """``kernel`` (None: the wait for a helper compiling kernels, timed but not counted) starts or ends."""
        if self.bar is None:
            if not self.quiet and not _json_lines:
                print("compiling kernels (first run only: they are kept in numba's disk cache)", file=sys.stderr,
                      flush=True)
            self.bar = progress(None, "compiling kernels", quiet=self.quiet, unit="kernel").__enter__()
        if started:
            if self.depth == 0:
                self.since = time.monotonic()
            self.depth += 1
            return
        self.depth -= 1
        if self.depth == 0:
            self.seconds += time.monotonic() - self.since
        if kernel is not None:
            self.compiled += 1
            self.bar.update()

    def close(self) -> None:
        from fluidymation.engine import compiling

        if self.heard in compiling.listeners:
            compiling.listeners.remove(self.heard)
        if self.heard_helper in compiling.helper_listeners:
            compiling.helper_listeners.remove(self.heard_helper)
        if self.bar is None:
            return
        self.bar.__exit__(None, None, None)
        if not self.quiet and not _json_lines:
            kernels = f"{self.compiled} kernel{'' if self.compiled == 1 else 's'}"
            helper = (f"; a helper process compiled {self.helper_compiled} more alongside in {self.helper_seconds:.0f} s "
                      f"(the {self.seconds:.0f} s include waiting for it)" if self.helper_compiled else "")
            print(f"compiled {kernels} in {self.seconds:.0f} s{helper}", file=sys.stderr)
        self.bar = None
