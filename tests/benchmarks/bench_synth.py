"""Benchmark: ``fluidymation synth`` on EbSynth's two example jobs, next to EbSynth's figures.

Run: ``.venv/bin/python tests/benchmarks/bench_synth.py [--out DIR] [--threads N]``.
Each job runs in its own process (whole-process wall time and peak RSS, as EbSynth's
figures were measured) after a tiny warm-up job that fills numba's on-disk cache.
Prints wall time, peak memory and the final mean patch error (0..255 units).
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

DATA = Path(os.environ.get("EBSYNTH_EXAMPLES", "/work/shared/data/ebsynth-examples"))
EBSYNTH_SECONDS = {"stylit": 62.4, "facestyle": 75.1}
JOBS = {
    "stylit": ("source_style.png", [(f"source_{g}.png", f"target_{g}.png", 0.5) for g in ("fullgi", "dirdif", "indirb", "dirspc")]),
    "facestyle": ("source_painting.png", [("source_Gapp.png", "target_Gapp.png", 0.5), ("source_Gseg.png", "target_Gseg.png", 1.5),
                                          ("source_Gpos.png", "target_Gpos.png", 10.0)]),
}


def synth_arguments(folder, style, guides, output):
    arguments = ["synth", "--style", str(folder / style)]
    for source, target, weight in guides:
        arguments += ["--guide", str(folder / source), str(folder / target), "--weight", str(weight)]
    return arguments + ["-o", str(output), "--report"]


def warm_up(threads):
    import imageio.v3 as iio

    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        rng = np.random.default_rng(0)
        iio.imwrite(folder / "s.png", (rng.random((40, 40, 3)) * 255).astype(np.uint8))
        iio.imwrite(folder / "g.png", (rng.random((40, 40)) * 255).astype(np.uint8))
        run_job(synth_arguments(folder, "s.png", [("g.png", "g.png", 1.0)], folder / "o.png"), threads)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=None, help="folder for the output images (default: a temporary one)")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--jobs", nargs="*", default=list(JOBS), choices=list(JOBS))
    args = parser.parse_args()
    out = Path(args.out or tempfile.mkdtemp(prefix="bench_synth_"))
    warm_up(args.threads)
    print(f"{'job':10s} {'wall s':>8s} {'EbSynth s':>10s} {'peak MiB':>9s} {'mean patch error':>17s}  output")
    for name in args.jobs:
        style, guides = JOBS[name]
        output = out / f"{name}.png"
        wall, peak, stdout = run_job(synth_arguments(DATA / name, style, guides, output), args.threads)
        error = re.search(r"mean patch error: ([0-9.]+)", stdout).group(1)
        print(f"{name:10s} {wall:8.1f} {EBSYNTH_SECONDS[name]:10.1f} {peak:9.0f} {error:>17s}  {output}", flush=True)
    load = os.getloadavg()[0]
    print(f"(threads {args.threads}; load average at the end {load:.1f} on {os.cpu_count()} cores)")


def run_job(arguments, threads):
    """Run ``python -m fluidymation ARGS``; return (wall s, the child's peak RSS in MiB, its output)."""
    env = dict(os.environ, NUMBA_NUM_THREADS=str(threads))
    started = time.perf_counter()
    with tempfile.TemporaryFile("w+") as captured:
        process = subprocess.Popen([sys.executable, "-m", "fluidymation", *arguments], stdout=captured,
                                   stderr=subprocess.STDOUT, env=env, text=True)
        _, status, usage = os.wait4(process.pid, 0)
        wall = time.perf_counter() - started
        captured.seek(0)
        stdout = captured.read()
    if status != 0:
        raise SystemExit(f"synth failed ({status}):\n{stdout}")
    return wall, usage.ru_maxrss / 1024.0, stdout


if __name__ == "__main__":
    main()
