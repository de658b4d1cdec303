"""Benchmark: ``fluidymation synth`` on EbSynth's two example jobs and a small one, next to EbSynth.

Run: ``.venv/bin/python tests/benchmarks/bench_synth.py [--out DIR] [--threads N] [--ebsynth BIN [--energy]]
[--jobs stylit facestyle small]``.
Each job runs in its own process (whole-process wall time and peak RSS, start-up included)
after a tiny warm-up job that fills numba's on-disk cache. Prints wall time, peak memory
and the final mean patch error (0..255 units). ``small`` is a 256×256 texture-by-numbers
job drawn here (a two-region style and label maps). With ``--ebsynth BIN`` (EbSynth's
public CPU build, ``build-linux-cpu_only.sh`` of jamriska/ebsynth, built for measuring
only) each job also runs through EbSynth in the same run, right after ours, with as many
OpenMP threads, and the ratio is printed; without it EbSynth's column is the figure once
measured on this kind of machine (``EBSYNTH_SECONDS``).

With ``--energy`` (needs ``--ebsynth``) both outputs of each job are then scored under one
guided patch energy, by :func:`guided_energy`: the mean over target pixels of the patch
distance (style colour SSD + Σ weight × guide SSD over the 5×5 window, EbSynth's weights and
0..255 units, target pixels outside the image left out) between the output, as written to
its PNG, and its best source patch. The best field for a fixed output is searched the same
way for both outputs (coarse-to-fine PatchMatch with the output held fixed, then random
restarts merged per pixel, then more passes), so neither is favoured; the printed energy is
the float64 re-evaluation of the field found. Prints energy_ours, energy_ebsynth and their
ratio (below 1: ours is lower), and for each output the search's gap: how far the field found
stays above the exact minimum on ``--energy-exact`` random pixels (an exhaustive search over
every source patch there), i.e. how much both energies overstate the true one. EbSynth's CPU
build is not deterministic (its threads update a shared field and occupancy map), so its
output and energy can change from run to run; ours do not.
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
from types import SimpleNamespace

import numba
import numpy as np

from fluidymation.engine._jit import kernel, run_parts  # the engine's numba flags and threads
from fluidymation.engine.nnf import NNF, fill_random, merge_nnf, upscale_nnf
from fluidymation.engine.patch_cost import _patch_cost, patch_errors, quantize_source, target_patch_cost
from fluidymation.engine.patchmatch import patchmatch_pass
from fluidymation.engine.pyramid import gaussian_pyramid, levels_that_fit
from fluidymation.pipeline.commands.synth import load_job
from fluidymation.stages.files import read_image

DATA = Path(os.environ.get("EBSYNTH_EXAMPLES", "/work/shared/data/ebsynth-examples"))
#: EbSynth's wall times on 2026-12-06, 2 threads, load 1.2–1.9 (machines differ by up to 3×)
EBSYNTH_SECONDS = {"stylit": 41.1, "facestyle": 20.6, "small": 1.0}
_EBSYNTH_SCALE = 255.0 ** 2  # energies: values in 0..1 compared, reported in EbSynth's 0..255 units
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


def _job_inputs(folder, style, guides):
    """The job's :class:`SynthesisInputs` exactly as ``fluidymation synth`` reads them (its weighting)."""
    return load_job(SimpleNamespace(style=str(folder / style), style_weight=None,
                                    guides=[[str(folder / source), str(folder / target), weight]
                                            for source, target, weight in guides]))


def _read_output(path, channels):
    """An output PNG as float32 (H, W, channels) in [0, 1], EbSynth's and ours alike."""
    image = read_image(path)
    if image.shape[2] != channels:
        image = read_image(path, channels=channels if channels in (1, 3, 4) else None)
    return image[:, :, :channels]


