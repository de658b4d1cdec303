"""The ``thorvg`` renderer: Lottie documents drawn by the ThorVG player, in a child process per document.

ThorVG is native code that has crashed and hung on fuzzed files, so it never runs in
this process: each document gets a persistent worker (:mod:`thorvg_worker`, started on
first use, core dumps disabled) that keeps the isolated animations it has loaded. A
worker that dies or does not answer within the timeout becomes an :class:`InputError`
naming the file and the frame; the next render starts a new one.
"""

from __future__ import annotations

import mmap
import os
import select
import signal
import struct
import subprocess
import sys
import tempfile
import time
import weakref
from collections import OrderedDict
from pathlib import Path

import numpy as np

from fluidymation.errors import InputError
from fluidymation.stages.vector import thorvg_worker as protocol
from fluidymation.stages.vector.base import Renderer

WORKER_SCRIPT = Path(protocol.__file__)
LOADED_PER_WORKER = 8  # isolated animations a worker keeps (a layer's frames are rendered one after the other)
SHARED_FOLDER = "/dev/shm" if os.path.isdir("/dev/shm") and os.access("/dev/shm", os.W_OK) else None


class PlayerFailed(Exception):
    """The worker died, hung or could not do what was asked; ``reason`` says which, for the user."""

    def __init__(self, reason: str):
        super().__init__(reason)
        self.reason = reason


class ThorVGRenderer(Renderer):
    """Draws Lottie documents (.json, .lottie, .tgs) with ThorVG, at fractional frames.

    ``document.isolate`` gives the JSON in which only the wanted layers draw and the frame
    counted from the in-point; the worker fits the composition into the output size as
    the SVG path did (uniform scale, centred) and returns premultiplied RGBA.
    ``frame_timeout`` and ``load_timeout`` (seconds) bound one frame and one load.
    """

    name = "thorvg"
    version = 1
    kinds = ("lottie", "dotlottie", "tgs")

    def __init__(self, *, frame_timeout: float = 60.0, load_timeout: float = 120.0,
                 command: tuple[str, ...] = (sys.executable, str(WORKER_SCRIPT))):
        self.frame_timeout, self.load_timeout, self.command = frame_timeout, load_timeout, command
        self._workers: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()

    def __getstate__(self):
        """Workers stay with their process: a copy of the renderer (a spawned job) starts its own."""
        return {"frame_timeout": self.frame_timeout, "load_timeout": self.load_timeout, "command": self.command}

    def __setstate__(self, state):
        self.__init__(**state)

    def render(self, document, layers, time_seconds, size):
        isolated = document.isolate(layers, time_seconds)
        width, height = size
        worker = self._workers.get(document)
        if worker is None or not worker.alive():
            worker = self._workers[document] = _Worker(self.command)
        try:
            key = worker.load(tuple(sorted(layers)), isolated.json, self.load_timeout)
            return worker.render(key, isolated.frame, width, height, self.frame_timeout)
        except PlayerFailed as exc:
            frame = f"frame {isolated.frame + document.in_point:g} ({time_seconds:.3f} s)"
            raise InputError(f"{document.path}: {frame}: {exc.reason}") from None


