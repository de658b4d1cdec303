"""``fluidymation compare SCENE --layer NAME --stylizers A,B,...``: one layer painted by several stylizers.

Each named stylizer paints the layer's frames: the layer's own stylizer with the layer's
parameters, any other with its defaults file and the scene's seed. The results go side by
side, each under the stylizer's name, into one video, and into a contact sheet whose rows
are captioned with quality figures of :mod:`fluidymation.quality` that need no reference
render, so the stylizers can be told apart at a glance (docs/extending.md, "Comparing
stylizers").
"""

from __future__ import annotations

import json
import tempfile
from typing import NamedTuple

import numpy as np

from fluidymation import quality
from fluidymation.errors import InputError
from fluidymation.pipeline.layer_stages import layer_motion, read_coverage
from fluidymation.pipeline.panels import LayerPanels, add_layer_arguments, over_paper, paper_colour
from fluidymation.pipeline.parameters import layer_guide_params, layer_stylize_params, scene_default_params
from fluidymation.pipeline.progress import progress, reporter
from fluidymation.pipeline.render import load_layer_source
from fluidymation.pipeline.stylizers import get_stylizer, stylizer_names
from fluidymation.stages import guides
from fluidymation.stages.files import write_png, write_text
from fluidymation.stages.labels import label_strip, wrapped_caption

#: The figures in the order shown: (key, name in the captions and the table, format).
FIGURES = (
    ("blocks", "blocks", "{:.2f}"),
    ("contrast", "C last/1st", "{:.2f}"),
    ("still", "still", "{:.2f}"),
    ("band_still", "band/still", "{:.1f}"),
    ("iou", "IoU", "{:.3f}"),
    ("fidelity", "fid", "{:.3f}"),
)
#: Fewest pixels (over all frame pairs) a still region or moving band needs to be measured.
MIN_REGION = 50
#: Exemplar frames (evenly spaced) whose patches the fidelity looks for: all of a 256² exemplar would take minutes.
FIDELITY_FRAMES = 4


class Row(NamedTuple):
    """One stylizer's result: its name, whose parameters it took (``layer`` or ``defaults``), its figures
    and the frames the contact sheet shows, (n, H, W, 4)."""

    name: str
    params: str
    figures: dict[str, float]
    shown: np.ndarray


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "compare", description="Stylize one layer with each named stylizer (the layer's own with the layer's params, any other "
                    "with its defaults and the scene's seed) into <output.dir>/compare/<layer>/<stylizer>/, write a "
                    "labelled side-by-side video <output.dir>/compare/<layer>.mp4, a contact sheet "
                    "<output.dir>/compare/<layer>.png (a row per stylizer: its first, middle and last frame, captioned "
                    "with its quality figures) and the figures to <output.dir>/compare/<layer>.json; the table is "
                    "printed as well.")
    add_layer_arguments(parser)
    parser.add_argument("--stylizers", required=True, metavar="A,B,...",
                        help="the stylizers, comma-separated (e.g. fluidymation,keyframes)")
    parser.set_defaults(run=run)


def run(args) -> int:
    layers = LayerPanels.from_args(args)
    plan, layer = layers.plan, layers.layer
    stylizers = [_stylizer(layers, name) for name in _names(args.stylizers)]
    layers.render_masks()
    guide_params = layer_guide_params(plan, layer)
    exemplar = (None if all(stylizer.uses_keyframes for stylizer in stylizers)
                else load_layer_source(plan, layer, guide_params, args.quiet))
    masks = [read_coverage(layers.coverage_dir, frame - plan.start) for frame in layers.frames]
    motion = _motion(layers, guide_params)
    folder = layers.out / "compare" / layer.dirname
    rows = []
    for stylizer in stylizers:
        own = stylizer.name == layer.spec.stylizer
        params = layer_stylize_params(plan, layer) if own else scene_default_params(plan, stylizer)
        source = None if stylizer.uses_keyframes else exemplar
        layers.stylize(folder / stylizer.name, stylizer, params, source, guide_params)
        frames = np.stack([layers.read(folder / stylizer.name, frame) for frame in layers.frames])
        with progress(1, "quality", layer=f"{layer.name} {stylizer.name}", quiet=args.quiet, unit="stylizer") as bar:
            figures = measure(frames, masks, motion, source)
            bar.update()
        rows.append(Row(stylizer.name, "layer" if own else "defaults", figures, frames[_columns(len(frames))]))
    paper = paper_colour(exemplar)
    video, sheet, table = (layers.out / "compare" / f"{layer.dirname}{suffix}" for suffix in (".mp4", ".png", ".json"))
    layers.write_video(video, [(row.name, folder / row.name) for row in rows], paper,
                       description="comparison video")
    write_png(sheet, contact_sheet(layers, rows, paper))
    write_text(table, json.dumps(_record(layers, rows), indent=2) + "\n")
    print(markdown_table(rows))
    if not args.quiet:
        print(f"wrote {len(rows)} stylizers of layer {layer.name} side by side to {video}, the contact sheet to "
              f"{sheet} and the figures to {table}")
    return 0


def _names(text: str) -> list[str]:
    """The ``--stylizers`` list: names, each once."""
    names = [name.strip() for name in text.split(",") if name.strip()]
    if not names:
        raise InputError(f"--stylizers {text!r}: name at least one stylizer (registered: "
                         f"{', '.join(stylizer_names())})")
    twice = sorted({name for name in names if names.count(name) > 1})
    if twice:
        raise InputError(f"--stylizers: {', '.join(twice)} named more than once")
    return names