def guided_energy(inputs, image, *, patch_size=5, level_passes=8, restarts=4, restart_passes=8, final_passes=16,
                  alpha=0.5, seed=7, exhaustive_pixels=0):
    """Guided energy of a fixed output ``image`` (H, W, Cc) for the job ``inputs``, in 0..255 units.

    E = mean over target pixels q of min over source patches p of D(q, p), D = Σ over the
    window of Σ_c w_c (O − S_style)² + Σ_g w_g (T_g − S_g)² (``inputs``' weights, as synth
    spreads them; target window pixels outside the image are left out, source samples past
    its border repeat the edge, as in the engine's cost). The output is fixed, so E is a
    per-pixel minimum; it is searched with the engine's own kernels: PatchMatch
    (``patchmatch_pass``, no uniformity term) on a Gaussian pyramid of the output, source and
    guides, ``level_passes`` per level from a random start at the coarsest, the field
    upscaled level to level; then ``restarts`` random fields with ``restart_passes`` each at
    the finest level, merged per pixel with it by patch error; then ``final_passes`` more
    passes. The features are quantized over fixed ranges (colours 0..1, guides the source's
    and target's), the same for any output of the job. Returns (energy, energy after each
    stage, gap): the energy is the final field re-evaluated in float64 on the images' values;
    with ``exhaustive_pixels`` N > 0, gap is how far the search stays above the exact minimum
    on N random target pixels (the same pixels for any output): ``Σ (found − exact) / Σ exact``
    there, each exact minimum an exhaustive search over every source patch; else None.
    """
    source_colour = np.asarray(inputs.source_colour, np.float32)
    source_guides = np.asarray(inputs.source_guides, np.float32)
    target_guides = np.asarray(inputs.target_guides, np.float32)
    image = np.ascontiguousarray(image, np.float32)
    colours = source_colour.shape[3]
    levels = levels_that_fit([source_colour.shape[1:3], target_guides.shape[:2]], patch_size=patch_size)
    source_colours = gaussian_pyramid(source_colour, levels)
    source_guide_levels = gaussian_pyramid(source_guides, levels)
    target_guide_levels = gaussian_pyramid(target_guides, levels)
    images = gaussian_pyramid(image, levels)
    guide_low = np.minimum(source_guides.min(axis=(0, 1, 2)), target_guides.min(axis=(0, 1)))
    guide_high = np.maximum(source_guides.max(axis=(0, 1, 2)), target_guides.max(axis=(0, 1)))
    low, high = np.concatenate([np.zeros(colours), guide_low]), np.concatenate([np.ones(colours), guide_high])
    stages = {}
    salt = 0

    def passes(cost, nnf, error, count):
        nonlocal salt
        for iteration in range(count):
            patchmatch_pass(cost, nnf, error, alpha=alpha, seed=seed, salt=salt, reverse=iteration % 2 == 1)
            salt += 1

    def random_field(cost, height, width):
        nnf = NNF.empty(height, width)
        nonlocal salt
        fill_random(nnf, target_segment=cost.target_segment, source_segment=cost.source_segment, seed=seed, salt=salt)
        salt += 1
        return nnf

    nnf = None
    for level in range(levels - 1, -1, -1):
        features = quantize_source(source_colours[level], source_guide_levels[level], low=low, high=high)
        cost = target_patch_cost(features, target_colour=images[level], target_guides=target_guide_levels[level],
                                 colour_weights=inputs.colour_weights, guide_weights=inputs.guide_weights,
                                 patch_size=patch_size)
        height, width = images[level].shape[:2]
        if nnf is None:
            nnf = random_field(cost, height, width)
        else:
            nnf = upscale_nnf(nnf, target_shape=(height, width), source_shape=source_colours[level].shape[1:3])
        error = patch_errors(cost, nnf)
        passes(cost, nnf, error, level_passes)
    stages["coarse-to-fine"] = float(error.mean())
    for _ in range(restarts):
        other = random_field(cost, height, width)
        other_error = patch_errors(cost, other)
        passes(cost, other, other_error, restart_passes)
        nnf, took = merge_nnf(nnf, other, error, other_error)
        error = np.where(took, other_error, error)
    stages["restarts merged"] = float(error.mean())
    passes(cost, nnf, error, final_passes)
    stages["final passes"] = float(error.mean())
    gap = None
    if exhaustive_pixels:
        pixels = np.random.default_rng(seed).choice(height * width, size=min(exhaustive_pixels, height * width),
                                                    replace=False)
        exact = np.empty(pixels.size, np.float32)
        run_parts(_exhaustive_minimum, cost.kernel_cost(), (pixels % width).astype(np.int64),
                  (pixels // width).astype(np.int64), exact)
        found = error.ravel()[pixels].astype(np.float64)
        gap = float((found - exact).sum() / exact.sum())
    weights = np.concatenate([inputs.colour_weights, inputs.guide_weights]).astype(np.float64)
    energy = _exact_energy(np.concatenate([source_colour[0], source_guides[0]], axis=2),
                           np.concatenate([image, target_guides], axis=2), weights, nnf, patch_size)
    return energy * _EBSYNTH_SCALE, {name: value * _EBSYNTH_SCALE for name, value in stages.items()}, gap


@kernel
def _exhaustive_minimum(cost, xs, ys, out, part, parts):
    """``out[k]``: the lowest cost over every integer, unturned source patch of frame 0 at target pixel
    ``(xs[k], ys[k])``, under the engine's own patch cost (its ``_patch_cost``, given the ``KernelCost``)."""
    source_height = cost.source.shape[1]
    source_width = cost.source.shape[2]
    for k in range(part, xs.shape[0], parts):
        best = np.float32(np.inf)
        for sy in range(source_height):
            for sx in range(source_width):
                value = _patch_cost(cost, xs[k], ys[k], np.int64(0), np.float32(sx), np.float32(sy), np.float32(0.0),
                                    best)
                if value < best:
                    best = value
        out[k] = best


def _exact_energy(source, target, weights, nnf, patch_size):
    """Mean float64 patch distance of an integer, unturned one-frame ``nnf`` (what :func:`guided_energy`'s
    search gives) between ``target`` (H, W, F) and ``source`` (Hs, Ws, F), in the engine's border convention."""
    if (nnf.frame != 0).any() or (nnf.coords[..., 2] != 0).any() or (nnf.coords[..., :2] % 1 != 0).any():
        raise ValueError("expected an integer, unturned field over one source frame")
    radius = patch_size // 2
    height, width = target.shape[:2]
    source_height, source_width = source.shape[:2]
    sx = nnf.coords[..., 0].astype(np.int64)
    sy = nnf.coords[..., 1].astype(np.int64)
    ty, tx = np.mgrid[:height, :width]
    total = np.zeros((height, width))
    for dy in range(-radius, radius + 1):
        for dx in range(-radius, radius + 1):
            qy, qx = ty + dy, tx + dx
            inside = (qy >= 0) & (qy < height) & (qx >= 0) & (qx < width)
            sample = source[np.clip(sy + dy, 0, source_height - 1), np.clip(sx + dx, 0, source_width - 1)]
            here = target[np.clip(qy, 0, height - 1), np.clip(qx, 0, width - 1)]
            total += np.where(inside, ((sample.astype(np.float64) - here) ** 2) @ weights, 0.0)
    return float(total.mean())


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=None, help="folder for the output images (default: a temporary one)")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--jobs", nargs="*", default=[*JOBS, "small"], choices=[*JOBS, "small"])
    parser.add_argument("--ebsynth", type=Path, help="EbSynth's CPU binary, to time it in the same run")
    parser.add_argument("--energy", action="store_true",
                        help="with --ebsynth: score both outputs of each job under one guided patch energy")
    parser.add_argument("--energy-restarts", type=int, default=4, help="random restarts of the energy's search")
    parser.add_argument("--energy-passes", type=int, default=8,
                        help="PatchMatch passes per level and per restart of the energy's search (twice as many at "
                             "the end)")
    parser.add_argument("--energy-exact", type=int, default=1000, metavar="N",
                        help="random target pixels whose exact minimum is searched exhaustively, to measure the "
                             "energy search's gap (0: none)")
    args = parser.parse_args()
    if args.energy and not args.ebsynth:
        parser.error("--energy needs --ebsynth BIN")
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
    if args.energy:
        print_energies(args, out)


def print_energies(args, out):
    """Score each job's two outputs (written above) under :func:`guided_energy` and print them."""
    numba.set_num_threads(min(args.threads, numba.config.NUMBA_NUM_THREADS))  # the same results on any count
    print(f"\nguided energy (0..255 units, lower is better; search: {args.energy_restarts} restarts, "
          f"{args.energy_passes} passes per level and restart, {2 * args.energy_passes} final; "
          f"gap: the search's excess over the exhaustive minimum on {args.energy_exact} random pixels)")
    print(f"{'job':10s} {'energy_ours':>12s} {'energy_ebsynth':>15s} {'ratio':>6s} {'gap ours':>9s} "
          f"{'gap EbSynth':>12s} {'score s':>8s}  energy after the coarse-to-fine / restarts / final passes: "
          "ours | EbSynth")
    for name in args.jobs:
        folder, (style, guides) = (out / "small", SMALL) if name == "small" else (DATA / name, JOBS[name])
        inputs = _job_inputs(folder, style, guides)
        scores = []
        started = time.perf_counter()
        for output in (out / f"{name}.png", out / f"{name}-ebsynth.png"):
            image = _read_output(output, inputs.source_colour.shape[3])
            scores.append(guided_energy(inputs, image, level_passes=args.energy_passes, restarts=args.energy_restarts,
                                        restart_passes=args.energy_passes, final_passes=2 * args.energy_passes,
                                        exhaustive_pixels=args.energy_exact))
        seconds = time.perf_counter() - started
        (ours, ours_stages, ours_gap), (theirs, their_stages, their_gap) = scores
        stages = " / ".join(f"{value:.1f}" for value in ours_stages.values()) + " | " + " / ".join(
            f"{value:.1f}" for value in their_stages.values())
        gaps = "".join(f" {'-' if gap is None else f'{100 * gap:.2f} %':>{width}s}"
                       for gap, width in ((ours_gap, 9), (their_gap, 12)))
        print(f"{name:10s} {ours:12.1f} {theirs:15.1f} {ours / theirs:6.3f}{gaps} {seconds:8.0f}  {stages}",
              flush=True)
    print(f"(load average at the end {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores)")


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
