"""``fluidymation masks SCENE``: write every scene layer's binary mask sequence."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from fluidymation.pipeline.progress import progress
from fluidymation.pipeline.resolve import parse_window, plan_scene
from fluidymation.pipeline.scene import load_scene
from fluidymation.stages.files import write_png, write_text
from fluidymation.stages.rasterize import ColorTally, Params, rasterize_frame


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser("masks", help="rasterize each scene layer into a mask sequence",
                                   description="Write DIR/<layer>/00000.png ... (0/255; numbered from the "
                                               "start of the scene's frame range) and DIR/layers.json.")
    parser.add_argument("scene", help="the scene's YAML file")
    parser.add_argument("-o", "--output", metavar="DIR", help="output folder (default: <output.dir>/masks)")
    parser.add_argument("--frames", metavar="A:B", help="only scene frames A to B (B exclusive)")
    parser.add_argument("--layer", action="append", metavar="NAME", help="only this layer (repeatable)")
    parser.set_defaults(run=run)


def run(args) -> int:
    plan = plan_scene(load_scene(args.scene))
    frames = plan.frames(parse_window(args.frames))
    layers = [plan.layer(name) for name in args.layer] if args.layer else list(plan.layers)
    out_dir = Path(args.output) if args.output else plan.scene.output.dir / "masks"
    params = Params(size=plan.size, fps=plan.fps)
    records = []
    with progress(len(frames) * len(layers), "masks", quiet=args.quiet) as bar:
        for layer in layers:
            tally, areas = ColorTally(), []
            for frame in frames:
                raster = rasterize_frame(plan.source, layer.vector_layers, frame, params)
                mask = raster.mask
                write_png(out_dir / layer.dirname / f"{frame - plan.start:05d}.png", mask.astype(np.uint8) * 255)
                tally.add(raster.rgba)
                areas.append(int(mask.sum()))
                bar.update()
            records.append({
                "name": layer.name,
                "folder": layer.dirname,
                "select": list(layer.vector_layers),
                "color": layer.spec.color or tally.dominant(),
                "z": layer.z,
                "area": areas,
            })
    summary = {
        "input": str(plan.scene.input),
        "size": list(plan.size),
        "fps": plan.fps,
        "frames": {"start": frames.start, "end": frames.stop, "scene_start": plan.start},
        "layers": records,
    }
    write_text(out_dir / "layers.json", json.dumps(summary, indent=2) + "\n")
    if not args.quiet:
        print(f"wrote {len(frames)} frames of {len(layers)} layer(s) to {out_dir}")
    return 0
