"""The child process that runs ThorVG for :mod:`thorvg_renderer`, so a crash or hang of the native player stays here.

Run as a script (``python thorvg_worker.py FD``): it imports only the standard library
and ``thorvg_python``, disables core dumps, and answers requests on stdin with replies on
stdout until stdin closes. Each message is a header ``struct.pack(HEADER, kind, length)``
followed by ``length`` bytes:

* ``L`` load: ``key`` (u32) + Lottie JSON → ``K`` (loaded) or ``E`` + message;
* ``R`` render: ``key`` (u32), frame from the in-point (f64), width, height (u32) →
  ``K`` + the byte count (u32) of the (height, width, 4) premultiplied RGBA frame, which
  is in the shared file ``FD`` (so a frame does not go through the pipe), or ``E`` + message;
* ``F`` forget: ``key`` (u32) → ``K``.

The composition is fitted into the target as the SVG path fits it: scaled uniformly to
the largest size that fits and centred.
"""

from __future__ import annotations

import mmap
import os
import resource
import struct
import sys

HEADER = ">cI"
KEY = ">I"
RENDER = ">IdII"
COUNT = ">I"


class Player:
    """Loaded animations by key, each with its own canvas, on one single-threaded ThorVG engine (deterministic)."""

    def __init__(self):
        import thorvg_python as tvg

        self.tvg = tvg
        self.engine = tvg.Engine(threads=0)
        self.loaded = {}

    def load(self, key: int, data: bytes) -> None:
        animation = self.tvg.LottieAnimation(self.engine)
        picture = animation.get_picture()
        result = picture.load_data(data, "lottie", None, True)
        if result != self.tvg.Result.SUCCESS:
            animation._del()
            raise ValueError(f"ThorVG cannot load the animation ({result.name})")
        canvas = self.tvg.SwCanvas(self.engine)
        canvas.add(picture)
        _, width, height = picture.get_size()
        self.loaded[key] = {"animation": animation, "picture": picture, "canvas": canvas, "target": None,
                            "size": (width, height)}

    def render(self, key: int, frame: float, width: int, height: int) -> bytes:
        entry = self.loaded[key]
        if entry["target"] != (width, height):
            self._fit(entry, width, height)
        entry["animation"].set_frame(frame)
        canvas = entry["canvas"]
        canvas.update()
        canvas.draw(True)
        canvas.sync()
        return memoryview(canvas.buffer_arr).cast("B")

    def _fit(self, entry: dict, width: int, height: int) -> None:
        """Draw into ``width``×``height``, the picture scaled to fit and centred."""
        entry["canvas"].set_target(width, height, cs=self.tvg.Colorspace.ABGR8888)  # premultiplied; bytes R, G, B, A
        source_width, source_height = entry["size"]
        scale = min(width / source_width, height / source_height)
        picture = entry["picture"]
        picture.set_size(source_width * scale, source_height * scale)
        picture.translate((width - source_width * scale) / 2, (height - source_height * scale) / 2)
        entry["target"] = (width, height)

    def forget(self, key: int) -> None:
        entry = self.loaded.pop(key, None)
        if entry is not None:
            entry["canvas"].destroy()
            entry["animation"]._del()


class SharedFrame:
    """The file the parent reads frames from, mapped again whenever the parent has resized it."""

    def __init__(self, descriptor: int):
        self.descriptor, self.view = descriptor, None

    def write(self, frame) -> int:
        size = os.fstat(self.descriptor).st_size
        if self.view is None or len(self.view) != size:
            if self.view is not None:
                self.view.close()
            self.view = mmap.mmap(self.descriptor, size)
        count = len(frame)
        if count > size:
            raise ValueError(f"a frame of {count} bytes does not fit the shared file of {size}")
        self.view[:count] = frame
        return count


def read_exactly(stream, count: int) -> bytes | None:
    """``count`` bytes from ``stream``, or None at the end of the stream."""
    data = stream.read(count)
    return data if len(data) == count else None


def serve(requests, replies, shared: SharedFrame) -> None:
    """Answer requests until ``requests`` ends."""
    player = Player()
    header_size = struct.calcsize(HEADER)
    while (header := read_exactly(requests, header_size)) is not None:
        kind, length = struct.unpack(HEADER, header)
        payload = read_exactly(requests, length)
        if payload is None:
            return
        try:
            reply = handle(player, shared, kind, payload)
        except Exception as exc:  # the reply names the failure; the parent turns it into an InputError
            message = f"{type(exc).__name__}: {exc}".encode()
            replies.write(struct.pack(HEADER, b"E", len(message)) + message)
        else:
            replies.write(struct.pack(HEADER, b"K", len(reply)) + reply)
        replies.flush()


def handle(player: Player, shared: SharedFrame, kind: bytes, payload: bytes) -> bytes:
    key_size = struct.calcsize(KEY)
    if kind == b"L":
        (key,) = struct.unpack_from(KEY, payload)
        player.load(key, payload[key_size:])
        return b""
    if kind == b"R":
        key, frame, width, height = struct.unpack(RENDER, payload)
        return struct.pack(COUNT, shared.write(player.render(key, frame, width, height)))
    if kind == b"F":
        (key,) = struct.unpack(KEY, payload)
        player.forget(key)
        return b""
    raise ValueError(f"unknown request {kind!r}")


def main() -> None:
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
    replies = os.fdopen(os.dup(1), "wb")
    os.dup2(2, 1)  # anything the native library prints goes to stderr, not into the replies
    serve(sys.stdin.buffer, replies, SharedFrame(int(sys.argv[1])))


if __name__ == "__main__":
    main()
