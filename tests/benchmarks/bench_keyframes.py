"""Benchmark: the keyframes stylizer at 512×512 (issue 17): s/frame, speed-up with 2 workers, peak memory.

Run: ``NUMBA_CACHE_DIR=.numba-cache .venv/bin/python tests/benchmarks/bench_keyframes.py [--size 512]
[--frames 8 16] [--key-every 8]``; with ``--schedules``, instead the energy of the Jacobi and the
sequential schedule after 2, 8 and 16 sweeps on the tests' scene (docs/keyframes.md).

The scene: a disk of radius 0.3·size, its own texture carried along, translating 3 px and
growing 0.5 px a frame, painted keyframes every ``--key-every`` frames and at the last one
(each painted independently: the texture shifted a little against the motion, as an
artist's keyframes are); the flow is the true motion. Each run is a fresh process (its
peak resident memory is its own) with the stylizer's defaults (configs/keyframes.yaml):
one worker for every ``--frames`` count, then for the first count 2 workers (local processes, a
numba thread each) and one worker on one numba thread (what the frames' parallelism scales).
Printed: wall time, s/frame, speed-up, peak RSS of the process and its workers, and the
load average. The seed (Browning 2013, section 8) reports 30 min for a 400×400 sequence
on a cluster node per frame (2.8 GHz 4-core), constant in the frame count.
"""

from __future__ import annotations

import argparse
import functools
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy import ndimage


def scene(size: int, frames: int, key_every: int):
    texture = ndimage.gaussian_filter(np.random.default_rng(7).random((2 * size, 2 * size, 3)), (2, 2, 0))
    texture = ((texture - texture.min()) / np.ptp(texture)).astype(np.float32)
    ys, xs = np.mgrid[:size, :size]

    def geometry(frame):
        return 0.3 * size + 3.0 * frame, 0.5 * size, 0.3 * size + 0.5 * frame

    def mask(frame):
        cx, cy, radius = geometry(frame)
        return np.clip(radius + 0.5 - np.hypot(xs - cx, ys - cy), 0, 1).astype(np.float32)

    def painted(frame, shift):
        cx, _, _ = geometry(frame)
        colour = texture[(ys + size // 3) % (2 * size), (xs - int(round(cx)) + shift + size) % (2 * size)]
        alpha = mask(frame)
        return np.dstack([colour * alpha[..., None], alpha]).astype(np.float32)

    def flow(frame):
        cx, cy, radius = geometry(frame)
        scale = 0.5 / radius
        field = np.empty((size, size, 2), np.float32)
        field[..., 0] = 3.0 + (xs - cx) * scale  # the translation plus the growth about the centre
        field[..., 1] = (ys - cy) * scale
        return field

    keys = sorted(set(range(0, frames, key_every)) | {frames - 1})
    return mask, flow, {key: painted(key, shift=2 * (index % 2)) for index, key in enumerate(keys)}


def run(size: int, frames: int, key_every: int, jobs: int) -> dict:
    from fluidymation.pipeline.executors import run_jobs
    from fluidymation.pipeline.parameters import default_params
    from fluidymation.pipeline.stylizers import get_stylizer
    from fluidymation.stages import keyframe_morph

    mask, flow, keys = scene(size, frames, key_every)
    params = default_params(get_stylizer("keyframes"))
    with tempfile.TemporaryDirectory() as root:
        keyframe_morph.prepare(root, mask, flow, frames, keys)
        begun = time.perf_counter()
        keyframe_morph.morph(root, params, list(keys), frames, (size, size),
                             map_tasks=functools.partial(run_jobs, jobs=jobs))
        seconds = time.perf_counter() - begun
    own = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    workers = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    return {"frames": frames, "jobs": jobs, "seconds": seconds, "peak_mib": max(own, workers) / 1024}


def schedules() -> None:
    """E of both schedules on tests/stages/test_keyframe_morph.py's scene (keys misregistered by 3 px, one pass)."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
    from fluidymation.stages import keyframe_morph, keyframe_params
    from tests.stages import test_keyframe_morph as case

    keys = {0: case.painted(0), case.FRAMES - 1: case.painted(case.FRAMES - 1, shift=3)}
    print("sweeps  jacobi    sequential  difference")
    for sweeps in (2, 8, 16):
        energy = {}
        for schedule in keyframe_params.SCHEDULES:
            with tempfile.TemporaryDirectory() as root:
                _, contexts = case.morph(Path(root), keys, schedule=schedule, two_pass=False, sweeps=sweeps)
                energy[schedule] = keyframe_morph.pass_energy(contexts[-1])
        gap = abs(energy["jacobi"] - energy["sequential"]) / energy["sequential"]
        print(f"{sweeps:6d}  {energy['jacobi']:.4f}    {energy['sequential']:.4f}      {100 * gap:.2f} %")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--frames", type=int, nargs="+", default=[8, 16])
    parser.add_argument("--key-every", type=int, default=8)
    parser.add_argument("--schedules", action="store_true", help="the Jacobi against the sequential energy")
    parser.add_argument("--child", type=int, nargs=2, metavar=("FRAMES", "JOBS"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.schedules:
        schedules()
        return
    if args.child:
        print(json.dumps(run(args.size, args.child[0], args.key_every, args.child[1])))
        return
    print(f"keyframes stylizer, {args.size}×{args.size}, keys every {args.key_every} frames; "
          f"load average {os.getloadavg()[0]:.2f}")
    if len(args.frames) < 1:
        raise SystemExit("give at least one --frames count")
    warm = [sys.executable, __file__, "--size", "64", "--key-every", "4", "--child", "5", "1"]
    subprocess.run(warm, check=True, capture_output=True)  # compile the kernels outside the timings
    results = []
    runs = [(count, 1, None) for count in args.frames] + [(args.frames[0], 2, None), (args.frames[0], 1, 1)]
    for frames, jobs, threads in runs:
        command = [sys.executable, __file__, "--size", str(args.size), "--key-every", str(args.key_every),
                   "--child", str(frames), str(jobs)]
        env = dict(os.environ, **({"NUMBA_NUM_THREADS": str(threads)} if threads else {}))
        results.append(json.loads(subprocess.run(command, check=True, capture_output=True, text=True,
                                                 env=env).stdout))
        row = results[-1]
        what = f"{row['jobs']} worker(s)" + (f", {threads} numba thread" if threads else "")
        print(f"  {row['frames']:3d} frames, {what}: {row['seconds']:7.1f} s, "
              f"{row['seconds'] / row['frames']:6.2f} s/frame, peak RSS {row['peak_mib']:6.0f} MiB", flush=True)
    serial, parallel, one_thread = results[0], results[-2], results[-1]
    print(f"speed-up with 2 workers: {serial['seconds'] / parallel['seconds']:.2f}× over one process with "
          f"its numba threads, {one_thread['seconds'] / parallel['seconds']:.2f}× over one process on one thread; "
          f"load average {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
