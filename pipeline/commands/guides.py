"""``fluidymation guides SCENE --layer NAME``: views (and arrays) of a layer's guidance channels."""

from __future__ import annotations

import tempfile
from pathlib import Path

from fluidymation.errors import InputError
from fluidymation.pipeline.layer_stages import motion_reader, write_layer_guides, write_layer_motion
from fluidymation.pipeline.resolve import parse_window, plan_scene
from fluidymation.pipeline.scene import load_scene
from fluidymation.stages.rasterize import Params as RasterParams
from fluidymation.stages.rasterize import rasterize_frame
from fluidymation.stages.vector.svg_reader import sequence_files


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "guides", description="Compute a layer's guidance channels over the whole scene range and write PNG views "
                    "per frame: flow/ (hue = direction, brightness = speed), ext_plus/, ext_minus/, shape/, "
                    "dist/, segments/. With --raw also the arrays as .npy.")
    parser.add_argument("scene", help="the scene's YAML file")
    parser.add_argument("--layer", required=True, metavar="NAME", help="the scene layer")
    parser.add_argument("-o", "--output", metavar="DIR", help="output folder (default: <output.dir>/guides/<layer>)")
    parser.add_argument("--frames", metavar="A:B", help="only write scene frames A to B (B exclusive)")
    parser.add_argument("--raw", action="store_true", help="also write flow/, ext_plus/, ext_minus/, dist/, "
                                                           "shape/ arrays as .npy (float32, flow in px/frame)")
    parser.add_argument("--flow", metavar="PATTERN", help="use given flows (.npy or Middlebury .flo, e.g. "
                                                          "flow/%%05d.flo) instead of estimating them from the masks")
    parser.set_defaults(run=run)


def run(args) -> int:
    plan = plan_scene(load_scene(args.scene), strict=args.strict)
    layer = plan.layer(args.layer)
    window = plan.frames(parse_window(args.frames))
    out_dir = Path(args.output) if args.output else plan.scene.output.dir / "guides" / layer.dirname
    raster = RasterParams(size=plan.size, fps=plan.fps)
    given = given_flows(args.flow, plan.frame_count) if args.flow else None

    def coverage(index: int):
        image = rasterize_frame(plan.renderer, plan.document, layer.vector_layers, plan.start + index, raster)
        return image.coverage

    with tempfile.TemporaryDirectory(prefix="fluidymation-motion-") as motion:
        if given is None and layer.flow == "vector":
            write_layer_motion(plan, layer, Path(motion))
            given = motion_reader(Path(motion))
        write_layer_guides(plan, layer, window, coverage, out_dir, quiet=args.quiet, raw=args.raw, given_flow=given)
    if not args.quiet:
        print(f"wrote guide views of frames {window.start}:{window.stop} of layer {layer.name} to {out_dir}")
    return 0


def given_flows(pattern: str, count: int) -> list[Path]:
    """The flow files of a pattern, one per scene frame of the range."""
    files = sequence_files(Path(pattern))
    if len(files) < count:
        raise InputError(f"{pattern}: {len(files)} flow files for {count} frames")
    return files[:count]
