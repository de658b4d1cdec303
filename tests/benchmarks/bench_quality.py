"""Quality benchmark (issue 15): scenes with known motion, stylized with every built-in medium.

Run: ``NUMBA_CACHE_DIR=.numba-cache .venv/bin/python tests/benchmarks/bench_quality.py
[--scenes translation still ...] [--media watercolor-bloom ...] [--scale K] [--exemplar-size N]
[--seeds 0 1 2] [--true-motion] [--write-docs] [--record-baseline]``.

Each scene is a layer of 12 frames drawn analytically here (soft 1-px edges) on a 128-px
canvas, or K times larger with ``--scale``, stylized with the stylizer's defaults
(configs/fluidymation.yaml, the guides' defaults) from an N×N×12 built-in exemplar
(default 96; generated once into the user cache); scenes with a still region are rendered
a second time with ``w_temp: 0``. The metrics (:mod:`fluidymation.quality`) are computed on
the output and, where they have one, on the exemplar's own frames and masks; each cell is
checked against issue 15's threshold (P/F). ``--write-docs`` writes the table, the
command, the date and the load average to docs/quality.md and one contact sheet per scene
to docs/quality/ (other sizes: docs/quality-<size>-<exemplar size>.md and its folder).
``--record-baseline`` stores this run's texture fidelity in docs/quality/baseline.json under
its sizes: the "no worse than today" reference later runs of those sizes are checked against.
``--seeds`` renders every scene once per stylizer seed: a single run's failing count moves by
about ±2 with the seed alone (docs/stylize.md), so changes are compared over several.
``--true-motion`` gives the guides each scene's own motion in place of the masks' estimate,
as ``flow: vector`` does for a vector input (printed only).
"""

from __future__ import annotations

import argparse
import dataclasses
import datetime
import json
import os
import shlex
import sys
import tempfile
import time
from pathlib import Path
from typing import Callable, NamedTuple

import numpy as np
import yaml
from PIL import Image

from fluidymation import quality
from fluidymation.pipeline import paths
from fluidymation.pipeline.parameters import default_params
from fluidymation.pipeline.presets import resolve_params
from fluidymation.pipeline.stylizers import get_stylizer
from fluidymation.stages import exemplar_builtin, exemplar_store, guides, stylize
from fluidymation.stages.guide_params import for_exemplar

ROOT = Path(__file__).resolve().parents[2]
BASELINE = ROOT / "docs" / "quality" / "baseline.json"
#: side of the canvas the scenes are described on, px (drawn --scale times larger)
DESIGN_SIZE = 128
FRAMES = 12
#: side of the built-in exemplars, px (default of --exemplar-size)
EXEMPLAR_SIZE = 96
MEDIA = ("watercolor-bloom", "watercolor-dry", "watercolor-backrun", "crumble")
#: fewest pixels (over all frame pairs) a still region or moving band needs to be measured
MIN_REGION = 200
FIDELITY_TOLERANCE = 1.05
#: bands of the edge-gradient profiles listed in docs/quality.md
CURVE_BANDS = 20
#: JPEG quality of the contact sheets
SHEET_QUALITY = 90
PAPER = np.array(exemplar_builtin.PAPER_COLOUR, np.float32)

