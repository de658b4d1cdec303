"""``fluidymation exemplar list|make|show``: the built-in moving exemplars.

``list`` prints each preset's name, description and default parameters (from
``configs/exemplars.yaml``); ``make NAME -o DIR`` writes ``DIR/rgb/00000.png …``,
``DIR/mask/00000.png …`` (0/255), ``DIR/flow/00000.npy …`` ((H, W, 2) float32, px/frame,
(dx, dy), y down) and ``DIR/exemplar.json``. Generated exemplars are cached (``--cache``).
``show DIR -o SHEET.png`` draws a contact sheet of such a folder: frames, frames with the
mask outline, and the flow (hue = direction, brightness = speed).
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
from scipy import ndimage

from fluidymation.errors import InputError
from fluidymation.pipeline import paths
from fluidymation.pipeline.presets import parse_size, preset_defaults, resolve_params
from fluidymation.pipeline.progress import progress
from fluidymation.stages import exemplar_builtin
from fluidymation.stages.files import read_image, write_npy, write_png, write_text
from fluidymation.stages.flow_io import read_flow


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "exemplar", description="Built-in moving exemplars: simulated watercolor and crumbling charcoal.")
    actions = parser.add_subparsers(dest="action", metavar="ACTION")
    actions.required = True
    listing = actions.add_parser("list", help="names, descriptions and default parameters")
    listing.set_defaults(run=run_list)
    make = actions.add_parser("make", help="generate a preset and write its frames, masks and flow",
                              description="Write DIR/rgb/*.png, DIR/mask/*.png, DIR/flow/*.npy and DIR/exemplar.json.")
    make.add_argument("name", help="preset name (see `fluidymation exemplar list`)")
    make.add_argument("-o", "--output", metavar="DIR", required=True, help="output folder")
    make.add_argument("--seed", type=int, help="random seed")
    make.add_argument("--size", nargs="+", metavar="N", help="width and height: `W H` or `WxH`")
    make.add_argument("--frames", type=int, metavar="N", help="number of frames")
    make.add_argument("--color", metavar="#RRGGBB", help="pigment colour")
    make.add_argument("--wetness", type=float, metavar="W", help="starting water, 0 to 1")
    make.add_argument("--cache", metavar="DIR",
                      help="cache folder (default: the exemplars/ folder of the user cache render reads, "
                           "$FLUIDYMATION_CACHE or ~/.cache/fluidymation)")
    make.add_argument("--no-cache", action="store_true", help="generate without reading or writing the cache")
    make.set_defaults(run=run_make)
    show = actions.add_parser("show", help="contact sheet of an exemplar folder: frames, mask outlines, flow",
                              description="Rows: frames; frames with the mask outline in red; flow colour-coded "
                                          "(hue = direction, brightness = speed relative to the fastest).")
    show.add_argument("folder", metavar="DIR", help="folder written by `exemplar make` (rgb/, mask/, flow/)")
    show.add_argument("-o", "--output", metavar="SHEET.png", required=True, help="the contact sheet to write")
    show.add_argument("--count", type=int, default=6, metavar="N", help="frames shown, evenly spaced (default 6)")
    show.set_defaults(run=run_show)


def run_list(args) -> int:
    for name, defaults in preset_defaults().items():
        if name not in exemplar_builtin.PRESETS:
            continue
        print(f"{name}: {exemplar_builtin.PRESETS[name].description}")
        width, height = defaults["size"]
        print(f"    seed={defaults['seed']} size={width}x{height} frames={defaults['frames']} "
              f"color={defaults['color']} wetness={defaults['wetness']}")
    return 0


def run_make(args) -> int:
    params = resolve_params(args.name, seed=args.seed, size=parse_size(args.size), frames=args.frames,
                            color=args.color, wetness=args.wetness)
    cache_dir = None if args.no_cache else Path(args.cache) if args.cache else paths.exemplar_cache_dir()
    out_dir = Path(args.output)
    with progress(params.frames, f"simulate {params.preset}", quiet=args.quiet) as bar:
        exemplar = exemplar_builtin.make_builtin_exemplar(params, cache_dir=cache_dir, progress=bar.update)
    with progress(params.frames, "write", quiet=args.quiet) as bar:
        for index in range(params.frames):
            write_png(out_dir / "rgb" / f"{index:05d}.png", exemplar.rgb[index])
            write_png(out_dir / "mask" / f"{index:05d}.png", exemplar.mask[index].astype(np.uint8) * 255)
            write_npy(out_dir / "flow" / f"{index:05d}.npy", exemplar.flow[index])
            bar.update()
    width, height = params.size
    record = {
        "name": params.preset,
        "params": dataclasses.asdict(params),
        "size": [width, height],
        "frames": params.frames,
        "flow": "px/frame, (dx, dy), y down; flow[k] is the motion from frame k-1 to frame k",
    }
    write_text(out_dir / "exemplar.json", json.dumps(record, indent=2) + "\n")
    if not args.quiet:
        print(f"wrote {params.frames} frames of {params.preset} ({width}x{height}) to {out_dir}")
    return 0


def run_show(args) -> int:
    folder = Path(args.folder)
    frames = sorted((folder / "rgb").glob("*.png"))
    if not frames:
        raise InputError(f"{folder / 'rgb'}: no frames (expected 00000.png ... written by `fluidymation exemplar make`)")
    if args.count < 1:
        raise InputError(f"--count must be at least 1, got {args.count}")
    picks = sorted(set(np.linspace(0, len(frames) - 1, min(args.count, len(frames))).round().astype(int)))
    columns = []
    images = {index: read_image(frames[index], channels=3) for index in picks}
    size = images[picks[0]].shape[:2]
    flows = {}
    for index in picks:
        if images[index].shape[:2] != size:
            raise InputError(f"{frames[index]}: the frame is {images[index].shape[1]}x{images[index].shape[0]}, "
                             f"{frames[picks[0]].name} is {size[1]}x{size[0]}; all frames must have one size")
        flow_path = folder / "flow" / f"{frames[index].stem}.npy"
        if flow_path.is_file():
            flows[index] = read_flow(flow_path, shape=size)
    fastest = max([float(np.hypot(f[..., 0], f[..., 1]).max()) for f in flows.values()] + [1e-6])
    for index in picks:
        rgb = images[index]
        outlined = rgb.copy()
        mask_path = folder / "mask" / frames[index].name
        if mask_path.is_file():
            mask = read_image(mask_path, channels=1)[:, :, 0] > 0.5
            if mask.shape != size:
                raise InputError(f"{mask_path}: the mask is {mask.shape[1]}x{mask.shape[0]}, its frame "
                                 f"{size[1]}x{size[0]}")
            outlined[mask & ~ndimage.binary_erosion(mask)] = (1.0, 0.0, 0.0)
        flow = flows.get(index)
        view = _flow_colours(flow, fastest) if flow is not None else np.zeros_like(rgb)
        columns.append(np.concatenate([rgb, outlined, view], axis=0))
    gap = np.ones((columns[0].shape[0], 4, 3), dtype=np.float32)
    sheet = np.concatenate([part for column in columns for part in (column, gap)][:-1], axis=1)
    write_png(args.output, sheet)
    if not args.quiet:
        print(f"wrote a contact sheet of {len(picks)} frames to {args.output}")
    return 0


def _flow_colours(flow, fastest):
    """(H, W, 2) flow to (H, W, 3) RGB: hue from the direction, value from the speed."""
    hue = (np.arctan2(flow[..., 1], flow[..., 0]) / (2 * np.pi)) % 1.0
    value = np.clip(np.hypot(flow[..., 0], flow[..., 1]) / fastest, 0.0, 1.0)
    sector = np.floor(hue * 6.0)
    fraction = hue * 6.0 - sector
    falling, rising = value * (1.0 - fraction), value * fraction
    zero = np.zeros_like(value)
    choices = [
        (value, rising, zero), (falling, value, zero), (zero, value, rising),
        (zero, falling, value), (rising, zero, value), (value, zero, falling),
    ]
    sector = sector.astype(int) % 6
    rgb = np.zeros(flow.shape[:2] + (3,), dtype=np.float32)
    for k, channels in enumerate(choices):
        rgb[sector == k] = np.stack(channels, axis=-1)[sector == k]
    return rgb
