"""Measure how the stylized paint follows the target (issue 6): the 48 px test scenes.

Run: ``NUMBA_CACHE_DIR=.numba-cache .venv/bin/python tests/benchmarks/bench_stylize_motion.py [--frames 8]``.

Prints per frame of a disk translating at 1 px/frame (the exemplar's texture drifts at
1 px/frame with exact flow): the mean target ext+ increment and flow speed in the
interior, the mean |Δi| SHIFTNNF chose (forward along ext+, or backward along ext−
where the rotated flows are opposite), the mean backlog it carried over, the share of
pixels whose final match is still the shifted one (same frame, within half a pixel),
how far the final matches moved in source time and space, and the texture's measured
displacement between consecutive frames (the integer x shift, −2..3 px, that best
aligns them, refined by a parabola). Then the figures the tests check: the stationary
ratio (change between frames of a still disk, with / without the temporal term), the
contrast ratio (local contrast of the output / the exemplar's) and the 4-frame
motion-following ratio (difference to the first frame shifted by the motion /
unshifted; below 1 means the texture travelled).
"""

import argparse
import dataclasses
import sys
import tempfile
from pathlib import Path

import numpy as np
from scipy import ndimage

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from stages import test_stylize as scene  # noqa: E402

from fluidymation.engine.shiftnnf import shift_nnf  # noqa: E402
from fluidymation.quality import local_contrast  # noqa: E402
from fluidymation.stages import exemplar_store, guides, stylize  # noqa: E402


def _texture_shift(a, b, region):
    """x shift (px) that best maps frame ``a`` onto frame ``b`` inside ``region``."""
    shifts = np.arange(-2, 4)
    errors = np.array([np.abs(np.roll(a, s, axis=1) - b)[region & np.roll(region, s, axis=1)].mean() for s in shifts])
    best = int(np.argmin(errors))
    if 0 < best < len(shifts) - 1:
        left, mid, right = errors[best - 1: best + 2]
        curvature = left - 2 * mid + right
        return shifts[best] + (0.5 * (left - right) / curvature if curvature > 0 else 0.0)
    return float(shifts[best])


def measure_moving(source, frames, speed, workdir, params):
    def moving(j):
        return scene._disk(18 + speed * j)

    cache_dir = Path(workdir) / "moving"
    results = list(stylize.stylize_sequence(moving, frames, source, params=params, guide_params=scene.GUIDES,
                                            cache_dir=cache_dir))
    target = guides.GuideCache.open(cache_dir)
    print("frame  ext+inc  |flow|  |Δi|(shift)  backlog  kept  |Δi|(final)  Δx(final)  texture-shift")
    backlog = np.zeros((target.height, target.width), np.float32)
    for previous, current in zip(results, results[1:]):
        k = current.index
        before, frame = target.frame(k - 1), target.frame(k)
        interior = ndimage.binary_erosion(frame.mask & before.mask, iterations=4)
        wanted = frame.ext_plus - before.ext_plus + np.where(before.mask | (moving(k - 1) > 0), backlog, 0.0)
        shifted, achieved = shift_nnf(previous.nnf, target_motion=wanted, target_angle=frame.direction,
                                      source_ext_plus=source.ext_plus, source_ext_minus=source.ext_minus,
                                      source_angle=source.angle)
        backlog = np.where(shifted.frame >= 0, wanted - achieved, 0.0).astype(np.float32)
        final = current.nnf
        kept = (final.frame == shifted.frame) & (np.abs(final.coords[..., :2] - shifted.coords[..., :2]).max(axis=2) < 0.5)
        print(f"{k:5d}  {(frame.ext_plus - before.ext_plus)[interior].mean():7.3f}  "
              f"{np.linalg.norm(frame.flow, axis=2)[interior].mean():6.3f}  "
              f"{np.abs(shifted.frame - previous.nnf.frame)[interior].mean():11.3f}  {backlog[interior].mean():7.3f}  "
              f"{kept[interior].mean():4.2f}  {np.abs(final.frame - previous.nnf.frame)[interior].mean():11.3f}  "
              f"{(final.coords[..., 0] - previous.nnf.coords[..., 0])[interior].mean():9.3f}  "
              f"{_texture_shift(previous.rgba[..., :3].mean(axis=2), current.rgba[..., :3].mean(axis=2), interior):13.2f}")
    first, last = results[0].rgba[..., :3], results[-1].rgba[..., :3]
    travel = int(round(speed * (len(results) - 1)))
    inner = ndimage.binary_erosion(moving(0) > 0.5, iterations=4)
    both = inner & np.roll(inner, travel, axis=1)
    following = np.abs(np.roll(first, travel, axis=1) - last)[both].mean() / np.abs(first - last)[both].mean()
    exemplar = np.mean([local_contrast(source.rgb[i], source.segment[i] >= 0) for i in range(source.frame_count)])
    contrast = [local_contrast(r.rgba, moving(r.index) > 0.5) / exemplar for r in results]
    print(f"motion-following ratio over {len(results) - 1} frames: {following:.3f} (below 1: the texture travelled)")
    print(f"contrast ratio per frame: {' '.join(f'{c:.2f}' for c in contrast)}")


def measure_still(source, frames, workdir, params):
    def still(j):
        return scene._disk(scene.SIZE / 2)

    def change(temporal_weight, name):
        chosen = params if temporal_weight is None else dataclasses.replace(params, w_temp=temporal_weight)
        results = list(stylize.stylize_sequence(still, frames, source, params=chosen, guide_params=scene.GUIDES,
                                                cache_dir=Path(workdir) / name))
        inside = still(0) > 0.5
        return np.mean([np.abs(a.rgba - b.rgba)[inside].mean() for a, b in zip(results, results[1:])])

    coherent, independent = change(None, "coherent"), change(0.0, "independent")
    exemplar = np.mean([np.abs(a - b).mean() for a, b in zip(source.rgb, source.rgb[1:])])
    print(f"still disk, mean change between frames: {coherent:.4f} with w_temp, {independent:.4f} without: "
          f"ratio {coherent / independent:.3f} (the exemplar's, moving everywhere: {exemplar:.4f})")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--frames", type=int, default=8)
    parser.add_argument("--speed", type=float, default=1.0)
    parser.add_argument("--still-frames", type=int, default=4)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--settle-passes", type=int, default=scene.FAST.settle_passes)
    args = parser.parse_args()
    params = dataclasses.replace(scene.FAST, seed=args.seed, settle_passes=args.settle_passes)
    rgb, mask, flow = scene._stain()
    with tempfile.TemporaryDirectory() as workdir:
        cache = guides.compute_guides(lambda j: mask[j], len(mask), params=scene.GUIDES,
                                      cache_dir=Path(workdir) / "source", given_flow=lambda j: flow[j])
        source = exemplar_store.in_memory(rgb, cache)
        measure_moving(source, args.frames, args.speed, workdir, params)
        if args.still_frames > 1:
            measure_still(source, args.still_frames, workdir, params)


if __name__ == "__main__":
    main()
