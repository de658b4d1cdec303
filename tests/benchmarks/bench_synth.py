"""Benchmark: ``fluidymation synth`` on EbSynth's two example jobs and a small one, next to EbSynth.

Run: ``.venv/bin/python tests/benchmarks/bench_synth.py [--out DIR] [--threads N] [--ebsynth BIN]
[--jobs stylit facestyle small]``.
Each job runs in its own process (whole-process wall time and peak RSS, start-up included)
after a tiny warm-up job that fills numba's on-disk cache. Prints wall time, peak memory
and the final mean patch error (0..255 units). ``small`` is a 256×256 texture-by-numbers
job drawn here (a two-region style and label maps). With ``--ebsynth BIN`` (EbSynth's
public CPU build, ``build-linux-cpu_only.sh`` of jamriska/ebsynth, built for measuring
only) each job also runs through EbSynth in the same run, right after ours, with as many
OpenMP threads, and the ratio is printed; without it EbSynth's column is the figure once
measured on this kind of machine (``EBSYNTH_SECONDS``; none for ``small``).
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


def small_job(folder: Path) -> Path:
    """A 256×256 texture-by-numbers job in ``folder``: a style of two textures split down the middle, its label
    map, and a target label map of a disk of the second texture on the first. Returns the folder."""
    import imageio.v3 as iio

    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(0)
    yy, xx = np.mgrid[:256, :256]
    right = xx >= 128
    stripes = 0.5 + 0.5 * np.sin((xx + 0.6 * yy) / 3.0)
    blobs = np.clip(rng.random((256, 256)) * 0.4 + 0.3 * np.sin(yy / 7.0) * np.cos(xx / 5.0) + 0.3, 0, 1)
    style = np.where(right[..., None], blobs[..., None] * [0.9, 0.5, 0.2], stripes[..., None] * [0.2, 0.4, 0.8])
    iio.imwrite(folder / "source_style.png", (style * 255).astype(np.uint8))
    iio.imwrite(folder / "source_labels.png", np.where(right, 255, 0).astype(np.uint8))
    disk = (xx - 128) ** 2 + (yy - 128) ** 2 < 80 ** 2
    iio.imwrite(folder / "target_labels.png", np.where(disk, 255, 0).astype(np.uint8))
    return folder


SMALL = ("source_style.png", [("source_labels.png", "target_labels.png", 1.0)])


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


def ebsynth_arguments(binary, folder, style, guides, output):
    """EbSynth's command line for the job (its options are ours with one dash)."""
    arguments = [str(binary), "-style", str(folder / style)]
    for source, target, weight in guides:
        arguments += ["-guide", str(folder / source), str(folder / target), "-weight", str(weight)]
    return arguments + ["-output", str(output)]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=None, help="folder for the output images (default: a temporary one)")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--jobs", nargs="*", default=[*JOBS, "small"], choices=[*JOBS, "small"])
    parser.add_argument("--ebsynth", type=Path, help="EbSynth's CPU binary, to time it in the same run")
    args = parser.parse_args()
    out = Path(args.out or tempfile.mkdtemp(prefix="bench_synth_"))
    warm_up(args.threads)
    print(f"{'job':10s} {'wall s':>8s} {'EbSynth s':>10s} {'ratio':>6s} {'peak MiB':>9s} {'mean patch error':>17s}  output")
    for name in args.jobs:
        folder, (style, guides) = (small_job(out / "small"), SMALL) if name == "small" else (DATA / name, JOBS[name])
        output = out / f"{name}.png"
        wall, peak, stdout = run_job(synth_arguments(folder, style, guides, output), args.threads)
        error = re.search(r"mean patch error: ([0-9.]+)", stdout).group(1)
        if args.ebsynth:
            peer, _, _ = run_command(ebsynth_arguments(args.ebsynth, folder, style, guides, out / f"{name}-ebsynth.png"),
                                     dict(os.environ, OMP_NUM_THREADS=str(args.threads)))
        else:
            peer = EBSYNTH_SECONDS.get(name, float("nan"))
        print(f"{name:10s} {wall:8.1f} {peer:10.1f} {wall / peer:6.2f} {peak:9.0f} {error:>17s}  {output}", flush=True)
    load = os.getloadavg()[0]
    source = "measured in this run" if args.ebsynth else "EBSYNTH_SECONDS, measured once"
    print(f"(threads {args.threads}; EbSynth {source}; load average at the end {load:.1f} on {os.cpu_count()} cores)")


def run_job(arguments, threads):
    """Run ``python -m fluidymation ARGS``; return (wall s, the child's peak RSS in MiB, its output)."""
    env = dict(os.environ, NUMBA_NUM_THREADS=str(threads))
    return run_command([sys.executable, "-m", "fluidymation", *arguments], env)


def run_command(command, env):
    """Run ``command``; return (wall s, its peak RSS in MiB, its output)."""
    started = time.perf_counter()
    with tempfile.TemporaryFile("w+") as captured:
        process = subprocess.Popen(command, stdout=captured, stderr=subprocess.STDOUT, env=env, text=True)
        _, status, usage = os.wait4(process.pid, 0)
        wall = time.perf_counter() - started
        captured.seek(0)
        stdout = captured.read()
    if status != 0:
        raise SystemExit(f"{command[0]} failed ({status}):\n{stdout}")
    return wall, usage.ru_maxrss / 1024.0, stdout


if __name__ == "__main__":
    main()