def _stylizer(layers: LayerPanels, name: str):
    """The installed stylizer ``name`` (an unknown name is an error listing the installed ones), checked against
    the layer (a keyframes stylizer needs its keyframes)."""
    stylizer = get_stylizer(name)
    if stylizer.uses_keyframes and not layers.layer.spec.keyframes:
        raise InputError(f"layer '{layers.layer.name}': the stylizer '{name}' paints from keyframes and the layer has "
                         "none (give it keyframes: {FRAME: IMAGE, ...})")
    return stylizer


def _motion(layers: LayerPanels, guide_params: guides.Params) -> list[np.ndarray]:
    """The layer's motion into each frame after the window's first, (H, W, 2) px, as the guides see it: from
    the geometry with ``flow: vector``, else estimated from the masks."""
    plan = layers.plan
    with tempfile.TemporaryDirectory(prefix=".motion-", dir=layers.out) as cache_dir, \
            progress(1, "motion", layer=layers.layer.name, quiet=layers.quiet, unit="step") as bar:
        cache = guides.compute_guides(lambda j: read_coverage(layers.coverage_dir, j), plan.frame_count,
                                      params=guide_params, cache_dir=cache_dir,
                                      given_flow=layer_motion(layers.out, layers.layer), progress=reporter(bar))
        return [np.array(cache.read("flow", frame - plan.start)) for frame in layers.frames[1:]]


def measure(frames: np.ndarray, masks: list[np.ndarray], motion: list[np.ndarray], exemplar) -> dict[str, float]:
    """The figures of stylized ``frames`` (T, H, W, 4) on their ``masks``, with the shape's ``motion`` into
    each frame after the first; ``exemplar`` (a StoredSource, or None) for the fidelity. nan: not measured."""
    pairs = range(1, len(frames))
    changes = [quality.change(frames[t - 1], frames[t]) for t in pairs]
    still_regions = [quality.still_region(masks[t - 1], masks[t], motion[t - 1]) for t in pairs]
    bands = [quality.moving_band(masks[t - 1], masks[t]) for t in pairs]
    still = quality.pooled_mean(changes, still_regions, min_pixels=MIN_REGION)
    return {
        "blocks": quality.blockiness(frames, masks)[0],
        "contrast": quality.ratio(quality.local_contrast(frames[-1], masks[-1]),
                                  quality.local_contrast(frames[0], masks[0])),
        "still": 1000 * still,
        "band_still": quality.ratio(quality.pooled_mean(changes, bands, min_pixels=MIN_REGION), still),
        "iou": min(quality.iou(frame[..., 3], mask) for frame, mask in zip(frames, masks)),
        "fidelity": float("nan") if exemplar is None else _fidelity(frames, masks, exemplar),
    }


def _fidelity(frames, masks, exemplar) -> float:
    """Texture fidelity against :data:`FIDELITY_FRAMES` of the exemplar's frames, evenly spaced."""
    last = exemplar.frame_count - 1
    picked = [exemplar.window(k, k + 1) for k in np.unique(np.linspace(0, last, FIDELITY_FRAMES).round().astype(int))]
    return quality.texture_fidelity(frames, masks, [part.rgb[0] for part in picked],
                                    [part.segment[0] >= 0 for part in picked])


def _shown(row: Row) -> list[str]:
    """The row's figures as the captions and the table show them, in :data:`FIGURES` order (n/a: not measured)."""
    values = [(row.figures[key], form) for key, _, form in FIGURES]
    return ["n/a" if np.isnan(value) else form.format(value) if np.isfinite(value) else f"{value:g}"
            for value, form in values]


def _columns(count: int) -> list[int]:
    """The window's first, middle and last frame (fewer when it is shorter)."""
    return sorted({0, count // 2, count - 1})


def contact_sheet(layers: LayerPanels, rows: list[Row], paper: np.ndarray) -> np.ndarray:
    """A row per stylizer: its frames of :func:`_columns` over ``paper``, under a caption of its name and
    figures; the frame numbers on top. (H', W', 3) float32."""
    columns = _columns(len(layers.frames))
    width = layers.plan.size[0]
    parts = [np.concatenate(label_strip([f"frame {layers.frames[c]}" for c in columns], width=width), axis=1)]
    for row in rows:
        figures = [f"{name} {shown}" for (_, name, _), shown in zip(FIGURES, _shown(row))]
        parts.append(wrapped_caption([f"{row.name}: {figures[0]}", *figures[1:]], width=width * len(columns)))
        parts.append(np.concatenate([over_paper(rgba, paper) for rgba in row.shown], axis=1))
    return np.concatenate(parts)


def markdown_table(rows: list[Row]) -> str:
    """The figures as a Markdown table, a row per stylizer."""
    lines = ["| stylizer | params | " + " | ".join(name for _, name, _ in FIGURES) + " |",
             "|---|---|" + "---|" * len(FIGURES)]
    for row in rows:
        lines.append("| " + " | ".join([row.name, row.params, *_shown(row)]) + " |")
    return "\n".join(lines)


def _record(layers: LayerPanels, rows: list[Row]) -> dict:
    """The JSON file's content: the layer, the frames and each stylizer's figures (null: not measured, or
    infinite)."""
    stylizers = [{"name": row.name, "params": row.params,
                  "figures": {key: value if np.isfinite(value) else None for key, value in row.figures.items()}}
                 for row in rows]
    return {"layer": layers.layer.name, "frames": {"start": layers.frames.start, "end": layers.frames.stop},
            "stylizers": stylizers}
