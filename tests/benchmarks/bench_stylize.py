"""Benchmark: the stylize stage at the sizes of issue 6, next to the paper's Table 2.

Run: ``.venv/bin/python tests/benchmarks/bench_stylize.py [--cases speed memory window] [--threads 2]
[--profile] [--param NAME=VALUE ...]``.

* speed: a 500×600 target with ~60 000 masked pixels (an ellipse drifting and turning)
  for 6 frames, the built-in ``watercolor-bloom`` at 200×200×20 as exemplar — the size of
  the paper's "sunflower" row (1.33 s/frame in C++ on 4 cores at 3 GHz). Target: ≤ 1.3
  s/frame on 2 cores.
* memory: a 1000×800 target (a wobbling blob) for 40 frames with a 400×222×20 exemplar
  — the thesis's horse (about 9 GiB there). Target: peak RSS < 1 GiB, flat per frame.
* window: a long exemplar, ``watercolor-bloom`` at 200×200×120, on a 400×300 target (an
  ellipse of ~23 000 px) for 30 frames, once with ``source_window: 20`` and once with the
  whole exemplar: the peak RSS follows the window, not the exemplar's length. The
  exemplar is stored (colour beside its guides, as the pipeline keeps it) before the
  runs, and each run reads it from disk (``StoredSource``).
* 1080p: production size, a 1920×1080 target with a layer covering 30 % of the frame (an
  ellipse drifting and turning) for 24 frames, the 400×222×20 exemplar of ``memory``.
  Target: peak RSS ≤ 2 GiB, flat in the number of frames.

Each case runs in its own process with ``NUMBA_NUM_THREADS`` threads. A tiny warm-up
scene first loads (or compiles) numba's kernels; its time is shown as "warm-up". The
stage computes the target guides of the whole sequence and prepares the exemplar before
its first frame, so the first frame's time includes them (the guides are also timed on
their own beforehand); later frames are synthesis only. Parameters are
configs/fluidymation.yaml's; exemplars are taken from (or generated into) the user cache.
``--profile`` prints the child's cProfile; ``--param`` times a stylizer parameter other than its
default (e.g. ``--param finest_propagation=0``), to weigh what a part of the method costs.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from bench_guides import blob_masks  # tests/benchmarks is on the path when run as a script
from bench_quality import overrides

PAPER_SECONDS_PER_FRAME = 1.33
CASES = {
    # name: target (width, height), frames, exemplar (width, height, frames), shape
    "speed": ((500, 600), 6, (200, 200, 20), "ellipse"),
    "memory": ((1000, 800), 40, (400, 222, 20), "blob"),
    "window": ((400, 300), 30, (200, 200, 120), "small ellipse"),
    "1080p": ((1920, 1080), 24, (400, 222, 20), "large ellipse"),
}
#: the source_window of each run of a case that compares windows (None: the whole exemplar)
WINDOWS = {"window": (20, None)}
RSS_EVERY = 5


def ellipse_masks(width, height, axes=(160.0, 120.0)):
    """An ellipse (by default of ~60 000 px) drifting (3, 2) px/frame and turning."""
    yy, xx = np.mgrid[:height, :width].astype(np.float32) + 0.5

    def mask(index):
        cx, cy = width / 2 - 3.0 * index, height / 2 - 2.0 * index
        turn = 0.02 * index
        u = (xx - cx) * np.cos(turn) + (yy - cy) * np.sin(turn)
        v = -(xx - cx) * np.sin(turn) + (yy - cy) * np.cos(turn)
        return (u / axes[0]) ** 2 + (v / axes[1]) ** 2 < 1.0

    return mask


def peak_and_current_rss_mib():
    """(VmHWM, VmRSS) of this process in MiB, from /proc/self/status."""
    fields = {}
    for line in Path("/proc/self/status").read_text().splitlines():
        key, _, value = line.partition(":")
        if key in ("VmHWM", "VmRSS"):
            fields[key] = int(value.split()[0]) / 1024.0
    return fields["VmHWM"], fields["VmRSS"]


def exemplar_source(width, height, frames, guide_params, folder, *, stored=False):
    """The built-in ``watercolor-bloom`` at this size with its guides, as a stylize Source (in memory), or
    with ``stored`` as a StoredSource in ``folder``."""
    from fluidymation.pipeline import paths
    from fluidymation.pipeline.presets import resolve_params
    from fluidymation.stages import exemplar_builtin, exemplar_store, guides
    from fluidymation.stages.guide_params import for_exemplar

    params = resolve_params("watercolor-bloom", size=(width, height), frames=frames)
    exemplar = exemplar_builtin.make_builtin_exemplar(params, cache_dir=paths.exemplar_cache_dir())
    cache = guides.compute_guides(lambda j: exemplar.mask[j], frames, params=for_exemplar(guide_params), cache_dir=folder,
                                  given_flow=lambda j: exemplar.flow[j])
    if not stored:
        return exemplar_store.in_memory(exemplar.rgb, cache)
    exemplar_store.store_colour(exemplar.rgb, folder)
    return exemplar_store.StoredSource(folder)


def target_masks(shape, width, height):
    if shape == "small ellipse":
        return ellipse_masks(width, height, (100.0, 75.0))
    if shape == "large ellipse":  # 30 % of the frame: π·a·b = 0.3·W·H with a : b = W : H
        scale = np.sqrt(0.3 * 4.0 / np.pi) / 2.0
        return ellipse_masks(width, height, (scale * width, scale * height))
    return (ellipse_masks if shape == "ellipse" else blob_masks)(width, height)


def run_case(name, profile, window=None, stored=None, changed=()):
    """Child process: run one case (with ``source_window`` ``window``, the parameters ``changed``
    (``NAME=VALUE`` texts); the exemplar stored in ``stored``, or generated here), print one JSON
    line with its figures."""
    from fluidymation.pipeline.parameters import default_params
    from fluidymation.pipeline.stylizers import get_stylizer
    from fluidymation.stages import exemplar_store, guides, stylize

    (width, height), frame_count, (ex_width, ex_height, ex_frames), shape = CASES[name]
    defaults = default_params(get_stylizer("fluidymation"))
    params = dataclasses.replace(defaults, source_window=window, **overrides(list(changed)))
    guide_params = guides.Params()
    masks = target_masks(shape, width, height)
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        started = time.perf_counter()
        small = exemplar_source(48, 48, 6, guide_params, folder / "warm-source")
        for _ in stylize.stylize_sequence(ellipse_masks(64, 64, (20.0, 15.0)), 2, small,
                                          params=defaults, guide_params=guide_params,
                                          cache_dir=folder / "warm"):
            pass
        del small
        warm_up = time.perf_counter() - started
        if stored is None:
            source = exemplar_source(ex_width, ex_height, ex_frames, guide_params, folder / "source")
        else:
            source = exemplar_store.StoredSource(stored)
        packed = [np.packbits(masks(j)) for j in range(frame_count)]
        masked = [int(masks(j).sum()) for j in range(frame_count)]

        def mask(j):
            return np.unpackbits(packed[j], count=width * height).reshape(height, width).view(bool)

        started = time.perf_counter()
        guides.compute_guides(mask, frame_count, params=guide_params, cache_dir=folder / "target")
        guide_seconds = time.perf_counter() - started
        rss = [("before the stage", *peak_and_current_rss_mib())]
        times, cpu_times = [], []
        profiler = None
        if profile:
            import cProfile

            profiler = cProfile.Profile()
            profiler.enable()
        loads = [os.getloadavg()[0]]
        started, cpu_started = time.perf_counter(), time.process_time()
        for done, _ in enumerate(stylize.stylize_sequence(mask, frame_count, source, params=params,
                                                          guide_params=guide_params, cache_dir=folder / "target"),
                                 start=1):
            times.append(time.perf_counter() - started)
            cpu_times.append(time.process_time() - cpu_started)
            started, cpu_started = time.perf_counter(), time.process_time()
            if done % RSS_EVERY == 0:
                rss.append((f"frame {done}", *peak_and_current_rss_mib()))
        loads.append(os.getloadavg()[0])
        if profiler is not None:
            import pstats

            profiler.disable()
            pstats.Stats(profiler, stream=sys.stderr).sort_stats("cumulative").print_stats(30)
    print(json.dumps({"warm_up": warm_up, "guides": guide_seconds, "times": times, "cpu_times": cpu_times,
                      "masked": masked, "rss": rss,
                      "peak": peak_and_current_rss_mib()[0], "loads": loads}))


def run_child(name, threads, profile, window=None, stored=None, changed=()):
    env = dict(os.environ, NUMBA_NUM_THREADS=str(threads))
    command = [sys.executable, __file__, "--child", name] + (["--profile"] if profile else [])
    command += [f"--param={item}" for item in changed]
    command += [] if window is None else ["--window", str(window)]
    command += [] if stored is None else ["--stored", str(stored)]
    result = subprocess.run(command, env=env, stdout=subprocess.PIPE, text=True)
    if result.returncode != 0:
        raise SystemExit(f"case {name} failed ({result.returncode})")
    return json.loads(result.stdout.strip().splitlines()[-1])


def report(name, figures, threads, window=None):
    (width, height), frame_count, (ex_width, ex_height, ex_frames), _ = CASES[name]
    times = np.array(figures["times"])
    cpu_times = np.array(figures["cpu_times"])
    masked = np.array(figures["masked"], np.float64)
    held = "" if window is None else f" (source_window {window})"
    print(f"\n{name}: target {width}x{height} px, {frame_count} frames, {masked.mean():.0f} masked px/frame; "
          f"exemplar {ex_width}x{ex_height}x{ex_frames}{held}; {threads} thread{'s' * (threads > 1)}; load average "
          f"{figures['loads'][0]:.2f} -> {figures['loads'][1]:.2f}")
    print(f"  warm-up (numba load/compile, tiny scene) {figures['warm_up']:.1f} s; target guides of all "
          f"{frame_count} frames {figures['guides']:.1f} s (the stage's first frame includes them)")
    paper = name == "speed"
    # CPU s/frame: the process's CPU time over all threads, which leaves out time the shared
    # machine gives to others, so it compares runs more steadily than the wall clock
    print(f"  {'':24s} {'s/frame':>8s} {'µs/px/frame':>12s} {'CPU s/frame':>12s}"
          + (f" {'paper s/frame':>14s}" if paper else ""))
    later = slice(1, None) if len(times) > 1 else slice(None)
    rows = (("first frame", slice(0, 1)), ("later frames (mean)", later), ("all frames (mean)", slice(None)))
    for label, part in rows:
        per_pixel = (times[part] / masked[part]).mean() * 1e6
        print(f"  {label:24s} {times[part].mean():8.2f} {per_pixel:12.1f} {cpu_times[part].mean():12.2f}"
              + (f" {PAPER_SECONDS_PER_FRAME:14.2f}" if paper else ""))
    print(f"  peak RSS {figures['peak']:.0f} MiB ({figures['rss'][0][1]:.0f} before the stage); RSS (MiB) " + ", ".join(
        f"{label}: {now:.0f}" for label, _, now in figures["rss"]))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", nargs="*", default=list(CASES), choices=list(CASES))
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--profile", action="store_true", help="print each case's cProfile (cumulative)")
    parser.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                        help="a stylizer parameter instead of its default (YAML value; repeatable)")
    parser.add_argument("--child", choices=list(CASES), help=argparse.SUPPRESS)
    parser.add_argument("--window", type=int, help=argparse.SUPPRESS)
    parser.add_argument("--stored", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        run_case(args.child, args.profile, args.window, args.stored, args.param)
        return
    if args.param:
        print("parameters other than configs/fluidymation.yaml's: " + ", ".join(args.param))
    for name in args.cases:
        if name not in WINDOWS:
            report(name, run_child(name, args.threads, args.profile, changed=args.param), args.threads)
            continue
        from fluidymation.stages import guides

        _, _, (ex_width, ex_height, ex_frames), _ = CASES[name]
        with tempfile.TemporaryDirectory() as stored:  # stored here, so no run holds the generated exemplar
            exemplar_source(ex_width, ex_height, ex_frames, guides.Params(), stored, stored=True)
            for window in WINDOWS[name]:
                report(name, run_child(name, args.threads, args.profile, window, stored, args.param), args.threads,
                       window)


if __name__ == "__main__":
    main()
