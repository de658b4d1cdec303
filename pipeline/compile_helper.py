"""Compile a layer's stylize kernels in a helper process while a first render does other work.

Numba compiles one kernel at a time on one core. On a first run (numba's disk cache empty) the
synthesis kernels alone took two thirds of the quick start's compile time (docs/performance.md).
:func:`alongside` wraps the layers of a render: when a chosen layer's stylizer has a warm-up
(:attr:`~fluidymation.stages.stylizer.Stylizer.warm_up_modules`) and the cache lacks the PatchMatch
search, it starts ``python -m fluidymation.pipeline.compile_helper``, which runs that layer's stylizer with the
layer's parameters on a tiny made-up layer (:meth:`~fluidymation.stages.stylizer.Stylizer.warm_up`). It
compiles into the disk cache on the second core while the render rasterizes the layers, computes their
guides and simulates the exemplar. When the render needs a kernel of those modules that is not in the
cache yet, it waits for the helper and loads what the helper saved; a kernel the helper did not compile
(another signature) it compiles itself (:func:`fluidymation.engine._jit.compiled_elsewhere`). Loaded or
compiled here, a kernel gives the same bits (docs/engine.md). The helper is stopped when the render
ends, finished or not; a helper that fails, or takes longer than :data:`WAIT_AT_MOST`, leaves the
compiling to the render.
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
import pickle
import subprocess
import sys
import tempfile
import threading
from pathlib import Path

from fluidymation.stages.stylizer import Stylizer

log = logging.getLogger(__name__)

#: s the render waits for its helper at most (22–29 s in the runs of docs/performance.md)
WAIT_AT_MOST = 600


class _Helper:
    """The running helper process and what it reported."""

    def __init__(self, stylizer: Stylizer, params):
        environment = dict(os.environ, NUMBA_NUM_THREADS="1")  # its jobs are tiny: one thread, one core
        self.errors = tempfile.TemporaryFile()  # not a pipe: nobody reads it while the helper runs
        self.lock = threading.Lock()
        self.process = subprocess.Popen([sys.executable, "-m", "fluidymation.pipeline.compile_helper"], env=environment,
                                        stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=self.errors)
        self.process.stdin.write(pickle.dumps((stylizer.name, params)))
        self.process.stdin.close()
        self.name = stylizer.name

    def wait(self) -> None:
        """Wait for the helper to finish (at once if it has), then tell the compile listeners what it did."""
        from fluidymation.engine import compiling

        with self.lock:  # kernels may be looked up on several threads
            if self.process.returncode is not None:
                return
            compiling.notify(None, True)
            try:
                self.process.wait(timeout=WAIT_AT_MOST)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
                log.debug("the %s kernel warm-up took over %g s; the render compiles the kernels itself", self.name,
                          WAIT_AT_MOST)
                return
            finally:
                compiling.notify(None, False)
            output = self.process.stdout.read()  # one line: it fits the pipe while the helper runs
        if self.process.returncode != 0:
            self.errors.seek(0)
            log.debug("the %s kernel warm-up failed (%d); the render compiles them itself: %s", self.name,
                      self.process.returncode, self.errors.read().decode(errors="replace").strip()[-2000:])
            return
        report = json.loads(output.decode().strip().splitlines()[-1])
        compiling.helper_finished(report["kernels"], report["seconds"])

    def stop(self) -> None:
        with self.lock:
            if self.process.poll() is None:
                self.process.kill()
                self.process.wait()
        self.process.stdout.close()
        self.errors.close()


@contextlib.contextmanager
def alongside(stylizers_and_params):
    """Within the block, the first of the (stylizer, params) pairs whose stylizer has a warm-up is warmed up in a
    helper process, unless numba's disk cache holds the PatchMatch search already; a kernel of its modules
    missing from the disk cache waits for the helper."""
    chosen = next(((stylizer, params) for stylizer, params in stylizers_and_params if stylizer.warm_up_modules), None)
    if chosen is None:
        yield
        return
    from fluidymation.engine import _jit, patchmatch  # numerical code: only when rendering

    if _jit.in_disk_cache(patchmatch._search_tile):
        yield
        return

    helper = _Helper(*chosen)
    log.debug("compiling the %s kernels in a helper process (pid %d)", helper.name, helper.process.pid)
    try:
        with _jit.compiled_elsewhere(chosen[0].warm_up_modules, helper.wait):
            yield
    finally:
        helper.stop()


def _warm_up_here() -> None:
    """The helper: warm up the stylizer named on stdin (a pickle of (name, params)); print what it compiled."""
    import time

    from fluidymation.engine import compiling
    from fluidymation.pipeline.stylizers import get_stylizer

    name, params = pickle.loads(sys.stdin.buffer.read())
    compiled = []
    compiling.listeners.append(lambda kernel, started: None if started else compiled.append(kernel))
    started = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="fluidymation-warm-up-") as folder:
        get_stylizer(name).warm_up(params, Path(folder))
    print(json.dumps({"kernels": len(compiled), "seconds": time.perf_counter() - started}))


if __name__ == "__main__":
    _warm_up_here()