class Canvas:
    """The square the scenes are drawn on: described on a 128-px canvas, drawn ``scale`` times larger.

    Shapes take centres and lengths in canvas units; the coverage they return and the
    displacements are in output pixels."""

    def __init__(self, scale: float = 1.0):
        self.scale = float(scale)
        self.size = int(round(DESIGN_SIZE * self.scale))
        self.yy, self.xx = (np.mgrid[:self.size, :self.size].astype(np.float64) + 0.5) / self.scale

    def soft(self, distance: np.ndarray) -> np.ndarray:
        """Coverage from a signed distance in canvas units (positive inside): a 1-px linear edge."""
        return np.clip(distance * self.scale + 0.5, 0.0, 1.0).astype(np.float32)

    def ellipse(self, cx, cy, a, b, angle=0.0) -> np.ndarray:
        """Soft ellipse with semi-axes a (along ``angle``, radians) and b; first-order distance to its edge."""
        u = (self.xx - cx) * np.cos(angle) + (self.yy - cy) * np.sin(angle)
        v = -(self.xx - cx) * np.sin(angle) + (self.yy - cy) * np.cos(angle)
        g = np.maximum(np.hypot(u / a, v / b), 1e-6)
        return self.soft((1.0 - g) * g / np.maximum(np.hypot(u / a**2, v / b**2), 1e-9))

    def capsule(self, x0, x1, y, radius) -> np.ndarray:
        """Soft horizontal capsule: the points within ``radius`` of the segment (x0, y)–(x1, y)."""
        return self.soft(radius - np.hypot(self.xx - np.clip(self.xx, x0, x1), self.yy - y))

    def rotation(self, cx, cy, angle) -> np.ndarray:
        """Displacement (H, W, 2) of a rotation by ``angle`` about (cx, cy)."""
        x, y = self.xx - cx, self.yy - cy
        return self.scale * np.stack([x * np.cos(angle) - y * np.sin(angle) - x,
                                      x * np.sin(angle) + y * np.cos(angle) - y], axis=-1)

    def scaling(self, cx, cy, factor) -> np.ndarray:
        """Displacement (H, W, 2) of a scaling by ``factor`` about (cx, cy)."""
        return self.scale * np.stack([(self.xx - cx) * (factor - 1.0), (self.yy - cy) * (factor - 1.0)], axis=-1)

    def uniform(self, dx, dy) -> np.ndarray:
        """Displacement (H, W, 2) of a translation by (dx, dy) canvas units."""
        return np.broadcast_to(self.scale * np.array([dx, dy], np.float64), (self.size, self.size, 2))

    def where_left_of(self, x, left, right) -> np.ndarray:
        """``left`` where the canvas x is below ``x``, else ``right`` (displacements)."""
        return np.where((self.xx < x)[..., None], left, right)

    def stretch_right_of(self, x, factor) -> np.ndarray:
        """Displacement of a horizontal stretch by ``factor`` away from the line at canvas x (left of it: none)."""
        dx = np.where(self.xx > x, (self.xx - x) * (factor - 1.0), 0.0)
        return self.scale * np.stack([dx, np.zeros_like(dx)], axis=-1)


class Scene(NamedTuple):
    """A layer with known motion: ``coverage(t)`` (H, W) and ``displacement(t)`` (H, W, 2), the shape's
    motion in px from frame t − 1 to frame t (t ≥ 1)."""

    name: str
    description: str
    coverage: Callable[[int], np.ndarray]
    displacement: Callable[[int], np.ndarray]


def _grow_end(t):
    return 36.0 + 5.0 * t


def make_scenes(c: Canvas) -> tuple[Scene, ...]:
    """The benchmark's scenes on canvas ``c`` (descriptions in canvas units, the 128-px canvas)."""
    def grown_stretch(t):
        """Anchored growth: the capsule's straight part and right cap stretch away from the fixed left cap."""
        return c.stretch_right_of(32.0, (_grow_end(t) - 32.0) / (_grow_end(t - 1) - 32.0))

    return (
        Scene("translation", "ellipse 60×44 px tilted 20°, moving (2.5, 1) px/frame",
              lambda t: c.ellipse(50 + 2.5 * t, 58 + 1.0 * t, 30, 22, np.radians(20)), lambda t: c.uniform(2.5, 1.0)),
        Scene("rotation", "ellipse 88×48 px turning 4°/frame about its centre",
              lambda t: c.ellipse(64, 64, 44, 24, np.radians(4 * t)), lambda t: c.rotation(64, 64, np.radians(4))),
        Scene("scale", "ellipse 56×40 px growing uniformly to 1.6× about its centre",
              lambda t: c.ellipse(64, 64, 28 * 1.6 ** (t / 11), 20 * 1.6 ** (t / 11)),
              lambda t: c.scaling(64, 64, 1.6 ** (1 / 11))),
        Scene("growth", "capsule 48 px tall, left end fixed, right end moving 5 px/frame (52→107 px wide)",
              lambda t: c.capsule(32, _grow_end(t), 64, 24), grown_stretch),
        Scene("shrink", "ellipse 88×64 px shrinking uniformly to 0.6× about its centre",
              lambda t: c.ellipse(64, 64, 44 * 0.6 ** (t / 11), 32 * 0.6 ** (t / 11)),
              lambda t: c.scaling(64, 64, 0.6 ** (1 / 11))),
        Scene("still", "ellipse 80×56 px tilted 15°, not moving",
              lambda t: c.ellipse(64, 64, 40, 28, np.radians(15)), lambda t: c.uniform(0.0, 0.0)),
        Scene("two shapes", "one layer: a still disk (r 20 px) and an ellipse 32×44 px moving (2, 0.5) px/frame",
              lambda t: np.maximum(c.ellipse(30, 64, 20, 20), c.ellipse(78 + 2.0 * t, 60 + 0.5 * t, 16, 22)),
              lambda t: c.where_left_of(54, 0.0, c.uniform(2.0, 0.5))),
    )


