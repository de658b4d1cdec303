"""``fluidymation masks SCENE``: write every scene layer's binary mask sequence."""

from __future__ import annotations

from pathlib import Path

from fluidymation.pipeline.layer_stages import rasterize_layer
from fluidymation.pipeline.progress import progress
from fluidymation.pipeline.render import write_layers_summary
from fluidymation.pipeline.resolve import parse_window, plan_scene
from fluidymation.pipeline.scene import load_scene


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "masks", description="Write DIR/<layer>/00000.png ... (0/255; numbered from the start of the scene's "
                             "frame range) and DIR/layers.json.")
    parser.add_argument("scene", help="the scene's YAML file")
    parser.add_argument("-o", "--output", metavar="DIR", help="output folder (default: <output.dir>/masks)")
    parser.add_argument("--frames", metavar="A:B", help="only scene frames A to B (B exclusive)")
    parser.add_argument("--layer", action="append", metavar="NAME", help="only this layer (repeatable)")
    parser.set_defaults(run=run)


def run(args) -> int:
    plan = plan_scene(load_scene(args.scene), strict=args.strict)
    frames = plan.frames(parse_window(args.frames))
    layers = [plan.layer(name) for name in args.layer] if args.layer else list(plan.layers)
    out_dir = Path(args.output) if args.output else plan.scene.output.dir / "masks"
    with progress(len(frames) * len(layers), "masks", quiet=args.quiet) as bar:
        records = {layer.name: rasterize_layer(plan, layer, frames, out_dir / layer.dirname, bar=bar)
                   for layer in layers}
    write_layers_summary(plan, records, out_dir, frames)
    if not args.quiet:
        print(f"wrote {len(frames)} frames of {len(layers)} layer(s) to {out_dir}")
    return 0