class _Worker:
    """One ThorVG child process and the isolated animations it has loaded (least recently used first).

    Frames come back through a shared file (in memory where /dev/shm exists), not the pipe.
    """

    def __init__(self, command: tuple[str, ...]):
        self.errors = tempfile.TemporaryFile()
        self.shared = tempfile.TemporaryFile(dir=SHARED_FOLDER)
        self.view: mmap.mmap | None = None
        descriptor = self.shared.fileno()
        self.process = subprocess.Popen((*command, str(descriptor)), stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                        stderr=self.errors, pass_fds=(descriptor,))
        self.loaded: OrderedDict[tuple[str, ...], int] = OrderedDict()
        self.next_key = 0
        weakref.finalize(self, _stop, self.process, self.errors, self.shared)

    def alive(self) -> bool:
        return self.process.poll() is None

    def load(self, names: tuple[str, ...], data: bytes, timeout: float) -> int:
        """The worker's key for the animation of ``names``, loading ``data`` if it is not loaded yet."""
        if names in self.loaded:
            self.loaded.move_to_end(names)
            return self.loaded[names]
        if len(self.loaded) >= LOADED_PER_WORKER:
            _, oldest = self.loaded.popitem(last=False)
            self._ask(b"F", struct.pack(protocol.KEY, oldest), timeout, "forgetting an animation")
        key, self.next_key = self.next_key, self.next_key + 1
        self._ask(b"L", struct.pack(protocol.KEY, key) + data, timeout, "loading the animation")
        self.loaded[names] = key
        return key

    def render(self, key: int, frame: float, width: int, height: int, timeout: float) -> np.ndarray:
        """(height, width, 4) uint8 premultiplied RGBA."""
        size = width * height * 4
        if self.view is None or len(self.view) < size:
            if self.view is not None:
                self.view.close()
            os.ftruncate(self.shared.fileno(), size)
            self.view = mmap.mmap(self.shared.fileno(), size)
        reply = self._ask(b"R", struct.pack(protocol.RENDER, key, frame, width, height), timeout, "drawing")
        (count,) = struct.unpack(protocol.COUNT, reply)
        if count != size:
            raise PlayerFailed(f"the Lottie player returned {count} bytes for a {width}x{height} frame")
        return np.frombuffer(self.view, np.uint8, count=size).reshape(height, width, 4).copy()

    def _ask(self, kind: bytes, payload: bytes, timeout: float, doing: str) -> bytes:
        """Send one request and wait up to ``timeout`` seconds for its reply."""
        try:
            self.process.stdin.write(struct.pack(protocol.HEADER, kind, len(payload)) + payload)
            self.process.stdin.flush()
        except BrokenPipeError:
            raise PlayerFailed(self._death(doing)) from None
        deadline = time.monotonic() + timeout
        header = self._read(struct.calcsize(protocol.HEADER), deadline, doing)
        status, length = struct.unpack(protocol.HEADER, header)
        reply = self._read(length, deadline, doing)
        if status != b"K":
            raise PlayerFailed(f"the Lottie player failed while {doing} ({reply.decode(errors='replace')})")
        return reply

    def _read(self, count: int, deadline: float, doing: str) -> bytes:
        stream = self.process.stdout.fileno()
        chunks, remaining = [], count
        while remaining:
            ready, _, _ = select.select([stream], [], [], max(0.0, deadline - time.monotonic()))
            if not ready:
                self.process.kill()
                self.process.wait()
                raise PlayerFailed(f"the Lottie player did not finish {doing} in time (hung?); it was stopped")
            chunk = os.read(stream, min(remaining, 1 << 20))
            if not chunk:
                raise PlayerFailed(self._death(doing))
            chunks.append(chunk)
            remaining -= len(chunk)
        return b"".join(chunks)

    def _death(self, doing: str) -> str:
        """Why the worker is gone: the signal that killed it, or its exit status and last error line."""
        code = self.process.wait()
        if code < 0:
            return f"the Lottie player crashed while {doing} (signal {_signal_name(-code)})"
        self.errors.seek(0)
        lines = self.errors.read().decode(errors="replace").strip().splitlines()
        return f"the Lottie player exited with status {code} while {doing}" + (f" ({lines[-1]})" if lines else "")


def _signal_name(number: int) -> str:
    try:
        return signal.Signals(number).name
    except ValueError:
        return str(number)


def _stop(process: subprocess.Popen, errors, shared) -> None:
    """End a worker: closing its input ends its loop; one that does not end is killed."""
    try:
        process.stdin.close()
    except BrokenPipeError:
        pass
    try:
        process.wait(timeout=5)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()
    process.stdout.close()
    errors.close()
    shared.close()