SCENE_NAMES = tuple(scene.name for scene in make_scenes(Canvas()))

#: the issue's thresholds, as printed under the table
THRESHOLDS = (
    ("profile", "edge-gradient profile peak/median (bands 5–40 px) ≤ 1.1 × the exemplar's"),
    ("blocks", "blockiness ≤ 1.05"),
    ("C last/1st", "local contrast, last frame / first frame ≥ 0.9"),
    ("C/ex", "local contrast (mean over frames) / the exemplar's within 0.85–1.15"),
    ("still/wt0", "still-region change ≤ 0.3 × that of the w_temp: 0 render"),
    ("still/ex", "still-region change ≤ 2 × the exemplar's stationary paint's"),
    ("band/still", "moving-band change ≥ 2 × the still-region change"),
    ("IoU", "IoU of output alpha with the masks (worst frame) ≥ 0.98"),
    ("fidelity", f"texture fidelity ≤ {FIDELITY_TOLERANCE} × the recorded baseline (docs/quality/baseline.json)"),
)


class Exemplar(NamedTuple):
    """A built-in medium: its frames and masks, its stylize source and its own figures."""

    rgb: np.ndarray
    mask: np.ndarray
    source: exemplar_store.Source
    figures: dict


def profile_curve(profile: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """Bands 1..CURVE_BANDS of a gradient profile over its median across the fitting bands (docs/quality.md)."""
    fitting = quality.fitting_bands(counts)
    return profile[1:CURVE_BANDS + 1] / np.median(profile[fitting.start:fitting.stop])


def exemplar_figures(rgb, mask, flow) -> dict:
    """The metrics that have a value on the exemplar's own frames and masks."""
    profile, counts = quality.gradient_profile(rgb, mask)
    peak, band = quality.profile_peak_ratio(profile, counts)
    contrast = [quality.local_contrast(frame, m) for frame, m in zip(rgb, mask)]
    changes = [quality.change(a, b) for a, b in zip(rgb, rgb[1:])]
    stationary = [quality.exemplar_stationary(mask[t - 1], mask[t], flow[t]) for t in range(1, len(rgb))]
    bands = [quality.moving_band(mask[t - 1], mask[t]) for t in range(1, len(rgb))]
    still = quality.pooled_mean(changes, stationary, min_pixels=MIN_REGION)
    return {"profile": peak, "profile_band": band, "profile_curve": profile_curve(profile, counts),
            "blockiness": quality.blockiness(rgb, mask),
            "contrast_last_first": contrast[-1] / contrast[0], "contrast": float(np.mean(contrast)),
            "contrasts": contrast, "still": still,
            "band_still": quality.ratio(quality.pooled_mean(changes, bands, min_pixels=MIN_REGION), still)}


def load_exemplar(medium: str, size: int, workdir: Path, guide_params: guides.Params) -> Exemplar:
    """The medium at ``size``² (from the user cache) with its guides, as the pipeline makes them."""
    params = resolve_params(medium, size=(size, size), frames=FRAMES)
    made = exemplar_builtin.make_builtin_exemplar(params, cache_dir=paths.exemplar_cache_dir())
    cache = guides.compute_guides(lambda j: made.mask[j], FRAMES, params=for_exemplar(guide_params),
                                  cache_dir=workdir / f"{medium}-source", given_flow=lambda j: made.flow[j])
    return Exemplar(made.rgb, made.mask, exemplar_store.in_memory(made.rgb, cache),
                    exemplar_figures(made.rgb, made.mask, made.flow))


def render_with_matches(scene: Scene, exemplar: Exemplar, params: stylize.Params, guide_params: guides.Params,
                        cache_dir: Path, true_motion: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """The stylized layer, (T, H, W, 4), and each pixel's exemplar frame, (T, H, W) (−1: none); with
    ``true_motion`` its guides take the scene's own motion (frame 0 that of frame 1)."""
    given = (lambda j: scene.displacement(max(j, 1)).astype(np.float32)) if true_motion else None
    frames = list(stylize.stylize_sequence(scene.coverage, FRAMES, exemplar.source, params=params,
                                           guide_params=guide_params, cache_dir=cache_dir, given_flow=given))
    return np.stack([frame.rgba for frame in frames]), np.stack([frame.nnf.frame for frame in frames])


def render(scene: Scene, exemplar: Exemplar, params: stylize.Params, guide_params: guides.Params,
           cache_dir: Path, true_motion: bool = False) -> np.ndarray:
    """The stylized layer, (T, H, W, 4) (:func:`render_with_matches`)."""
    return render_with_matches(scene, exemplar, params, guide_params, cache_dir, true_motion)[0]


def measure(scene: Scene, exemplar: Exemplar, params: stylize.Params, guide_params: guides.Params,
            workdir: Path, true_motion: bool = False) -> tuple[dict, np.ndarray]:
    """Render the scene (and its ``w_temp: 0`` twin when it has a still region); return its figures and frames."""
    masks = [scene.coverage(t) for t in range(FRAMES)]
    output, matched = render_with_matches(scene, exemplar, params, guide_params, workdir / "default", true_motion)
    still = [quality.still_region(masks[t - 1], masks[t], scene.displacement(t)) for t in range(1, FRAMES)]
    bands = [quality.moving_band(masks[t - 1], masks[t]) for t in range(1, FRAMES)]
    changes = [quality.change(a, b) for a, b in zip(output, output[1:])]
    profile, counts = quality.gradient_profile(output, masks)
    peak, band = quality.profile_peak_ratio(profile, counts)
    contrast = [quality.local_contrast(frame, mask) for frame, mask in zip(output, masks)]
    used = [quality.used_contrast(quality.frame_usage(frames, mask, len(exemplar.rgb)), exemplar.figures["contrasts"])
            for frames, mask in zip(matched, masks)]
    still_change = quality.pooled_mean(changes, still, min_pixels=MIN_REGION)
    independent = float("nan")
    if np.isfinite(still_change):
        without = render(scene, exemplar, dataclasses.replace(params, w_temp=0.0), guide_params, workdir / "w_temp0",
                         true_motion)
        independent = quality.pooled_mean([quality.change(a, b) for a, b in zip(without, without[1:])], still)
    figures = {
        "profile": peak, "profile_band": band, "profile_curve": profile_curve(profile, counts),
        "blockiness": quality.blockiness(output, masks),
        "contrast_last_first": contrast[-1] / contrast[0], "contrast": float(np.mean(contrast)),
        "contrast_used": float(np.mean(used)), "used_last_first": used[-1] / used[0],
        "still": still_change, "still_w_temp0": independent,
        "band_still": quality.ratio(quality.pooled_mean(changes, bands, min_pixels=MIN_REGION), still_change),
        "iou": min(quality.iou(frame[..., 3], mask) for frame, mask in zip(output, masks)),
        "fidelity": quality.texture_fidelity(output, masks, exemplar.rgb, exemplar.mask),
    }
    return figures, output


def verdicts(figures: dict, reference: dict, baseline: float | None) -> dict:
    """Issue 15's pass/fail per metric (None where the metric does not apply)."""

    def check(value, passes):
        return None if value is None or np.isnan(value) else bool(passes(value))

    return {
        "profile": check(figures["profile"], lambda v: v <= 1.1 * reference["profile"]),
        "blocks": check(figures["blockiness"][0], lambda v: v <= 1.05),
        "C last/1st": check(figures["contrast_last_first"], lambda v: v >= 0.9),
        "C/ex": check(quality.ratio(figures["contrast"], reference["contrast"]), lambda v: 0.85 <= v <= 1.15),
        "still/wt0": check(quality.ratio(figures["still"], figures["still_w_temp0"]), lambda v: v <= 0.3),
        "still/ex": check(quality.ratio(figures["still"], reference["still"]), lambda v: v <= 2.0),
        "band/still": check(figures["band_still"], lambda v: v >= 2.0),
        "IoU": check(figures["iou"], lambda v: v >= 0.98),
        "fidelity": None if baseline is None else check(figures["fidelity"],
                                                        lambda v: v <= FIDELITY_TOLERANCE * baseline),
    }


COLUMNS = ("scene", "profile", "blocks", "C last/1st", "C/ex", "used last/1st", "C/used", "still Δ", "still/wt0",
           "still/ex", "band/still", "IoU", "fidelity")


def _number(value, digits=2) -> str:
    return "n/a" if value is None or np.isnan(value) else f"{value:.{digits}f}"


def _cell(text: str, verdicts: list) -> str:
    """``text`` with P, or F and, over several seeds, how many of them failed (``F2/3``)."""
    if verdicts[0] is None:
        return text
    failed = sum(not verdict for verdict in verdicts)
    if not failed:
        return f"{text} P"
    return f"{text} F" if len(verdicts) == 1 else f"{text} F{failed}/{len(verdicts)}"


def exemplar_row(medium: str, figures: dict) -> list[str]:
    return [f"{medium} (exemplar)", f"{_number(figures['profile'])}@{figures['profile_band']}",
            f"{figures['blockiness'][0]:.3f}", _number(figures["contrast_last_first"]), "1", "", "",
            _number(1e3 * figures["still"]), "", "1", _number(figures["band_still"]), "", ""]


def seed_verdicts(runs: list[dict], reference: dict, baseline: float | None) -> dict:
    """Per check, its verdict in each seed's run (:func:`verdicts`)."""
    by_seed = [verdicts(run, reference, baseline) for run in runs]
    return {check: [seed[check] for seed in by_seed] for check in by_seed[0]}


def scene_row(name: str, runs: list[dict], reference: dict, baseline: float | None) -> list[str]:
    """The figures of the first seed's run; each check's verdicts over every seed's."""
    figures = runs[0]
    verdict = seed_verdicts(runs, reference, baseline)
    fidelity = _number(figures["fidelity"], 4) + ("" if baseline is None else f" ({baseline:.4f})")
    return [name,
            _cell(f"{_number(figures['profile'])}@{figures['profile_band']}", verdict["profile"]),
            _cell(f"{figures['blockiness'][0]:.3f}", verdict["blocks"]),
            _cell(_number(figures["contrast_last_first"]), verdict["C last/1st"]),
            _cell(_number(quality.ratio(figures["contrast"], reference["contrast"])), verdict["C/ex"]),
            _number(figures["used_last_first"]), _number(quality.ratio(figures["contrast"], figures["contrast_used"])),
            _number(1e3 * figures["still"]) + f" / {_number(1e3 * figures['still_w_temp0'])}",
            _cell(_number(quality.ratio(figures["still"], figures["still_w_temp0"])), verdict["still/wt0"]),
            _cell(_number(quality.ratio(figures["still"], reference["still"])), verdict["still/ex"]),
            _cell(_number(figures["band_still"]), verdict["band/still"]),
            _cell(_number(figures["iou"], 3), verdict["IoU"]),
            _cell(fidelity, verdict["fidelity"])]


def failure_summary(results, baseline: dict, seeds: list[int]) -> str:
    """Failing checks per seed, and how many checks fail in every seed and in at least one."""
    per_seed = np.zeros(len(seeds), int)
    every = some = 0
    for medium, reference, measured in results:
        for name, runs in measured:
            for checked in seed_verdicts(runs, reference, baseline.get(medium, {}).get(name)).values():
                failed = np.array([verdict is False for verdict in checked])
                per_seed += failed
                every += bool(failed.all())
                some += bool(failed.any())
    text = "failing checks: " + ", ".join(f"{count} (seed {seed})" for count, seed in zip(per_seed, seeds))
    return text if len(seeds) == 1 else f"{text}; {every} fail in every seed, {some} in at least one"


def text_table(rows: list[list[str]]) -> str:
    widths = [max(len(row[i]) for row in [list(COLUMNS)] + rows) for i in range(len(COLUMNS))]
    lines = ["  ".join(cell.ljust(width) for cell, width in zip(row, widths)) for row in [list(COLUMNS)] + rows]
    return "\n".join(lines)


def markdown_table(rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(COLUMNS) + " |", "|" + "---|" * len(COLUMNS)]
    lines += ["| " + " | ".join(cell.replace("|", "\\|") for cell in row) + " |" for row in rows]
    return "\n".join(lines)


def over_paper(rgba: np.ndarray) -> np.ndarray:
    """RGBA composited over the exemplars' paper colour."""
    alpha = rgba[..., 3:4]
    return rgba[..., :3] * alpha + PAPER * (1 - alpha)


def _tile(image: np.ndarray, size: int) -> np.ndarray:
    """An RGB image in [0, 1] centred on a size×size paper tile (cropped if larger)."""
    tile = np.broadcast_to(PAPER, (size, size, 3)).copy()
    top, left = max(size - image.shape[0], 0) // 2, max(size - image.shape[1], 0) // 2
    top_in, left_in = max(image.shape[0] - size, 0) // 2, max(image.shape[1] - size, 0) // 2
    image = image[top_in:top_in + size, left_in:left_in + size]
    tile[top:top + image.shape[0], left:left + image.shape[1]] = image
    return tile


def contact_sheet(scene: Scene, rows: list[tuple[np.ndarray, np.ndarray]], path: Path) -> None:
    """One row per medium: exemplar middle frame; output frames first, middle and last; the change into
    the middle frame inside both frames' masks (×5, dark = change; paper elsewhere)."""
    middle = FRAMES // 2
    both = quality.inside(scene.coverage(middle - 1)) & quality.inside(scene.coverage(middle))
    lines = []
    for exemplar_rgb, output in rows:
        difference = 1.0 - np.clip(5.0 * quality.change(output[middle - 1], output[middle]), 0, 1)
        difference = np.where(both[..., None], difference[..., None], PAPER)
        lines.append(np.concatenate([_tile(exemplar_rgb[middle], output.shape[1]), over_paper(output[0]),
                                     over_paper(output[middle]), over_paper(output[-1]), difference], axis=1))
    sheet = (np.clip(np.concatenate(lines, axis=0), 0, 1) * 255 + 0.5).astype(np.uint8)
    Image.fromarray(sheet).save(path, quality=SHEET_QUALITY)


def sheet_name(scene: Scene) -> str:
    return scene.name.replace(" ", "-") + ".jpg"


def curves_table(results) -> str:
    """Markdown: every profile curve (exemplar and scenes), one row each."""
    lines = ["| | " + " | ".join(str(k) for k in range(1, CURVE_BANDS + 1)) + " |", "|---|" + "---|" * CURVE_BANDS]
    for medium, reference, measured in results:
        for name, figures in [("exemplar", reference)] + [(name, runs[0]) for name, runs in measured]:
            values = " | ".join("" if np.isnan(v) else f"{v:.2f}" for v in figures["profile_curve"])
            lines.append(f"| {medium} {name} | {values} |")
    return "\n".join(lines)


class Setup(NamedTuple):
    """Where the scenes are drawn and how large the exemplars are; ``key`` names it in the baseline."""

    canvas: Canvas
    exemplar_size: int

    @property
    def key(self) -> str:
        return f"{self.canvas.size}/{self.exemplar_size}"

    @property
    def is_default(self) -> bool:
        return self.canvas.size == DESIGN_SIZE and self.exemplar_size == EXEMPLAR_SIZE

    @property
    def docs(self) -> Path:
        """docs/quality.md for the default setup, else docs/quality-<size>-<exemplar size>.md."""
        name = "quality" if self.is_default else f"quality-{self.canvas.size}-{self.exemplar_size}"
        return ROOT / "docs" / f"{name}.md"

    @property
    def sheets(self) -> Path:
        return self.docs.with_suffix("")


def write_docs(setup: Setup, command: str, loads: tuple, started: str, seconds: float, rows: list[list[str]],
               summary: str, results, scenes, media) -> None:
    size, exemplar_size = setup.canvas.size, setup.exemplar_size
    sheets = "\n".join(f"- {scene.name} ({scene.description}): ![{scene.name}]({setup.sheets.name}/{sheet_name(scene)})"
                       for scene in scenes)
    setup.docs.write_text(f"""## Quality benchmark (issue 15)

Written by `tests/benchmarks/bench_quality.py --write-docs`; do not edit by hand.

Command: `{command}`. Run {started} in {seconds:.0f} s; load average
{loads[0]:.2f} at the start, {loads[1]:.2f} at the end (2 cores).

Each scene is a {size}×{size} layer of {FRAMES} frames with soft 1-px edges, drawn analytically by the
benchmark ({setup.canvas.scale:g} × the 128-px canvas its descriptions use), stylized with the defaults of
configs/fluidymation.yaml and the guides' defaults from a
{exemplar_size}×{exemplar_size}×{FRAMES} built-in exemplar of each medium (seed and colour of
configs/exemplars.yaml). Media: {', '.join(media)}.

{markdown_table(rows)}

{summary[0].upper() + summary[1:]}.

P/F: issue 15's thresholds (over several seeds, F2/3: failed with two of three; the figures are the
first seed's); n/a: the scene has no such region (no still region: the still-region
and band/still figures; no moving edge: the band). The exemplar row of each medium holds the
exemplar's own values, computed on its frames and masks.

{chr(10).join(f'- **{name}**: {text}' for name, text in THRESHOLDS)}

### What the figures are (`fluidymation/quality.py`)

Luminance is the mean of R, G and B (sRGB in [0, 1]); a pixel is inside where the mask's
coverage is ≥ 0.5; the edge distance of an inside pixel is its Euclidean distance to the
nearest outside pixel centre (1 next to the edge).

- **profile**: the mean luminance-gradient magnitude (central differences) in 1-px bands of
  edge distance (band k: k ≤ distance < k + 1), over all frames; printed is max/median over
  bands 5–40, clipped to the bands that hold ≥ 100 pixels (stopping at the first that does
  not), and `@` the band of the maximum. A seam ring parallel to the edge is a peak.
- **blocks**: for each axis, |Δ luminance| of adjacent pixel pairs with both pixels inside the
  mask eroded by 2 px, pooled over all frames; a pair straddles boundary i (between pixels
  i − 1 and i). Printed is the larger of mean |Δ| over even boundaries / mean |Δ| over odd ones
  and its inverse, over both axes. 1.0: no grid. The blocks the stylizer makes are 2 px (their
  pattern at period 4 is the period-2 one). The figure's noise on one image is about ±4 %: the
  exemplars' frames (nearly alike, so about one image's worth) give 1.02–1.03 for the
  watercolors; crumble's exemplar has a real period-2 structure along y (1.16).
- **C last/1st**, **C/ex**: local contrast is the mean 5×5 standard deviation of luminance
  inside the mask eroded by 3 px; the last frame's over the first's, and the mean over frames
  over the exemplar's mean over its frames (in its masks).
- **used last/1st**, **C/used** (no threshold): the same contrast as the exemplar frames each output
  frame draws from would give it: the exemplar's per-frame contrast weighted by the share of the
  output's matches (in the same eroded mask) taken from that frame. `used last/1st` is how much the
  medium itself changes between the frames the first and the last output frame draw from (the
  paper moves a patch forward in exemplar time as the shape moves, so a moving shape ages with its
  medium; `watercolor-bloom` loses contrast as it spreads); `C/used` is the output's mean contrast
  over that of its sources: below 1 is wash-out by the synthesis itself, whatever frames it uses.
- **still Δ** (×10⁻³): the mean over R, G, B of |frame t − frame t − 1|, pooled over the pixels
  of the still region of every pair: inside both masks ≥ 2 px from the edge in both, whose edge
  distance changes by < 0.1 px and whose known displacement (the scene's own motion) is
  < 0.1 px. Beside it (`/`) the same on the `w_temp: 0` render. Measured only with
  ≥ {MIN_REGION} pixels in all. The exemplar's: its pixels in its mask in both frames with
  exact flow < 0.05 px/frame, eroded by 2 px.
- **still/wt0**, **still/ex**: still Δ over the `w_temp: 0` render's, and over the exemplar's.
- **band/still**: the change pooled over the moving band (inside both masks, ≤ 10 px from the
  edge in the later frame, edge distance changed by ≥ 0.5 px) over the still Δ. The exemplar's:
  the same band on its masks over its stationary change.
- **IoU**: output alpha ≥ 0.5 against the mask ≥ 0.5, the worst frame. The stylizer's alpha
  is the target coverage, so this guards against a regression rather than measuring synthesis.
- **fidelity**: 2000 5×5 output patches lying wholly inside the masks, drawn with a fixed
  seed from all frames, each against every exemplar patch centred in the exemplar's masks
  (exact nearest neighbour): the mean RMS colour difference per pixel and channel. 0: the
  output is made of exemplar patches. In parentheses the baseline recorded with
  `--record-baseline` (the stylizer before issue 15's item 2).

### Edge-gradient profiles

The profile behind the **profile** column: mean luminance-gradient magnitude in band k (k ≤ edge
distance < k + 1) for k = 1–{CURVE_BANDS}, over its median across the bands the figure uses. The
target guides' border/interior split (guides `border_width` 10 px) lies at an edge distance of
about 9.5–10 px in these scenes.

{curves_table(results)}

### Contact sheets

Per scene, one row per medium: the exemplar's middle frame, the output's first, middle and last
frames over paper, and the change into the middle frame where both frames are inside the mask
(×5, dark = change).

{sheets}
""")


def overrides(items: list[str]) -> dict:
    """``NAME=VALUE`` options as keyword arguments, each value read as YAML (``opt_iters=[4, 2, 2]``)."""
    pairs = [item.split("=", 1) for item in items]
    if any(len(pair) != 2 for pair in pairs):
        raise SystemExit(f"expected NAME=VALUE, got {items}")
    return {name: tuple(value) if isinstance(value := yaml.safe_load(text), list) else value for name, text in pairs}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", nargs="+", default=list(SCENE_NAMES), choices=SCENE_NAMES,
                        metavar="SCENE", help=f"scenes to run (default all: {', '.join(SCENE_NAMES)})")
    parser.add_argument("--media", nargs="+", default=list(MEDIA), choices=MEDIA, metavar="MEDIUM",
                        help=f"built-in exemplars (default all: {', '.join(MEDIA)})")
    parser.add_argument("--scale", type=float, default=1.0,
                        help="draw the scenes this many times larger than their 128-px canvas (default 1)")
    parser.add_argument("--exemplar-size", type=int, default=EXEMPLAR_SIZE,
                        help=f"side of the built-in exemplars, px (default {EXEMPLAR_SIZE}; their own default: 256)")
    parser.add_argument("--write-docs", action="store_true",
                        help="write docs/quality.md and docs/quality/*.png (other sizes: docs/quality-<size>-<exemplar>*)")
    parser.add_argument("--record-baseline", action="store_true",
                        help="store this run's texture fidelity as the baseline of its sizes (docs/quality/baseline.json)")
    parser.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                        help="a stylizer parameter instead of its default (YAML value; repeatable)")
    parser.add_argument("--guide", action="append", default=[], metavar="NAME=VALUE",
                        help="a guides parameter instead of its default (YAML value; repeatable)")
    parser.add_argument("--seeds", nargs="+", type=int, metavar="SEED",
                        help="render every scene with each of these stylizer seeds (default: the stylizer's); the table "
                             "shows the first seed's figures and, per check, how many seeds failed it (F2/3)")
    parser.add_argument("--true-motion", action="store_true",
                        help="guides from each scene's own motion instead of the masks' estimate (printed only)")
    args = parser.parse_args()
    if args.true_motion and (args.write_docs or args.record_baseline):
        raise SystemExit("--true-motion runs are printed only (no --write-docs, --record-baseline)")
    setup = Setup(Canvas(args.scale), args.exemplar_size)
    scenes = [s for s in make_scenes(setup.canvas) if s.name in args.scenes]
    command = "NUMBA_CACHE_DIR=.numba-cache .venv/bin/python " + shlex.join(["tests/benchmarks/bench_quality.py",
                                                                             *sys.argv[1:]])
    started = datetime.datetime.now().strftime("%Y-%m-%d %H:%M")
    clock, load_start = time.perf_counter(), os.getloadavg()
    print(f"{command}\nload average {load_start[0]:.2f} {load_start[1]:.2f} {load_start[2]:.2f}", flush=True)
    params = dataclasses.replace(default_params(get_stylizer("fluidymation")), **overrides(args.param))
    seeds = args.seeds or [params.seed]
    if args.record_baseline and len(seeds) > 1:
        raise SystemExit("--record-baseline takes one seed")
    guide_params = guides.Params(**overrides(args.guide))
    baselines = json.loads(BASELINE.read_text()) if BASELINE.is_file() else {}
    baseline = baselines.setdefault(setup.key, {})
    results, sheet_rows = [], {s.name: [] for s in scenes}
    with tempfile.TemporaryDirectory() as workdir:
        workdir = Path(workdir)
        for medium in args.media:
            exemplar = load_exemplar(medium, setup.exemplar_size, workdir, guide_params)
            results.append((medium, exemplar.figures, []))
            for scene in scenes:
                runs = []
                for index, seed in enumerate(seeds):
                    begun = time.perf_counter()
                    figures, output = measure(scene, exemplar, dataclasses.replace(params, seed=seed), guide_params,
                                              workdir / medium / scene.name / str(seed), args.true_motion)
                    runs.append(figures)
                    if index == 0:
                        sheet_rows[scene.name].append((exemplar.rgb, output))
                    print(f"{medium} / {scene.name} / seed {seed}: {time.perf_counter() - begun:.1f} s",
                          file=sys.stderr, flush=True)
                results[-1][2].append((scene.name, runs))
    if args.record_baseline:
        for medium, _, measured in results:
            baseline.setdefault(medium, {}).update({name: runs[0]["fidelity"] for name, runs in measured})
        BASELINE.parent.mkdir(parents=True, exist_ok=True)
        BASELINE.write_text(json.dumps(baselines, indent=1, sort_keys=True) + "\n")
    rows = []
    for medium, reference, measured in results:
        rows.append(exemplar_row(medium, reference))
        rows += [scene_row(f"  {name}", runs, reference, baseline.get(medium, {}).get(name))
                 for name, runs in measured]
    loads = (load_start[0], os.getloadavg()[0])
    seconds = time.perf_counter() - clock
    print(text_table(rows))
    print("\nthresholds (issue 15, item 2):")
    for name, text in THRESHOLDS:
        print(f"  {name:10s} {text}")
    summary = failure_summary(results, baseline, seeds)
    print(f"\n{summary}\n{seconds:.0f} s; load average {loads[0]:.2f} -> {loads[1]:.2f}")
    if args.write_docs:
        setup.sheets.mkdir(parents=True, exist_ok=True)
        for scene in scenes:
            contact_sheet(scene, sheet_rows[scene.name], setup.sheets / sheet_name(scene))
        write_docs(setup, command, loads, started, seconds, rows, summary, results, scenes, args.media)


if __name__ == "__main__":
    main()
